"""The TABLE strategy's mixture weight and n_h, measured in renders (issue 5: "choose its default
and the n_h it uses from measurements").

Run inside Blender through tests/blender/run_test.py (scripts/bench does):

    /usr/bin/python3 tests/blender/run_test.py --zip build/hairis-addon.zip \
        bench/mixture_weight_study.py

A head of particle hair (the demo scene, smaller) under a sun and a sky is rendered with the
TABLE strategy at several multiple_weight and n_h values, and with ANALYTIC for reference,
SEEDS times at SAMPLES samples. The noise of each setting is the mean over pixels of the
variance across seeds, relative to the squared image mean (per sample: times SAMPLES);
efficiency divides by the render time as well. Writes mixture_weight.md and .json into
HAIRIS_STUDY_OUT (default bench/results).
"""

import json
import math
import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests",
                                "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
QUICK = os.environ.get("HAIRIS_STUDY_QUICK", "0") == "1"
OUT = os.environ.get("HAIRIS_STUDY_OUT",
                     os.path.join(os.path.dirname(os.path.abspath(__file__)), "results"))
SEEDS = 4 if QUICK else 12
SAMPLES = 8 if QUICK else 16
SETTINGS = [("ANALYTIC", 0.0, 2)] + [("TABLE", w, 2) for w in (0.0, 0.1, 0.25, 0.5)] + \
    [("TABLE", 0.25, n_h) for n_h in (1, 8)]


LIGHTINGS = {
    # Key light from the front-left, and a back light (the sun behind and above the head,
    # outside the frame), where light reaches most strands through other strands.
    "front": (math.radians(50), 0.0, math.radians(30)),
    "back": (math.radians(-30), 0.0, math.radians(10)),
}


def make_scene(lighting):
    scene = helpers.reset()
    scene.render.engine = "HAIRIS"
    helpers.make_camera(scene, location=(0.0, -7.5, 0.3), resolution=(96, 72), percentage=100)
    helpers.make_world(scene, color=(0.35, 0.45, 0.6), strength=1.0)
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.45, "Melanin Redness": 0.5, "Roughness": 0.3, "Radial Roughness": 0.3})
    skin = helpers.make_surface_material("Skin", (0.7, 0.5, 0.4, 1.0))
    helpers.make_particle_hair(scene, count=800, children=10, location=(0.0, 0.0, 0.3),
                               scale=1.3, hair_material=hair, skin_material=skin)
    helpers.make_light(scene, "SUN", "Sun", energy=4.0, angle=math.radians(2.0),
                       rotation=LIGHTINGS[lighting])
    settings = scene.hairis
    settings.samples = SAMPLES
    settings.max_bounces = 8
    settings.auto_bake = True
    settings.threads = 0
    bpy.context.view_layer.update()
    return scene


def render(scene):
    start = time.monotonic()
    bpy.ops.render.render()
    seconds = time.monotonic() - start
    path = os.path.join(ARGS.workdir, "render.exr")
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    bpy.data.images["Render Result"].save_render(path, scene=scene)
    image = bpy.data.images.load(path)
    pixels = np.empty(image.size[0] * image.size[1] * 4, np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(-1, 4)[:, :3].astype(np.float64), seconds


def main():
    rows = []
    for lighting in LIGHTINGS:
        rows += study(lighting)
    write(rows)
    sys.exit(0)


def study(lighting):
    scene = make_scene(lighting)
    settings = scene.hairis
    settings.strategy = "TABLE"
    render(scene)  # warm-up: the auto-bake happens here, not in the timed renders
    rows = []
    for strategy, weight, n_h in SETTINGS:
        settings.strategy = strategy
        settings.multiple_weight = weight
        settings.n_h = str(n_h)
        images, seconds = [], 0.0
        for seed in range(1, SEEDS + 1):
            settings.seed = seed
            image, t = render(scene)
            images.append(image)
            seconds += t
        stack = np.stack(images)
        luminance = stack @ np.array([0.2126, 0.7152, 0.0722])
        mean = float(luminance.mean())
        variance = float(luminance.var(axis=0, ddof=1).mean()) * SAMPLES / mean ** 2
        time_per_render = seconds / SEEDS
        rows.append({"lighting": lighting, "strategy": strategy, "multiple_weight": weight,
                     "n_h": n_h,
                     "relative_variance_per_sample": variance, "mean": mean,
                     "seconds_per_render": time_per_render,
                     "efficiency": 1.0 / (variance * time_per_render)})
        print("%s %-8s w=%.2f n_h=%d: variance/sample %.4g, %.2f s per render, mean %.5f"
              % (lighting, strategy, weight, n_h, variance, time_per_render, mean), flush=True)
    return rows


def write(rows):
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "mixture_weight.json"), "w") as f:
        json.dump({"seeds": SEEDS, "samples": SAMPLES, "rows": rows}, f, indent=1)
    best = {lighting: max(r["efficiency"] for r in rows if r["lighting"] == lighting)
            for lighting in LIGHTINGS}
    with open(os.path.join(OUT, "mixture_weight.md"), "w") as f:
        f.write("# TABLE strategy: mixture weight and n_h in a render\n\n"
                "Demo-like head (800 parents × 10 children), sun and sky, 96×72, 8 bounces; "
                "%d seeds × %d samples per setting. Relative variance per sample = mean over "
                "pixels of the luminance variance across seeds × samples / mean²; efficiency = "
                "1 / (variance × seconds per render), relative to the best. "
                "Generated by `bench/mixture_weight_study.py`.\n\n"
                "| lighting | strategy | multiple_weight | n_h | variance per sample "
                "| s per render | relative efficiency | image mean |\n"
                "|---|---|---|---|---|---|---|---|\n"
                % (SEEDS, SAMPLES))
        for r in rows:
            f.write("| %s | %s | %.2f | %d | %.4g | %.2f | %.2f | %.5f |\n"
                    % (r["lighting"], r["strategy"], r["multiple_weight"], r["n_h"],
                       r["relative_variance_per_sample"], r["seconds_per_render"],
                       r["efficiency"] / best[r["lighting"]], r["mean"]))


main()
