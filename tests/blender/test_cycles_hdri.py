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
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_stats  # noqa: E402
import hdri  # noqa: E402
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
if not os.path.isfile(helpers.bundled_library(PACKAGE)):
    helpers.skip("libhairis.so is not built yet (looked for %s)"
                 % helpers.bundled_library(PACKAGE))
SAMPLES = int(os.environ.get("HAIRIS_COMPARE_SAMPLES", "32"))
SEEDS = int(os.environ.get("HAIRIS_COMPARE_SEEDS", "8"))
BOUNCES = 4
BLOCK = 4
WIDTH, HEIGHT = 64, 32
SUN = (44, 9)
"""The hot spot's texel (x, y from the top): above the horizon."""


def sky_texel(x, y):
    """A blue sky brightening towards the zenith, a brown ground, a 2 × 2 sun of 60."""
    if SUN[0] <= x <= SUN[0] + 1 and SUN[1] <= y <= SUN[1] + 1:
        return (60.0, 55.0, 45.0)
    elevation = 0.5 - (y + 0.5) / HEIGHT  # +0.5 at the zenith, -0.5 at the nadir
    if elevation < 0.0:
        return (0.08, 0.06, 0.04)
    return (0.25 + 0.3 * elevation, 0.35 + 0.4 * elevation, 0.6 + 0.5 * elevation)


def make_scene():
    """Sphere on a floor, the HDRI world through a Mapping rotation, one spot light."""
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -4.0, 1.2), rotation=(math.radians(80), 0.0, 0.0),
                        resolution=(64, 48), percentage=100)
    path = os.path.join(ARGS.workdir, "sky.hdr")
    hdri.write_hdr(path, WIDTH, HEIGHT, sky_texel)
    world = helpers.make_world(scene, color=(0.0, 0.0, 0.0), strength=1.3)
    nodes, links = world.node_tree.nodes, world.node_tree.links
    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(path)
    mapping = nodes.new("ShaderNodeMapping")
    helpers.socket(mapping, "Rotation").default_value = (0.2, -0.1, 1.1)
    coordinates = nodes.new("ShaderNodeTexCoord")
    links.new(coordinates.outputs["Generated"], helpers.socket(mapping, "Vector"))
    links.new(mapping.outputs["Vector"], helpers.socket(texture, "Vector"))
    links.new(texture.outputs["Color"], helpers.socket(nodes["Background"], "Color"))
    world.cycles.sampling_method = "AUTOMATIC"

    skin = helpers.make_diffuse_material("Clay", (0.7, 0.55, 0.45, 1.0))
    floor_material = helpers.make_diffuse_material("Floor", (0.5, 0.5, 0.5, 1.0))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.8, location=(0.0, 0.0, 0.8), segments=32,
                                         ring_count=16)
    sphere = bpy.context.view_layer.objects.active
    sphere.data.materials.append(skin)
    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, 0.0))
    floor = bpy.context.view_layer.objects.active
    floor.data.materials.append(floor_material)
    helpers.make_light(scene, "SPOT", "Spot", location=(1.8, -1.6, 3.0),
                       rotation=(math.radians(40), 0.0, math.radians(48)), energy=400.0,
                       spot_size=math.radians(50), spot_blend=0.3, shadow_soft_size=0.15)
    helpers.match_cycles(scene, SAMPLES, BOUNCES)
    settings = scene.hairis
    settings.samples = SAMPLES
    settings.max_bounces = BOUNCES
    settings.threads = 0
    bpy.context.view_layer.update()
    return scene


def test_hdri_and_spot_match_cycles():
    """Cycles and Hairis render the HDRI world and the spot light to the same image."""
    scene = make_scene()
    stacks, times = {}, {}
    for engine in ("CYCLES", "HAIRIS"):
        images = []
        times[engine] = 0.0
        for seed in range(1, SEEDS + 1):
            image, seconds = helpers.render_pixels(scene, engine, seed, ARGS.workdir)
            assert np.all(np.isfinite(image)), "%s rendered non-finite pixels" % engine
            images.append(image)
            times[engine] += seconds
        stacks[engine] = np.stack(images)
    print("render time for %d x %d samples: cycles %.1f s, hairis %.1f s"
          % (SEEDS, SAMPLES, times["CYCLES"], times["HAIRIS"]))
    dump = os.environ.get("HAIRIS_COMPARE_DUMP")
    if dump:
        np.savez(dump, cycles=stacks["CYCLES"], hairis=stacks["HAIRIS"])
    compare_stats.compare(stacks["CYCLES"], stacks["HAIRIS"], BLOCK)


helpers.run([test_hdri_and_spot_match_cycles])
