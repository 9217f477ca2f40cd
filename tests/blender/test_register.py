"""Registration tests: the add-on installs, enables and reports cleanly without the library.

Runs with HAIRIS_LIBRARY pointing at a file that does not exist, so it does not depend on
whether libhairis.so is built. Installed as a legacy add-on or as an Extension (run_test.py
--install), the add-on must behave the same.
"""

import ast
import os
import sys
import types

import bpy  # first: as a Python module, importing bpy puts addon_utils on sys.path
import addon_utils  # noqa: I100

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
MISSING = os.path.join(ARGS.workdir, "nowhere", "libhairis.so")
helpers.use_library(MISSING)
native = helpers.module("native")
ui = helpers.module("ui")
preferences = helpers.module("preferences")


def source_bl_info():
    """bl_info as written in the installed __init__.py (Extensions drop it from the module)."""
    with open(PACKAGE.__file__) as handle:
        tree = ast.parse(handle.read())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "bl_info"
                                                for t in node.targets):
            return ast.literal_eval(node.value)
    raise AssertionError("no bl_info in %s" % PACKAGE.__file__)


def test_bl_info_and_modules():
    """bl_info asks for Blender 3.4+, the manifest for 4.2+ with the same version; every
    module is there, inside the installed package."""
    info = source_bl_info()
    assert info["blender"] == (3, 4, 0) and info["category"] == "Render", info
    assert PACKAGE.__name__ == helpers.MODULE
    if ARGS.install == "extension":
        assert PACKAGE.__name__ == "bl_ext.user_default.hairis", PACKAGE.__name__
        import tomllib  # Python 3.11+: Blender 4.2+ only, like Extensions
        with open(os.path.join(os.path.dirname(PACKAGE.__file__), "blender_manifest.toml"),
                  "rb") as handle:
            manifest = tomllib.load(handle)
        assert manifest["id"] == "hairis" and manifest["type"] == "add-on", manifest
        assert manifest["blender_version_min"] == "4.2.0", manifest
        assert manifest["version"] == ".".join(map(str, info["version"])), manifest
    else:  # addon_utils adds defaults of its own to the module's bl_info
        assert all(PACKAGE.bl_info[key] == value for key, value in info.items()), PACKAGE.bl_info
    for name in ("compat", "native", "properties", "ui", "operators", "export", "engine",
                 "preferences", "tables"):
        assert helpers.MODULE + "." + name in sys.modules, name
    # No stray copy under the legacy name when installed as an Extension.
    assert (ARGS.install == "legacy") == ("hairis" in sys.modules)


def test_preferences_registered_under_the_package():
    """The preferences' bl_idname is the package name (bl_ext.<repo>.hairis as an Extension)."""
    assert preferences.HairisPreferences.bl_idname == helpers.MODULE
    assert helpers.MODULE in bpy.context.preferences.addons.keys()
    prefs = bpy.context.preferences.addons[helpers.MODULE].preferences
    assert isinstance(prefs, preferences.HairisPreferences), type(prefs)


def test_supported_versions():
    """3.4 to 5.x are supported; older versions and unknown majors are refused by name."""
    compat = helpers.module("compat")
    assert compat.version_problem() is None, compat.version_problem()
    for version in ((3, 4, 0), (3, 6, 9), (4, 2, 0), (4, 5, 15), (5, 0, 1), (5, 9, 0)):
        assert compat.version_problem(version) is None, version
    for version, text in (((3, 3, 9), "Blender 3.3.9"), ((2, 93, 0), "Blender 2.93.0"),
                          ((6, 0, 0), "Blender 6.0.0")):
        problem = compat.version_problem(version)
        assert problem is not None and text in problem, (version, problem)
        assert "3.4 to 5.x" in problem, problem
    assert "does not know" in compat.version_problem((6, 0, 0))


def test_render_refuses_unsupported_version():
    """F12 and the bake in an unknown Blender: a report naming both versions, no traceback."""
    compat = helpers.module("compat")
    helpers.make_test_scene(with_curves=False)
    running = compat.running_version
    compat.running_version = lambda: (6, 1, 0)
    try:
        for call in (bpy.ops.render.render, bpy.ops.hairis.bake_tables):
            error = helpers.assert_raises(RuntimeError, call, "Blender 6.1.0",
                                          "%s must refuse Blender 6.1.0" % call)
            assert "3.4 to 5.x" in str(error), error
            assert "Traceback" not in str(error), error
        layout = helpers.draw_panel(preferences.HairisPreferences, bpy.context)
        assert any("Blender 6.1.0" in label for label in layout.labels()), layout.labels()
    finally:
        compat.running_version = running


def test_engine_and_properties_registered():
    """The engine, scene.hairis defaults, material.hairis and the operator exist."""
    # (Blender 4.x lists a HydraRenderEngine base class without a bl_idname.)
    assert "HAIRIS" in {getattr(engine, "bl_idname", None)
                        for engine in bpy.types.RenderEngine.__subclasses__()}
    engine = helpers.module("engine").HairisRenderEngine
    assert engine.is_registered
    assert engine.bl_label == "Hairis" and engine.bl_use_preview is False
    assert engine.bl_use_shading_nodes_custom is False
    scene = helpers.reset()
    scene.render.engine = "HAIRIS"
    settings = scene.hairis
    assert settings.samples == 64 and settings.max_bounces == 12
    assert settings.strategy == "TABLE" and settings.multiple_weight == 0.0
    assert settings.n_h == "2" and settings.n_h_value == 2
    assert settings.seed == 0 and settings.threads == 0 and settings.auto_bake is True
    assert settings.huang_bake == "FAST" and settings.huang_f_refinement == 1
    assert [item.identifier for item in
            settings.bl_rna.properties["n_h"].enum_items] == ["1", "2", "4", "8", "16"]
    assert [item.identifier for item in settings.bl_rna.properties["strategy"].enum_items] == \
        ["UNIFORM", "ANALYTIC", "GAUSSIAN", "TABLE"]
    material = bpy.data.materials.new("M")
    assert material.hairis.table_image is None and material.hairis.baked_parameters == ""
    assert hasattr(bpy.ops.hairis, "bake_tables")


def test_library_status_message():
    """The status names the path and the reason."""
    status = native.library_status()
    assert not status.ok
    assert status.message == ("hairis native library not found at %s: no such file" % MISSING), \
        status.message
    error = helpers.assert_raises(native.LibraryUnavailable, native.load_library, "",
                                  "load_library must raise")
    assert str(error) == status.message, error


def test_preferences_and_panels_draw():
    """Preferences and panels draw the message instead of failing."""
    layout = helpers.draw_panel(preferences.HairisPreferences, bpy.context)
    text = " ".join(layout.labels())
    assert "hairis native library not found at" in text and "no such file" in text, text
    assert "HAIRIS_LIBRARY" in text

    scene = helpers.make_test_scene(with_curves=False)
    hair = bpy.data.materials["Hair"]
    context = types.SimpleNamespace(
        engine="HAIRIS", scene=scene, material=hair, object=bpy.data.objects["Head"],
        active_object=bpy.data.objects["Head"], material_slot=None, space_data=None,
        world=scene.world, light=bpy.data.lights["Sun"])
    for panel in ui.classes:
        context.light = bpy.data.lights["Spot" if panel is ui.HAIRIS_LIGHT_PT_spot else "Sun"]
        assert panel.poll(context), panel.__name__
        helpers.draw_panel(panel, context)
    context.light = bpy.data.lights["Sun"]
    assert not ui.HAIRIS_LIGHT_PT_spot.poll(context), "the spot panel is for spot lights"
    layout = helpers.draw_panel(ui.HAIRIS_MATERIAL_PT_tables, context)
    assert ("operator", "hairis.bake_tables") in layout.log
    assert any("not found" in label for label in layout.labels())
    layout = helpers.draw_panel(ui.HAIRIS_MATERIAL_PT_surface, context)
    assert ("template_node_view", "Material Output", "Surface") in layout.log
    context.material = bpy.data.materials["Skin"]
    assert not ui.HAIRIS_MATERIAL_PT_tables.poll(context), "only hair materials get the bake"
    context.engine = "CYCLES"
    assert not any(panel.poll(context) for panel in ui.classes)


def test_generic_panels_compatible():
    """Generic panels list HAIRIS, the replaced ones do not; Cycles' panels are untouched."""
    assert "HAIRIS" in bpy.types.DATA_PT_lens.COMPAT_ENGINES
    assert "HAIRIS" in bpy.types.PARTICLE_PT_hair_shape.COMPAT_ENGINES
    assert "HAIRIS" in bpy.types.RENDER_PT_format.COMPAT_ENGINES
    assert "HAIRIS" not in bpy.types.DATA_PT_light.COMPAT_ENGINES
    cycles = getattr(bpy.types, "CYCLES_MATERIAL_PT_surface", None)
    if cycles is not None:
        assert "HAIRIS" not in cycles.COMPAT_ENGINES


def test_render_reports_missing_library():
    """F12 with the library missing: an error naming it, Blender keeps running."""
    helpers.make_test_scene(with_curves=False)
    for _ in range(2):  # twice: a failed render must leave nothing behind
        helpers.assert_raises(RuntimeError, bpy.ops.render.render,
                              "hairis native library not found at %s" % MISSING,
                              "the render must fail")
    assert bpy.context.scene.render.engine == "HAIRIS"


def test_bake_operator_reports_missing_library():
    """The bake operator reports the missing library instead of raising a traceback."""
    helpers.make_test_scene(with_curves=False)
    helpers.assert_raises(RuntimeError, bpy.ops.hairis.bake_tables,
                          "hairis native library not found at", "the bake must report an error")


def test_disable_and_enable_again():
    """Unregistering removes everything; enabling again works."""
    engine = helpers.module("engine")
    result = bpy.ops.preferences.addon_disable(module=helpers.MODULE)
    assert result == {"FINISHED"}
    assert not hasattr(bpy.types.Scene, "hairis")
    assert "HAIRIS" not in bpy.types.DATA_PT_lens.COMPAT_ENGINES
    assert not engine.HairisRenderEngine.is_registered
    assert addon_utils.check(helpers.MODULE)[1] is False
    assert bpy.ops.preferences.addon_enable(module=helpers.MODULE) == {"FINISHED"}
    assert hasattr(bpy.types.Scene, "hairis")
    assert helpers.module("engine").HairisRenderEngine.is_registered


helpers.run([
    test_bl_info_and_modules,
    test_preferences_registered_under_the_package,
    test_supported_versions,
    test_render_refuses_unsupported_version,
    test_engine_and_properties_registered,
    test_library_status_message,
    test_preferences_and_panels_draw,
    test_generic_panels_compatible,
    test_render_reports_missing_library,
    test_bake_operator_reports_missing_library,
    test_disable_and_enable_again,
])
