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
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_stats  # noqa: E402
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
if not os.path.isfile(helpers.bundled_library(PACKAGE)):
    helpers.skip("libhairis.so is not built yet (looked for %s)"
                 % helpers.bundled_library(PACKAGE))
SAMPLES = int(os.environ.get("HAIRIS_COMPARE_SAMPLES", "32"))
SEEDS = int(os.environ.get("HAIRIS_COMPARE_SEEDS", "8"))
BOUNCES = 4
BLOCK = 4
V4 = helpers.VERSION >= (4, 0, 0)


def skin_pixels(width=64, height=32):
    """RGBA floats (bottom row first): a skin tone, darker bands along u, spots."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    uu, vv = np.meshgrid(u, v)
    base = np.array([0.85, 0.62, 0.5])
    band = 0.75 + 0.25 * np.cos(2.0 * math.pi * 6.0 * uu)
    spots = np.where((np.sin(17.0 * uu) * np.sin(11.0 * vv * math.pi)) > 0.8, 0.6, 1.0)
    rgb = base[None, None, :] * (band * spots)[:, :, None]
    rgb[..., 2] *= 0.8 + 0.2 * vv
    rgba = np.concatenate([rgb, np.ones((height, width, 1))], axis=2)
    return rgba.astype(np.float32)


def write_skin_png(path):
    image = bpy.data.images.new("SkinPaint", 64, 32, alpha=False)
    image.pixels.foreach_set(skin_pixels().reshape(-1))
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def principled_material(name, **inputs):
    material = bpy.data.materials.new(name)
    helpers.use_nodes(material)
    node = material.node_tree.nodes["Principled BSDF"]
    for key, value in inputs.items():
        helpers.socket(node, key).default_value = value
    return material, node


def sphere(name, radius, location, material, scale=(1.0, 1.0, 1.0)):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, location=location, segments=48,
                                         ring_count=24)
    obj = bpy.context.view_layer.objects.active
    obj.name = name
    obj.scale = scale
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(material)
    return obj


def make_scene():
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -4.2, 1.1), rotation=(math.radians(82), 0.0, 0.0),
                        resolution=(64, 48), percentage=100)
    helpers.make_world(scene, color=(0.3, 0.35, 0.45), strength=1.0)

    path = os.path.join(ARGS.workdir, "skin.png")
    write_skin_png(path)
    coat = {"Coat Weight": 0.25, "Coat Roughness": 0.15} if V4 else \
        {"Clearcoat": 0.25, "Clearcoat Roughness": 0.15}
    skin, node = principled_material("Skin", Roughness=0.45, **coat)
    tree = skin.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.load(path)
    tree.links.new(texture.outputs["Color"], helpers.socket(node, "Base Color"))
    sphere("Head", 0.8, (0.0, 0.0, 1.0), skin, scale=(0.85, 0.95, 1.15))

    metal, _ = principled_material("Metal", **{"Base Color": (0.9, 0.7, 0.35, 1.0),
                                               "Metallic": 1.0, "Roughness": 0.3})
    sphere("Metal", 0.4, (1.25, -0.3, 0.4), metal)

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
    sphere("Mixed", 0.4, (-1.25, -0.3, 0.4), mixed)

    floor = helpers.make_diffuse_material("Floor", (0.45, 0.45, 0.45, 1.0))
    bpy.ops.mesh.primitive_plane_add(size=12.0, location=(0.0, 0.0, 0.0))
    bpy.context.view_layer.objects.active.data.materials.append(floor)
    helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(4.0),
                       rotation=(math.radians(50), math.radians(10), math.radians(-35)))
    helpers.match_cycles(scene, SAMPLES, BOUNCES)
    settings = scene.hairis
    settings.samples = SAMPLES
    settings.max_bounces = BOUNCES
    settings.threads = 0
    bpy.context.view_layer.update()
    return scene


def test_surfaces_match_cycles():
    """Cycles and Hairis render the textured Principled head, the metal and the mix alike."""
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


helpers.run([test_surfaces_match_cycles])
