"""Scene export tests: no native library needed.

Builds the hair test scene by script and checks the exported numpy arrays against values read
through other Blender APIs (mathutils transforms, particle locations, node inputs, curve
slices) and against Cycles' radius rules written out independently here.
"""

import math
import os
import sys
import types

import bpy
import numpy as np
from mathutils import Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
export = helpers.module("export")

# Node input name → hairis_principled_hair field, written out here on purpose (not imported).
HAIR_FIELDS = {
    "Color": "color", "Melanin": "melanin", "Melanin Redness": "melanin_redness",
    "Tint": "tint", "Absorption Coefficient": "absorption_coefficient",
    "Roughness": "roughness", "Radial Roughness": "radial_roughness", "Coat": "coat",
    "IOR": "ior", "Offset": "offset", "Random Color": "random_color",
    "Random Roughness": "random_roughness", "Random": "random",
}
# The Huang model's inputs (Blender 4.0+), by socket identifier: Chiang's without Radial
# Roughness and Coat, plus Aspect Ratio and the lobe multipliers (shown as Reflection,
# Transmission, Secondary Reflection).
HUANG_FIELDS = {
    "Color": "color", "Melanin": "melanin", "Melanin Redness": "melanin_redness",
    "Tint": "tint", "Absorption Coefficient": "absorption_coefficient",
    "Aspect Ratio": "aspect_ratio", "Roughness": "roughness", "IOR": "ior", "Offset": "offset",
    "Random Color": "random_color", "Random Roughness": "random_roughness", "Random": "random",
    "R lobe": "reflection", "TT lobe": "transmission", "TRT lobe": "secondary_reflection",
}
PARAMETRIZATION = {"ABSORPTION": 0, "MELANIN": 1, "COLOR": 2}


def particle_curves(data):
    """The one CurvesData exported from particles."""
    found = [c for c in data.curves if c.source == "PARTICLES"]
    assert len(found) == 1, [c.name for c in data.curves]
    return found[0]


def check_hair_material(material_data, material, fields=HAIR_FIELDS):
    """The exported parameters equal the node's inputs, field for field."""
    node = material.node_tree.nodes["Principled Hair BSDF"]
    assert material_data.kind == "HAIR", material_data.kind
    params = material_data.hair
    assert params.parametrization == PARAMETRIZATION[node.parametrization]
    for name, field in fields.items():
        expected = helpers.socket(node, name).default_value
        actual = getattr(params, field)
        if isinstance(actual, tuple):
            np.testing.assert_allclose(actual, tuple(expected)[:3], rtol=0, atol=1e-7,
                                       err_msg=name)
        else:
            assert actual == float(expected), (name, actual, expected)


def test_particle_hair_viewport():
    """200 strands, 2**display_step + 1 keys, world positions, Cycles radii, material."""
    scene = helpers.make_test_scene()
    data = export.export_context()
    curves = particle_curves(data)
    settings = bpy.data.objects["Head"].particle_systems[0].settings
    keys = 2 ** settings.display_step + 1
    assert curves.curve_count == 200, curves.curve_count
    np.testing.assert_array_equal(curves.first, np.arange(201) * keys)
    assert curves.positions.dtype == np.float32 and curves.positions.shape == (200 * keys, 3)
    points = curves.positions.reshape(200, keys, 3).astype(np.float64)

    # Tips are the particles' locations (world space), read with another API.
    evaluated = bpy.data.objects["Head"].evaluated_get(bpy.context.evaluated_depsgraph_get())
    locations = np.empty(200 * 3, np.float32)
    evaluated.particle_systems[0].particles.foreach_get("location", locations)
    np.testing.assert_allclose(points[:, -1], locations.reshape(-1, 3), atol=1e-5)

    # Roots lie on the scaled low-poly sphere (faces sit inside the unit sphere).
    head = bpy.data.objects["Head"]
    center = np.array(head.location)
    scale = head.scale[0]
    root_distance = np.linalg.norm(points[:, 0] - center, axis=1)
    assert np.all(root_distance <= scale * 1.0 + 1e-4), root_distance.max()
    assert np.all(root_distance >= scale * 0.85), root_distance.min()

    # Straight hair: hair_length is a world-space length (Blender divides it by the object
    # scale when it grows the hair). The path cache's keys are not evenly spaced.
    segments = np.linalg.norm(np.diff(points, axis=1), axis=2)
    np.testing.assert_allclose(segments.sum(axis=1), settings.hair_length, rtol=2e-3)

    # Cycles' shaperadius, written out: t is the arc-length fraction (uniform scale, so world
    # fractions equal object-space ones), root/tip = radius_scale·0.5·root/tip, times the
    # object scale, 0 at the tip with close tip.
    half = settings.radius_scale * 0.5
    root, tip = half * settings.root_radius, half * settings.tip_radius
    radii = curves.radii.reshape(200, keys)
    for strand in (0, 1, 99, 199):
        lengths = np.concatenate([[0.0], np.cumsum(segments[strand])])
        for k in range(keys):
            t = lengths[k] / lengths[-1]
            r = ((1.0 - t) ** (1.0 / (1.0 - settings.shape)) * (root - tip) + tip) * scale
            if settings.use_close_tip and k == keys - 1:
                r = 0.0
            assert math.isclose(radii[strand, k], r, rel_tol=1e-4, abs_tol=1e-8), \
                (strand, k, radii[strand, k], r)
    assert radii[0, 0] == np.float32(root * scale)
    assert np.all(radii[:, -1] == 0.0)

    material = data.materials[curves.material]
    assert material.name == "Hair", material.name
    check_hair_material(material, bpy.data.materials["Hair"])
    assert scene.render.engine == "HAIRIS"
    # Random Color/Roughness with Random unlinked: Cycles randomizes per strand, hairis not.
    assert any("per strand" in w and "'Hair'" in w for w in data.warnings), data.warnings


def test_curves_object():
    """Curves: offsets, world positions (mathutils), radii × scale, material."""
    helpers.make_test_scene()
    data = export.export_context()
    found = [c for c in data.curves if c.source == "CURVES"]
    assert len(found) == 1, [c.name for c in data.curves]
    curves = found[0]
    obj = bpy.data.objects["Curls"]
    source = obj.data
    assert curves.curve_count == len(source.curves)
    assert curves.point_count == len(source.points)
    for index in (0, 1, len(source.curves) // 2, len(source.curves) - 1):
        assert curves.first[index] == source.curves[index].first_point_index
    assert curves.first[-1] == len(source.points)
    matrix = obj.matrix_world
    for index in (0, 7, 1234, len(source.points) - 1):
        expected = matrix @ Vector(source.points[index].position)
        np.testing.assert_allclose(curves.positions[index], tuple(expected), atol=1e-5)
        assert math.isclose(curves.radii[index], source.points[index].radius * 2.0,
                            rel_tol=1e-6)
    material = data.materials[curves.material]
    assert material.name == "Curly"
    check_hair_material(material, bpy.data.materials["Curly"])
    np.testing.assert_allclose(material.hair.absorption_coefficient, (0.3, 0.6, 1.2), atol=1e-7)


def test_curves_without_radius():
    """Without a radius attribute Cycles uses 0.005 (times the object scale)."""
    scene = helpers.reset()
    helpers.make_camera(scene)
    helpers.make_curves(scene, helpers.make_hair_material("Plain", "COLOR"), radius=False)
    data = export.export_context()
    (curves,) = data.curves
    np.testing.assert_allclose(curves.radii, 0.005 * 2.0, rtol=1e-6)
    assert data.materials[curves.material].hair.parametrization == 2


def test_lights_world_camera():
    """Sun direction/strength/angle, point, area, spot, world, camera frame."""
    scene = helpers.make_test_scene()
    data = export.export_context()
    kinds = sorted(light.kind for light in data.lights)
    assert kinds == ["AREA", "POINT", "SPOT", "SUN"], kinds
    assert not any("spot" in w for w in data.warnings), data.warnings

    spot = next(light for light in data.lights if light.kind == "SPOT")
    spot_data = bpy.data.lights["Spot"]
    np.testing.assert_allclose(spot.matrix, np.array(bpy.data.objects["Spot"].matrix_world),
                               atol=1e-6)
    assert math.isclose(spot.strength, 10.0)
    assert math.isclose(spot.spot_size, spot_data.spot_size, rel_tol=1e-6)
    assert math.isclose(spot.spot_blend, spot_data.spot_blend, rel_tol=1e-6)
    assert math.isclose(spot.radius, spot_data.shadow_soft_size, rel_tol=1e-6)
    assert spot.cycles == ("3.4" if bpy.app.version < (4, 0, 0) else "4.5"), spot.cycles

    sun = next(light for light in data.lights if light.kind == "SUN")
    sun_object = bpy.data.objects["Sun"]
    direction = (sun_object.matrix_world.to_3x3() @ Vector((0.0, 0.0, 1.0))).normalized()
    np.testing.assert_allclose(sun.direction, tuple(direction), atol=1e-6)
    assert math.isclose(sun.strength, 3.0)
    assert math.isclose(sun.angle, math.radians(5.0), rel_tol=1e-6)

    point = next(light for light in data.lights if light.kind == "POINT")
    np.testing.assert_allclose(point.position, (1.0, -2.0, 3.0), atol=1e-6)
    assert math.isclose(point.strength, 100.0) and math.isclose(point.radius, 0.25)

    area = next(light for light in data.lights if light.kind == "AREA")
    assert area.shape == "RECTANGLE" and math.isclose(area.size_x, 0.5)
    assert math.isclose(area.size_y, 0.25) and math.isclose(area.strength, 50.0)
    np.testing.assert_allclose(area.matrix, np.array(bpy.data.objects["Panel"].matrix_world),
                               atol=1e-6)

    np.testing.assert_allclose(data.world_color, (0.05, 0.1, 0.2), atol=1e-7)
    assert math.isclose(data.world_strength, 1.5)

    camera = data.camera
    assert (camera.width, camera.height) == (32, 24), (camera.width, camera.height)
    assert not camera.orthographic
    frame = [tuple(v) for v in scene.camera.data.view_frame(scene=scene)]
    np.testing.assert_allclose(camera.frame, frame, atol=1e-6)
    np.testing.assert_allclose(camera.camera_to_world, np.array(scene.camera.matrix_world),
                               atol=1e-6)


def test_camera_orthographic_and_scale():
    """Orthographic flag; a scaled camera's matrix is exported without scale."""
    scene = helpers.make_test_scene(with_curves=False)
    scene.camera.data.type = "ORTHO"
    scene.camera.scale = (2.0, 2.0, 2.0)
    bpy.context.view_layer.update()
    camera = export.export_context().camera
    assert camera.orthographic
    np.testing.assert_allclose(np.linalg.norm(camera.camera_to_world[:3, :3], axis=0), 1.0,
                               atol=1e-6)
    scene.camera.data.type = "PANO"
    try:
        export.export_context()
    except export.ExportError as error:
        assert "panoramic" in str(error)
    else:
        raise AssertionError("a panoramic camera must be refused")


def test_mesh():
    """The emitter mesh: loop triangles, world positions, per-triangle material."""
    helpers.make_test_scene(with_curves=False)
    data = export.export_context()
    meshes = [m for m in data.meshes if m.name == "Head"]
    assert len(meshes) == 1
    mesh = meshes[0]
    head = bpy.data.objects["Head"]
    evaluated = head.evaluated_get(bpy.context.evaluated_depsgraph_get())
    source = evaluated.to_mesh()
    source.calc_loop_triangles()
    assert mesh.indices.shape == (len(source.loop_triangles), 3)
    assert mesh.positions.shape == (len(source.vertices), 3)
    for index in (0, 5, len(source.vertices) - 1):
        expected = head.matrix_world @ source.vertices[index].co
        np.testing.assert_allclose(mesh.positions[index], tuple(expected), atol=1e-5)
    triangle = source.loop_triangles[3]
    assert tuple(mesh.indices[3]) == tuple(triangle.vertices)
    evaluated.to_mesh_clear()
    names = {data.materials[i].name for i in np.unique(mesh.materials)}
    assert names == {"Skin"}, names
    skin = data.materials[mesh.materials[0]]
    assert skin.kind == "DIFFUSE"
    np.testing.assert_allclose(skin.albedo, (0.6, 0.4, 0.3), atol=1e-7)


def test_unsupported_things_warn():
    """Linked hair inputs, an environment texture without image, unknown shaders: warnings,
    no crash."""
    scene = helpers.make_test_scene(with_curves=False)
    hair = bpy.data.materials["Hair"]
    tree = hair.node_tree
    info = tree.nodes.new("ShaderNodeHairInfo")
    tree.links.new(info.outputs["Random"],
                   helpers.socket(tree.nodes["Principled Hair BSDF"], "Random"))
    world_tree = scene.world.node_tree
    environment = world_tree.nodes.new("ShaderNodeTexEnvironment")
    world_tree.links.new(environment.outputs["Color"],
                         helpers.socket(world_tree.nodes["Background"], "Color"))
    skin = bpy.data.materials["Skin"]
    glass = skin.node_tree.nodes.new("ShaderNodeBsdfGlass")
    output = skin.node_tree.nodes["Material Output"]
    skin.node_tree.links.new(glass.outputs["BSDF"], output.inputs["Surface"])
    data = export.export_context()
    text = "\n".join(data.warnings)
    assert "'Random'" in text and "linked" in text, text
    assert "Environment Texture 'Environment Texture' has no image" in text, text
    assert "Glass BSDF is not supported" in text, text


class StubSocket:
    """A node input with a name, an identifier and a value (for nodes no Blender makes)."""

    def __init__(self, name, value, identifier=None):
        self.name = name
        self.identifier = identifier or name
        self.default_value = value
        self.is_linked = False
        self.enabled = True


def stub_hair_node(model="CHIANG", leave_out=(), rename=None, values=None):
    """A stand-in Principled Hair BSDF with the model's inputs, some left out or renamed."""
    rename = rename or {}
    given = {"Color": (0.2, 0.3, 0.4, 1.0), "Tint": (1.0, 1.0, 1.0, 1.0),
             "Absorption Coefficient": (0.2, 0.5, 1.3)}
    given.update(values or {})
    fields = HUANG_FIELDS if model == "HUANG" else HAIR_FIELDS
    inputs = [StubSocket(rename.get(name, name), given.get(name, 0.5), rename.get(name))
              for name in fields if name not in leave_out]
    return types.SimpleNamespace(model=model, parametrization="COLOR", inputs=inputs)


def test_hair_node_models_and_missing_sockets():
    """An unknown model is refused naming the material; a missing socket is named with the
    version; a socket found by its identifier alone is read."""
    params, _warnings, error = export.read_hair_node(stub_hair_node("FUTURE"), "Future")
    assert params is None and "'Future'" in error and "'FUTURE' is not supported" in error, error
    params, _warnings, error = export.read_hair_node(stub_hair_node(leave_out=("Coat",)), "Old")
    assert params is None, params
    assert "'Old'" in error and "'Coat'" in error and bpy.app.version_string.split()[0] in error \
        and "3.4 to 5.x" in error, error
    # A socket whose display name changed but whose identifier did not.
    params, _warnings, error = export.read_hair_node(
        stub_hair_node(rename={"Coat": "Coating"}), "Renamed")
    compat = helpers.module("compat")
    assert error == "material 'Renamed': the Principled Hair BSDF has no 'Coat' input in " \
        "Blender %s; Hairis supports %s" % (compat.version_string(), compat.SUPPORTED_TEXT), error
    node = stub_hair_node()
    node.inputs[7].name = "Coating"  # Coat: the identifier stays "Coat"
    params, _warnings, error = export.read_hair_node(node, "Identifier")
    assert error is None and params.coat == 0.5, (error, params)
    # Huang reads the lobes by identifier; a Huang node without one is named.
    params, _warnings, error = export.read_hair_node(
        stub_hair_node("HUANG", leave_out=("TT lobe",)), "NoLobe")
    assert params is None and "'TT lobe'" in error and "'NoLobe'" in error, error


def test_huang_rules_on_stub_nodes():
    """Cycles' Huang rules: Aspect Ratio must be finite and > 0 (above 1 is passed on, the
    library inverts it); a negative lobe is 0 with a warning; all three <= 0: no closure
    (exported as black, opaque strands, with a warning)."""
    def read(**values):
        return export.read_hair_node(stub_hair_node("HUANG", values=values), "H")

    params, warnings, error = read(**{"Aspect Ratio": 0.5, "R lobe": 1.0, "TT lobe": 0.5,
                                      "TRT lobe": 0.2})
    assert error is None, error
    assert (params.model, params.aspect_ratio, params.reflection, params.transmission,
            params.secondary_reflection) == ("HUANG", 0.5, 1.0, 0.5, 0.2), params
    assert params.scatters and params.oriented
    assert read(**{"Aspect Ratio": 1.0})[0].oriented is False
    assert read(**{"Aspect Ratio": 2.0})[0].aspect_ratio == 2.0
    for bad in (0.0, -0.3, float("nan"), float("inf")):
        params, _warnings, error = read(**{"Aspect Ratio": bad})
        assert params is None and "'H'" in error and "Aspect Ratio" in error, (bad, error)
    params, warnings, error = read(**{"TT lobe": -0.25})
    assert error is None and params.transmission == 0.0, (error, params)
    assert any("Transmission is -0.25" in w and "Cycles uses 0" in w for w in warnings), warnings
    params, warnings, error = read(**{"R lobe": 0.0, "TT lobe": -1.0, "TRT lobe": 0.0})
    assert error is None and not params.scatters, (error, params)
    assert any("Cycles makes no closure" in w for w in warnings), warnings
    params, _warnings, error = read(**{"R lobe": float("nan")})
    assert params is None and "Reflection" in error and "finite" in error, error


def test_huang_materials_export():
    """Blender 4.0+: a new hair node is Chiang (RNA's default says Huang); with model Huang it
    exports every Huang input by identifier and none of Chiang's; all lobes 0 exports black
    diffuse strands with Cycles' reason."""
    if helpers.VERSION < (4, 0, 0):
        return  # Blender 3.4 has no model setting (the stub tests cover the reading)
    helpers.make_test_scene(with_curves=False)
    material = bpy.data.materials["Hair"]
    node = material.node_tree.nodes["Principled Hair BSDF"]
    assert node.model == "CHIANG", node.model
    assert node.bl_rna.properties["model"].default == "HUANG"
    node.model = "HUANG"
    values = {"Aspect Ratio": 0.5, "R lobe": 1.0, "TT lobe": 0.5, "TRT lobe": 0.2,
              "Roughness": 0.35, "IOR": 1.5, "Offset": math.radians(-3.0)}
    for name, value in values.items():
        helpers.socket(node, name).default_value = value
    helpers.socket(node, "Radial Roughness").default_value = 0.9  # Chiang only: not read
    data = export.export_context()
    hair = data.materials[particle_curves(data).material]
    check_hair_material(hair, material, HUANG_FIELDS)
    assert hair.hair.model == "HUANG" and hair.hair.radial_roughness == 0.3, hair.hair
    native = helpers.module("native")
    options = native.principled_options(hair.hair.as_dict())
    assert options["model"] == "huang" and "radial_roughness" not in options \
        and "coat" not in options and "cycles" not in options, options
    assert options["aspect_ratio"] == 0.5, options
    assert math.isclose(options["secondary_reflection"], 0.2, rel_tol=1e-6), options
    # Particle hair has no normals (Cycles' fallback frame).
    assert particle_curves(data).normals is None
    for name in ("R lobe", "TT lobe", "TRT lobe"):
        helpers.socket(node, name).default_value = 0.0
    data = export.export_context()
    dark = data.materials[particle_curves(data).material]
    assert dark.kind == "DIFFUSE" and dark.albedo == (0.0, 0.0, 0.0), dark
    assert any("'Hair'" in w and "no closure" in w for w in data.warnings), data.warnings


def test_curves_normals_for_huang():
    """A Curves object with an elliptical Huang material exports Blender's curve normals
    (Curves.normals, which Cycles reads), in object space. Checked on planar curves, whose
    minimum-twist normals keep one angle to the plane along each curve (parallel transport): unit
    length and a constant |n_z| per curve, which a misread array would break. A Chiang
    material or aspect 1 exports none; a rotated object warns and exports the same normals."""
    if helpers.VERSION < (4, 0, 0):
        return
    scene = helpers.reset()
    helpers.make_camera(scene)
    material = helpers.make_hair_material("Oval", "COLOR")
    node = material.node_tree.nodes["Principled Hair BSDF"]
    node.model = "HUANG"
    helpers.socket(node, "Aspect Ratio").default_value = 0.6
    # New curves whose points are set before anything asks for their normals: Blender caches
    # normals and does not drop the cache when positions are written through position_data.
    curves = bpy.data.hair_curves.new("Planar")
    count, points = 30, 8
    curves.add_curves([points] * count)
    planar = np.random.default_rng(5).uniform(-0.5, 0.5, (count * points, 3)).astype(np.float32)
    planar[:, 2] = 0.01 * np.repeat(np.arange(count), points)  # each curve in a plane z = const
    curves.position_data.foreach_set("vector", planar.reshape(-1))
    curves.materials.append(material)
    obj = bpy.data.objects.new("Curls", curves)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.update()
    data = export.export_context()
    (exported,) = data.curves
    assert exported.normals is not None and exported.normals.shape == (exported.point_count, 3)
    np.testing.assert_allclose(np.linalg.norm(exported.normals, axis=1), 1.0, atol=1e-5)
    first = exported.first.astype(np.int64)
    spread = max(float(np.ptp(np.abs(exported.normals[first[c]:first[c + 1], 2])))
                 for c in range(exported.curve_count))
    assert spread < 5e-3, spread  # float rounding over the evaluated points; a misread is O(1)
    assert not any("rotated" in w for w in data.warnings), data.warnings
    obj.rotation_euler = (0.0, 0.0, 1.2)
    bpy.context.view_layer.update()
    data = export.export_context()
    np.testing.assert_allclose(data.curves[0].normals, exported.normals, atol=1e-6)
    assert any("'Curls' is rotated" in w and "object space" in w for w in data.warnings), \
        data.warnings
    helpers.socket(node, "Aspect Ratio").default_value = 1.0
    assert export.export_context().curves[0].normals is None
    node.model = "CHIANG"
    assert export.export_context().curves[0].normals is None


def test_disabled_modifier_and_strands():
    """A particle modifier hidden in the viewport exports no strands."""
    helpers.make_test_scene(with_curves=False)
    head = bpy.data.objects["Head"]
    head.modifiers["Hair"].show_viewport = False
    bpy.context.view_layer.update()
    data = export.export_context()
    assert not [c for c in data.curves if c.source == "PARTICLES"]


def test_no_camera():
    """A scene without a camera is refused with ExportError."""
    scene = helpers.make_test_scene(with_curves=False)
    scene.camera = None
    try:
        export.export_context()
    except export.ExportError as error:
        assert "no camera" in str(error)
    else:
        raise AssertionError("export without a camera must fail")


def test_render_mode_export_through_engine():
    """F12 export: render_step keys, rendered_child_count children (dumped before the
    library is needed; the missing library then fails the render cleanly)."""
    helpers.make_test_scene(children=3, with_curves=False)
    settings = bpy.data.objects["Head"].particle_systems[0].settings
    settings.display_percentage = 50
    bpy.context.view_layer.update()
    viewport = particle_curves(export.export_context())  # child_nbr 1, half displayed
    assert viewport.curve_count == 100, viewport.curve_count
    np.testing.assert_array_equal(np.diff(viewport.first), 2 ** settings.display_step + 1)
    dump = os.path.join(ARGS.workdir, "render_export.npz")
    os.environ["HAIRIS_EXPORT_DUMP"] = dump
    helpers.use_library(os.path.join(ARGS.workdir, "missing", "libhairis.so"))
    try:
        bpy.ops.render.render()
    except RuntimeError as error:
        assert "hairis native library not found at" in str(error), error
    else:
        raise AssertionError("rendering without the library must report an error")
    finally:
        del os.environ["HAIRIS_EXPORT_DUMP"]
        helpers.use_library(None)
    arrays = np.load(dump)
    index = [i for i in range(int(arrays["counts"][0]))
             if str(arrays["curves%d_source" % i]) == "PARTICLES"]
    assert len(index) == 1
    first = arrays["curves%d_first" % index[0]]
    keys = 2 ** 3 + 1  # render_step = 3
    assert first.size - 1 == 200 * 3, first.size - 1  # children only: 200 parents × 3
    np.testing.assert_array_equal(np.diff(first), keys)
    assert tuple(arrays["camera_size"]) == (32, 24)


def _environment_world(scene, image, rotation=(0.0, 0.0, 0.0), coordinates="Generated"):
    """A world: Texture Coordinate → Mapping (rotation) → Environment Texture → Background."""
    world = helpers.make_world(scene, color=(0.3, 0.2, 0.1), strength=2.5)
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = nodes["Background"]
    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.image = image
    mapping = nodes.new("ShaderNodeMapping")
    helpers.socket(mapping, "Rotation").default_value = rotation
    coords = nodes.new("ShaderNodeTexCoord")
    links.new(coords.outputs[coordinates], helpers.socket(mapping, "Vector"))
    links.new(mapping.outputs["Vector"], helpers.socket(texture, "Vector"))
    links.new(texture.outputs["Color"], helpers.socket(background, "Color"))
    return world


def test_environment_world():
    """An Environment Texture world: a file by path, a generated image by pixels, the Mapping
    rotation, the Strength, the Sampling settings; unsupported nodes are named."""
    import hdri  # noqa: E402 (beside this file)
    scene = helpers.make_test_scene(with_curves=False)
    path = os.path.join(ARGS.workdir, "sky.hdr")
    hdri.write_hdr(path, 16, 8, hdri.spot_world(16, 8, spot=(4, 2), spot_value=20.0))
    image = bpy.data.images.load(path)
    world = _environment_world(scene, image, rotation=(0.1, 0.2, 0.3))
    world.cycles.sampling_method = "MANUAL"
    world.cycles.sample_map_resolution = 256
    data = export.export_context()
    env = data.world_environment
    assert env is not None, data.warnings
    assert env.path == os.path.abspath(path) and env.pixels is None
    np.testing.assert_allclose(env.rotation, (0.1, 0.2, 0.3), atol=1e-6)
    assert env.mapping == "point" and math.isclose(env.strength, 2.5)
    assert env.sampling == "manual" and env.map_resolution == 256
    assert env.color_space == "linear"
    np.testing.assert_allclose(env.matrix, np.eye(4))

    # A generated image goes as pixels (bottom row first, as Blender stores them).
    generated = bpy.data.images.new("Generated", 8, 4, float_buffer=True)
    generated.colorspace_settings.name = "sRGB"  # before the pixels: it regenerates them
    values = np.linspace(0.0, 1.0, 8 * 4 * 4, dtype=np.float32)
    generated.pixels.foreach_set(values)
    _environment_world(scene, generated)
    scene.world.cycles.sampling_method = "NONE"
    env = export.export_context().world_environment
    assert env.path is None and env.pixels.shape == (4, 8, 4)
    np.testing.assert_allclose(env.pixels.reshape(-1), values, atol=1e-6)
    assert env.color_space == "srgb" and env.sampling == "none"

    # Something else between the texture and the Background: named, the colour used.
    world = _environment_world(scene, image)
    nodes, links = world.node_tree.nodes, world.node_tree.links
    gamma = nodes.new("ShaderNodeGamma")
    links.new(nodes["Environment Texture"].outputs["Color"], helpers.socket(gamma, "Color"))
    links.new(gamma.outputs["Color"], helpers.socket(nodes["Background"], "Color"))
    data = export.export_context()
    assert data.world_environment is None
    assert any("Gamma" in w and "not supported" in w for w in data.warnings), data.warnings
    np.testing.assert_allclose(data.world_color, (0.3, 0.2, 0.1), atol=1e-6)

    # A Texture Coordinate's Object output: the object's inverse rotation and scale.
    empty = bpy.data.objects.new("Frame", None)
    scene.collection.objects.link(empty)
    empty.rotation_euler = (0.0, 0.0, 0.5)
    bpy.context.view_layer.update()
    world = _environment_world(scene, image, coordinates="Object")
    world.node_tree.nodes["Texture Coordinate"].object = empty
    env = export.export_context().world_environment
    np.testing.assert_allclose(env.matrix[:3, :3],
                               np.linalg.inv(np.array(empty.matrix_world)[:3, :3]), atol=1e-6)


helpers.run([
    test_particle_hair_viewport,
    test_curves_object,
    test_curves_without_radius,
    test_lights_world_camera,
    test_camera_orthographic_and_scale,
    test_mesh,
    test_unsupported_things_warn,
    test_hair_node_models_and_missing_sockets,
    test_huang_rules_on_stub_nodes,
    test_huang_materials_export,
    test_curves_normals_for_huang,
    test_disabled_modifier_and_strands,
    test_no_camera,
    test_render_mode_export_through_engine,
    test_environment_world,
])
