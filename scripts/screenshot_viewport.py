"""Screenshots of Hairis' Rendered shading in a real Blender window, for docs/.

Run by scripts/screenshot_viewport (under xvfb-run) as
    blender --factory-startup -p 0 0 W H --python-exit-code 1 \
        --python scripts/screenshot_viewport.py -- --zip build/hairis-addon.zip \
        --workdir <tmp> --output docs
It installs the add-on, builds the demo head (tests/blender/helpers.make_demo_head), maximises
the 3D view, switches it to Rendered shading and screenshots it refining (early, later), after
an orbit (the render restarts with only the camera changed) and after the hair colour changed
(its material is exported again, the built strands kept): <output>/viewport_early.png,
viewport_later.png, viewport_orbit.png, viewport_colour.png. It prints the time to the first
pixels, then closes the Rendered view (the worker thread must end) and quits; any failure exits
with code 1.
"""
import argparse
import math
import os
import sys
import threading
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "tests", "blender"))
import helpers  # noqa: E402
from screenshot_ui import (Steps, largest_area, maximise,  # noqa: E402
                           save_png, screenshot)

STEPS = Steps("screenshot_viewport", delay=1.0)


def parse_args():
    """The arguments after ``--``."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--zip", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("--output", required=True)
    return parser.parse_args(argv)


ARGS = parse_args()
STATE = {}


def engine_module(name):
    """The installed add-on's module."""
    return sys.modules["hairis." + name]


def view_area():
    """The 3D view."""
    return largest_area("VIEW_3D")


def shoot(name):
    """Screenshots the 3D view to <output>/<name>.png."""
    area = view_area()
    path = os.path.join(ARGS.workdir, name + "_raw.png")
    pixels = screenshot(area, path)
    save_png(pixels, os.path.join(ARGS.output, name + ".png"), "screenshot_viewport")


def renders():
    """The live viewport renders (one once Rendered shading runs)."""
    return list(engine_module("viewport")._LIVE)


def wait_for(predicate, what, timeout=300.0):
    """Re-queues the next step until ``predicate()`` (the UI keeps drawing in between)."""
    start = time.monotonic()

    def check():
        if not predicate():
            if time.monotonic() - start > timeout:
                STEPS.fail("timed out waiting for " + what)
            STEPS.queue.insert(0, check)

    STEPS.queue.insert(0, check)


@STEPS.add
def install():
    """Installs and enables the add-on; builds the demo head."""
    bpy.ops.preferences.addon_install(filepath=ARGS.zip, overwrite=True)
    bpy.ops.preferences.addon_enable(module="hairis")
    scene = helpers.make_demo_head(empty_file=False)
    scene.hairis.preview_samples = 64
    scene.hairis.strategy = "ANALYTIC"  # no tables to bake in the screenshots
    area = view_area()
    maximise(area, hide_panels=True)


@STEPS.add
def through_camera():
    """Looks through the scene camera, Rendered shading (the render starts)."""
    area = view_area()
    space = area.spaces.active
    space.region_3d.view_perspective = "CAMERA"
    space.overlay.show_overlays = False
    STATE["start"] = time.monotonic()
    space.shading.type = "RENDERED"


@STEPS.add
def early():
    """The first pixels, then a screenshot of an early image."""
    wait_for(lambda: renders() and renders()[0].frame is not None
             and renders()[0].frame.rgba.shape[0] > 100, "the first full image")
    STEPS.queue.insert(1, shoot_early)


def shoot_early():
    """The early screenshot, and the time to first pixels."""
    render = renders()[0]
    print("screenshot_viewport: first pixels %.2f s after the viewport started (export, "
          "scene build, the low-resolution pass); full resolution at %d samples now"
          % (render.first_image_seconds, render.frame.samples), flush=True)
    STATE["early_samples"] = render.frame.samples
    shoot("viewport_early")


@STEPS.add
def later():
    """A later, less noisy image."""
    wait_for(lambda: renders()[0].frame.samples >= 32, "32 samples")
    STEPS.queue.insert(1, lambda: (shoot("viewport_later"), print(
        "screenshot_viewport: later at %d samples" % renders()[0].frame.samples, flush=True)))


@STEPS.add
def orbit():
    """Orbits the view (the render restarts with only the camera changed)."""
    area = view_area()
    region3d = area.spaces.active.region_3d
    camera = bpy.context.scene.camera
    rotation = camera.matrix_world.to_quaternion()
    rotation.rotate(helpers.Euler((0.0, 0.0, math.radians(35.0))))
    region3d.view_perspective = "PERSP"
    region3d.view_location = (0.0, 0.0, 0.3)
    region3d.view_distance = 7.5
    region3d.view_rotation = rotation
    STATE["builds"] = renders()[0].scene_builds
    STATE["generation"] = renders()[0]._generation


@STEPS.add
def after_orbit():
    """The orbited view once it has a few samples."""
    wait_for(lambda: renders()[0].frame.generation > STATE["generation"]
             and renders()[0].frame.samples >= 8, "the orbited view")
    STEPS.queue.insert(1, lambda: (shoot("viewport_orbit"), print(
        "screenshot_viewport: orbit rebuilt the scene %d times"
        % (renders()[0].scene_builds - STATE["builds"]), flush=True)))


@STEPS.add
def colour():
    """Changes the hair colour (its material is exported again, the built strands stay)."""
    hair = bpy.data.materials["Hair"]
    node = next(n for n in hair.node_tree.nodes if n.bl_idname.startswith("ShaderNodeBsdfHair"))
    helpers.socket(node, "Melanin").default_value = 0.1
    render = renders()[0]
    STATE["builds"], STATE["reshades"] = render.scene_builds, render.scene_reshades


@STEPS.add
def after_colour():
    """The blonde hair once it has a few samples."""
    def changed():
        render = renders()[0]
        return render.scene_builds + render.scene_reshades > STATE["builds"] + STATE["reshades"]
    wait_for(lambda: changed() and renders()[0].frame.samples >= 8, "the new colour")
    STEPS.queue.insert(1, lambda: (shoot("viewport_colour"), print(
        "screenshot_viewport: the colour change built the scene %d times, reshaded it %d times"
        % (renders()[0].scene_builds - STATE["builds"],
           renders()[0].scene_reshades - STATE["reshades"]), flush=True)))


@STEPS.add
def close_view():
    """Solid shading while the render runs: the worker must end."""
    render = renders()[0]
    STATE["thread"] = render._thread
    view_area().spaces.active.shading.type = "SOLID"


@STEPS.add
def check_closed():
    """No worker thread left."""
    wait_for(lambda: not STATE["thread"].is_alive(), "the worker to end", timeout=30.0)
    STEPS.queue.insert(1, lambda: print(
        "screenshot_viewport: threads after closing: %s"
        % [t.name for t in threading.enumerate()], flush=True))


@STEPS.add
def reopen_and_quit():
    """Rendered again, then quit while it renders (atexit and free must join the thread)."""
    view_area().spaces.active.shading.type = "RENDERED"
    wait_for(lambda: renders() and renders()[0].frame is not None, "the render again")
    STEPS.queue.insert(1, lambda: bpy.ops.wm.quit_blender())


STEPS.start()
