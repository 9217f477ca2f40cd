"""Hairis against Cycles on the hair pixels alone, with the power to see a 1% bias there.

The scene is test_cycles_compare's (Chiang hair: particle hair at Offset 2° on a diffuse
sphere, a sun, a point light with a radius, an area light and a world colour; Cycles matched
by helpers.match_cycles, Hairis at its default strategy) at BOUNCES bounces, so multiple
scattering between strands is compared, framed as a square crop of the hair, with the
settings match_cycles turns off back at Blender's defaults, as a scene set up for Cycles has
them: Filter Glossy 1, Clamping Indirect 10, Light Threshold 0.01, Blackman-Harris 1.5 px. A
mask marks the hair pixels: Cycles renders the scene once with every hair material replaced by
an emission of its own primary colour and everything else black, and a pixel is hair where the
hair covers at least half of it.

Both engines render SEEDS images of SAMPLES samples; compare_stats.compare_hair compares, per
channel, the mean over all hair pixels and over each hair material's pixels (Welch's t,
Šidák-corrected over masks × channels) and the hair mean of every 16×16 block. From the
seed-to-seed variances it measures, it computes the smallest bias of the hair mean found with
90% power at the test's false-alarm level, and fails when that exceeds 1% in a channel
(tests/blender/POWER.md explains the computation).

Negative controls: the Hairis side is rendered again with a deliberate error (every light and
the world 2% brighter; Filter Glossy off), and the same comparison must find each. (The other
Blender's Chiang tilt convention moves this hair's mean by 0.1-0.25%, below what the test is
sized for, so it is not a control; POWER.md.) Blender 3.4 is skipped: one 16×16 block of its
hair differs from Cycles 3.4 beyond the noise (tests/allowed_skips.txt).
"""

import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hair_power  # noqa: E402
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
if helpers.VERSION < (4, 0, 0):
    helpers.skip("Blender %s: a block of the hair differs from Cycles beyond the noise "
                 "(under investigation)" % bpy.app.version_string)
SAMPLES = int(os.environ.get("HAIRIS_POWER_SAMPLES", "192"))
SEEDS = int(os.environ.get("HAIRIS_POWER_SEEDS", "16"))


def test_hair_matches_cycles_with_power():
    """Hairis' hair pixels are Cycles' within the noise, the comparison has the power to see a
    1% bias of their mean, and it finds every deliberate error of
    hair_power.DEFAULTS_CONTROLS."""
    hair_power.check(hair_power.defaults_head_scene, hair_power.HAIR, SAMPLES, SEEDS, ARGS.workdir,
                     hair_power.DEFAULTS_CONTROLS)


helpers.run([test_hair_matches_cycles_with_power])
