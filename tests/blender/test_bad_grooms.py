"""Bad grooms: strands Cycles cannot show, NaN points, no radius attribute, no hair material.

Each is exported with a warning naming the object (and the strands, for NaN points) and
rendered as Cycles renders it, never refused:
  * zero-length, zero-radius and invalid strands (a NaN position, a negative radius) are
    skipped with a counted warning; the rest of the object renders;
  * a scene whose only strands have zero radius renders the world, as Cycles does;
  * a Curves object without a radius attribute (Cycles: 0.005) and particle hair whose
    material slot is empty (Cycles' default surface) render as in Cycles, within the noise
    (compare_stats.compare, as test_cycles_compare).
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
export = helpers.module("export")
SAMPLES, SEEDS = 16, 6
BLOCK = 4


def make_groom(scene, name, radius=0.02, grid=False):
    """A Curves object of straight vertical strands on a row, or short ones on a grid facing
    the camera (any Blender: the random-curves operator's strands moved); returns (object,
    offsets, positions, radii)."""
    bpy.ops.object.curves_random_add(location=(0.0, 0.0, 0.0))
    obj = bpy.context.view_layer.objects.active
    obj.name = name
    curves = obj.data
    count = len(curves.curves)
    offsets = np.empty(count + 1, np.int32)
    curves.curve_offset_data.foreach_get("value", offsets)
    curve_of_point = np.repeat(np.arange(count), np.diff(offsets))
    t = (np.arange(offsets[-1]) - offsets[curve_of_point]) / (np.diff(offsets)[curve_of_point] - 1)
    positions = np.zeros((offsets[-1], 3), np.float32)
    if grid:
        columns = int(np.ceil(np.sqrt(count * 1.5)))
        column, row = curve_of_point % columns, curve_of_point // columns
        positions[:, 0] = -0.9 + 1.8 * column / (columns - 1)
        positions[:, 2] = -0.7 + 1.4 * row / (count // columns) + 0.05 * t
    else:
        positions[:, 0] = np.linspace(-0.9, 0.9, count)[curve_of_point]
        positions[:, 1] = np.linspace(-0.3, 0.3, count)[curve_of_point]
        positions[:, 2] = -0.8 + 1.6 * t
    radii = np.full(offsets[-1], radius, np.float32)
    return obj, offsets, positions, radii


def set_groom(obj, positions, radii):
    """Writes the points and their radius attribute (None: without one)."""
    curves = obj.data
    curves.position_data.foreach_set("vector", positions.reshape(-1))
    attribute = curves.attributes.get("radius")
    if radii is None:
        if attribute is not None:
            curves.attributes.remove(attribute)
    else:
        if attribute is None:
            attribute = curves.attributes.new("radius", "FLOAT", "POINT")
        attribute.data.foreach_set("value", radii)
    curves.update_tag()  # Blender 3.4 does not see writes through position_data otherwise


def base_scene(resolution=(32, 24)):
    """An empty file with the camera, a world colour and both engines matched."""
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -3.2, 0.0), resolution=resolution, percentage=100)
    helpers.make_world(scene, color=(0.4, 0.5, 0.7), strength=0.8)
    return scene


def warning_with(warnings, *words):
    """The one warning containing every word of ``words``."""
    found = [w for w in warnings if all(word in w for word in words)]
    assert len(found) == 1, (words, warnings)
    return found[0]


def test_degenerate_and_invalid_strands_are_skipped_with_a_warning():
    """Zero-length, zero-radius, NaN and negative-radius strands are left out with warnings
    naming the object, counting them and numbering the invalid ones; the render completes."""
    scene = base_scene()
    obj, offsets, positions, radii = make_groom(scene, "Groom")
    count = offsets.size - 1
    positions[offsets[0]:offsets[3]] = positions[offsets[0]]  # strands 0-2: zero length
    radii[offsets[3]:offsets[7]] = 0.0  # strands 3-6: zero radius
    positions[offsets[10] + 2, 0] = np.nan  # strand 10: a NaN point
    radii[offsets[12] + 1] = -0.01  # strand 12: a negative radius
    set_groom(obj, positions, radii)
    sphere = helpers.make_particle_hair(scene, count=50, location=(0.0, 1.5, 0.0), scale=0.5,
                                        hair_material=None, skin_material=None)
    sphere.particle_systems[0].settings.radius_scale = 0.0  # every strand: zero radius
    bpy.context.view_layer.update()

    data = export.export_context()
    assert warning_with(data.warnings, "'Groom'", "3 strand(s) of zero length")
    assert warning_with(data.warnings, "'Groom'", "4 strand(s) of zero radius")
    assert warning_with(data.warnings, "'Groom'", "2 strand(s)", "NaN", "(strands 10, 12)")
    assert warning_with(data.warnings, "'Head'", "'Hair'", "50 strand(s) of zero radius")
    (curves,) = data.curves  # the particle system has nothing left
    kept = [c for c in range(count) if c not in (0, 1, 2, 3, 4, 5, 6, 10, 12)]
    assert curves.name == "Groom" and curves.curve_count == len(kept), curves.curve_count
    roots = curves.positions[curves.first[:-1]]
    np.testing.assert_allclose(roots[:, 0], positions[offsets[kept], 0], atol=1e-6)
    assert np.all(np.isfinite(curves.positions)) and np.all(curves.radii > 0.0)

    scene.render.engine = "HAIRIS"
    helpers.set_samples(scene, 4)
    image, _ = helpers.render_pixels(scene, "HAIRIS", 1, ARGS.workdir)
    assert np.all(np.isfinite(image))
    world = np.array([0.4, 0.5, 0.7]) * 0.8
    assert np.any(np.abs(image - world).max(axis=2) > 0.05), "the strands left must show"


def test_only_zero_radius_strands_render_the_world():
    """Cycles renders the world when no strand can be seen; so does Hairis."""
    scene = base_scene()
    obj, _offsets, positions, radii = make_groom(scene, "Bald")
    set_groom(obj, positions, np.zeros_like(radii))
    helpers.match_engines(scene, 4, 2)
    data = export.export_context()
    assert not data.curves and not data.meshes
    assert warning_with(data.warnings, "'Bald'", "of zero radius")
    world = np.array([0.4, 0.5, 0.7]) * 0.8
    hairis, _ = helpers.render_pixels(scene, "HAIRIS", 1, ARGS.workdir)
    np.testing.assert_allclose(hairis, np.broadcast_to(world, hairis.shape), atol=1e-5)
    # Cycles 5.0's thick curves (Embree 4) still catch a rare camera sample on a zero-radius
    # strand: at most a few pixels differ, by a sample's share.
    cycles, _ = helpers.render_pixels(scene, "CYCLES", 1, ARGS.workdir)
    off = np.abs(cycles - world).max(axis=2) > 1e-5
    assert np.count_nonzero(off) <= 0.01 * off.size, np.count_nonzero(off)
    np.testing.assert_allclose(cycles.mean(axis=(0, 1)), world, rtol=1e-3)


def test_default_radius_and_material_match_cycles():
    """A Curves object without a radius attribute, and particle hair whose material slot is
    empty: Cycles' radius 0.005 and default surface, in both engines."""
    scene = base_scene(resolution=(48, 36))
    obj, _offsets, positions, _radii = make_groom(scene, "Plain", grid=True)
    set_groom(obj, positions, None)
    obj.scale = (1.2, 1.2, 1.2)
    obj.data.materials.append(helpers.make_hair_material("Dyed", "COLOR", **{
        "Color": (0.2, 0.5, 0.8, 1.0), "Roughness": 0.45}))
    skin = helpers.make_diffuse_material("Skin", (0.7, 0.5, 0.4, 1.0))
    head = helpers.make_particle_hair(scene, count=150, location=(0.3, 1.0, -0.4), scale=0.7,
                                      hair_material=None, skin_material=skin)
    assert head.material_slots[1].material is None
    helpers.make_comparison_lights(scene)
    helpers.match_engines(scene, SAMPLES, 3)
    scene.hairis.strategy = "ANALYTIC"

    data = export.export_context()
    by_source = {c.source: c for c in data.curves}
    np.testing.assert_allclose(by_source["CURVES"].radii, 0.005 * 1.2, rtol=1e-6)
    material = data.materials[by_source["PARTICLES"].material]
    assert material.kind == "DIFFUSE" and material.material_name is None, material
    # Cycles' own default: the same image (same seed) as with a radius attribute of 0.005.
    cycles, _ = helpers.render_pixels(scene, "CYCLES", 1, ARGS.workdir)
    set_groom(obj, positions, np.full(len(positions), 0.005, np.float32))
    explicit, _ = helpers.render_pixels(scene, "CYCLES", 1, ARGS.workdir)
    np.testing.assert_array_equal(cycles, explicit)
    set_groom(obj, positions, None)
    helpers.compare_with_cycles(scene, SEEDS, ARGS.workdir, BLOCK)


helpers.run([test_degenerate_and_invalid_strands_are_skipped_with_a_warning,
             test_only_zero_radius_strands_render_the_world,
             test_default_radius_and_material_match_cycles])
