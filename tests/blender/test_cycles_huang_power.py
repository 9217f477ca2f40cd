"""Hairis against Cycles on Huang hair alone, with the power to see a 1% bias there.

The scene is test_cycles_hair_power's head of hair with Huang fibers
(hair_power.huang_head_scene). Hairis renders with the add-on's defaults for Huang hair: the
Table strategy with Auto Bake and Huang Sampling Cycles, so BSDF samples are Cycles' chained
sampler with its weight and light samples are shaded with the baked f. The comparison, its
sizing and its negative control (every light and the world 2% brighter) are
hair_power.check's (POWER.md).

Not in CI: it passes, but one block of its hair sits at 0.99 of its critical value on a real
difference of about 1% that the baked f's quadrature rule leaves (at 48 seeds that block
fails; POWER.md has the figures and what removes it). Blender 3.4 has no Huang model.
"""

import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hair_power  # noqa: E402
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
if helpers.VERSION < (4, 0, 0):
    helpers.skip("Blender %s has no Huang model" % bpy.app.version_string)
SAMPLES = int(os.environ.get("HAIRIS_POWER_SAMPLES", "96"))
SEEDS = int(os.environ.get("HAIRIS_POWER_SEEDS", "16"))


def test_huang_hair_matches_cycles_with_power():
    """Hairis' Huang hair pixels are Cycles' within the noise, the comparison has the power to
    see a 1% bias of their mean, and it finds every deliberate error of hair_power.CONTROLS."""
    hair_power.check(hair_power.huang_head_scene, hair_power.HAIR, SAMPLES, SEEDS, ARGS.workdir)


helpers.run([test_huang_hair_matches_cycles_with_power])
