"""Hairis against Cycles under an HDRI world and a spot light.

The world's Background Color is an Environment Texture of a small Radiance HDR (hdri.py: a sky
gradient, a dark ground and a sun-like hot spot), looked up through a Mapping node with an XYZ
rotation from the Texture Coordinate's Generated output; World > Settings > Sampling is Auto
(Cycles' importance map at the image's resolution). A spot light with a radius and a blend
shines on a diffuse sphere standing on a diffuse floor; no hair, so that the comparison is of
the lights and the world alone. Cycles is set up as for test_cycles_compare
(helpers.match_cycles). Both engines render SEEDS images of SAMPLES samples, compared per 4×4
block by compare_stats.compare (channel means within 2%, mean t² and max |t| within the noise
bounds).
"""

import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hdri  # noqa: E402
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
SAMPLES, SEEDS = helpers.COMPARE_SAMPLES, helpers.COMPARE_SEEDS
BOUNCES, BLOCK = helpers.COMPARE_BOUNCES, helpers.COMPARE_BLOCK
HDRI_SIZE = (64, 32)
SUN = (44, 9)
"""The hot spot's top-left texel (x, y from the top): above the horizon."""


def make_scene():
    """Sphere on a floor, the HDRI world through a Mapping rotation, one spot light."""
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -4.0, 1.2), rotation=(math.radians(80), 0.0, 0.0),
                        resolution=(64, 48), percentage=100)
    helpers.make_hdri_world(scene, os.path.join(ARGS.workdir, "sky.hdr"),
                            hdri.sky_world(*HDRI_SIZE, sun=SUN), rotation=(0.2, -0.1, 1.1),
                            strength=1.3, size=HDRI_SIZE)

    skin = helpers.make_diffuse_material("Clay", (0.7, 0.55, 0.45, 1.0))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.8, location=(0.0, 0.0, 0.8), segments=32,
                                         ring_count=16)
    bpy.context.view_layer.objects.active.data.materials.append(skin)
    helpers.make_floor(20.0)
    helpers.make_key_spot(scene, (1.8, -1.6, 3.0))
    helpers.match_engines(scene, SAMPLES, BOUNCES)
    return scene


def test_hdri_and_spot_match_cycles():
    """Cycles and Hairis render the HDRI world and the spot light to the same image."""
    helpers.compare_with_cycles(make_scene(), SEEDS, ARGS.workdir, BLOCK)


helpers.run([test_hdri_and_spot_match_cycles])
