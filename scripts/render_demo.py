"""The main job's render: a demo hair scene built by script and rendered headless with Hairis.

Run by scripts/main as
    blender -b --factory-startup --python-exit-code 1 --python scripts/render_demo.py -- \
        --zip build/hairis-addon.zip --workdir out/demo
with BLENDER_USER_SCRIPTS pointing to an empty folder. It installs and enables the add-on,
builds a head of particle hair (with interpolated children) under a sun and a sky, saves the
.blend, bakes the sampling tables next to it (bpy.ops.hairis.bake_tables), renders with the
TABLE strategy and writes out/demo/demo.png.
"""
import os
import sys

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "blender"))
import helpers  # noqa: E402  (scene-building helpers shared with the add-on's tests)

ARGS, PACKAGE = helpers.setup()


def main():
    scene = helpers.make_demo_head()
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
