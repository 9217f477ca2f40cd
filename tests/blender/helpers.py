"""Shared code of the headless Blender tests (runs inside Blender's Python).

Each test script calls :func:`setup` (parse the arguments run_test.py passes after ``--``,
install the add-on into the temporary user folders and enable it), builds scenes with the
``make_*`` helpers and runs its test functions with :func:`run`, which ends with the result
line run_test.py judges the test by.

Runs in a Blender executable (``blender -b --python``) and in a bpy module's Python alike. The
add-on is installed as a legacy add-on (package ``hairis``) or as an Extension (package
``bl_ext.user_default.hairis``): tests reach its modules through :func:`module`.
"""

import argparse
import math
import os
import platform
import subprocess
import sys
import threading
import time
import traceback
import types

import bpy  # first: as a Python module, importing bpy puts addon_utils on sys.path
import addon_utils  # noqa: I100
import numpy as np
from mathutils import Euler, Vector

import compare_stats  # siblings: whoever imports helpers has this folder on sys.path
import hdri

SKIP = 77
RESULT_PREFIX = "hairis-test-result: "
"""run_test.py judges a test by the last line starting with this (not only by exit codes)."""
LEGACY_MODULE = "hairis"
EXTENSION_REPOSITORY = "user_default"
EXTENSION_MODULE = "bl_ext.%s.hairis" % EXTENSION_REPOSITORY
MODULE = LEGACY_MODULE
"""The installed add-on's package name (set by :func:`install_addon`)."""
VERSION = tuple(bpy.app.version)


def parse_args():
    """The arguments after ``--``: zip, install (legacy/extension), fake_library, workdir."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--zip", required=True)
    parser.add_argument("--install", choices=("legacy", "extension"), default="legacy")
    parser.add_argument("--fake-library", default="")
    parser.add_argument("--workdir", required=True)
    parser.add_argument("--expect-version", default="")
    return parser.parse_args(argv)


def assert_raises(kind, call, text, failure):
    """Asserts that ``call()`` raises ``kind`` with ``text`` in its message (``failure`` says
    what went wrong when it raises nothing); returns the error."""
    try:
        call()
    except kind as error:
        assert text in str(error), error
        return error
    raise AssertionError(failure)


def result(outcome):
    """Prints the result line run_test.py reads (PASSED, FAILED or SKIPPED)."""
    print(RESULT_PREFIX + outcome, flush=True)


def skip(message):
    """Ends the test as skipped (exit code 77, CTest's SKIP_RETURN_CODE)."""
    print("SKIP: " + message, flush=True)
    result("SKIPPED")
    sys.exit(SKIP)


class Skipped(Exception):
    """Raised by :func:`skip_function`: :func:`run` counts that test function as skipped."""


def skip_function(message):
    """Skips the running test function: the file then ends as skipped (exit code 77) unless
    another function failed, so CI's allow-list sees the skip and its reason."""
    raise Skipped(message)


def skip_without_huang():
    """Skips the running test function on a Blender without the Huang model (before 4.0)."""
    if VERSION < (4, 0, 0):
        skip_function("Blender %d.%d has no Huang model" % VERSION[:2])


def install_legacy(zip_path):
    """Installs the bl_info zip into BLENDER_USER_SCRIPTS/addons and enables it."""
    user_scripts = os.environ.get("BLENDER_USER_SCRIPTS")
    assert user_scripts, "BLENDER_USER_SCRIPTS must point to a temporary folder"
    done = bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    assert done == {"FINISHED"}, done
    done = bpy.ops.preferences.addon_enable(module=LEGACY_MODULE)
    assert done == {"FINISHED"}, done
    return LEGACY_MODULE, os.path.join(user_scripts, "addons", LEGACY_MODULE)


def install_extension(zip_path):
    """Installs the Extension zip into the user_default repository and enables it (4.2+)."""
    if VERSION < (4, 2, 0):
        skip("Extensions need Blender 4.2 or newer (this is %s)" % bpy.app.version_string)
    repositories = {repo.module: repo for repo in bpy.context.preferences.extensions.repos}
    assert EXTENSION_REPOSITORY in repositories, sorted(repositories)
    done = bpy.ops.extensions.package_install_files(
        filepath=zip_path, repo=EXTENSION_REPOSITORY, enable_on_install=True)
    assert done == {"FINISHED"}, done
    folder = repositories[EXTENSION_REPOSITORY].directory
    return EXTENSION_MODULE, os.path.join(folder, "hairis")


def install_addon(zip_path, how="legacy"):
    """Installs the zip (``how``: 'legacy' or 'extension') and enables it; returns the package.

    The package must come from the temporary folder it was installed into (not from any
    other copy on the machine).
    """
    global MODULE
    assert os.path.isfile(zip_path), "add-on zip %s does not exist" % zip_path
    name, expected = (install_extension if how == "extension" else install_legacy)(zip_path)
    MODULE = name
    loaded, enabled = addon_utils.check(name)
    assert loaded and enabled, "the add-on %s did not enable" % name
    package = sys.modules[name]
    installed = os.path.realpath(os.path.dirname(package.__file__))
    assert installed == os.path.realpath(expected), \
        "add-on loaded from %s, not %s" % (installed, expected)
    print("helpers: Blender %s, add-on %s installed as %s from %s"
          % (bpy.app.version_string, name, how, installed), flush=True)
    return package


def module(name):
    """The add-on's submodule ``name`` ('native', 'engine', ...) as installed."""
    return sys.modules["%s.%s" % (MODULE, name)]


def setup():
    """Parses arguments, installs and enables the add-on; returns (args, package)."""
    args = parse_args()
    try:
        if args.expect_version:
            running = "%d.%d" % VERSION[:2]
            assert running == args.expect_version, \
                "this test is for Blender %s, but this is Blender %s" \
                % (args.expect_version, bpy.app.version_string)
        package = install_addon(args.zip, args.install)
    except Exception:  # noqa: BLE001 - the result line must still come
        traceback.print_exc()
        result("FAILED")
        sys.exit(1)
    return args, package


def bundled_library(package):
    """The path of the library inside the installed add-on (may not exist)."""
    return os.path.join(os.path.dirname(package.__file__), "lib", "libhairis.so")


def require_library(package, override=None):
    """The library to render with (``override``, else the one bundled in ``package``); ends the
    test as skipped while it does not exist."""
    path = override or bundled_library(package)
    if not os.path.isfile(path):
        skip("libhairis.so is not built yet (looked for %s)" % path)
    return path


def use_library(path):
    """Points the add-on at ``path`` through HAIRIS_LIBRARY ('' or None: the bundled one)."""
    if path:
        os.environ["HAIRIS_LIBRARY"] = path
    else:
        os.environ.pop("HAIRIS_LIBRARY", None)


def run(tests):
    """Runs test functions in order; prints PASS/FAIL and exits 1 if any failed.
    HAIRIS_TEST_ONLY (comma-separated function names) runs only those, for development."""
    only = [name for name in os.environ.get("HAIRIS_TEST_ONLY", "").split(",") if name]
    if only:
        tests = [test for test in tests if test.__name__ in only]
    failed, skipped = [], []
    for test in tests:
        start = time.monotonic()
        try:
            test()
        except Skipped as reason:
            skipped.append((test.__name__, str(reason)))
            print("SKIP %s: %s" % (test.__name__, reason), flush=True)
        except Exception:  # noqa: BLE001 - report every failure
            traceback.print_exc()
            failed.append(test.__name__)
            print("FAIL %s" % test.__name__, flush=True)
        else:
            print("PASS %s (%.2f s)" % (test.__name__, time.monotonic() - start), flush=True)
    print("%d passed, %d failed, %d skipped"
          % (len(tests) - len(failed) - len(skipped), len(failed), len(skipped)), flush=True)
    if failed:
        result("FAILED")
    elif skipped:
        # The reasons again at the end, where a truncated log keeps them.
        for name, reason in skipped:
            print("SKIP: %s (%s)" % (reason, name), flush=True)
        result("SKIPPED")
    else:
        result("PASSED")
    # Exit explicitly: Blender exits 1 after any render that reported an error, even one a
    # test provoked and caught.
    sys.exit(1 if failed else SKIP if skipped else 0)


# ---- Scenes ----------------------------------------------------------------------------------

def configure(target, **values):
    """Sets each of ``values`` on ``target`` (particle settings, engine settings)."""
    for name, value in values.items():
        setattr(target, name, value)


def reset():
    """An empty file (the add-on stays enabled)."""
    bpy.ops.wm.read_homefile(use_empty=True)
    return bpy.context.scene


def use_nodes(idblock):
    """Gives a material or world its node tree (5.0+: always there; use_nodes is deprecated)."""
    if VERSION < (5, 0, 0):
        idblock.use_nodes = True
    assert idblock.node_tree is not None, idblock.name


def make_bsdf_material(name, node_type):
    """A material whose output is fed by one new ``node_type`` BSDF; returns (material, node)."""
    material = bpy.data.materials.new(name)
    use_nodes(material)
    tree = material.node_tree
    for node in list(tree.nodes):
        if node.type != "OUTPUT_MATERIAL":
            tree.nodes.remove(node)
    output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
    bsdf = tree.nodes.new(node_type)
    tree.links.new(bsdf.outputs["BSDF"], output.inputs["Surface"])
    return material, bsdf


def socket(node, name):
    """The input called ``name`` (by name or identifier), available or not.

    From Blender 4.0 ``node.inputs[name]`` skips sockets the node's settings hide (a hair
    node's Color under the Melanin parametrization).
    """
    for candidate in node.inputs:
        if candidate.name == name or candidate.identifier == name:
            return candidate
    raise KeyError("%s has no input %r in Blender %s" % (node.name, name, bpy.app.version_string))


def make_hair_material(name, parametrization="MELANIN", **inputs):
    """A material whose output is fed by a Principled Hair BSDF with the given inputs."""
    material, hair = make_bsdf_material(name, "ShaderNodeBsdfHairPrincipled")
    hair.parametrization = parametrization
    for key, value in inputs.items():
        socket(hair, key).default_value = value
    return material


def make_surface_material(name, color=(0.6, 0.4, 0.3, 1.0)):
    """A Principled BSDF material with a base colour."""
    material = bpy.data.materials.new(name)
    use_nodes(material)
    node = material.node_tree.nodes["Principled BSDF"]
    socket(node, "Base Color").default_value = color
    return material


def make_camera(scene, location=(0.0, -6.0, 1.0), rotation=(math.radians(90), 0.0, 0.0),
                resolution=(64, 48), percentage=50):
    """A perspective camera looking along +Y; sets the output resolution."""
    data = bpy.data.cameras.new("Camera")
    data.lens = 50.0
    camera = bpy.data.objects.new("Camera", data)
    camera.location = location
    camera.rotation_euler = Euler(rotation)
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = percentage
    return camera


def make_world(scene, color=(0.05, 0.1, 0.2), strength=1.5):
    """A world whose Background node has ``color``·``strength``."""
    world = bpy.data.worlds.new("World")
    use_nodes(world)
    background = world.node_tree.nodes["Background"]
    socket(background, "Color").default_value = tuple(color) + (1.0,)
    socket(background, "Strength").default_value = strength
    scene.world = world
    return world


def make_light(scene, kind, name, location=(0.0, 0.0, 5.0), rotation=(0.3, 0.2, 0.1), **props):
    """A light object of ``kind`` with ``props`` set on its data."""
    data = bpy.data.lights.new(name, kind)
    for key, value in props.items():
        setattr(data, key, value)
    light = bpy.data.objects.new(name, data)
    light.location = location
    light.rotation_euler = Euler(rotation)
    scene.collection.objects.link(light)
    return light


def make_particle_hair(scene, count=200, children=None, location=(0.5, -0.25, 0.1), scale=1.5,
                       hair_material=None, skin_material=None):
    """A sphere with a hair particle system (``children``: None or rendered count).

    Without children the strands grow from the vertices of an icosphere that has enough of
    them, in order, so every Blender process makes the same groom: Blender places particles on
    faces, and children, anew in each process, which would make a comparison's verdict change
    from run to run. An icosphere's vertices do not line up in rings, and its faces are
    triangles, flat however they are shaded."""
    if children is None:
        subdivisions = 1
        while 10 * 4 ** (subdivisions - 1) + 2 < count:  # its vertex count
            subdivisions += 1
        bpy.ops.mesh.primitive_ico_sphere_add(radius=1.0, location=location,
                                              subdivisions=subdivisions)
    else:
        bpy.ops.mesh.primitive_uv_sphere_add(radius=1.0, location=location, segments=16,
                                             ring_count=8)
    sphere = bpy.context.view_layer.objects.active
    sphere.name = "Head"
    sphere.scale = (scale, scale, scale)
    sphere.data.materials.append(skin_material)
    sphere.data.materials.append(hair_material)
    settings = add_hair_particles(sphere, count, material_index=2, children=children)
    if children is None:
        settings.emit_from = "VERT"
        settings.use_emit_random = False
    return sphere


def scatter_vertices(mesh, spread, seed):
    """Moves each vertex of a unit sphere ``mesh`` by about ``spread`` radians along the sphere
    (a fixed random draw), so that hairs grown from its vertices do not line up in rings."""
    co = np.empty(len(mesh.vertices) * 3)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    step = np.random.default_rng(seed).normal(scale=spread, size=co.shape)
    step -= np.sum(step * co, axis=1, keepdims=True) * co
    co += step
    co /= np.linalg.norm(co, axis=1, keepdims=True)
    mesh.vertices.foreach_set("co", co.reshape(-1))
    mesh.update()


def make_groom_head(scene, hair_material, skin_material, children, radius_scale):
    """A head-sized sphere (radius 0.1) with 1000 hair parents of length 0.3, ``children``
    interpolated children each (rendered), strands of ``radius_scale``; returns the particle
    settings."""
    sphere = make_particle_hair(scene, count=1000, children=children, location=(0.0, 0.0, 0.0),
                                scale=0.1, hair_material=hair_material,
                                skin_material=skin_material)
    settings = sphere.modifiers["Hair"].particle_system.settings
    settings.hair_length = 0.3
    settings.radius_scale = radius_scale
    return settings


def add_hair_particles(obj, count, material_index, hair_length=0.4, children=None,
                       density_group=""):
    """A hair particle system on mesh ``obj`` shaded with its material slot ``material_index``
    (1-based); ``density_group``: a vertex group whose weights are the emission density.
    Returns the particle settings."""
    modifier = obj.modifiers.new("Hair", "PARTICLE_SYSTEM")
    modifier.particle_system.vertex_group_density = density_group
    settings = modifier.particle_system.settings
    settings.type = "HAIR"
    settings.count = count
    settings.hair_length = hair_length
    settings.render_step = 3
    settings.display_step = 2
    settings.root_radius = 1.0
    settings.tip_radius = 0.2
    settings.radius_scale = 0.02
    settings.shape = 0.3
    settings.use_close_tip = True
    settings.material = material_index
    if children:
        settings.child_type = "INTERPOLATED"
        # Display amount of children per parent: child_nbr, child_percent from 4.0.
        setattr(settings, "child_percent" if VERSION >= (4, 0, 0) else "child_nbr", 1)
        settings.rendered_child_count = children
    else:
        settings.child_type = "NONE"
    return settings


def make_curves(scene, hair_material, location=(0.0, 0.0, 1.0), rotation=(0.0, 0.0, 1.2),
                scale=2.0, radius=True):
    """A Curves object with known positions and radii; returns (object, positions, radii)."""
    bpy.ops.object.curves_random_add(location=(0.0, 0.0, 0.0))
    obj = bpy.context.view_layer.objects.active
    obj.name = "Curls"
    curves = obj.data
    n = len(curves.points)
    rng = np.random.default_rng(7)
    positions = rng.uniform(-0.5, 0.5, size=(n, 3)).astype(np.float32)
    curves.position_data.foreach_set("vector", positions.reshape(-1))
    radii = rng.uniform(0.001, 0.01, size=n).astype(np.float32)
    attribute = curves.attributes.get("radius")
    if radius:
        if attribute is None:
            attribute = curves.attributes.new("radius", "FLOAT", "POINT")
        attribute.data.foreach_set("value", radii)
    elif attribute is not None:
        curves.attributes.remove(attribute)
    obj.location = location
    obj.rotation_euler = Euler(rotation)
    obj.scale = (scale, scale, scale)
    curves.materials.append(hair_material)
    return obj, positions, radii


def make_demo_head(resolution=(480, 360), count=1500, children=10,
                   sun_rotation=(math.radians(50), 0.0, math.radians(30)), empty_file=True):
    """The demo scene (scripts/render_demo.py): a head of brown particle hair under a sun and a
    sky, rendered by Hairis. Returns the scene. ``empty_file`` False builds it in the open
    file, without its objects (a running UI must keep its screen)."""
    if empty_file:
        scene = reset()
    else:
        scene = bpy.context.scene
        for obj in list(bpy.data.objects):
            bpy.data.objects.remove(obj)
    scene.render.engine = "HAIRIS"
    make_camera(scene, location=(0.0, -7.5, 0.3), resolution=resolution, percentage=100)
    make_world(scene, color=(0.35, 0.45, 0.6), strength=1.0)
    hair = make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.45, "Melanin Redness": 0.5, "Roughness": 0.3, "Radial Roughness": 0.3})
    skin = make_surface_material("Skin", (0.7, 0.5, 0.4, 1.0))
    make_particle_hair(scene, count=count, children=children, location=(0.0, 0.0, 0.3),
                       scale=1.3, hair_material=hair, skin_material=skin)
    make_light(scene, "SUN", "Sun", energy=4.0, angle=math.radians(2.0), rotation=sun_rotation)
    return scene


def make_test_scene(children=None, with_curves=True):
    """The standard test scene: particle hair, Curves, sun, point, area, spot, world, camera."""
    scene = reset()
    scene.render.engine = "HAIRIS"
    make_camera(scene)
    make_world(scene)
    hair = make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.35, "Melanin Redness": 0.6, "Tint": (0.9, 0.8, 0.7, 1.0),
        "Roughness": 0.25, "Radial Roughness": 0.4, "Coat": 0.1, "IOR": 1.6,
        "Offset": math.radians(3.0), "Random Color": 0.2, "Random Roughness": 0.1})
    skin = make_surface_material("Skin")
    curly = make_hair_material("Curly", "ABSORPTION", **{
        "Absorption Coefficient": (0.3, 0.6, 1.2), "Roughness": 0.5, "IOR": 1.5})
    make_particle_hair(scene, children=children, hair_material=hair, skin_material=skin)
    if with_curves:
        make_curves(scene, curly)
    make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(5.0))
    make_light(scene, "POINT", "Bulb", location=(1.0, -2.0, 3.0), energy=100.0,
               shadow_soft_size=0.25)
    make_light(scene, "AREA", "Panel", location=(-2.0, -1.0, 2.0), energy=50.0,
               shape="RECTANGLE", size=0.5, size_y=0.25)
    make_light(scene, "SPOT", "Spot", location=(0.0, -3.0, 3.0), energy=10.0)
    bpy.context.view_layer.update()
    return scene


def make_sphere_and_curves(resolution):
    """A small Hairis scene: Curves in front of a sphere under a sun and a sky, seen at
    ``resolution``."""
    scene = reset()
    scene.render.engine = "HAIRIS"
    make_camera(scene, location=(0.0, -3.2, 0.0), resolution=resolution, percentage=100)
    make_world(scene, color=(0.4, 0.5, 0.7), strength=1.0)
    hair = make_hair_material("Hair", "MELANIN", **{"Melanin": 0.3, "Roughness": 0.3})
    skin = make_surface_material("Skin", (0.7, 0.5, 0.4, 1.0))
    make_curves(scene, hair, location=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0), scale=1.6)
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.5, location=(0.0, 1.0, 0.0))
    bpy.context.view_layer.objects.active.data.materials.append(skin)
    make_light(scene, "SUN", "Sun", energy=3.0, angle=0.05, rotation=(0.6, 0.3, 0.0))
    return scene


# ---- Hairis against Cycles -------------------------------------------------------------------

def make_diffuse_material(name, color):
    """A Diffuse BSDF material (Lambertian, as Hairis shades meshes)."""
    material, diffuse = make_bsdf_material(name, "ShaderNodeBsdfDiffuse")
    socket(diffuse, "Color").default_value = color
    return material


def match_cycles(scene, samples, bounces):
    """Cycles settings under which its image is comparable with Hairis' (see the README)."""
    cycles = scene.cycles
    cycles.device = "CPU"
    cycles.samples = samples
    cycles.use_adaptive_sampling = False
    # Neither engine samples adaptively: every pixel of both gets every sample.
    scene.hairis.use_adaptive_sampling = False
    cycles.use_denoising = False
    for name in ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces",
                 "transparent_max_bounces"):
        setattr(cycles, name, bounces)
    cycles.volume_bounces = 0
    cycles.blur_glossy = 0.0
    cycles.sample_clamp_direct = 0.0
    cycles.sample_clamp_indirect = 0.0
    cycles.light_sampling_threshold = 0.0
    cycles.pixel_filter_type = "BOX"
    cycles.filter_width = 1.0
    scene.cycles_curves.shape = "THICK"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"


def match_engines(scene, samples, bounces):
    """Cycles as Hairis needs it (``match_cycles``) and Hairis at the same samples and bounce
    limit on every core."""
    match_cycles(scene, samples, bounces)
    settings = scene.hairis
    settings.samples = samples
    settings.max_bounces = bounces
    settings.threads = 0
    bpy.context.view_layer.update()


def use_table(scene, bounces, threads=0):
    """Hairis at TABLE with Auto Bake and ``bounces``; ``threads`` above 0 fixes both engines'
    thread count, so that timings compare like with like."""
    settings = scene.hairis
    settings.max_bounces = bounces
    settings.strategy = "TABLE"
    settings.auto_bake = True
    if threads:
        settings.threads = threads
        scene.render.threads_mode = "FIXED"
        scene.render.threads = threads


def set_samples(scene, samples):
    """The same sample count for Cycles and Hairis."""
    scene.cycles.samples = samples
    scene.hairis.samples = samples


def make_comparison_lights(scene):
    """The comparison scenes' lights: a 3° sun, a point light with a radius and an area light."""
    make_light(scene, "SUN", "Sun", energy=2.5, angle=math.radians(3.0),
               rotation=(0.6, 0.3, 0.0))
    make_light(scene, "POINT", "Bulb", location=(1.5, -1.5, 1.5), energy=60.0,
               shadow_soft_size=0.2)
    make_light(scene, "AREA", "Panel", location=(-1.5, -1.0, 1.0), energy=40.0,
               shape="RECTANGLE", size=0.6, size_y=0.3,
               rotation=(math.radians(60), 0.0, math.radians(-40)))


def make_compare_scene(samples, bounces, strategy, resolution=(64, 48), curves_offset=None,
                       extras=(), strands=300):
    """The Hairis-against-Cycles scene: particle hair, Curves, a diffuse sphere, three kinds
    of light and a world colour, with both engines set up alike (``match_cycles``).

    Both hair materials are Chiang's (the node's default model); the particle hair keeps the
    node's default Offset (2°), the Curves object's takes ``curves_offset`` (radians) when
    given. ``extras``: functions of the scene that add more objects (other hair models)
    before both engines are set up; ``strands``: the head's number of hairs.
    """
    scene = reset()
    make_camera(scene, location=(0.0, -3.2, 0.0), resolution=resolution, percentage=100)
    make_world(scene, color=(0.4, 0.5, 0.7), strength=0.8)
    hair = make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.3, "Melanin Redness": 0.7, "Roughness": 0.3, "Radial Roughness": 0.4,
        "Coat": 0.1, "IOR": 1.55})
    dyed_inputs = {"Color": (0.2, 0.5, 0.8, 1.0), "Roughness": 0.45}
    if curves_offset is not None:
        dyed_inputs["Offset"] = curves_offset
    dyed = make_hair_material("Dyed", "COLOR", **dyed_inputs)
    skin = make_diffuse_material("Skin", (0.7, 0.5, 0.4, 1.0))
    make_curves(scene, dyed, location=(0.2, 0.0, 0.1), rotation=(0.0, 0.0, 0.0), scale=1.4)
    make_particle_hair(scene, count=strands, location=(-0.3, 1.2, -0.5), scale=0.8,
                       hair_material=hair, skin_material=skin)
    make_comparison_lights(scene)
    for extra in extras:
        extra(scene)
    match_engines(scene, samples, bounces)
    scene.hairis.strategy = strategy
    scene.hairis.auto_bake = True
    return scene


def make_huang_material(name, color, aspect, lobes=(1.0, 1.0, 1.0), roughness=0.3):
    """A Principled Hair BSDF with the Huang model (Direct Coloring)."""
    material = make_hair_material(name, "COLOR", **{
        "Color": color, "Roughness": roughness, "IOR": 1.55, "Offset": math.radians(2.0),
        "Aspect Ratio": aspect, "R lobe": lobes[0], "TT lobe": lobes[1], "TRT lobe": lobes[2]})
    material.node_tree.nodes["Principled Hair BSDF"].model = "HUANG"
    return material


def make_curves_object(scene, name, material, positions, radius, location):
    """A Curves object of strands with ``positions`` (count, points, 3) and one ``radius``, its
    points set before anything asks for its normals (Blender keeps normals cached when
    positions are written through position_data)."""
    count, points = positions.shape[:2]
    curves = bpy.data.hair_curves.new(name)
    curves.add_curves([points] * count)
    curves.position_data.foreach_set("vector", positions.astype(np.float32).reshape(-1))
    radii = curves.attributes.new("radius", "FLOAT", "POINT")
    radii.data.foreach_set("value", np.full(count * points, radius, np.float32))
    curves.materials.append(material)
    obj = bpy.data.objects.new(name, curves)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def make_fresh_curves(scene, name, material, count, points, radius, seed, location, spread):
    """A Curves object of `count` wavy strands (:func:`make_curves_object`)."""
    rng = np.random.default_rng(seed)
    roots = rng.uniform(-spread, spread, (count, 3)) * np.array([1.0, 0.3, 1.0])
    lean = rng.uniform(-0.4, 0.4, (count, 3)) + np.array([0.0, 0.0, 1.0])
    t = np.linspace(0.0, 1.0, points)[None, :, None]
    wave = 0.08 * np.sin(7.0 * t + rng.uniform(0.0, 6.3, (count, 1, 1)))
    positions = roots[:, None, :] + 0.8 * lean[:, None, :] * t + wave * np.array([1.0, 0.5, 0.0])
    return make_curves_object(scene, name, material, positions, radius, location)


def make_huang_scene(samples, bounces, huang_sampling, resolution=(64, 48)):
    """test_cycles_huang's scene: Huang hair of aspect 0.85 on a Curves object and on particle
    hair (on a diffuse sphere), thick fibers of aspect 0.5 with lobes (1, 0.5, 0.2) wider than a
    pixel, a sun, a point light with a radius, an area light and a world colour; Cycles matched
    (match_cycles), Hairis at UNIFORM with Huang Sampling ``huang_sampling``."""
    scene = reset()
    make_camera(scene, location=(0.0, -3.2, 0.0), resolution=resolution, percentage=100)
    make_world(scene, color=(0.4, 0.5, 0.7), strength=0.8)
    blond = make_huang_material("Blond", (0.55, 0.4, 0.25, 1.0), 0.85)
    dark = make_huang_material("Dark", (0.12, 0.06, 0.03, 1.0), 0.85, roughness=0.4)
    oval = make_huang_material("Oval", (0.2, 0.5, 0.8, 1.0), 0.5, lobes=(1.0, 0.5, 0.2),
                               roughness=0.25)
    skin = make_diffuse_material("Skin", (0.7, 0.5, 0.4, 1.0))
    make_fresh_curves(scene, "Curls", blond, 120, 8, 0.006, 3, (0.45, 0.0, -0.6), 0.35)
    make_fresh_curves(scene, "Ribbons", oval, 6, 6, 0.05, 5, (-0.55, -0.3, -0.5), 0.25)
    make_particle_hair(scene, count=300, location=(-0.3, 1.2, -0.5), scale=0.8,
                       hair_material=dark, skin_material=skin)
    make_comparison_lights(scene)
    match_cycles(scene, samples, bounces)
    settings = scene.hairis
    settings.samples = samples
    settings.max_bounces = bounces
    settings.max_transparent_bounces = bounces
    settings.strategy = "UNIFORM"
    settings.huang_sampling = huang_sampling
    settings.threads = 0
    bpy.context.view_layer.update()
    return scene


REPOSITORY = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def study_settings(resolution, ref_spp, spps, seeds):
    """A study's (resolution, reference spp, spps, seeds): the defaults given, each replaced by
    HAIRIS_STUDY_RESOLUTION ("WxH"), HAIRIS_STUDY_REF_SPP, HAIRIS_STUDY_SPPS ("a,b,c") and
    HAIRIS_STUDY_SEEDS when set."""
    env = os.environ.get
    text = env("HAIRIS_STUDY_RESOLUTION", "%dx%d" % tuple(resolution))
    return (tuple(int(v) for v in text.split("x")), int(env("HAIRIS_STUDY_REF_SPP", ref_spp)),
            [int(v) for v in env("HAIRIS_STUDY_SPPS", ",".join(map(str, spps))).split(",")],
            int(env("HAIRIS_STUDY_SEEDS", seeds)))


class Waiter:
    """A viewport worker's redraw callback: wakes whoever waits for a condition on its render."""

    def __init__(self, timeout=120.0):
        self.condition = threading.Condition()
        self.timeout = timeout

    def __call__(self):
        with self.condition:
            self.condition.notify_all()

    def until(self, predicate, what):
        """Waits (at most ``timeout`` seconds) until ``predicate()``; fails naming ``what``."""
        with self.condition:
            if not self.condition.wait_for(predicate, self.timeout):
                raise AssertionError("timed out waiting for " + what)


def run_script(main):
    """Runs a study script's ``main``: prints its result line (FAILED with the traceback when
    it raises) and exits with 0 or 1, so run_test.py reports it."""
    try:
        main()
    except Exception:  # noqa: BLE001 - report and fail
        traceback.print_exc()
        result("FAILED")
        sys.exit(1)
    result("PASSED")
    sys.exit(0)


def machine_info():
    """nproc, CPU model, load, Blender version, git commit."""
    model = ""
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            for line in cpuinfo:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    try:
        commit = subprocess.run(["git", "-C", REPOSITORY, "describe", "--always",
                                 "--dirty=+changes"],
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                universal_newlines=True).stdout.strip()
    except OSError:
        commit = ""
    return {
        "nproc": len(os.sched_getaffinity(0)),
        "cpu_count": os.cpu_count(),
        "cpu_model": model,
        "platform": platform.platform(),
        "blender_version": bpy.app.version_string,
        "git_commit": commit,
        "load_average_start": list(os.getloadavg()),
    }


def render_pixels(scene, engine, seed, workdir, name=None, alpha=False):
    """Renders with ``engine``; returns (linear RGB float64 array (height, width, 3), seconds),
    RGBA (height, width, 4) with ``alpha``.

    The seconds are the wall time of ``bpy.ops.render.render()`` alone; the image is read
    back from a 32-bit EXR written to ``workdir``.
    """
    scene.render.engine = engine
    scene.cycles.seed = seed
    scene.hairis.seed = seed
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    path = os.path.join(workdir, (name or "%s_%d" % (engine.lower(), seed)) + ".exr")
    start = time.monotonic()
    bpy.ops.render.render()
    seconds = time.monotonic() - start
    bpy.data.images["Render Result"].save_render(path, scene=scene)
    image = bpy.data.images.load(path)
    width, height = image.size
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    os.remove(path)
    return pixels.reshape(height, width, 4)[..., :4 if alpha else 3].astype(np.float64), seconds


def compare_counts(prefix="HAIRIS_COMPARE", samples=32, seeds=8):
    """A comparison's (samples per image, images per engine): the defaults given, each replaced
    by ``<prefix>_SAMPLES`` and ``<prefix>_SEEDS`` when set."""
    return (int(os.environ.get(prefix + "_SAMPLES", samples)),
            int(os.environ.get(prefix + "_SEEDS", seeds)))


COMPARE_SAMPLES, COMPARE_SEEDS = compare_counts()
"""Samples per image and images per engine of the comparisons (environment overrides)."""
COMPARE_BOUNCES, COMPARE_BLOCK = 4, 4
"""The comparisons' bounce limit and the side of the pixel blocks compare_stats compares."""
ENGINES = ("CYCLES", "HAIRIS")


def setup_compare():
    """:func:`setup` for a test that renders with libhairis (skipped while it is not built);
    returns the arguments."""
    args, package = setup()
    require_library(package)
    return args


def render_engines(scene, seeds, workdir, note=""):
    """{engine: (seeds, height, width, 3) stack} of Cycles and Hairis at seeds 1..``seeds``.

    Every pixel must be finite; HAIRIS_COMPARE_DUMP names an .npz file to keep the stacks in.
    """
    stacks, times = {}, {}
    for engine in ENGINES:
        images = []
        times[engine] = 0.0
        for seed in range(1, seeds + 1):
            image, seconds = render_pixels(scene, engine, seed, workdir)
            assert np.all(np.isfinite(image)), "%s rendered non-finite pixels" % engine
            images.append(image)
            times[engine] += seconds
        stacks[engine] = np.stack(images)
    print("render time for %d x %d samples: cycles %.1f s, hairis %.1f s%s"
          % (seeds, scene.hairis.samples, times["CYCLES"], times["HAIRIS"], note))
    dump = os.environ.get("HAIRIS_COMPARE_DUMP")
    if dump:
        np.savez(dump, cycles=stacks["CYCLES"], hairis=stacks["HAIRIS"])
    return stacks


def compare_with_cycles(scene, seeds, workdir, block, note=""):
    """Renders both engines (``render_engines``) and asserts compare_stats.compare on the
    stacks; returns its figures."""
    stacks = render_engines(scene, seeds, workdir, note)
    return compare_stats.compare(stacks["CYCLES"], stacks["HAIRIS"], block)


def make_principled_material(name, **inputs):
    """A Principled BSDF material with ``inputs`` set; returns (material, node)."""
    material = bpy.data.materials.new(name)
    use_nodes(material)
    node = material.node_tree.nodes["Principled BSDF"]
    for key, value in inputs.items():
        socket(node, key).default_value = value
    return material, node


def make_sphere(name, radius, location, material, scale=(1.0, 1.0, 1.0)):
    """A smooth-shaded 48×24 UV sphere (with its UV map) of ``material``."""
    bpy.ops.mesh.primitive_uv_sphere_add(radius=radius, location=location, segments=48,
                                         ring_count=24)
    obj = bpy.context.view_layer.objects.active
    obj.name = name
    obj.scale = scale
    bpy.ops.object.shade_smooth()
    obj.data.materials.append(material)
    return obj


def skin_pixels(width=64, height=32):
    """RGBA floats (bottom row first): a skin tone, darker bands along u, spots."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    uu, vv = np.meshgrid(u, v)
    base = np.array([0.85, 0.62, 0.5])
    band = 0.75 + 0.25 * np.cos(2.0 * math.pi * 6.0 * uu)
    spots = np.where((np.sin(17.0 * uu) * np.sin(11.0 * vv * math.pi)) > 0.8, 0.6, 1.0)
    rgb = base[None, None, :] * (band * spots)[:, :, None]
    rgb[..., 2] *= 0.8 + 0.2 * vv
    rgba = np.concatenate([rgb, np.ones((height, width, 1))], axis=2)
    return rgba.astype(np.float32)


def make_textured_principled(name, path, pixels, **inputs):
    """A Principled BSDF material whose Base Color is an Image Texture (on the UV map) of
    ``pixels`` (``skin_pixels``' layout), saved as an 8-bit sRGB PNG at ``path``; returns
    (material, node)."""
    height, width = pixels.shape[:2]
    image = bpy.data.images.new(name + "Paint", width, height, alpha=False)
    image.pixels.foreach_set(pixels.reshape(-1))
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)
    material, node = make_principled_material(name, **inputs)
    tree = material.node_tree
    texture = tree.nodes.new("ShaderNodeTexImage")
    texture.image = bpy.data.images.load(path)
    tree.links.new(texture.outputs["Color"], socket(node, "Base Color"))
    return material, node


def link_hair_random(tree, node, name, low, high):
    """Feeds ``node``'s input ``name`` from Hair Info Random through a Map Range onto
    ``low``..``high``; returns the Map Range node."""
    info = tree.nodes.new("ShaderNodeHairInfo")
    remap = tree.nodes.new("ShaderNodeMapRange")
    socket(remap, "To Min").default_value = low
    socket(remap, "To Max").default_value = high
    tree.links.new(info.outputs["Random"], socket(remap, "Value"))
    tree.links.new(remap.outputs["Result"], socket(node, name))
    return remap


def vary_melanin(material, random_color=0.6, random_roughness=0.3):
    """Makes a Melanin hair material's melanin vary per strand (Random Color, Random unlinked:
    Cycles' per-strand number) and from root to tip (a ColorRamp on Hair Info Intercept)."""
    tree = material.node_tree
    node = tree.nodes["Principled Hair BSDF"]
    socket(node, "Random Color").default_value = random_color
    socket(node, "Random Roughness").default_value = random_roughness
    info = tree.nodes.new("ShaderNodeHairInfo")
    ramp = tree.nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.75, 0.75, 0.75, 1.0)  # dark roots
    ramp.color_ramp.elements[1].color = (0.15, 0.15, 0.15, 1.0)  # light tips
    ramp.color_ramp.elements[1].position = 0.9
    tree.links.new(info.outputs["Intercept"], socket(ramp, "Fac"))
    tree.links.new(ramp.outputs["Color"], socket(node, "Melanin"))


def make_floor(size, color=(0.5, 0.5, 0.5, 1.0)):
    """A square diffuse floor of side ``size`` at z = 0, centred on the origin."""
    material = make_diffuse_material("Floor", color)
    bpy.ops.mesh.primitive_plane_add(size=size, location=(0.0, 0.0, 0.0))
    floor = bpy.context.view_layer.objects.active
    floor.data.materials.append(material)
    return floor


def make_key_spot(scene, location):
    """The comparisons' spot light (radius 0.15, a 50° cone, blend 0.3, 400 W) at ``location``,
    aimed down towards the origin from the front right."""
    return make_light(scene, "SPOT", "Spot", location=location,
                      rotation=(math.radians(40), 0.0, math.radians(48)), energy=400.0,
                      spot_size=math.radians(50), spot_blend=0.3, shadow_soft_size=0.15)


def make_hdri_world(scene, path, texel, rotation, strength, size=(64, 32)):
    """A world whose Background Color is an Environment Texture of the Radiance HDR that
    hdri.write_hdr makes of ``texel`` at ``size`` (width, height), looked up through a Mapping
    rotation (radians, XYZ) of the Generated coordinates; World > Settings > Sampling Auto."""
    hdri.write_hdr(path, size[0], size[1], texel)
    world = make_world(scene, color=(0.0, 0.0, 0.0), strength=strength)
    nodes, links = world.node_tree.nodes, world.node_tree.links
    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(path)
    mapping = nodes.new("ShaderNodeMapping")
    socket(mapping, "Rotation").default_value = rotation
    coordinates = nodes.new("ShaderNodeTexCoord")
    links.new(coordinates.outputs["Generated"], socket(mapping, "Vector"))
    links.new(mapping.outputs["Vector"], socket(texture, "Vector"))
    links.new(texture.outputs["Color"], socket(nodes["Background"], "Color"))
    world.cycles.sampling_method = "AUTOMATIC"
    return world


# ---- UI stubs --------------------------------------------------------------------------------

class RecordingLayout:
    """A stand-in for ``UILayout`` that records what a draw function puts in it."""

    def __init__(self, log=None):
        self.log = log if log is not None else []
        self.use_property_split = False
        self.use_property_decorate = True
        self.active = True
        self.alert = False
        self.enabled = True

    def _child(self, *args, **kwargs):
        return RecordingLayout(self.log)

    row = column = box = split = column_flow = grid_flow = _child

    def label(self, text="", icon="NONE", **kwargs):
        """Records a label."""
        self.log.append(("label", text, icon))

    def prop(self, data, prop, **kwargs):
        """Records a property (checking it exists)."""
        assert hasattr(data, prop) or prop in getattr(data, "bl_rna").properties, prop
        self.log.append(("prop", prop))

    def operator(self, idname, **kwargs):
        """Records an operator button; returns a namespace to set properties on."""
        self.log.append(("operator", idname))
        return types.SimpleNamespace()

    def separator(self, **kwargs):
        """Ignored."""

    def menu(self, *args, **kwargs):
        """Records a menu."""
        self.log.append(("menu", args[0] if args else ""))

    def template_ID(self, *args, **kwargs):  # noqa: N802 - Blender's name
        """Records an ID template."""
        self.log.append(("template_ID", args[1] if len(args) > 1 else ""))

    def template_list(self, *args, **kwargs):
        """Records a list template."""
        self.log.append(("template_list",))

    def template_node_view(self, tree, node, socket):
        """Records a node view."""
        self.log.append(("template_node_view", node.name, socket.name))

    def labels(self):
        """The texts of all recorded labels."""
        return [entry[1] for entry in self.log if entry[0] == "label"]


class PanelStandIn:
    """A panel instance's stand-in: its class's attributes and methods, and a RecordingLayout."""

    def __init__(self, panel_class):
        self.panel_class = panel_class
        self.layout = RecordingLayout()

    def __getattr__(self, name):
        value = getattr(self.panel_class, name)
        return types.MethodType(value, self) if isinstance(value, types.FunctionType) else value


def draw_panel(panel_class, context):
    """Runs a panel's draw() on a :class:`PanelStandIn`; returns the layout."""
    panel = PanelStandIn(panel_class)
    panel_class.draw(panel, context)
    return panel.layout


def vector(values):
    """A mathutils Vector (helper for readability)."""
    return Vector(values)
