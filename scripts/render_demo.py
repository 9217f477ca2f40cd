"""The main job's render: a demo hair scene built by script and rendered headless with Hairis.

Run by scripts/main as
    blender -b --factory-startup --python-exit-code 1 --python scripts/render_demo.py -- \
        --zip build/hairis-addon.zip --workdir out/demo
with BLENDER_USER_SCRIPTS pointing to an empty folder. It installs and enables the add-on,
builds a head of particle hair (with interpolated children) under a sun and a sky, saves the
.blend, bakes the sampling tables next to it (bpy.ops.hairis.bake_tables), renders with the
TABLE strategy and writes out/demo/demo.png.
"""
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "blender"))
import helpers  # noqa: E402  (scene-building helpers shared with the add-on's tests)

ARGS, PACKAGE = helpers.setup()


def main():
    scene = helpers.reset()
    scene.render.engine = "HAIRIS"
    helpers.make_camera(scene, location=(0.0, -7.5, 0.3), resolution=(480, 360), percentage=100)
    helpers.make_world(scene, color=(0.35, 0.45, 0.6), strength=1.0)
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.45, "Melanin Redness": 0.5, "Roughness": 0.3, "Radial Roughness": 0.3})
    skin = helpers.make_surface_material("Skin", (0.7, 0.5, 0.4, 1.0))
    helpers.make_particle_hair(scene, count=1500, children=10, location=(0.0, 0.0, 0.3), scale=1.3,
                               hair_material=hair, skin_material=skin)
    helpers.make_light(scene, "SUN", "Sun", energy=4.0, angle=math.radians(2.0),
                       rotation=(math.radians(50), 0.0, math.radians(30)))
    settings = scene.hairis
    settings.samples = 64
    settings.max_bounces = 8
    settings.strategy = "TABLE"
    settings.auto_bake = True
    bpy.context.view_layer.update()

    os.makedirs(ARGS.workdir, exist_ok=True)
    blend = os.path.join(os.path.abspath(ARGS.workdir), "demo.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    assert bpy.ops.hairis.bake_tables() == {"FINISHED"}, "baking the sampling tables failed"
    bpy.ops.wm.save_mainfile()
    bpy.ops.render.render()
    image = bpy.data.images["Render Result"]
    path = os.path.join(os.path.abspath(ARGS.workdir), "demo.png")
    scene.render.image_settings.file_format = "PNG"
    image.save_render(path, scene=scene)
    assert os.path.getsize(path) > 0, "no image was written"
    print("render_demo: wrote %s" % path)


main()
