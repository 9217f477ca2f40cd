"""Hairis against Cycles on Huang hair alone, with the power to see a 1% bias there.

The scene is test_cycles_hair_power's head of hair with Huang fibers
(hair_power.huang_head_scene). Hairis renders with the add-on's defaults for Huang hair: the
Table strategy with Auto Bake and Huang Sampling Cycles, so BSDF samples are Cycles' chained
sampler with its weight and light samples are shaded with the baked f. The comparison, its
sizing and its negative control (every light and the world 2% brighter) are
hair_power.check's (POWER.md).

Not in CI: in Blender 5.0 a block of its hair lies at or beyond its critical value (1.29 on
the icosphere head; on an earlier head 0.92 in one process and 1.02 in another, from Cycles'
heavy-tailed Huang weights), and on another head the error the baked f's quadrature rule
leaves, about 1% towards some lights, put a block beyond it (POWER.md has the figures and the
bake option that removes that error). Blender 3.4 has no Huang model.
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
