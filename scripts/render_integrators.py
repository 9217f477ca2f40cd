"""The README's side-by-side of Hairis' two integrators: the demo head (tests/blender/helpers.py's
make_demo_head) in blonde hair, rendered with PATH and with DUAL_SCATTERING.

    /usr/bin/python3 tests/blender/run_test.py --blender blender --zip build/hairis-addon.zip \\
        --timeout 3600 scripts/render_integrators.py

Renders PATH at PATH_SPP samples, then DUAL_SCATTERING at the sample count that takes about as
long (from a timed 4-spp render), both on one thread after a warm-up render, and writes
docs/integrators.png: PATH on the left, DUAL_SCATTERING on the right, and
docs/integrators.txt with the sample counts and times. Environment: HAIRIS_FIGURE_SIZE
(240x180), HAIRIS_FIGURE_PATH_SPP (64), HAIRIS_FIGURE_OUT (docs).
"""
import os
import sys

import bpy
import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
SIZE = tuple(int(v) for v in os.environ.get("HAIRIS_FIGURE_SIZE", "240x180").split("x"))
PATH_SPP = int(os.environ.get("HAIRIS_FIGURE_PATH_SPP", "64"))
OUT = os.environ.get("HAIRIS_FIGURE_OUT", os.path.join(ROOT, "docs"))


def render(scene, integrator, samples):
    """(linear RGB image, seconds)."""
    scene.hairis.integrator = integrator
    scene.hairis.samples = samples
    return helpers.render_pixels(scene, "HAIRIS", 1, ARGS.workdir)


def to_srgb(linear):
    """The sRGB transfer function (Blender's Standard view transform)."""
    linear = np.clip(linear, 0.0, 1.0)
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)


def main():
    scene = helpers.make_demo_head(resolution=SIZE, count=1500, children=10)
    hair = bpy.data.materials["Hair"].node_tree.nodes["Principled Hair BSDF"]
    helpers.socket(hair, "Melanin").default_value = 0.1
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    settings = scene.hairis
    settings.max_bounces = 8
    settings.strategy = "TABLE"
    settings.auto_bake = True
    settings.threads = 1
    bpy.context.view_layer.update()
    render(scene, "DUAL_SCATTERING", 1)  # warm-up: bake, dual-scattering averages
    path, path_seconds = render(scene, "PATH", PATH_SPP)
    _, probe_seconds = render(scene, "DUAL_SCATTERING", 4)
    dual_spp = max(1, int(round(4 * path_seconds / probe_seconds)))
    dual, dual_seconds = render(scene, "DUAL_SCATTERING", dual_spp)
    height, width = path.shape[:2]
    gap = 4
    canvas = np.ones((height, 2 * width + gap, 4), np.float32)
    canvas[:, :width, :3] = to_srgb(path)
    canvas[:, width + gap:, :3] = to_srgb(dual)
    image = bpy.data.images.new("integrators", canvas.shape[1], canvas.shape[0], alpha=True)
    image.colorspace_settings.name = "Non-Color"  # the pixels are display values already
    image.pixels.foreach_set(canvas.reshape(-1))
    os.makedirs(OUT, exist_ok=True)
    image.filepath_raw = os.path.join(OUT, "integrators.png")
    image.file_format = "PNG"
    image.save()
    with open(os.path.join(OUT, "integrators.txt"), "w") as handle:
        handle.write("left: PATH %d spp, %.1f s; right: DUAL_SCATTERING %d spp, %.1f s "
                     "(one thread, %dx%d, 8 bounces, Blender %s)\n"
                     % (PATH_SPP, path_seconds, dual_spp, dual_seconds, width, height,
                        bpy.app.version_string))
    print("integrators: PATH %d spp %.1f s, DUAL %d spp %.1f s" % (
        PATH_SPP, path_seconds, dual_spp, dual_seconds), flush=True)


helpers.run_script(main)
