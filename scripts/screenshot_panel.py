"""Screenshots of the add-on's panels in a real Blender UI, for the README.

Run by scripts/screenshot (under xvfb-run, with a clean environment) as
    blender --factory-startup -p 0 0 720 1000 --python-exit-code 1 \
        --python scripts/screenshot_panel.py -- \
        --zip build/hairis-addon.zip --workdir <tmp> --output docs
with BLENDER_USER_SCRIPTS pointing to an empty folder. NOT in background mode: it needs the
window (its width, -p, is the Properties editor's). From timers, so that the UI draws in
between, it installs and enables the add-on, builds a small hair scene (a UV sphere with
particle hair and a Principled Hair BSDF material), bakes its sampling tables, switches the
scene to Hairis, maximises the Properties editor, screenshots its Render tab and its Material tab
(the Hairis Sampling Tables panel with the Bake button), crops them below the last open panel
and writes <output>/panel_render.png and <output>/panel_material.png. Then it quits; any failure
exits with code 1.
"""
import argparse
import os
import sys

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "tests", "blender"))
import helpers  # noqa: E402  (scene-building helpers shared with the add-on's tests)
from screenshot_ui import (Steps, largest_area, main_region, maximise,  # noqa: E402
                           save_png, screenshot, window_and_screen)

UI_SCALE = 1.0
STEPS = Steps("screenshot_panel")
fail = STEPS.fail


def parse_args():
    """The arguments after ``--``."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--zip", required=True)
    parser.add_argument("--workdir", required=True, help="temporary folder (.blend, tables)")
    parser.add_argument("--output", required=True, help="folder for the PNGs")
    parser.add_argument("--no-bake", action="store_true", help="do not bake the tables")
    parser.add_argument("--keep", default="", help="folder to keep the uncropped screenshots in")
    return parser.parse_args(argv)


ARGS = parse_args()


def properties_area():
    """The Properties editor of the layout."""
    return largest_area("PROPERTIES")


def build_scene():
    """The factory scene without its cube, plus a sphere of particle hair (active object)."""
    scene = bpy.context.scene
    for obj in list(bpy.data.objects):
        if obj.type == "MESH":
            bpy.data.objects.remove(obj)
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.45, "Melanin Redness": 0.5, "Roughness": 0.3, "Radial Roughness": 0.3})
    skin = helpers.make_surface_material("Skin", (0.7, 0.5, 0.4, 1.0))
    window, screen = window_and_screen()
    view3d = next((a for a in screen.areas if a.type == "VIEW_3D"), None)
    override = {"window": window, "screen": screen}
    if view3d is not None:
        override.update(area=view3d, region=main_region(view3d))
    with bpy.context.temp_override(**override):
        sphere = helpers.make_particle_hair(scene, count=1500, children=10,
                                            location=(0.0, 0.0, 0.0), scale=1.0,
                                            hair_material=hair, skin_material=skin)
    bpy.context.view_layer.objects.active = sphere
    sphere.select_set(True)
    sphere.active_material_index = 1  # the hair material
    scene.render.engine = "HAIRIS"
    settings = scene.hairis
    settings.samples = 128
    settings.max_bounces = 12
    settings.strategy = "TABLE"
    settings.multiple_weight = 0.25
    settings.n_h = "2"
    settings.seed = 0
    settings.threads = 0
    settings.auto_bake = True
    bpy.context.view_layer.update()
    return scene, sphere


def show_tab(tab):
    """Shows ``tab`` ('RENDER', 'MATERIAL') in the Properties editor, scrolled to the top."""
    area = properties_area()
    space = area.spaces.active
    space.context = tab
    window, screen = window_and_screen()
    with bpy.context.temp_override(window=window, screen=screen, area=area,
                                   region=main_region(area)):
        bpy.ops.view2d.scroll_up(deltay=100000)
    area.tag_redraw()


def content_runs(pixels):
    """(first, end) ranges of rows (top first) of the header and the panels.

    A row is content where, right of the tab column, some pixel differs from the region's
    background colour (taken near the bottom right, below every panel); panels are separated
    by background rows.
    """
    top_first = pixels[::-1, :, :3]
    height, width = top_first.shape[:2]
    background = top_first[height - 8, width - 24]
    left = int(45 * UI_SCALE)
    differs = (np.abs(top_first[:, left:width - 12] - background).max(axis=2) > 0.02).any(axis=1)
    runs, start = [], None
    for row, value in enumerate(differs):
        if value and start is None:
            start = row
        elif not value and start is not None:
            runs.append((start, row))
            start = None
    return runs


def last_open_panel_end(pixels):
    """The row (top first) just below the last open panel (collapsed ones are left out)."""
    runs = content_runs(pixels)
    height = pixels.shape[0]
    tall = [end for start, end in runs if end - start > 40 * UI_SCALE and end < height - 4]
    if not tall:
        fail("no open panel found in the screenshot")
    return tall[-1] + 1


def save_crop(pixels, top, bottom, path):
    """Writes rows ``top``..``bottom`` (top first, exclusive) of ``pixels`` as a PNG."""
    height, width = pixels.shape[:2]
    top, bottom = max(0, top), min(height, bottom)
    top_first = pixels[::-1]
    # A margin below the last panel: copies of an empty row near the bottom (tab column and
    # region background), not the next panel's header.
    margin = np.repeat(top_first[height - 8:height - 7], int(8 * UI_SCALE), axis=0)
    crop = np.concatenate((top_first[top:bottom], margin))[::-1]  # back to bottom row first
    save_png(crop, path, "screenshot_panel")


# ---- Steps (timers) -------------------------------------------------------------------------

@STEPS.add
def setup():
    """Builds the scene, bakes, maximises the Properties editor and shows the Render tab."""
    prefs = bpy.context.preferences
    prefs.view.ui_scale = UI_SCALE
    helpers.install_addon(ARGS.zip)
    build_scene()
    for folder in (ARGS.workdir, ARGS.output, ARGS.keep):
        if folder:
            os.makedirs(folder, exist_ok=True)
    blend = os.path.join(os.path.abspath(ARGS.workdir), "screenshot.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    if not ARGS.no_bake:
        result = bpy.ops.hairis.bake_tables()  # exec: synchronous
        if result != {"FINISHED"}:
            fail("baking the sampling tables failed: %s" % result)
    maximise(properties_area())
    show_tab("RENDER")


def save_tab(name):
    """Screenshots the Properties editor as <name>_full.png and its panels down to the last open
    one as panel_<name>.png."""
    pixels = screenshot(properties_area(),
                        os.path.join(ARGS.keep or ARGS.workdir, name + "_full.png"))
    save_crop(pixels, 0, last_open_panel_end(pixels),
              os.path.join(ARGS.output, "panel_%s.png" % name))


@STEPS.add
def render_tab():
    """Screenshots the Render tab: down to Hair Sampling Strategy and the library status."""
    save_tab("render")
    show_tab("MATERIAL")


@STEPS.add
def material_tab():
    """Screenshots the Material tab: slots, Surface node view, Hairis Sampling Tables."""
    save_tab("material")


@STEPS.add
def finish():
    """Quits."""
    bpy.ops.wm.quit_blender()


STEPS.start()
