"""Cycles 3.4 against Hairis PATH on the demo head's hair, by strand geometry: the whole image's
mean per channel (256 spp each, blonde Principled Hair, the dual study's area light, 8 bounces)
for the demo's strands (also with Embree 4's rule for the insides of tubes in Hairis), strands a
third as thick, thick tips without Close Tip, and no children.
A diagnostic of the difference the dual study's head run shows between the two engines
(README, Dual scattering); prints one GAP line per geometry.

    /usr/bin/python3 tests/blender/run_test.py --blender blender --zip build/hairis-addon.zip \\
        --timeout 3000 bench/studies/cycles_hair_geometry/cycles_hair_geometry.py
"""
import importlib
import os
import sys

import bpy
import numpy as np
from mathutils import Vector

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "tests", "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()


def scene_for(radius_scale, tip, close_tip, children):
    """The demo head's hair with these strand settings under the area light."""
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -7.5, 0.3), resolution=(96, 72), percentage=100)
    helpers.make_world(scene, color=(0.0, 0.0, 0.0), strength=0.0)
    light = helpers.make_light(scene, "AREA", "Panel", location=(2.0, -2.2, 2.6),
                               energy=250.0, shape="SQUARE", size=1.2)
    d = Vector((0.0, 0.0, 0.6)) - light.location
    light.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.1, "Melanin Redness": 0.5, "Roughness": 0.3,
        "Radial Roughness": 0.3, "Coat": 0.0, "IOR": 1.55})
    skin = helpers.make_diffuse_material("Skin", (0.7, 0.5, 0.4, 1.0))
    sphere = helpers.make_particle_hair(scene, count=1500, children=children,
                                        location=(0.0, 0.0, 0.3), scale=1.3,
                                        hair_material=hair, skin_material=skin)
    st = sphere.modifiers["Hair"].particle_system.settings
    st.radius_scale = radius_scale
    st.tip_radius = tip
    st.use_close_tip = close_tip
    helpers.match_cycles(scene, 4, 8)
    scene.cycles.diffuse_bounces = 4
    helpers.use_table(scene, 8, threads=2)
    bpy.context.view_layer.update()
    return scene, sphere


def main():
    """Renders each geometry with both engines, and the demo's also with Embree 4's rule for
    the insides of tubes (curve_backfaces=hit) in Hairis."""
    compat = importlib.import_module(getattr(PACKAGE, "__name__", PACKAGE) + ".compat")
    backfaces = compat.curve_backfaces
    cases = [(0.02, 0.2, True, 10, None), (0.02, 0.2, True, 10, "hit"),
             (0.006, 0.2, True, 10, None), (0.02, 0.5, False, 10, None),
             (0.02, 0.2, True, 0, None)]
    for case in cases:
        scene, _sphere = scene_for(*case[:4])
        means = {}
        for engine in ("CYCLES", "HAIRIS"):
            if engine == "HAIRIS" and case[4]:
                compat.curve_backfaces = lambda version=None, rule=case[4]: rule
            helpers.set_samples(scene, 256)
            img, _seconds = helpers.render_pixels(scene, engine, 1, ARGS.workdir)
            compat.curve_backfaces = backfaces
            means[engine] = img.reshape(-1, 3).mean(axis=0)
        print("GAP radius_scale %.3f tip %.1f close %s children %d backfaces %s: Cycles %s "
              "Hairis %s rel %s"
              % (case[0], case[1], case[2], case[3], case[4] or "as the add-on",
                 np.round(means["CYCLES"], 4), np.round(means["HAIRIS"], 4),
                 np.round(means["CYCLES"] / means["HAIRIS"] - 1, 4)), flush=True)


helpers.run_script(main)
