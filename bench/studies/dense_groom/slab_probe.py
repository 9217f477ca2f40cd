"""Cycles against Hairis on a slab of straight, parallel strands on a grid (particle hair
emitted from the vertices of a grid mesh): the strand spacing relative to the diameter
decides whether the tubes overlap. A diagnostic; prints one SLAB line per render.

Knobs: SLAB_GRID strands per side, SLAB_RADIUS strand radius, SLAB_TIP tip radius (a factor
of the root's), SLAB_BOUNCES, SLAB_SPP,
SLAB_MEL melanin, SLAB_ORDER engines (CYCLES, HAIRIS, HAIRIS:hit, HAIRIS:ignore).
"""
import importlib
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "tests", "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()


def env(name, default):
    return float(os.environ.get(name, default))


def make_scene():
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -1.6, 0.25), resolution=(64, 64), percentage=100)
    helpers.make_world(scene, color=(0.5, 0.5, 0.5), strength=0.5)
    helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(3.0),
                       rotation=(math.radians(60), 0.0, math.radians(20)))
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": env("SLAB_MEL", "0.15"), "Melanin Redness": 0.8, "Roughness": 0.3,
        "Radial Roughness": 0.3, "Coat": 0.0, "IOR": 1.55})
    grid = int(env("SLAB_GRID", "60"))
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=grid, y_subdivisions=grid, size=0.5)
    plane = bpy.context.view_layer.objects.active
    plane.data.materials.append(helpers.make_diffuse_material("Base", (0.5, 0.5, 0.5, 1.0)))
    plane.data.materials.append(hair)
    settings = helpers.add_hair_particles(plane, len(plane.data.vertices), material_index=2,
                                          hair_length=0.5)
    settings.emit_from = "VERT"
    settings.use_emit_random = False
    settings.hair_step = 2
    settings.render_step = 1
    settings.radius_scale = 2.0 * env("SLAB_RADIUS", "0.002")
    settings.root_radius = 1.0
    settings.tip_radius = env("SLAB_TIP", "1.0")
    settings.use_close_tip = False
    settings.shape = 0.0
    bounces = int(env("SLAB_BOUNCES", "8"))
    helpers.match_cycles(scene, int(env("SLAB_SPP", "16")), bounces)
    scene.hairis.samples = scene.cycles.samples
    helpers.use_table(scene, bounces)
    bpy.context.view_layer.update()
    return scene


def main():
    compat = importlib.import_module(getattr(PACKAGE, "__name__", PACKAGE) + ".compat")
    backfaces = compat.curve_backfaces
    scene = make_scene()
    for item in os.environ.get("SLAB_ORDER", "CYCLES,HAIRIS").split(","):
        engine, _, rule = item.partition(":")
        if rule:
            compat.curve_backfaces = lambda version=None, r=rule: r
        image, seconds = helpers.render_pixels(scene, engine, 1, ARGS.workdir)
        compat.curve_backfaces = backfaces
        print("SLAB grid %d radius %.4f %s %s mean %s (%.1f s)" % (
            int(env("SLAB_GRID", "60")), env("SLAB_RADIUS", "0.002"), engine, rule,
            np.round(image.reshape(-1, 3).mean(axis=0), 5), seconds), flush=True)


helpers.run_script(main)
