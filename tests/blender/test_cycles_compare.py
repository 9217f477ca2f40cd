"""Hairis against Cycles: the same scene, rendered by both, must agree within the noise.

The scene has Chiang hair at Offset 2° (particle hair on a diffuse sphere) and at −4° (a
Curves object of self-crossing strands), a sun, a point light with a radius, an area light and
a world colour. Cycles is set up as the README's "Comparing with Cycles" section says (3D
Curves, a 1-pixel box filter, the same bounce limit for every kind of bounce, no clamping, no
glossy filter, no denoising, no adaptive sampling, no light threshold; the light tree as
Blender sets it). Hairis follows the running Blender's Cycles through the add-on: Chiang's
tilt (3.4's or 4.2+'s), the light units (3.4's or 4.x's) and whether a ray starting inside
another strand hits it (Embree 4 from 3.6).

Both engines render SEEDS independent images of SAMPLES samples, compared per 4×4 block by
compare_stats.compare (channel means within 2%, mean t² and max |t| within the noise bounds).
"""

import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
SAMPLES, SEEDS = helpers.COMPARE_SAMPLES, helpers.COMPARE_SEEDS
BOUNCES, BLOCK = helpers.COMPARE_BOUNCES, helpers.COMPARE_BLOCK
STRATEGY = os.environ.get("HAIRIS_COMPARE_STRATEGY", "TABLE")
EXTRA_HAIR = ()
"""Functions of the scene adding more hair (other models' materials) to the comparison."""


def make_scene():
    """The comparison scene of helpers.make_compare_scene at SAMPLES samples."""
    return helpers.make_compare_scene(SAMPLES, BOUNCES, STRATEGY,
                                      curves_offset=math.radians(-4.0), extras=EXTRA_HAIR)


def test_hairis_matches_cycles():
    """Cycles and Hairis render the same scene to the same image within the noise."""
    scene = make_scene()
    blend = os.path.join(ARGS.workdir, "compare.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    helpers.compare_with_cycles(scene, SEEDS, ARGS.workdir, BLOCK, " (%s)" % STRATEGY)


helpers.run([test_hairis_matches_cycles])
