"""Hairis against Cycles on meshes shaded as artists set them up.

A head-like mesh (a smooth-shaded ellipsoid) with a Principled BSDF whose Base Color is an Image
Texture on the UV map (an 8-bit sRGB PNG this test paints: a skin tone with darker bands and
spots), a coat and the running Blender's default distribution; a metal sphere (Principled,
Metallic 1); a sphere with a Mix Shader of a Diffuse and a Glossy BSDF; a grey floor; a sun with
a disc and a constant world. Cycles is set up as for test_cycles_compare (helpers.match_cycles).
Both engines render SEEDS images of SAMPLES samples, compared per 4×4 block by
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
V4 = helpers.VERSION >= (4, 0, 0)


def make_scene():
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -4.2, 1.1), rotation=(math.radians(82), 0.0, 0.0),
                        resolution=(64, 48), percentage=100)
    helpers.make_world(scene, color=(0.3, 0.35, 0.45), strength=1.0)

    coat = {"Coat Weight": 0.25, "Coat Roughness": 0.15} if V4 else \
        {"Clearcoat": 0.25, "Clearcoat Roughness": 0.15}
    skin, _ = helpers.make_textured_principled("Skin", os.path.join(ARGS.workdir, "skin.png"),
                                               helpers.skin_pixels(), Roughness=0.45, **coat)
    helpers.make_sphere("Head", 0.8, (0.0, 0.0, 1.0), skin, scale=(0.85, 0.95, 1.15))

    metal, _ = helpers.make_principled_material(
        "Metal", **{"Base Color": (0.9, 0.7, 0.35, 1.0), "Metallic": 1.0, "Roughness": 0.3})
    helpers.make_sphere("Metal", 0.4, (1.25, -0.3, 0.4), metal)

    mixed = bpy.data.materials.new("Mixed")
    helpers.use_nodes(mixed)
    nodes, links = mixed.node_tree.nodes, mixed.node_tree.links
    nodes.remove(nodes["Principled BSDF"])
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    helpers.socket(diffuse, "Color").default_value = (0.2, 0.5, 0.3, 1.0)
    glossy = nodes.new("ShaderNodeBsdfGlossy")
    helpers.socket(glossy, "Color").default_value = (0.8, 0.8, 0.8, 1.0)
    helpers.socket(glossy, "Roughness").default_value = 0.25
    mix = nodes.new("ShaderNodeMixShader")
    helpers.socket(mix, "Fac").default_value = 0.35
    links.new(diffuse.outputs["BSDF"], mix.inputs[1])
    links.new(glossy.outputs["BSDF"], mix.inputs[2])
    links.new(mix.outputs["Shader"], nodes["Material Output"].inputs["Surface"])
    helpers.make_sphere("Mixed", 0.4, (-1.25, -0.3, 0.4), mixed)

    floor = helpers.make_diffuse_material("Floor", (0.45, 0.45, 0.45, 1.0))
    bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0.0, 0.0, 0.0))
    bpy.context.view_layer.objects.active.data.materials.append(floor)
    helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(4.0),
                       rotation=(math.radians(50), math.radians(10), math.radians(-35)))
    helpers.match_engines(scene, SAMPLES, BOUNCES)
    return scene


def test_surfaces_match_cycles():
    """Cycles and Hairis render the textured Principled head, the metal and the mix alike."""
    helpers.compare_with_cycles(make_scene(), SEEDS, ARGS.workdir, BLOCK)


helpers.run([test_surfaces_match_cycles])
