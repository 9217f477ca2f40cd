"""Registration tests: the add-on installs, enables and reports cleanly without the library.

Runs with HAIRIS_LIBRARY pointing at a file that does not exist, so it does not depend on
whether libhairis.so is built.
"""

import os
import sys
import types

import addon_utils
import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
MISSING = os.path.join(ARGS.workdir, "nowhere", "libhairis.so")
helpers.use_library(MISSING)
native = sys.modules["hairis.native"]
ui = sys.modules["hairis.ui"]
preferences = sys.modules["hairis.preferences"]


def test_bl_info_and_modules():
    """bl_info asks for Blender 3.4+; every module is there."""
    assert PACKAGE.bl_info["blender"] >= (3, 4, 0)
    assert PACKAGE.bl_info["category"] == "Render"
    for name in ("native", "properties", "ui", "operators", "export", "engine", "preferences",
                 "tables"):
        assert "hairis." + name in sys.modules, name


def test_engine_and_properties_registered():
    """The engine, scene.hairis defaults, material.hairis and the operator exist."""
    assert "HAIRIS" in {engine.bl_idname for engine in bpy.types.RenderEngine.__subclasses__()}
    engine = sys.modules["hairis.engine"].HairisRenderEngine
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
    try:
        native.load_library()
    except native.LibraryUnavailable as error:
        assert str(error) == status.message
    else:
        raise AssertionError("load_library must raise")


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
        assert panel.poll(context), panel.__name__
        helpers.draw_panel(panel, context)
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
        try:
            bpy.ops.render.render()
        except RuntimeError as error:
            assert "hairis native library not found at %s" % MISSING in str(error), error
        else:
            raise AssertionError("the render must fail")
    assert bpy.context.scene.render.engine == "HAIRIS"


def test_bake_operator_reports_missing_library():
    """The bake operator reports the missing library instead of raising a traceback."""
    helpers.make_test_scene(with_curves=False)
    try:
        bpy.ops.hairis.bake_tables()
    except RuntimeError as error:
        assert "hairis native library not found at" in str(error), error
    else:
        raise AssertionError("the bake must report an error")


def test_disable_and_enable_again():
    """Unregistering removes everything; enabling again works."""
    result = bpy.ops.preferences.addon_disable(module="hairis")
    assert result == {"FINISHED"}
    assert not hasattr(bpy.types.Scene, "hairis")
    assert "HAIRIS" not in bpy.types.DATA_PT_lens.COMPAT_ENGINES
    assert not sys.modules["hairis.engine"].HairisRenderEngine.is_registered
    assert addon_utils.check("hairis")[1] is False
    assert bpy.ops.preferences.addon_enable(module="hairis") == {"FINISHED"}
    assert hasattr(bpy.types.Scene, "hairis")


helpers.run([
    test_bl_info_and_modules,
    test_engine_and_properties_registered,
    test_library_status_message,
    test_preferences_and_panels_draw,
    test_generic_panels_compatible,
    test_render_reports_missing_library,
    test_bake_operator_reports_missing_library,
    test_disable_and_enable_again,
])
