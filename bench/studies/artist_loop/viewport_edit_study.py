"""The viewport after a material edit on a dense groom: seconds to the first new pixels when the
whole scene is exported and built again, against the built scene given new shading.

Runs inside Blender through tests/blender/run_test.py (4.5 shown; 5.0 with its venv and
--expect-version 5.0; 3.4 with --blender blender --zip build/hairis-addon.zip):

    python3 tests/blender/run_test.py --bpy-python .venvs/bpy-4.5/bin/python \\
        --expect-version 4.5 --install extension --extension-zip build/hairis-extension.zip \\
        --zip build/hairis-addon.zip --timeout 3600 \\
        bench/studies/artist_loop/viewport_edit_study.py

The groom is groom_scale's particle groom (a head-sized sphere, 1000 parents with
interpolated children, all shown in the viewport; HAIRIS_STUDY_CHILDREN per parent, default
250: 250k strands), Chiang hair with the ANALYTIC strategy (no tables to bake), a sun and a
world, viewport 160 × 160 at 16 samples. One ViewportRender (the add-on's worker) renders the
scene; then, REPEATS times, Melanin is changed and the time is taken from the edit to the
worker's first image of the edited scene, once through a whole export and build (what every
edit cost before) and once through export.export_shading and a reshade, alternating which goes
first. Prints one RUN line per edit and a SUMMARY with the medians and their ratio.
"""

import os
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "tests", "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
helpers.use_library(None)
native = helpers.module("native")
engine = helpers.module("engine")
export = helpers.module("export")
viewport = helpers.module("viewport")

CHILDREN = int(os.environ.get("HAIRIS_STUDY_CHILDREN", "250"))
REPEATS = int(os.environ.get("HAIRIS_STUDY_REPEATS", "3"))
SIZE, SAMPLES, WAIT = 160, 16, 1800.0


def groom_scene():
    """groom_scale's particle groom under a sun and a grey world."""
    scene = helpers.reset()
    scene.render.engine = "HAIRIS"
    helpers.make_camera(scene, location=(0.0, -0.75, 0.05), resolution=(SIZE, SIZE),
                        percentage=100)
    helpers.make_world(scene, color=(0.5, 0.5, 0.5), strength=0.3)
    helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=0.05, rotation=(0.7, 0.0, 0.5))
    hair = helpers.make_hair_material("Hair", "MELANIN", **{"Melanin": 0.15, "Roughness": 0.3})
    skin = helpers.make_diffuse_material("Skin", (0.7, 0.5, 0.4, 1.0))
    settings = helpers.make_groom_head(scene, hair, skin, CHILDREN, 0.004)
    # The viewport shows every child: the dense groom an artist looks at.
    setattr(settings, "child_percent" if bpy.app.version >= (4, 0, 0) else "child_nbr", CHILDREN)
    settings.display_step = settings.render_step
    scene.hairis.strategy = "ANALYTIC"
    scene.hairis.threads = 2
    bpy.context.view_layer.update()
    return scene


def melanin(value):
    """Sets the hair material's Melanin and lets the depsgraph see it."""
    nodes = bpy.data.materials["Hair"].node_tree.nodes
    node = next(n for n in nodes if n.bl_idname == "ShaderNodeBsdfHairPrincipled")
    helpers.socket(node, "Melanin").default_value = value
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    return depsgraph


def first_image(render, waiter, start):
    """Seconds from ``start`` to the worker's first image of its newest request."""
    generation = render._generation
    waiter.until(lambda: render.frame is not None and render.frame.generation >= generation,
                 "the viewport's image")
    if render.error:
        raise AssertionError(render.error)
    return time.monotonic() - start


def main():
    scene = groom_scene()
    waiter = helpers.Waiter(WAIT)
    render = viewport.ViewportRender(native.load_library(), waiter)
    try:
        depsgraph = bpy.context.evaluated_depsgraph_get()
        camera = engine.camera_options(export.export_scene(depsgraph).camera)
        del camera["width"], camera["height"]
        job = viewport.SceneJob(engine._export_view(depsgraph))
        start = time.monotonic()
        render.set_scene(job)
        render.set_view(viewport.ViewRequest(camera, SIZE, SIZE,
                                             engine.render_settings(scene.hairis), SAMPLES))
        print("RUN first view %.2f s (%d strands, Blender %s)" % (
            first_image(render, waiter, start), 1000 * CHILDREN, bpy.app.version_string),
            flush=True)
        times = {"whole": [], "shading": []}
        value = 0.15
        for repeat in range(REPEATS):
            order = ("whole", "shading") if repeat % 2 == 0 else ("shading", "whole")
            for way in order:
                value = 0.6 if value < 0.5 else 0.15
                start = time.monotonic()
                depsgraph = melanin(value)
                if way == "whole":
                    job = viewport.SceneJob(engine._export_view(depsgraph))
                else:
                    job = viewport.SceneJob(export.export_shading(depsgraph, job.data),
                                            geometry=job.geometry)
                render.set_scene(job)
                seconds = first_image(render, waiter, start)
                times[way].append(seconds)
                print("RUN %s %.3f s (builds %d, reshades %d)" % (
                    way, seconds, render.scene_builds, render.scene_reshades), flush=True)
    finally:
        render.stop()
    whole, shading = (float(np.median(times[k])) for k in ("whole", "shading"))
    print("SUMMARY %d strands, Blender %s: whole export and build %.3f s, shading only %.3f s, "
          "ratio %.3f (medians of %d)" % (1000 * CHILDREN, bpy.app.version_string, whole,
                                          shading, shading / whole, REPEATS), flush=True)


helpers.run_script(main)
