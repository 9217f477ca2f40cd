"""What a viewport view change costs on a big groom: the add-on's viewport sequence through the
C API, outside Blender.

    python3 bench/studies/groom_scale/viewport_restart.py [strands (default 250000)] \\
        [library (default build/lib/libhairis.so)]

A Curves-like groom of `strands` random strands of 9 points (radius 0.002) in a unit cube, a
Chiang material (analytic strategy: no tables), a sun and a grey world; then four orbit steps,
each as the viewport renders a view: a quarter-resolution pass of 1 sample, then the full
320x180 at 4 samples (hairis_render_progressive). Prints, per call, its seconds,
build_seconds and scene_reused: the first call builds the scene (what every call paid when
each render built anew), the others keep that build while only the camera moves.
"""

import math
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(ROOT, "addon", "hairis"))
import native  # noqa: E402

POINTS = 9


def groom(library, strands):
    """The scene with its groom, lights and world (no camera yet)."""
    rng = np.random.default_rng(1)
    roots = rng.uniform(-0.5, 0.5, (strands, 3)).astype(np.float32)
    t = np.linspace(0.0, 0.3, POINTS, dtype=np.float32)[None, :, None]
    lean = rng.normal(0.0, 0.3, (strands, 1, 3)).astype(np.float32)
    lean += np.array([0, 0, 1], np.float32)
    positions = (roots[:, None, :] + t * lean).reshape(-1, 3)
    first = np.arange(strands + 1, dtype=np.uint32) * POINTS
    radii = np.full(strands * POINTS, 0.002, np.float32)
    scene = library.scene()
    with library.fiber({"model": "chiang"}) as fiber:
        material = scene.add_hair_material(fiber)
    scene.add_curves(material, first, positions, radii)
    scene.add_light({"type": "sun", "direction": "0.3,0.2,1", "strength": 3})
    scene.set_world((0.4, 0.45, 0.5), 1.0)
    return scene


def camera(angle, width, height):
    """A camera on a circle around the groom, looking at its centre."""
    eye = np.array([3.0 * math.sin(angle), -3.0 * math.cos(angle), 0.3])
    forward = -eye / np.linalg.norm(eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    matrix = np.eye(4)
    matrix[:3, 0], matrix[:3, 1], matrix[:3, 2], matrix[:3, 3] = right, up, -forward, eye
    aspect, half = width / height, 0.3
    frame = [half * aspect, half, -1, half * aspect, -half, -1, -half * aspect, -half, -1,
             -half * aspect, half, -1]
    return {"matrix": ",".join("%g" % v for v in matrix.reshape(-1)),
            "frame": ",".join("%g" % v for v in frame), "width": width, "height": height}


def main():
    strands = int(sys.argv[1]) if len(sys.argv) > 1 else 250000
    library = native.load_library(sys.argv[2] if len(sys.argv) > 2
                                  else os.path.join(ROOT, "build", "lib", "libhairis.so"))
    start = time.monotonic()
    scene = groom(library, strands)
    print("groom of %d strands handed over in %.2f s" % (strands, time.monotonic() - start))
    settings = {"strategy": "analytic", "max_bounces": 4, "threads": 0}
    print("| step | pass | seconds | build_seconds | scene_reused |")
    print("|---|---|---|---|---|")
    for step in range(4):
        for label, width, height, samples in (("preview", 80, 45, 1), ("full", 320, 180, 4)):
            scene.set_camera(camera(0.3 * step, width, height))
            _, _, stats = scene.render_progressive(dict(settings, samples=samples))
            reused = getattr(stats, "scene_reused", 0)
            print("| %d | %s | %.2f | %.2f | %d |"
                  % (step, label, stats.seconds, stats.build_seconds, reused))
    scene.close()


if __name__ == "__main__":
    main()
