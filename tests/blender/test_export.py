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
hair_material = helpers.module("hair_material")
memory = helpers.module("memory")
scene_data = helpers.module("scene_data")

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


def check_hair_material(material_data, material, overrides=None, fields=HAIR_FIELDS):
    """The exported parameters equal the node's inputs, field for field (``overrides``: the
    fields whose value is not the socket's, e.g. Random when it varies per strand)."""
    node = material.node_tree.nodes["Principled Hair BSDF"]
    assert material_data.kind == "HAIR", material_data.kind
    params = material_data.hair
    assert params.parametrization == PARAMETRIZATION[node.parametrization]
    for name, field in fields.items():
        expected = helpers.socket(node, name).default_value
        if overrides and field in overrides:
            expected = overrides[field]
        actual = getattr(params, field)
        if isinstance(actual, tuple):
            np.testing.assert_allclose(actual, tuple(expected)[:3], rtol=0, atol=1e-7,
                                       err_msg=name)
        else:
            assert actual == float(expected), (name, actual, expected)


def check_tilt_convention(hair):
    """The exported Chiang material evaluates as this Blender's Cycles: 3.4 to 4.1 tilt the
    cuticle cones on θ_i, 4.2 and later on θ_o, which gives another f wherever θ_o ≠ 0."""
    expected = "%d.%d" % tuple(bpy.app.version[:2])
    assert hair.cycles == expected, (hair.cycles, expected)
    assert abs(hair.offset) > 0.01, hair.offset  # no tilt, no difference to see
    native = helpers.module("native")
    lib = native.load_library()
    options = native.principled_options(hair.as_dict())
    wi = np.array([[-0.4, 0.9 * math.cos(2.6), 0.9 * math.sin(2.6)]], np.float32)
    wo = np.array([[0.5, 0.0, -math.sqrt(0.75)]], np.float32)
    wi /= np.linalg.norm(wi)

    def f(cycles):
        with lib.fiber(dict(options, cycles=cycles)) as fiber:
            return fiber.eval(wi, wo)[0]
    exported = f(options["cycles"])
    incident, outgoing = f("3.4"), f("4.5")
    assert np.all(np.abs(incident - outgoing) > 0.01 * outgoing), (incident, outgoing)
    np.testing.assert_array_equal(exported, incident if helpers.VERSION < (4, 2, 0) else outgoing)


def check_strand_random(domain, random, count):
    """Per-curve numbers distributed as Cycles' curve random: uniform in [0, 1] (test_cycles_
    strands checks them against Cycles' own)."""
    assert domain == "curve", domain
    assert random.shape == (count, 1) and random.dtype == np.float32, (random.shape, random.dtype)
    values = np.sort(random[:, 0].astype(np.float64))
    assert values[0] >= 0.0 and values[-1] <= 1.0, (values[0], values[-1])
    # Kolmogorov-Smirnov against U[0, 1]: reject at alpha = 0.001 (1.95 / sqrt(n)).
    cdf = np.arange(1, count + 1) / count
    distance = max(np.max(cdf - values), np.max(values - (cdf - 1.0 / count)))
    assert distance < 1.95 / math.sqrt(count), distance
    assert np.unique(values).size == count


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
    # Random Color/Roughness with Random unlinked: Cycles' per-strand random number, per
    # curve; the fiber itself (what tables are baked for) is the middle strand, Random 0.5.
    check_hair_material(material, bpy.data.materials["Hair"], {"random": 0.5})
    check_tilt_convention(material.hair)
    assert scene.render.engine == "HAIRIS"
    assert set(curves.inputs) == {"random"}, curves.inputs.keys()
    domain, random = curves.inputs["random"]
    check_strand_random(domain, random, 200)
    assert not any("per strand" in w for w in data.warnings), data.warnings


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
    helpers.assert_raises(export.ExportError, export.export_context, "panoramic",
                          "a panoramic camera must be refused")


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
    assert skin.kind == "SURFACE" and len(skin.nodes) == 1, skin
    principled = skin.nodes[0]
    assert principled["type"] == "principled" and principled["cycles"] == CYCLES, principled
    np.testing.assert_allclose(principled["base_color"], (0.6, 0.4, 0.3), atol=1e-7)
    assert principled["base_color_texture"] == -1


CYCLES = "3.4" if helpers.VERSION < (4, 0, 0) else "4.5"
"""The Cycles whose surface nodes this Blender has (written here, not read from compat)."""


def _sphere(name, smooth, location=(0.0, 0.0, 0.0), scale=(1.0, 1.0, 1.0)):
    bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=location, segments=16,
                                         ring_count=8)
    obj = bpy.context.view_layer.objects.active
    obj.name = name
    obj.scale = scale
    if smooth:
        bpy.ops.object.shade_smooth()
    else:
        bpy.ops.object.shade_flat()
    bpy.context.view_layer.update()
    return obj


def test_mesh_normals_and_uvs():
    """Corner normals: radial on a smooth sphere (its vertex normals, through a non-uniform
    scale); on a flat one each triangle's own normal, as Cycles shades flat faces, also where
    its quads are not planar (their polygon normal is then another); the UV map per corner as
    the loops hold it."""
    helpers.reset()
    helpers.make_camera(bpy.context.scene)
    _sphere("Smooth", True, location=(0.0, 0.0, 0.0), scale=(1.0, 1.0, 2.0))
    flat = _sphere("Flat", False, location=(3.0, 0.0, 0.0))
    helpers.scatter_vertices(flat.data, 0.1, seed=1)
    flat.data.calc_loop_triangles()
    polygon_normals = [np.array(flat.data.polygons[t.polygon_index].normal)
                       for t in flat.data.loop_triangles]
    bpy.context.view_layer.update()
    data = export.export_context()
    by_name = {m.name: m for m in data.meshes}
    mesh = by_name["Smooth"]
    assert mesh.normals.shape == (mesh.indices.shape[0], 3, 3)
    # The ellipsoid x² + y² + (z/2)² = 1: its normal at p is normalize(x, y, z/4).
    corners = mesh.positions[mesh.indices.reshape(-1)]
    analytic = corners * np.array([1.0, 1.0, 0.25])
    analytic /= np.linalg.norm(analytic, axis=1, keepdims=True)
    cosines = np.sum(mesh.normals.reshape(-1, 3) * analytic, axis=1)
    assert cosines.min() > 0.97, cosines.min()  # vertex normals of a 16 x 8 tessellation
    mesh = by_name["Flat"]
    p = mesh.positions[mesh.indices.reshape(-1)].reshape(-1, 3, 3)
    face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    keep = np.linalg.norm(face, axis=1) > 1e-9
    face = face[keep] / np.linalg.norm(face[keep], axis=1, keepdims=True)
    for k in range(3):  # thin triangles near the poles lose a little in float32
        np.testing.assert_allclose(mesh.normals[keep, k], face, atol=1e-4)
    # The quads are bent enough that a polygon's normal would fail the check above.
    polygon_normals = np.array(polygon_normals)[keep]
    assert np.abs(polygon_normals - face).max() > 0.01, np.abs(polygon_normals - face).max()
    # UVs: corner k of triangle t is loop loop_triangles[t].loops[k] of the active UV map.
    evaluated = flat.evaluated_get(bpy.context.evaluated_depsgraph_get())
    source = evaluated.to_mesh()
    source.calc_loop_triangles()
    layer = source.uv_layers.active
    for t in (0, 7, len(source.loop_triangles) - 1):
        for k, loop in enumerate(source.loop_triangles[t].loops):
            np.testing.assert_allclose(mesh.uvs[t, k], tuple(layer.data[loop].uv), atol=1e-7)
    evaluated.to_mesh_clear()
    # Without a UV map: no UVs.
    flat.data.uv_layers.remove(flat.data.uv_layers[0])
    flat.data.update()  # 4.x does not tag the mesh for the depsgraph by itself
    bpy.context.view_layer.update()
    assert {m.name: m for m in export.export_context().meshes}["Flat"].uvs is None


def _surface_material(name):
    material = bpy.data.materials.new(name)
    helpers.use_nodes(material)
    return material, material.node_tree.nodes, material.node_tree.links


def _principled(nodes):
    return next(n for n in nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")


def test_surface_nodes():
    """Principled BSDF inputs per version, an Image Texture through a Mapping node (file by
    path, generated image by pixels), Mix and Add Shaders, Emission, warnings."""
    scene = helpers.reset()
    helpers.make_camera(scene)
    obj = _sphere("Head", True)

    # A Principled BSDF with a PNG on Base Color through a Mapping node and a UV Map node.
    path = os.path.join(ARGS.workdir, "skin.png")
    image = bpy.data.images.new("SkinImage", 4, 2, alpha=False)
    image.pixels.foreach_set(np.linspace(0.0, 1.0, 4 * 2 * 4, dtype=np.float32))
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    skin, nodes, links = _surface_material("Skin")
    principled = _principled(nodes)
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.load(path)
    texture.interpolation = "Closest"
    texture.extension = "EXTEND"
    mapping = nodes.new("ShaderNodeMapping")
    helpers.socket(mapping, "Location").default_value = (0.1, 0.2, 0.0)
    helpers.socket(mapping, "Rotation").default_value = (0.0, 0.0, 0.3)
    helpers.socket(mapping, "Scale").default_value = (2.0, 1.0, 1.0)
    uv_map = nodes.new("ShaderNodeUVMap")
    links.new(uv_map.outputs["UV"], helpers.socket(mapping, "Vector"))
    links.new(mapping.outputs["Vector"], helpers.socket(texture, "Vector"))
    links.new(texture.outputs["Color"], helpers.socket(principled, "Base Color"))
    values = {"Metallic": 0.25, "Roughness": 0.35, "IOR": 1.4}
    if CYCLES == "3.4":
        values.update({"Specular": 0.6, "Specular Tint": 0.2, "Clearcoat": 0.3,
                       "Clearcoat Roughness": 0.1, "Sheen": 0.4, "Sheen Tint": 0.7})
    else:
        values.update({"Specular IOR Level": 0.6, "Coat Weight": 0.3, "Coat Roughness": 0.1,
                       "Coat IOR": 1.6})
        helpers.socket(principled, "Specular Tint").default_value = (0.9, 0.8, 0.7, 1.0)
        helpers.socket(principled, "Coat Tint").default_value = (0.5, 0.6, 0.7, 1.0)
    for name, value in values.items():
        helpers.socket(principled, name).default_value = value
    emission_name = "Emission" if CYCLES == "3.4" else "Emission Color"
    helpers.socket(principled, emission_name).default_value = (0.5, 0.25, 0.0, 1.0)
    helpers.socket(principled, "Emission Strength").default_value = 2.0
    obj.data.materials.append(skin)
    data = export.export_context()
    material = data.materials[data.meshes[0].materials[0]]
    assert material.kind == "SURFACE" and len(material.nodes) == 1, material
    node = material.nodes[0]
    names = {"Metallic": "metallic", "Roughness": "roughness", "IOR": "ior",
             "Specular": "specular", "Specular IOR Level": "specular",
             "Specular Tint": "specular_tint",
             "Clearcoat": "coat", "Clearcoat Roughness": "coat_roughness", "Sheen": "sheen",
             "Sheen Tint": "sheen_tint", "Coat Weight": "coat", "Coat Roughness": "coat_roughness",
             "Coat IOR": "coat_ior"}
    for name, value in values.items():
        assert math.isclose(node[names[name]], value, rel_tol=1e-6), (name, node)
    if CYCLES != "3.4":
        np.testing.assert_allclose(node["specular_tint_color"], (0.9, 0.8, 0.7), atol=1e-6)
        np.testing.assert_allclose(node["coat_tint"], (0.5, 0.6, 0.7), atol=1e-6)
        assert node["distribution"] == "multi_ggx"  # 4.x's default
    else:
        assert node["distribution"] == "ggx"
    np.testing.assert_allclose(node["emission"], (1.0, 0.5, 0.0), atol=1e-6)
    texture_data = data.textures[node["base_color_texture"]]
    assert texture_data.path == os.path.abspath(path) and texture_data.pixels is None
    assert texture_data.color_space == "srgb"  # an 8-bit PNG
    assert texture_data.interpolation == "closest" and texture_data.extension == "extend"
    assert texture_data.mapping == "point"
    np.testing.assert_allclose(texture_data.location, (0.1, 0.2, 0.0), atol=1e-6)
    np.testing.assert_allclose(texture_data.rotation, (0.0, 0.0, 0.3), atol=1e-6)
    np.testing.assert_allclose(texture_data.scale, (2.0, 1.0, 1.0), atol=1e-6)
    skin_warnings = [w for w in data.warnings if "Skin" in w]
    if CYCLES == "3.4":
        assert not skin_warnings, skin_warnings
    else:  # a coat over an emission: Cycles 4 dims the emission, hairis does not
        assert len(skin_warnings) == 1 and "emission under the coat" in skin_warnings[0], \
            skin_warnings

    # Mix (0.3) of a Diffuse with a generated texture and a Multiscatter Glossy, plus an
    # Emission through an Add Shader; one Mix input left empty.
    generated = bpy.data.images.new("Generated", 2, 2, float_buffer=True)
    generated.colorspace_settings.name = "Non-Color"
    pixels = np.array([0.1, 0.2, 0.3, 1.0, 0.4, 0.5, 0.6, 1.0, 0.7, 0.8, 0.9, 1.0,
                       0.2, 0.4, 0.6, 1.0], np.float32)
    generated.pixels.foreach_set(pixels)
    mixed, nodes, links = _surface_material("Mixed")
    output = nodes["Material Output"]
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    helpers.socket(diffuse, "Roughness").default_value = 0.4
    picture = nodes.new("ShaderNodeTexImage")
    picture.image = generated
    links.new(picture.outputs["Color"], helpers.socket(diffuse, "Color"))
    glossy = nodes.new("ShaderNodeBsdfGlossy")
    glossy.distribution = "MULTI_GGX"
    helpers.socket(glossy, "Roughness").default_value = 0.2
    mix = nodes.new("ShaderNodeMixShader")
    helpers.socket(mix, "Fac").default_value = 0.3
    links.new(diffuse.outputs["BSDF"], mix.inputs[1])
    links.new(glossy.outputs["BSDF"], mix.inputs[2])
    glow = nodes.new("ShaderNodeEmission")
    helpers.socket(glow, "Strength").default_value = 3.0
    add = nodes.new("ShaderNodeAddShader")
    links.new(mix.outputs["Shader"], add.inputs[0])
    links.new(glow.outputs["Emission"], add.inputs[1])
    links.new(add.outputs["Shader"], output.inputs["Surface"])
    half = nodes.new("ShaderNodeMixShader")  # feeds nothing: not read
    links.new(diffuse.outputs["BSDF"], half.inputs[1])
    obj.data.materials[0] = mixed
    data = export.export_context()
    nodes_out = data.materials[data.meshes[0].materials[0]].nodes
    kinds = [n["type"] for n in nodes_out]
    assert kinds == ["diffuse", "glossy", "mix", "emission", "add"], kinds
    assert nodes_out[2]["shader1"] == 0 and nodes_out[2]["shader2"] == 1
    assert math.isclose(nodes_out[2]["factor"], 0.3, rel_tol=1e-6)
    assert nodes_out[4]["shader1"] == 2 and nodes_out[4]["shader2"] == 3
    assert nodes_out[1]["distribution"] == "multi_ggx"
    assert math.isclose(nodes_out[0]["roughness"], 0.4, rel_tol=1e-6)
    assert math.isclose(nodes_out[3]["strength"], 3.0)
    generated_texture = data.textures[nodes_out[0]["color_texture"]]
    assert generated_texture.path is None and generated_texture.color_space == "linear"
    np.testing.assert_allclose(generated_texture.pixels.reshape(-1), pixels, atol=1e-6)

    # Unsupported things are named: a Noise Texture on Base Color, Transmission, Alpha,
    # a Box projection, a Glass BSDF, an empty Mix input.
    odd, nodes, links = _surface_material("Odd")
    principled = _principled(nodes)
    noise = nodes.new("ShaderNodeTexNoise")
    links.new(noise.outputs["Color"], helpers.socket(principled, "Base Color"))
    helpers.socket(principled, "Transmission" if CYCLES == "3.4" else "Transmission Weight") \
        .default_value = 0.5
    helpers.socket(principled, "Alpha").default_value = 0.5
    mix = nodes.new("ShaderNodeMixShader")
    glass = nodes.new("ShaderNodeBsdfGlass")
    links.new(glass.outputs["BSDF"], mix.inputs[1])
    links.new(mix.outputs["Shader"], nodes["Material Output"].inputs["Surface"])
    obj.data.materials[0] = odd
    data = export.export_context()
    text = "\n".join(data.warnings)
    assert "Glass BSDF is not supported on meshes" in text, text
    odd_nodes = data.materials[data.meshes[0].materials[0]].nodes
    assert [n["type"] for n in odd_nodes] == ["diffuse", "emission", "mix"], odd_nodes
    assert odd_nodes[1]["strength"] == 0.0  # the empty input: no closure
    links.new(principled.outputs["BSDF"], nodes["Material Output"].inputs["Surface"])
    data = export.export_context()
    text = "\n".join(data.warnings)
    assert "Noise Texture" in text and "not supported" in text, text
    assert "Transmission" in text and "opaque" in text, text
    assert "Alpha is not supported" in text, text
    if CYCLES != "3.4":
        helpers.socket(principled, "Sheen Weight").default_value = 0.5
        assert any("Sheen Weight is not supported" in w for w in export.export_context().warnings)


def test_unsupported_things_warn():
    """An unsupported node feeding a hair input, an environment texture without image,
    unknown shaders: warnings, no crash."""
    scene = helpers.make_test_scene(with_curves=False)
    hair = bpy.data.materials["Hair"]
    tree = hair.node_tree
    noise = tree.nodes.new("ShaderNodeTexNoise")
    tree.links.new(noise.outputs["Fac"],
                   helpers.socket(tree.nodes["Principled Hair BSDF"], "Roughness"))
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
    assert "Noise Texture 'Noise Texture' is not supported" in text and \
        "unlinked value of the Principled Hair BSDF's 'Roughness'" in text, text
    (curves,) = [c for c in data.curves if c.source == "PARTICLES"]
    assert "roughness" not in curves.inputs
    assert math.isclose(data.materials[curves.material].hair.roughness, 0.25, rel_tol=1e-6)
    assert "Environment Texture 'Environment Texture' has no image" in text, text
    assert "Glass BSDF is not supported" in text, text


def test_non_uniform_scale_on_hair_warns():
    """Cycles squashes the strands of a non-uniformly scaled object; the export says so for
    particle hair and Curves, and is silent for a uniform scale."""
    helpers.make_test_scene()
    head, curls = bpy.data.objects["Head"], bpy.data.objects["Curls"]
    head.scale = (1.3, 1.3, 1.3)
    curls.scale = (0.7, 0.7, 0.7)
    bpy.context.view_layer.update()
    text = "\n".join(export.export_context().warnings)
    assert "non-uniform scale" not in text, text
    head.scale = (0.85, 0.95, 1.15)
    curls.scale = (1.0, 2.0, 1.0)
    bpy.context.view_layer.update()
    text = "\n".join(export.export_context().warnings)
    for name in ("Head", "Curls"):
        assert "object %r has a non-uniform scale" % name in text, text


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
    params, _warnings, error = hair_material.read_hair_node(stub_hair_node("FUTURE"), "Future")
    assert params is None and "'Future'" in error and "'FUTURE' is not supported" in error, error
    params, _warnings, error = hair_material.read_hair_node(stub_hair_node(leave_out=("Coat",)),
                                                            "Old")
    assert params is None, params
    assert "'Old'" in error and "'Coat'" in error and bpy.app.version_string.split()[0] in error \
        and "3.4 to 5.x" in error, error
    # A socket whose display name changed but whose identifier did not.
    params, _warnings, error = hair_material.read_hair_node(
        stub_hair_node(rename={"Coat": "Coating"}), "Renamed")
    compat = helpers.module("compat")
    assert error == "material 'Renamed': the Principled Hair BSDF has no 'Coat' input in " \
        "Blender %s; Hairis supports %s" % (compat.version_string(), compat.SUPPORTED_TEXT), error
    node = stub_hair_node()
    node.inputs[7].name = "Coating"  # Coat: the identifier stays "Coat"
    params, _warnings, error = hair_material.read_hair_node(node, "Identifier")
    assert error is None and params.coat == 0.5, (error, params)
    # Huang reads the lobes by identifier; a Huang node without one is named.
    params, _warnings, error = hair_material.read_hair_node(
        stub_hair_node("HUANG", leave_out=("TT lobe",)), "NoLobe")
    assert params is None and "'TT lobe'" in error and "'NoLobe'" in error, error


def test_huang_rules_on_stub_nodes():
    """Cycles' Huang rules: Aspect Ratio must be finite and > 0 (above 1 is passed on, the
    library inverts it); a negative lobe is 0 with a warning; all three <= 0: no closure
    (exported as black, opaque strands, with a warning)."""
    def read(**values):
        return hair_material.read_hair_node(stub_hair_node("HUANG", values=values), "H")

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
    helpers.skip_without_huang()
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
    # Random Color/Roughness with Random unlinked vary per strand for Huang as for Chiang.
    check_hair_material(hair, material, {"random": 0.5}, fields=HUANG_FIELDS)
    curves = particle_curves(data)
    assert set(curves.inputs) == {"random"}, curves.inputs.keys()
    check_strand_random(*curves.inputs["random"], len(curves.first) - 1)
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
    helpers.skip_without_huang()
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
    helpers.assert_raises(export.ExportError, export.export_context, "no camera",
                          "export without a camera must fail")


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
        helpers.assert_raises(RuntimeError, bpy.ops.render.render,
                              "hairis native library not found at",
                              "rendering without the library must report an error")
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


# ---- Hair inputs per strand and per point (node_eval) ---------------------------------------

def _hair_tree():
    """The test scene's particle hair material: (node tree, Principled Hair BSDF)."""
    tree = bpy.data.materials["Hair"].node_tree
    return tree, tree.nodes["Principled Hair BSDF"]


def _intercepts(curves, keys):
    """Arc-length fractions of the exported (uniformly scaled) strands, written out here."""
    points = curves.positions.reshape(-1, keys, 3).astype(np.float64)
    steps = np.linalg.norm(np.diff(points, axis=1), axis=2)
    along = np.concatenate([np.zeros((points.shape[0], 1)), np.cumsum(steps, axis=1)], axis=1)
    return (along / along[:, -1:]).reshape(-1)


def test_color_ramp_on_intercept_into_melanin():
    """Hair Info Intercept → ColorRamp → Melanin: per point, the ramp's luminance at each
    point's arc-length fraction (Blender's own ColorRamp.evaluate, read here)."""
    helpers.make_test_scene(with_curves=False)
    tree, node = _hair_tree()
    info = tree.nodes.new("ShaderNodeHairInfo")
    ramp = tree.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.2, 0.2, 0.2, 1.0)
    ramp.color_ramp.elements[1].color = (0.9, 0.9, 0.9, 1.0)
    ramp.color_ramp.elements[1].position = 0.8
    tree.links.new(info.outputs["Intercept"], helpers.socket(ramp, "Fac"))
    tree.links.new(ramp.outputs["Color"], helpers.socket(node, "Melanin"))
    data = export.export_context()
    curves = particle_curves(data)
    keys = curves.point_count // curves.curve_count
    domain, melanin = curves.inputs["melanin"]
    assert domain == "point" and melanin.shape == (curves.point_count, 1), (domain, melanin.shape)
    expected = [0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
                for c in (ramp.color_ramp.evaluate(float(t)) for t in _intercepts(curves, keys))]
    # Cycles' 256-entry table is exact for a linear ramp, up to the kink at 0.8.
    np.testing.assert_allclose(melanin[:, 0], expected, atol=2e-3)
    assert np.isclose(melanin[:, 0].min(), 0.2, atol=1e-6) and melanin[:, 0].max() > 0.85
    params = data.materials[curves.material].hair
    assert math.isclose(params.melanin, 0.35, rel_tol=1e-6)  # the fiber keeps the socket's value
    assert "random" in curves.inputs  # Random Color 0.2 with Random unlinked, as before
    # Under another parametrization Melanin is not read: nothing is exported for it (Random
    # still is: Random Roughness reads it under every parametrization).
    node.parametrization = "COLOR"
    curves = particle_curves(export.export_context())
    assert "melanin" not in curves.inputs and "random" in curves.inputs, curves.inputs.keys()


def test_map_range_of_hair_random_into_roughness():
    """Hair Info Random → Map Range (0..1 → 0.15..0.6) → Roughness: per curve, the Map Range
    of the same per-strand random that feeds an unlinked Random."""
    helpers.make_test_scene(with_curves=False)
    tree, node = _hair_tree()
    remap = helpers.link_hair_random(tree, node, "Roughness", 0.15, 0.6)
    # A constant chain folds into the fiber: Value → Coat.
    value = tree.nodes.new("ShaderNodeValue")
    value.outputs[0].default_value = 0.45
    tree.links.new(value.outputs[0], helpers.socket(node, "Coat"))
    data = export.export_context()
    curves = particle_curves(data)
    domain, roughness = curves.inputs["roughness"]
    assert domain == "curve" and roughness.shape == (200, 1)
    random_domain, random = curves.inputs["random"]
    check_strand_random(random_domain, random, 200)
    np.testing.assert_allclose(roughness, 0.15 + 0.45 * random, atol=1e-6)
    params = data.materials[curves.material].hair
    assert math.isclose(params.coat, 0.45, rel_tol=1e-6) and "coat" not in curves.inputs
    assert params.random == 0.5
    # Clamp off and a range past 1: clamped to [0, 1] with a warning naming the input.
    remap.clamp = False
    helpers.socket(remap, "To Max").default_value = 1.4
    data = export.export_context()
    domain, roughness = particle_curves(data).inputs["roughness"]
    assert roughness.max() == 1.0 and roughness.min() >= 0.15 - 1e-6
    assert any("'Roughness'" in w and "hairis clamps them" in w for w in data.warnings), \
        data.warnings


def test_math_mix_and_separate_chains():
    """Math (Multiply Add) on Intercept into Melanin Redness, MixRGB of two RGB nodes by
    Intercept into Tint through Invert and Separate/Combine Color, Mix (Float) into Radial
    Roughness: per point, as written out here."""
    helpers.make_test_scene(with_curves=False)
    tree, node = _hair_tree()
    info = tree.nodes.new("ShaderNodeHairInfo")
    math_node = tree.nodes.new("ShaderNodeMath")
    math_node.operation = "MULTIPLY_ADD"
    helpers.socket(math_node, "Value_001").default_value = 0.5
    helpers.socket(math_node, "Value_002").default_value = 0.2
    tree.links.new(info.outputs["Intercept"], helpers.socket(math_node, "Value"))
    tree.links.new(math_node.outputs[0], helpers.socket(node, "Melanin Redness"))
    root, tip = tree.nodes.new("ShaderNodeRGB"), tree.nodes.new("ShaderNodeRGB")
    root.outputs[0].default_value = (0.9, 0.8, 0.7, 1.0)
    tip.outputs[0].default_value = (0.5, 0.6, 1.0, 1.0)
    mix = tree.nodes.new("ShaderNodeMixRGB")  # Blender 3.4 to 5.0
    tree.links.new(info.outputs["Intercept"], helpers.socket(mix, "Fac"))
    tree.links.new(root.outputs[0], helpers.socket(mix, "Color1"))
    tree.links.new(tip.outputs[0], helpers.socket(mix, "Color2"))
    invert = tree.nodes.new("ShaderNodeInvert")
    helpers.socket(invert, "Fac").default_value = 0.0  # passes the colour through
    separate = tree.nodes.new("ShaderNodeSeparateColor")
    combine = tree.nodes.new("ShaderNodeCombineColor")
    tree.links.new(mix.outputs[0], helpers.socket(invert, "Color"))
    tree.links.new(invert.outputs[0], helpers.socket(separate, "Color"))
    for channel in ("Red", "Green", "Blue"):
        tree.links.new(separate.outputs[channel], helpers.socket(combine, channel))
    tree.links.new(combine.outputs[0], helpers.socket(node, "Tint"))
    blend = tree.nodes.new("ShaderNodeMix")  # Blender 3.4's new Mix node, data type Float
    blend.data_type = "FLOAT"
    helpers.socket(blend, "A_Float").default_value = 0.2
    helpers.socket(blend, "B_Float").default_value = 0.6
    tree.links.new(info.outputs["Intercept"], helpers.socket(blend, "Factor_Float"))
    result = next(o for o in blend.outputs if o.identifier == "Result_Float")
    tree.links.new(result, helpers.socket(node, "Radial Roughness"))
    data = export.export_context()
    curves = particle_curves(data)
    t = _intercepts(curves, curves.point_count // curves.curve_count)
    domain, redness = curves.inputs["melanin_redness"]
    assert domain == "point"
    np.testing.assert_allclose(redness[:, 0], 0.2 + 0.5 * t, atol=1e-5)
    domain, tint = curves.inputs["tint"]
    assert domain == "point" and tint.shape == (curves.point_count, 3)
    expected = ((1.0 - t)[:, None] * np.array([0.9, 0.8, 0.7])
                + t[:, None] * np.array([0.5, 0.6, 1.0]))
    np.testing.assert_allclose(tint, expected, atol=1e-5)
    domain, radial = curves.inputs["radial_roughness"]
    assert domain == "point"
    np.testing.assert_allclose(radial[:, 0], 0.2 + 0.4 * t, atol=1e-5)
    # An HSV-based blend is not supported: named, the unlinked Tint used.
    mix.blend_type = "HUE"
    data = export.export_context()
    assert "tint" not in particle_curves(data).inputs
    assert any("blend mode HUE is not supported" in w and "'Tint'" in w for w in data.warnings), \
        data.warnings


def test_curves_object_intercept_and_length():
    """A Curves object: Intercept per point and Length per curve in object space, as Cycles."""
    scene = helpers.reset()
    helpers.make_camera(scene)
    material = helpers.make_hair_material("Strands", "MELANIN", Melanin=0.3)
    tree = material.node_tree
    node = tree.nodes["Principled Hair BSDF"]
    info = tree.nodes.new("ShaderNodeHairInfo")
    tree.links.new(info.outputs["Intercept"], helpers.socket(node, "Melanin"))
    scale = tree.nodes.new("ShaderNodeMath")
    scale.operation = "MULTIPLY"
    helpers.socket(scale, "Value_001").default_value = 0.25
    tree.links.new(info.outputs["Length"], helpers.socket(scale, "Value"))
    tree.links.new(scale.outputs[0], helpers.socket(node, "Coat"))
    obj, positions, _radii = helpers.make_curves(scene, material)
    data = export.export_context()
    (curves,) = data.curves
    first = curves.first.astype(np.int64)
    domain, melanin = curves.inputs["melanin"]
    assert domain == "point" and melanin.shape == (curves.point_count, 1)
    domain, coat = curves.inputs["coat"]
    assert domain == "curve" and coat.shape == (curves.curve_count, 1)
    for c in (0, 3, curves.curve_count - 1):
        local = positions[first[c]:first[c + 1]].astype(np.float64)  # object space
        steps = np.linalg.norm(np.diff(local, axis=0), axis=1)
        along = np.concatenate([[0.0], np.cumsum(steps)])
        np.testing.assert_allclose(melanin[first[c]:first[c + 1], 0], along / along[-1], atol=1e-5)
        assert math.isclose(coat[c, 0], min(0.25 * along[-1], 1.0), rel_tol=1e-5), \
            (coat[c], along[-1])


def test_groom_memory_estimate():
    """The library's memory for a groom is estimated from its point count before it is built:
    5M strands of 9 points fit the 24 GB machine the add-on is measured on, the estimate is
    not below the copies the library provably holds, and a groom above the available memory
    is refused by the export with its object and strand counts and the estimate."""
    strands, points = 5000000, 9
    # The handle's and the render's copy of points and radii (16 bytes each), the control
    # points with duplicated ends (16 bytes), a segment start and curve index per segment.
    floor = strands * points * 48 + strands * (points - 1) * 8
    estimate = memory.render_bytes_estimate(strands * points, strands)
    assert floor < estimate < 16e9, (floor, estimate)
    assert memory.render_bytes_estimate(2 * strands * points, 2 * strands) == 2 * estimate
    # Broadcast arrays: the counts of a 5M groom without its memory.
    groom = scene_data.CurvesData(
        name="Groom", source="CURVES", material=0,
        first=np.broadcast_to(np.uint32(0), (strands + 1,)),
        positions=np.broadcast_to(np.zeros(3, np.float32), (strands * points, 3)),
        radii=np.broadcast_to(np.float32(0.001), (strands * points,)))
    data = scene_data.SceneData(curves=[groom, groom])
    need = 2 * estimate
    assert memory.memory_problem(data, need) is None
    assert memory.memory_problem(data, None) is None
    message = memory.memory_problem(data, need - 1)
    assert message is not None
    for part in ("2 object(s)", "%d strands" % (2 * strands), "%d points" % (2 * strands * points),
                 "%.1f GB" % (need / 1e9)):
        assert part in message, (part, message)
    helpers.make_test_scene()
    exported = export.export_context()
    available = memory.available_memory_bytes()
    assert available is None or available > 0
    need = memory.render_bytes_estimate(sum(c.point_count for c in exported.curves),
                                        sum(c.curve_count for c in exported.curves))
    original = memory.available_memory_bytes
    memory.available_memory_bytes = lambda: need - 1
    try:
        helpers.assert_raises(export.ExportError, export.export_context,
                              "%d object(s)" % len(exported.curves),
                              "a groom above the available memory was exported")
    finally:
        memory.available_memory_bytes = original


def test_ray_visibility_warns():
    """Ray Visibility switched off, Holdout or Shadow Catcher on an object is named in a
    warning (Hairis renders every object visible to every ray); a scene at the defaults has
    no such warning."""
    helpers.make_test_scene()
    assert not any("Ray Visibility" in w for w in export.export_context().warnings)
    mesh = next(o for o in bpy.data.objects if o.type == "MESH")
    mesh.visible_camera = False
    mesh.visible_shadow = False
    mesh.is_holdout = True
    bpy.context.view_layer.update()
    warnings = [w for w in export.export_context().warnings if repr(mesh.name) in w]
    assert len(warnings) == 1, warnings
    assert ("Ray Visibility Camera off and Ray Visibility Shadow off and Holdout on"
            in warnings[0]), warnings


helpers.run([
    test_ray_visibility_warns,
    test_particle_hair_viewport,
    test_curves_object,
    test_curves_without_radius,
    test_lights_world_camera,
    test_camera_orthographic_and_scale,
    test_mesh,
    test_mesh_normals_and_uvs,
    test_surface_nodes,
    test_unsupported_things_warn,
    test_non_uniform_scale_on_hair_warns,
    test_hair_node_models_and_missing_sockets,
    test_huang_rules_on_stub_nodes,
    test_huang_materials_export,
    test_curves_normals_for_huang,
    test_disabled_modifier_and_strands,
    test_no_camera,
    test_render_mode_export_through_engine,
    test_environment_world,
    test_color_ramp_on_intercept_into_melanin,
    test_map_range_of_hair_random_into_roughness,
    test_math_mix_and_separate_chains,
    test_curves_object_intercept_and_length,
    test_groom_memory_estimate,
])
