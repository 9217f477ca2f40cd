"""Hairis' Denoising Albedo and Denoising Normal against Cycles' (Blender 4.5 and 5.0).

The compositor's Denoise node reads these two passes as guides, so an artist's Denoise gives
what it gives with Cycles only if Hairis writes Cycles' definitions: the albedo of the closures
at the first vertex that is not mostly specular (Principled Hair: Chiang's or Huang's
reflectance estimate; a diffuse surface: its colour) plus the world where the camera sees it,
and the closure-weighted normal there in camera space (Chiang: perpendicular to the strand and
the view; Huang: the strand's tangent).

The scene: Chiang hair on a Curves object, Huang hair of aspect ratio 0.85 (Blender's default)
on another, a diffuse sphere and a world colour, 32 x 24 pixels. Both engines store the passes
because the view layer asks (Cycles' Store Denoising Passes); each pass reaches the image
through the compositor (Render Layers -> output). Per 4 x 4 block and channel the seed-to-seed noise
gives the t statistic of the difference (compare_stats.compare: mean t^2 and max |t| within
the noise, noise-free blocks such as the world equal); the normal is compared shifted by +1
so that its channel means (about 0) make the 2% mean check meaningful.

Skipped in 3.4: the comparison runs in 4.5 and 5.0 (CI time); the library's test covers 3.4's
Chiang albedo.
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_stats  # noqa: E402
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
if helpers.VERSION < (4, 0, 0):
    helpers.skip("Blender %s: the denoising passes are compared in 4.5 and 5.0 only"
                 % bpy.app.version_string)
compositor = helpers.module("compositor")
SAMPLES = int(os.environ.get("HAIRIS_COMPARE_SAMPLES", "8"))
SEEDS = int(os.environ.get("HAIRIS_COMPARE_SEEDS", "6"))
BLOCK = 4
PASSES = ("Denoising Albedo", "Denoising Normal")


def make_scene():
    """The comparison scene, both engines matched, the denoising passes stored."""
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -3.2, 0.0), resolution=(32, 24), percentage=100)
    helpers.make_world(scene, color=(0.4, 0.5, 0.7), strength=0.8)
    chiang = helpers.make_hair_material("Dyed", "COLOR", **{
        "Color": (0.2, 0.5, 0.8, 1.0), "Roughness": 0.45, "Radial Roughness": 0.4})
    chiang.node_tree.nodes["Principled Hair BSDF"].model = "CHIANG"
    huang = helpers.make_huang_material("Blond", (0.55, 0.4, 0.25, 1.0), 0.85)
    skin = helpers.make_diffuse_material("Skin", (0.7, 0.5, 0.4, 1.0))
    helpers.make_curves(scene, chiang, location=(-0.3, 0.0, 0.1), rotation=(0.0, 0.0, 0.0),
                        scale=1.2)
    helpers.make_fresh_curves(scene, "Curls", huang, 60, 8, 0.01, 3, (0.5, 0.0, -0.5), 0.3)
    helpers.make_sphere("Head", 0.5, (0.0, 1.0, -0.2), skin)
    helpers.match_engines(scene, SAMPLES, 4)
    scene.hairis.strategy = "UNIFORM"
    scene.hairis.max_transparent_bounces = 4
    bpy.context.view_layer.cycles.denoising_store_passes = True
    return scene


def show_pass(scene, name):
    """Routes the view layer's pass ``name`` to the compositor's output."""
    bpy.context.view_layer.update_render_passes()
    tree = compositor.compositor_tree(scene, True)
    layers = compositor._render_layers(tree, scene)
    socket = layers.outputs.get(name)
    assert socket is not None and socket.enabled, \
        "%s has no %s output" % (scene.render.engine, name)
    compositor._link(tree, socket, compositor._output(tree).inputs[0])


def render_passes(scene):
    """{pass: {engine: (seeds, height, width, 3) stack}} and each engine's seconds."""
    stacks = {name: {} for name in PASSES}
    seconds = {}
    for engine in helpers.ENGINES:
        scene.render.engine = engine
        seconds[engine] = 0.0
        for name in PASSES:
            show_pass(scene, name)
            images = []
            for seed in range(1, SEEDS + 1):
                image, time = helpers.render_pixels(scene, engine, seed, ARGS.workdir)
                assert np.all(np.isfinite(image)), "%s wrote non-finite %s" % (engine, name)
                images.append(image)
                seconds[engine] += time
            stacks[name][engine] = np.stack(images)
    print("render time for 2 passes x %d seeds x %d samples: cycles %.1f s, hairis %.1f s"
          % (SEEDS, SAMPLES, seconds["CYCLES"], seconds["HAIRIS"]))
    dump = os.environ.get("HAIRIS_COMPARE_DUMP")
    if dump:
        np.savez(dump, **{"%s_%s" % (name.split()[1].lower(), engine.lower()): stack
                          for name, engines in stacks.items() for engine, stack in engines.items()})
    return stacks


def test_denoising_passes_match_cycles():
    """Hairis' Denoising Albedo and Denoising Normal are Cycles' within the noise."""
    stacks = render_passes(make_scene())
    albedo = stacks["Denoising Albedo"]
    normal = stacks["Denoising Normal"]
    # What the comparison can see: hair, sphere and world, normals of every direction.
    cycles_normal = normal["CYCLES"].mean(axis=0)
    lengths = np.linalg.norm(cycles_normal, axis=-1)
    assert lengths.max() > 0.9 and lengths.min() < 1e-6, (lengths.min(), lengths.max())
    assert np.any(cycles_normal[..., 0] > 0.5) and np.any(cycles_normal[..., 0] < -0.5)
    # Where the camera sees the world: its colour times its strength.
    world = albedo["CYCLES"].mean(axis=0)[lengths < 1e-6]
    assert np.allclose(world, (0.32, 0.4, 0.56), atol=1e-4), world
    print("Denoising Albedo:")
    compare_stats.compare(albedo["CYCLES"], albedo["HAIRIS"], BLOCK)
    print("Denoising Normal (+1):")
    compare_stats.compare(normal["CYCLES"] + 1.0, normal["HAIRIS"] + 1.0, BLOCK)


helpers.run([test_denoising_passes_match_cycles])
