"""Hairis against Cycles 4.5/5.0 on Huang hair alone, with the power to see a 1% bias there
(Blender 4.0+; 3.4 has no Huang model). A study, not a CI test: see its README section.

    python3 tests/blender/run_test.py --bpy-python .venvs/bpy-4.5/bin/python \
        --expect-version 4.5 --install extension --extension-zip build/hairis-extension.zip \
        --zip build/hairis-addon.zip --timeout 1400 \
        bench/studies/huang_coverage/huang_power_study.py

The scene is test_cycles_hair_power's head of hair (hair_power.head_scene: particle hair on a
diffuse sphere, a sun, a point light with a radius, an area light and a world colour, 8
bounces, Cycles matched by helpers.match_cycles) with the Principled Hair BSDF switched to the
Huang model at Blender's defaults for it (aspect 0.85, the lobes at 1). Hairis renders with
the add-on's defaults for Huang hair: the Table strategy with Auto Bake and Huang Sampling
Cycles, so BSDF samples are Cycles' chained sampler with its weight and light samples are
shaded with the baked f, the expectation of Cycles' eval. The comparison and its sizing are
hair_power.check's (tests/blender/POWER.md): the hair mean per channel and its 16×16 blocks
against Cycles' and the smallest bias found with 90% power, and the negative control (every
light and the world 2% brighter). Prints hair_power.check's figures and its verdict.
"""

import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "tests", "blender"))
import hair_power  # noqa: E402
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
if helpers.VERSION < (4, 0, 0):
    raise SystemExit("Blender %s has no Huang model" % bpy.app.version_string)
SAMPLES = int(os.environ.get("HAIRIS_POWER_SAMPLES", "96"))
SEEDS = int(os.environ.get("HAIRIS_POWER_SEEDS", "16"))


def huang_head(samples):
    """The head of hair with Huang fibers."""
    return hair_power.head_scene(samples, "HUANG")


def main():
    """hair_power.check on the Huang head; its verdict printed, not raised."""
    try:
        hair_power.check(huang_head, hair_power.HAIR, SAMPLES, SEEDS, ARGS.workdir)
        print("VERDICT within the noise, and the control found")
    except AssertionError as error:
        print("VERDICT %s" % error)


helpers.run_script(main)
