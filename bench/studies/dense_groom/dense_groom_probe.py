"""Cycles against Hairis on a dense particle groom: the whole image's mean per channel, for
each engine in the order PROBE_ORDER gives, all in one Blender process (Blender rebuilds a
particle groom's children differently in each process, so engines are only compared within
one). A diagnostic; prints one PROBE line per render and one EXPORT line per Hairis export.

Knobs (environment): PROBE_LEN hair length, PROBE_RS radius scale, PROBE_MEL melanin,
PROBE_OFFSET cuticle tilt in degrees, PROBE_TIP tip radius (of
the root's), PROBE_CLOSE Close Tip (1 or 0), PROBE_SHAPE the radius shape, PROBE_EMITTER 0
to hide the sphere, PROBE_BOUNCES bounce limit, PROBE_SPP samples,
PROBE_CHILDREN rendered children per parent (1000 parents), PROBE_DEFAULTS 1 to keep Cycles'
Filter Glossy, Clamping and Pixel Filter at Blender's defaults (else all off), PROBE_ORDER a
comma-separated list
of CYCLES, HAIRIS, HAIRIS:<strategy>, HAIRIS:hit / HAIRIS:ignore (the rule for the insides of
tubes) and X:curves (replace the particles by a Curves object of the same strands).

    /usr/bin/python3 tests/blender/run_test.py --blender blender --zip build/hairis-addon.zip \\
        --timeout 3000 bench/studies/dense_groom/dense_groom_probe.py
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
EXPORTED = []


def env(name, default):
    return float(os.environ.get(name, default))


def to_curves():
    """Replaces the particle groom by a Curves object converted from it (the same strands in
    world space, as the last Hairis export shows) with the exported radii."""
    exported = EXPORTED[-1]
    head = bpy.data.objects["Head"]
    modifier = head.modifiers["Hair"]
    settings = modifier.particle_system.settings
    # The conversion reads the viewport's groom: show what renders.
    setattr(settings, "child_percent" if helpers.VERSION >= (4, 0, 0) else "child_nbr",
            settings.rendered_child_count)
    settings.display_step = settings.render_step
    bpy.context.view_layer.objects.active = head
    bpy.context.view_layer.update()
    with bpy.context.temp_override(object=head, active_object=head):
        bpy.ops.curves.convert_from_particle_system()
    obj = bpy.context.view_layer.objects.active
    modifier.show_render = modifier.show_viewport = False
    radii = obj.data.attributes.new("radius", "FLOAT", "POINT")
    scale = obj.matrix_world.to_scale()[0]
    radii.data.foreach_set("value", (np.asarray(exported.radii) / scale).astype(np.float32))
    obj.data.materials.append(bpy.data.materials["Hair"])
    bpy.context.view_layer.update()


def make_scene():
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -0.75, 0.05), resolution=(80, 80), percentage=100)
    lamps = env("PROBE_LAMPS", "1") != 0.0
    helpers.make_world(scene, color=(0.5, 0.5, 0.5),
                       strength=env("PROBE_WORLD", "0.3") if lamps else env("PROBE_WORLD", "2.0"))
    if lamps:
        helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(3.0),
                           rotation=(math.radians(40), 0.0, math.radians(30)))
        helpers.make_light(scene, "AREA", "Panel", location=(-0.4, -0.5, 0.5), energy=20.0,
                           size=0.3, rotation=(math.radians(50), 0.0, math.radians(-40)))
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": env("PROBE_MEL", "0.15"), "Melanin Redness": 0.8, "Roughness": 0.3,
        "Radial Roughness": 0.3, "Coat": 0.0, "IOR": 1.55,
        "Offset": math.radians(env("PROBE_OFFSET", "2"))})
    skin = helpers.make_diffuse_material("Skin", (0.7, 0.5, 0.4, 1.0))
    sphere = helpers.make_particle_hair(scene, count=1000,
                                        children=int(env("PROBE_CHILDREN", "250")),
                                        location=(0.0, 0.0, 0.0), scale=0.1,
                                        hair_material=hair, skin_material=skin)
    settings = sphere.modifiers["Hair"].particle_system.settings
    settings.hair_length = env("PROBE_LEN", "0.3")
    settings.radius_scale = env("PROBE_RS", "0.004")
    settings.tip_radius = env("PROBE_TIP", "0.2")
    settings.use_close_tip = env("PROBE_CLOSE", "1") != 0.0
    settings.shape = env("PROBE_SHAPE", "0.3")
    sphere.show_instancer_for_render = env("PROBE_EMITTER", "1") != 0.0
    bounces = int(env("PROBE_BOUNCES", "8"))
    helpers.match_cycles(scene, int(env("PROBE_SPP", "16")), bounces)
    if env("PROBE_DEFAULTS", "0") != 0.0:
        scene.cycles.blur_glossy, scene.cycles.sample_clamp_indirect = 1.0, 10.0
        scene.cycles.pixel_filter_type, scene.cycles.filter_width = "BLACKMAN_HARRIS", 1.5
    scene.hairis.samples = scene.cycles.samples
    helpers.use_table(scene, bounces, threads=2)
    bpy.context.view_layer.update()
    return scene


def main():
    name = getattr(PACKAGE, "__name__", PACKAGE)
    compat = importlib.import_module(name + ".compat")
    export = importlib.import_module(name + ".export")
    export_scene, backfaces = export.export_scene, compat.curve_backfaces
    cycles_version = compat.cycles_version

    def traced(depsgraph, camera=None):
        data = export_scene(depsgraph, camera)
        for curves in data.curves:
            points = np.asarray(curves.positions, np.float64)
            print("EXPORT %s: %d strands, %d points, coordinate sum %.4f" % (
                curves.name, len(curves.first) - 1, len(points), points.sum()), flush=True)
        EXPORTED.extend(data.curves[:1])
        return data

    export.export_scene = traced
    scene = make_scene()
    for item in os.environ.get("PROBE_ORDER", "CYCLES,HAIRIS").split(","):
        engine, _, option = item.partition(":")
        if option == "curves":
            to_curves()
            continue
        scene.hairis.strategy = "TABLE"
        if option.startswith("v"):  # follow another Cycles version's conventions
            compat.cycles_version = lambda version=None, v=option[1:]: v
            option = ""
        if option in ("hit", "ignore"):
            compat.curve_backfaces = lambda version=None, rule=option: rule
        elif option:
            scene.hairis.strategy = option
        image, seconds = helpers.render_pixels(scene, engine, 1, ARGS.workdir)
        compat.curve_backfaces = backfaces
        compat.cycles_version = cycles_version
        print("PROBE %s %s mean %s (%.1f s)" % (
            engine, option, np.round(image.reshape(-1, 3).mean(axis=0), 5), seconds), flush=True)


helpers.run_script(main)
