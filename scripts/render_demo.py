"""The main job's render: the demo scene built by script and rendered headless with Hairis.

Run by scripts/main through tests/blender/run_test.py (in Blender 3.4, or bpy 4.5 / 5.0), as
the Blender tests are, with HAIRIS_DEMO_OUT naming the output folder (default: the run's
--workdir). It installs and enables the add-on, builds the product shot of demo_scene (a bust
with long brunette hair, a Curves object of Principled Hair BSDF strands, in a studio of three
area lights), saves the .blend, bakes the sampling tables next to it
(bpy.ops.hairis.bake_tables), renders with the TABLE strategy and writes demo.blend, its
tables and demo.png to the output folder.
"""
import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "blender"))
import helpers  # noqa: E402  (scene-building helpers shared with the add-on's tests)
import demo_scene  # noqa: E402  (this folder: the demo's scene)

ARGS, PACKAGE = helpers.setup()


def main():
    scene = demo_scene.make_product_head()
    settings = scene.hairis
    settings.samples = 64
    settings.max_bounces = 8
    settings.strategy = "TABLE"
    settings.auto_bake = True
    bpy.context.view_layer.update()

    out = os.path.abspath(os.environ.get("HAIRIS_DEMO_OUT") or ARGS.workdir)
    os.makedirs(out, exist_ok=True)
    blend = os.path.join(out, "demo.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    assert bpy.ops.hairis.bake_tables() == {"FINISHED"}, "baking the sampling tables failed"
    bpy.ops.wm.save_mainfile()
    start = time.monotonic()
    bpy.ops.render.render()
    seconds = time.monotonic() - start
    image = bpy.data.images["Render Result"]
    path = os.path.join(out, "demo.png")
    scene.render.image_settings.file_format = "PNG"
    image.save_render(path, scene=scene)
    assert os.path.getsize(path) > 0, "no image was written"
    print("render_demo: wrote %s (Blender %s), rendered in %.1f s"
          % (path, bpy.app.version_string, seconds))


helpers.run([main])
