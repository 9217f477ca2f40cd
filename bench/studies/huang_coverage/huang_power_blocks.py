"""Which part of Hairis' Huang shading makes a block of the Huang power test differ from Cycles:
Hairis re-rendered in other configurations against the Cycles stack a power-test run kept.

First keep a power-test run (Cycles' and Hairis' stacks and the hair mask):

    HAIRIS_POWER_SEEDS=48 HAIRIS_COMPARE_DUMP=/tmp/huang48.npz python3 tests/blender/run_test.py \
        --bpy-python .venvs/bpy-4.5/bin/python --expect-version 4.5 --install extension \
        --extension-zip build/hairis-extension.zip --zip build/hairis-addon.zip \
        --timeout 1800 tests/blender/test_cycles_huang_power.py

then, with the same Blender:

    HAIRIS_STUDY_DUMP=/tmp/huang48.npz HAIRIS_STUDY_CONFIGS=TABLE:CYCLES,UNIFORM:CYCLES \
    python3 tests/blender/run_test.py --bpy-python .venvs/bpy-4.5/bin/python \
        --expect-version 4.5 --install extension --extension-zip build/hairis-extension.zip \
        --zip build/hairis-addon.zip --timeout 1800 \
        bench/studies/huang_coverage/huang_power_blocks.py

Each configuration is STRATEGY:HUANG_SAMPLING (the add-on's names), or
FINE:option=value:... to bake the head's tables with those bake options (hairis.h, e.g.
huang_theta_o=48) into the auto-bake cache and render TABLE:CYCLES with them. The scene is the
same in every process (its groom grows from the sphere's vertices), so the kept Cycles stack
stands for this process' scene. Per 16×16 block of the mask (as the test's blocks): the
relative difference of the hair mean per channel and Welch's t over the seeds.
"""

import importlib
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "tests", "blender"))
import hair_power  # noqa: E402
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
helpers.require_library(PACKAGE)
if helpers.VERSION < (4, 0, 0):
    raise SystemExit("Blender %s has no Huang model" % bpy.app.version_string)
BLOCK, MIN_PIXELS = 16, 32
SAMPLES = int(os.environ.get("HAIRIS_POWER_SAMPLES", "96"))


def block_lines(cycles, hairis, mask):
    """One line per block with at least MIN_PIXELS hair pixels: relative difference and t."""
    seeds = cycles.shape[0]
    lines = []
    for y in range(0, mask.shape[0] - BLOCK + 1, BLOCK):
        for x in range(0, mask.shape[1] - BLOCK + 1, BLOCK):
            inside = mask[y:y + BLOCK, x:x + BLOCK]
            if inside.sum() < MIN_PIXELS:
                continue
            c = cycles[:, y:y + BLOCK, x:x + BLOCK][:, inside].mean(axis=1)
            h = hairis[:, y:y + BLOCK, x:x + BLOCK][:, inside].mean(axis=1)
            difference = h.mean(axis=0) - c.mean(axis=0)
            se = np.sqrt(h.var(axis=0, ddof=1) / seeds + c.var(axis=0, ddof=1) / seeds)
            lines.append("block (%d, %d), %d pixels: relative difference %s%%, t %s"
                         % (y, x, inside.sum(), np.round(100 * difference / c.mean(axis=0), 2),
                            np.round(difference / se, 2)))
    return lines


def bake_into_cache(values):
    """Bakes the head's hair material with the default bake options and ``values`` into the
    auto-bake cache, where the next render finds it."""
    native = importlib.import_module(PACKAGE.__name__ + ".native")
    tables = importlib.import_module(PACKAGE.__name__ + ".tables")
    library = native.load_library()
    params = tables.material_parameters(bpy.data.materials[hair_power.HAIR])
    fiber = library.fiber_principled(tables.principled_struct(library, params))
    options = tables.bake_options(library, multiple=False)
    options.update(values)
    baked = library.bake_tables(fiber, options)
    print("baked %s into %s" % (baked.info, tables.write_cache(baked, fiber)))


def main():
    """Every configuration of HAIRIS_STUDY_CONFIGS against the kept Cycles stack."""
    kept = np.load(os.environ["HAIRIS_STUDY_DUMP"])
    cycles, mask = kept["cycles"], kept["mask"]
    scene = hair_power.huang_head_scene(SAMPLES)
    for config in os.environ.get("HAIRIS_STUDY_CONFIGS", "TABLE:CYCLES").split(","):
        label = config
        if config.startswith("FINE"):
            bake_into_cache(dict(item.split("=") for item in config.split(":")[1:]))
            config = "TABLE:CYCLES"
        strategy, sampling = config.split(":")
        scene.hairis.strategy = strategy
        scene.hairis.huang_sampling = sampling
        scene.hairis.auto_bake = True
        hairis, _seconds = hair_power.render_stack(scene, "HAIRIS", "study", cycles.shape[0],
                                                   ARGS.workdir)
        print("RESULT %s\n  %s" % (label, "\n  ".join(block_lines(cycles, hairis, mask))))


helpers.run_script(main)
