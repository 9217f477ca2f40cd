"""Hairis against Cycles 4.5/5.0 on Huang hair alone, with the power to see a 1% bias there
(Blender 4.0+; 3.4 has no Huang model), at any sample and seed count.

    python3 tests/blender/run_test.py --bpy-python .venvs/bpy-4.5/bin/python \
        --expect-version 4.5 --install extension --extension-zip build/hairis-extension.zip \
        --zip build/hairis-addon.zip --timeout 1400 \
        bench/studies/huang_coverage/huang_power_study.py

The comparison of tests/blender/test_cycles_huang_power.py (hair_power.check on
hair_power.huang_head_scene) with its verdict printed rather than raised, at
HAIRIS_POWER_SAMPLES samples and HAIRIS_POWER_SEEDS seeds (the test's 96 and 16 by default).
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


def main():
    """hair_power.check on the Huang head; its verdict printed, not raised."""
    try:
        hair_power.check(hair_power.huang_head_scene, hair_power.HAIR, SAMPLES, SEEDS, ARGS.workdir)
        print("VERDICT within the noise, and the control found")
    except AssertionError as error:
        print("VERDICT %s" % error)


helpers.run_script(main)
