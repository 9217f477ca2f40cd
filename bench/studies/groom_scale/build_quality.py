"""What Embree's build quality costs and saves on a big groom, through the C API, outside
Blender.

    python3 bench/studies/groom_scale/build_quality.py [strands (default 250000)] \\
        [repeats (default 3)] [library (default build/lib/libhairis.so)]

viewport_restart.py's groom and camera. Each repeat renders, for each build quality in turn
(low, medium), a viewport-sized view (320x180, 4 samples) and then, on the build that view left,
16 samples more (a longer render of the same view); a change of quality builds anew. Prints
per repeat the build seconds and the render seconds of both renders, then the medians and the
low / medium ratios.
"""

import os
import statistics
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(ROOT, "addon", "hairis"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import native  # noqa: E402
from viewport_restart import camera, groom  # noqa: E402

QUALITIES = ("low", "medium")


def main():
    strands = int(sys.argv[1]) if len(sys.argv) > 1 else 250000
    repeats = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    library = native.load_library(sys.argv[3] if len(sys.argv) > 3
                                  else os.path.join(ROOT, "build", "lib", "libhairis.so"))
    scene = groom(library, strands)
    scene.set_camera(camera(0.3, 320, 180))
    base = {"strategy": "analytic", "max_bounces": 4, "threads": 0}
    results = {q: {"build": [], "view": [], "longer": []} for q in QUALITIES}
    print("groom of %d strands; %d repeats" % (strands, repeats))
    print("| repeat | quality | build (s) | 4 spp render (s) | 16 spp render (s) | reused |")
    print("|---|---|---|---|---|---|")
    for repeat in range(repeats):
        for quality in QUALITIES:
            settings = dict(base, build_quality=quality)
            _, _, view = scene.render_progressive(dict(settings, samples=4))
            _, _, longer = scene.render_progressive(dict(settings, samples=16))
            r = results[quality]
            r["build"].append(view.build_seconds)
            r["view"].append(view.seconds - view.build_seconds)
            r["longer"].append(longer.seconds - longer.build_seconds)
            print("| %d | %s | %.2f | %.2f | %.2f | %d |"
                  % (repeat, quality, view.build_seconds, view.seconds - view.build_seconds,
                     longer.seconds - longer.build_seconds, getattr(longer, "scene_reused", 0)))
    print()
    print("| quality | build (median s) | 4 spp render | 16 spp render |")
    print("|---|---|---|---|")
    medians = {q: {k: statistics.median(v) for k, v in results[q].items()} for q in QUALITIES}
    for quality in QUALITIES:
        m = medians[quality]
        print("| %s | %.2f | %.2f | %.2f |" % (quality, m["build"], m["view"], m["longer"]))
    low, medium = medians["low"], medians["medium"]
    print("| low / medium | %.2f | %.2f | %.2f |"
          % (low["build"] / medium["build"], low["view"] / medium["view"],
             low["longer"] / medium["longer"]))


if __name__ == "__main__":
    main()
