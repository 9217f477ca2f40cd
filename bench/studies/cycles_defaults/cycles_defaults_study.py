"""How much Cycles' biased defaults move hair, and whether Hairis follows them.

The demo head (helpers.make_demo_head at 160 x 120, 1500 strands x 10 children, a sun and a
sky) with light hair (Melanin from STUDY_MELANIN, default 0.15), 8 bounces, STUDY_SPP samples
(default 128) and STUDY_SEEDS seeds (default 4) per engine and case, film transparent so that
a pixel is hair or skin where its alpha is 1. Cases, each from helpers.match_cycles (every
biased setting off) with one setting back at Blender's default: none, Filter Glossy 1, Clamp
Indirect 10, Blackman-Harris 1.5 px, and all of them together. For each engine and case it
prints the mean of the covered pixels per channel, its ratio to the engine's own "none" case,
and Hairis / Cycles with the standard error of that ratio from the seeds.

    STUDY_SPP=128 STUDY_SEEDS=4 python3 tests/blender/run_test.py \\
        --bpy-python .venvs/bpy-4.5/bin/python --expect-version 4.5 --install extension \\
        --extension-zip build/hairis-extension.zip --zip build/hairis-addon.zip --timeout 3000 \\
        bench/studies/cycles_defaults/cycles_defaults_study.py
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "tests", "blender"))
import helpers  # noqa: E402

CASES = (
    ("none", {}),
    ("Filter Glossy 1", {"blur_glossy": 1.0}),
    ("Clamp Indirect 10", {"sample_clamp_indirect": 10.0}),
    ("Blackman-Harris 1.5 px", {"pixel_filter_type": "BLACKMAN_HARRIS", "filter_width": 1.5}),
    ("all defaults", {"blur_glossy": 1.0, "sample_clamp_indirect": 10.0,
                      "pixel_filter_type": "BLACKMAN_HARRIS", "filter_width": 1.5}),
)


def main():
    args, package = helpers.setup()
    helpers.require_library(package)
    spp = int(os.environ.get("STUDY_SPP", "128"))
    seeds = int(os.environ.get("STUDY_SEEDS", "4"))
    scene = helpers.make_demo_head(resolution=(160, 120))
    melanin = float(os.environ.get("STUDY_MELANIN", "0.15"))
    for node in bpy.data.materials["Hair"].node_tree.nodes:
        if node.bl_idname == "ShaderNodeBsdfHairPrincipled":
            node.inputs["Melanin"].default_value = melanin
    helpers.match_engines(scene, spp, 8)
    scene.render.film_transparent = True
    print("Blender %s, %d spp x %d seeds, melanin %g"
          % (bpy.app.version_string, spp, seeds, melanin))
    means = {}
    for name, values in CASES:
        helpers.match_cycles(scene, spp, 8)
        for key, value in values.items():
            setattr(scene.cycles, key, value)
        for engine in ("CYCLES", "HAIRIS"):
            per_seed = []
            for seed in range(1, seeds + 1):
                image, _seconds = helpers.render_pixels(scene, engine, seed, args.workdir,
                                                        alpha=True)
                covered = image[..., 3] > 0.999
                per_seed.append(image[covered][:, :3].mean(axis=0))
            means[engine, name] = np.array(per_seed)
    print("| case | Cycles / its none | Hairis / its none | Hairis / Cycles (± s.e.) |")
    print("|---|---|---|---|")
    for name, _values in CASES:
        cycles, hairis = means["CYCLES", name], means["HAIRIS", name]
        c, h = cycles.mean(axis=0), hairis.mean(axis=0)
        se = (h / c) * np.sqrt(cycles.var(axis=0, ddof=1) / (seeds * c * c)
                               + hairis.var(axis=0, ddof=1) / (seeds * h * h))
        fmt = ", ".join
        print("| %s | %s | %s | %s |" % (
            name, fmt("%.4f" % v for v in c / means["CYCLES", "none"].mean(axis=0)),
            fmt("%.4f" % v for v in h / means["HAIRIS", "none"].mean(axis=0)),
            fmt("%.4f ± %.4f" % (r, e) for r, e in zip(h / c, se))), flush=True)


helpers.run_script(main)
