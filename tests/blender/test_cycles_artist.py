"""Hairis against Cycles on one scene set up as an artist would, with every supported piece at once.

A head-like mesh (a smooth-shaded ellipsoid) with a Principled BSDF at its defaults (specular
included) whose Base Color is an Image Texture on the UV map (helpers.skin_pixels as an 8-bit
sRGB PNG); on its scalp (a vertex group of emission density) Chiang hair — the Principled Hair
BSDF, Melanin parametrization — whose melanin varies per strand by Random Color with Random
unlinked and from root to tip by a ColorRamp on Hair Info Intercept (helpers.vary_melanin); an
HDRI world (hdri.sky_world: a sky, a ground and a bright 2 × 2 "sun", written as a Radiance
HDR) through an Environment Texture with a Mapping rotation; a spot light with a radius and a
blend. Cycles is set up as for test_cycles_compare (helpers.match_cycles). The export must read
all of it without a warning. Both engines render SEEDS images of SAMPLES samples, compared per
4×4 block by compare_stats.compare (channel means within 2%, mean t² and max |t| within the
noise bounds).
"""

import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import hdri  # noqa: E402
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
SAMPLES, SEEDS = helpers.COMPARE_SAMPLES, helpers.COMPARE_SEEDS
BOUNCES, BLOCK = helpers.COMPARE_BOUNCES, helpers.COMPARE_BLOCK
STRANDS = 1500
SCALP_Z = 0.2
"""Hair grows where the head's undeformed vertices have z above this (the sphere's radius is 1),
or y above it (the back of the head, away from the camera)."""


def make_head(skin, hair):
    """The textured head with the hair particle system on its scalp."""
    head = helpers.make_sphere("Head", 0.8, (0.0, 0.0, 1.0), skin, scale=(0.85, 0.95, 1.15))
    # The ellipsoid is in the mesh, the object's scale is 1: Cycles does not apply a non-uniform
    # scale to curves (it intersects them in object space), hairis does.
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
    head.data.materials.append(hair)
    scalp = head.vertex_groups.new(name="Scalp")
    radius = 0.8
    scalp.add([v.index for v in head.data.vertices
               if v.co.z > SCALP_Z * radius or v.co.y > SCALP_Z * radius], 1.0, "REPLACE")
    helpers.add_hair_particles(head, STRANDS, material_index=2, hair_length=0.45,
                               density_group="Scalp")
    return head


def make_scene():
    """Head, scalp hair, the HDRI world through a Mapping rotation and a spot light."""
    scene = helpers.reset()
    # Looking down 17° onto a floor that hides most of the world's ground and its horizon.
    helpers.make_camera(scene, location=(0.0, -4.6, 2.4), rotation=(math.radians(73), 0.0, 0.0),
                        resolution=(64, 48), percentage=100)
    helpers.make_hdri_world(scene, os.path.join(ARGS.workdir, "sky.hdr"),
                            hdri.sky_world(), rotation=(0.2, -0.1, 1.1), strength=1.0)
    skin, _ = helpers.make_textured_principled("Skin", os.path.join(ARGS.workdir, "skin.png"),
                                               helpers.skin_pixels())
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin Redness": 0.6, "Roughness": 0.3, "Radial Roughness": 0.4})
    helpers.vary_melanin(hair, random_color=0.5, random_roughness=0.2)
    make_head(skin, hair)
    helpers.make_floor(40.0)
    helpers.make_key_spot(scene, (1.8, -1.6, 3.2))
    helpers.match_engines(scene, SAMPLES, BOUNCES)
    return scene


def test_artist_scene_matches_cycles():
    """The export reads the whole scene without a warning; Cycles and Hairis render it to the
    same image within the noise."""
    scene = make_scene()
    data = helpers.module("export").export_scene(bpy.context.evaluated_depsgraph_get())
    assert not data.warnings, data.warnings
    (curves,) = data.curves
    assert set(curves.inputs) == {"melanin", "random"}, curves.inputs.keys()
    assert curves.inputs["melanin"][0] == "point"
    assert data.world_environment is not None
    assert len(data.textures) == 1, data.textures
    kinds = {material.name: material.kind for material in data.materials}
    assert kinds.get("Skin") == "SURFACE" and kinds.get("Hair") == "HAIR", kinds
    strands = curves.curve_count
    assert 0.3 * STRANDS < strands < STRANDS + 1, "%d strands on the scalp" % strands
    helpers.compare_with_cycles(scene, SEEDS, ARGS.workdir, BLOCK, " (%d strands)" % strands)


helpers.run([test_artist_scene_matches_cycles])
