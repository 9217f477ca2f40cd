"""Binding, engine and bake-operator tests against the fake library (fake_hairis.c).

The fake implements every hairis.h function with trivial physics but the real conventions
(last error, argument checks, cancelling progress callbacks, table files that match fibers),
and exposes the C struct layouts. This exercises everything between Blender and the C API
before libhairis.so exists. Skips when no fake library could be built.
"""

import math
import os
import re
import sys
import time
import types

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
if not ARGS.fake_library or not os.path.isfile(ARGS.fake_library):
    helpers.skip("the fake library was not built (no C compiler?)")
helpers.use_library(ARGS.fake_library)
os.environ.pop("HAIRIS_FAKE_NOISE", None)  # exact images here
native = helpers.module("native")
engine = helpers.module("engine")
tables = helpers.module("tables")
export = helpers.module("export")
INCLUDE = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, os.pardir, "lib",
                       "include", "hairis")
HEADERS = [os.path.join(INCLUDE, name) for name in ("hairis.h", "hairis_render.h")]
SUMMARY = os.path.join(ARGS.workdir, "summary.txt")
os.environ["HAIRIS_FAKE_SUMMARY"] = SUMMARY


def library():
    """The fake library through the add-on's loader."""
    return native.load_library()


def render(scene):
    """F12; returns the Combined pixels (height, width, 4) and the fake's scene summary."""
    if os.path.exists(SUMMARY):
        os.remove(SUMMARY)
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    bpy.ops.render.render()
    path = os.path.join(ARGS.workdir, "render.exr")
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    bpy.data.images["Render Result"].save_render(path, scene=scene)
    image = bpy.data.images.load(path, check_existing=False)
    width, height = image.size
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    with open(SUMMARY) as handle:
        summary = handle.read()
    return pixels.reshape(height, width, 4), summary


def summary_value(summary, key):
    """A ``key=value`` from the fake's summary."""
    match = re.search(r"\b%s=(\S+)" % re.escape(key), summary)
    assert match, (key, summary)
    return match.group(1)


def expect_render_error(scene, *fragments):
    """F12 must fail with a message containing every fragment."""
    try:
        bpy.ops.render.render()
    except RuntimeError as error:
        for fragment in fragments:
            assert fragment in str(error), (fragment, str(error))
        return str(error)
    raise AssertionError("the render should have failed")


def test_every_header_function_bound():
    """PROTOTYPES names exactly the functions the headers declare (capi_ctypes checks types)."""
    declared = set()
    for header in HEADERS:
        with open(header) as handle:
            declared |= set(re.findall(r"HAIRIS_API\s+[^;(]*?\b(hairis_\w+)\s*\(", handle.read()))
    assert declared == set(native.PROTOTYPES), declared ^ set(native.PROTOTYPES)
    lib = library()
    for name in declared:
        assert getattr(lib.raw, name).argtypes is not None, name


def test_errors_carry_last_error():
    """Failing calls raise HairisError with hairis_last_error()'s text."""
    lib = library()
    try:
        lib.fiber_principled({"ior": 0.9})
    except native.HairisError as error:
        assert "IOR must be > 1" in str(error) and error.function == "hairis_fiber_create"
    else:
        raise AssertionError("IOR 0.9 must be refused")
    try:
        lib.load_tables_memory(b"not a table")
    except native.HairisError as error:
        assert "not a hairis table file" in error.message
    else:
        raise AssertionError("garbage must be refused")
    with lib.scene() as scene:
        try:
            scene.add_curves(5, [0, 2], np.zeros((2, 3)), np.zeros(2))
        except native.HairisError as error:
            assert error.code == native.ERROR_INVALID_ARGUMENT
            assert "HAIRIS_ERROR_INVALID_ARGUMENT" in str(error) and "material 5" in str(error)
        else:
            raise AssertionError("a missing material must be refused")
    try:
        lib.fiber_principled({"ior": 0.9})
    except native.HairisError:
        assert lib.last_error() != ""
    lib.defaults("chiang")
    with lib.fiber_principled({}) as fiber:
        assert fiber.model == "chiang2016"
    assert lib.last_error() == ""


def test_api_version_checked():
    """A library with another API version is refused with a readable message."""
    os.environ["HAIRIS_FAKE_API_VERSION"] = "3"
    try:
        status = native.library_status()
    finally:
        del os.environ["HAIRIS_FAKE_API_VERSION"]
    assert not status.ok
    assert "hairis native library not found at %s" % ARGS.fake_library in status.message
    assert "API version 3" in status.message, status.message


def test_progress_callbacks():
    """A callback returning True cancels; an exception in it is re-raised."""
    lib = library()
    seen = []
    with lib.fiber_principled({}) as fiber:
        with lib.bake_tables(fiber, progress=lambda p: seen.append(p) and False) as baked:
            assert baked.matches(fiber)
        assert seen[0] == 0.0 and seen[-1] == 1.0 and seen == sorted(seen)
        try:
            lib.bake_tables(fiber, progress=lambda p: p > 0.5)
        except native.HairisCancelled as error:
            assert "cancel" in str(error)
        else:
            raise AssertionError("the bake must be cancelled")

        def explode(progress):
            raise ValueError("callback failed")
        try:
            lib.bake_tables(fiber, progress=explode)
        except ValueError as error:
            assert "callback failed" in str(error)
        else:
            raise AssertionError("the callback's exception must come back")


def test_sampler_and_eval():
    """Batches go through numpy in the right shapes."""
    lib = library()
    with lib.fiber_principled({}) as fiber, lib.bake_tables(fiber) as baked:
        rgb = fiber.eval(np.tile([0.0, 1.0, 0.0], (5, 1)), np.tile([0.0, 0.0, 1.0], (5, 1)))
        assert rgb.shape == (5, 3) and np.all(rgb > 0)
        with lib.sampler("TABLE", fiber, baked, 0.25, 2) as sampler:
            wi, pdf = sampler.sample(np.tile([0.0, 0.0, 1.0], (8, 1)), np.random.rand(8, 3))
            np.testing.assert_allclose(np.linalg.norm(wi, axis=1), 1.0, atol=1e-5)
            np.testing.assert_allclose(sampler.pdf(wi, np.tile([0.0, 0.0, 1.0], (8, 1))), pdf)
        try:
            lib.sampler("TABLE", fiber, None)
        except native.HairisError as error:
            assert "tables must not be NULL" in str(error), error
        else:
            raise AssertionError("TABLE without tables must be refused")


def test_engine_renders_scene():
    """F12 through the fake: the image is the world radiance; the C side got the scene."""
    scene = helpers.make_test_scene()
    settings = scene.hairis
    settings.strategy = "ANALYTIC"
    settings.samples = 7
    settings.seed = 42
    settings.threads = 1
    settings.n_h = "4"
    settings.multiple_weight = 0.5
    settings.max_bounces = 5
    # Cycles' bounce limits per kind reach the library (values apart from every default).
    scene.cycles.diffuse_bounces, scene.cycles.glossy_bounces = 3, 6
    scene.cycles.transmission_bounces = 21
    pixels, summary = render(scene)
    assert pixels.shape == (24, 32, 4), pixels.shape
    np.testing.assert_allclose(pixels[..., :3], np.broadcast_to((0.075, 0.15, 0.3), (24, 32, 3)),
                               rtol=1e-5)
    assert summary_value(summary, "samples") == "7" and summary_value(summary, "seed") == "42"
    assert summary_value(summary, "strategy") == "1" and summary_value(summary, "n_h") == "4"
    assert summary_value(summary, "threads") == "1"
    assert summary_value(summary, "max_bounces") == "5"
    limits = [summary_value(summary, "max_%s_bounces" % kind)
              for kind in ("diffuse", "glossy", "transmission")]
    assert limits == ["3", "6", "21"], summary
    assert summary_value(summary, "integrator") == "0"  # PATH, the default
    assert float(summary_value(summary, "multiple_weight")) == 0.5
    # Cycles with Embree 4 (Blender's builds from 3.6) hits strands from inside their tube.
    backfaces = "hit" if helpers.VERSION >= (3, 6, 0) else "ignore"
    assert summary_value(summary, "curve_backfaces") == backfaces, summary
    # Cycles 5.0 stores Max Bounces: Transparent as set (4.5 and older: the setting + 1).
    limit = "setting" if helpers.VERSION >= (5, 0, 0) else "plus_one"
    assert summary_value(summary, "transparent_limit") == limit, summary
    # The scene's Curves > Shape (Cycles' default: Rounded Ribbons).
    assert summary_value(summary, "curve_shape") == scene.cycles_curves.shape.lower(), summary
    # Cycles' final render builds a Medium BVH, a High one with Use Spatial Splits.
    assert summary_value(summary, "bvh_quality") == "medium", summary
    scene.cycles.debug_use_spatial_splits = True
    assert summary_value(render(scene)[1], "bvh_quality") == "high"
    scene.cycles.debug_use_spatial_splits = False
    # Cycles' Filter Glossy, Clamping and Pixel Filter at Blender's defaults reach the library;
    # a Box filter is always 1 px wide, as Cycles' sync makes it.
    assert float(summary_value(summary, "filter_glossy")) == 1.0, summary
    assert float(summary_value(summary, "clamp_direct")) == 0.0, summary
    assert float(summary_value(summary, "clamp_indirect")) == 10.0, summary
    assert summary_value(summary, "pixel_filter") == "blackman_harris", summary
    assert float(summary_value(summary, "pixel_filter_width")) == 1.5, summary
    scene.cycles.blur_glossy, scene.cycles.sample_clamp_direct = 0.25, 3.0
    scene.cycles.pixel_filter_type, scene.cycles.filter_width = "BOX", 2.5
    changed = render(scene)[1]
    assert float(summary_value(changed, "filter_glossy")) == 0.25, changed
    assert float(summary_value(changed, "clamp_direct")) == 3.0, changed
    assert summary_value(changed, "pixel_filter") == "box", changed
    assert float(summary_value(changed, "pixel_filter_width")) == 1.0, changed
    assert summary_value(summary, "curve_subdivisions") == "2", summary  # Cycles' default
    assert float(summary_value(summary, "exposure")) == 1.0, summary
    scene.cycles.film_exposure = 1.75
    assert float(summary_value(render(scene)[1], "exposure")) == 1.75
    scene.cycles.film_exposure = 1.0
    scene.cycles_curves.subdivisions = 5
    assert summary_value(render(scene)[1], "curve_subdivisions") == "5"
    scene.cycles_curves.subdivisions = 2
    scene.cycles.pixel_filter_type = "GAUSSIAN"
    gaussian = render(scene)[1]
    assert summary_value(gaussian, "pixel_filter") == "gaussian", gaussian
    assert float(summary_value(gaussian, "pixel_filter_width")) == 2.5, gaussian
    data = export.export_scene(bpy.context.evaluated_depsgraph_get())
    assert int(summary_value(summary, "curve_sets")) == 2
    curves = {c.source: c for c in data.curves}
    # F12 exports 2**render_step + 1 keys per strand, the viewport 2**display_step + 1.
    assert int(summary_value(summary, "curves")) == 200 + curves["CURVES"].curve_count
    assert int(summary_value(summary, "points")) == 200 * 9 + curves["CURVES"].point_count
    assert summary_value(summary, "suns") == "1" and summary_value(summary, "areas") == "1"
    assert summary_value(summary, "points") != "0"
    assert summary_value(summary, "camera") == "32x24"
    assert summary.count("hair ") == 2 and "tables=0" in summary
    # The particle hair's Random Color and Random Roughness read Cycles' per-strand random
    # (Random unlinked): its curves go through hairis_scene_add_curves_with_inputs, one value
    # per strand; the Curves object's material has nothing per strand.
    assert summary_value(summary, "curve_input_sets") == "1", summary
    assert summary_value(summary, "curve_input_values") == "200", summary
    assert summary_value(summary, "curve_inputs") == "random=curve", summary


def test_table_strategy_refuses_missing_tables():
    """TABLE without tables and without auto bake: an error naming the materials."""
    scene = helpers.make_test_scene()
    scene.hairis.auto_bake = False
    message = expect_render_error(scene, "the Table strategy needs current sampling tables",
                                  "'Hair'", "'Curly'", "enable Auto Bake")
    assert "no sampling tables" in message


def test_dual_scattering_needs_tables_whatever_the_strategy():
    """DUAL_SCATTERING reaches the library and takes every hair material's tables, also with
    a strategy that needs none; without tables and auto bake it is refused naming them."""
    scene = helpers.make_test_scene()
    scene.hairis.integrator = "DUAL_SCATTERING"
    scene.hairis.strategy = "ANALYTIC"
    scene.hairis.auto_bake = False
    message = expect_render_error(scene, "Dual Scattering needs current sampling tables",
                                  "'Hair'", "'Curly'", "enable Auto Bake")
    assert "no sampling tables" in message
    scene.hairis.auto_bake = True
    _pixels, summary = render(scene)
    assert summary_value(summary, "integrator") == "1"
    assert summary_value(summary, "strategy") == "1"
    assert summary_value(summary, "dual_exact_bounces") == "3"
    assert summary_value(summary, "dual_bounce_limit") == "bounces"
    assert summary.count("tables=1") == 2, summary
    scene.hairis.dual_exact_bounces = 0
    scene.hairis.dual_bounce_limit = "NONE"
    _pixels, summary = render(scene)
    assert summary_value(summary, "dual_exact_bounces") == "0"
    assert summary_value(summary, "dual_bounce_limit") == "none"
    scene.hairis.integrator = "PATH"
    _pixels, summary = render(scene)
    assert summary_value(summary, "integrator") == "0"
    assert "tables=1" not in summary, summary


def test_auto_bake_leaves_blend_data_alone():
    """TABLE with auto bake: baked for the render, cached, bpy.data untouched."""
    scene = helpers.make_test_scene()
    _pixels, summary = render(scene)
    assert summary.count("tables=1") == 2, summary
    assert bpy.data.materials["Hair"].hairis.table_image is None
    cached = [name for name in os.listdir(bpy.app.tempdir) if name.startswith("hairis_autobake")]
    assert len(cached) == 2, cached
    _pixels, summary = render(scene)  # second render: from the cache
    assert summary.count("tables=1") == 2


def test_bake_operator_saved_blend():
    """Bake next to a saved .blend, //-relative, Non-Color; stale after an edit; re-bake."""
    scene = helpers.make_test_scene()
    scene.hairis.auto_bake = False
    blend = os.path.join(ARGS.workdir, "saved", "hair.blend")
    os.makedirs(os.path.dirname(blend), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    scene = bpy.context.scene
    assert bpy.ops.hairis.bake_tables() == {"FINISHED"}
    lib = library()
    for name in ("Hair", "Curly"):
        material = bpy.data.materials[name]
        image = material.hairis.table_image
        assert image is not None, name
        assert image.filepath == "//hairis_%s.exr" % name, image.filepath
        assert os.path.isfile(os.path.join(os.path.dirname(blend), "hairis_%s.exr" % name))
        assert image.colorspace_settings.name == "Non-Color"
        assert image.packed_file is None
        params = tables.material_parameters(material)
        with lib.fiber_principled(tables.principled_struct(lib, params)) as fiber:
            assert material.hairis.baked_parameters == fiber.parameters
        assert tables.quick_state(lib, material) == "OK"
    _pixels, summary = render(scene)
    assert summary.count("tables=1") == 2, summary

    path = os.path.join(os.path.dirname(blend), "hairis_Hair.exr")
    before = os.path.getmtime(path)
    time.sleep(0.05)
    assert bpy.ops.hairis.bake_tables() == {"FINISHED"}
    assert os.path.getmtime(path) == before, "current tables must not be re-baked"

    hair = bpy.data.materials["Hair"]
    helpers.socket(hair.node_tree.nodes["Principled Hair BSDF"], "Roughness").default_value = 0.6
    assert tables.quick_state(lib, hair) == "STALE"
    expect_render_error(scene, "'Hair'", "baked for other hair parameters")
    assert bpy.ops.hairis.bake_tables(material="Hair") == {"FINISHED"}
    assert tables.quick_state(lib, hair) == "OK"
    _pixels, summary = render(scene)
    assert summary.count("tables=1") == 2, summary


def test_bake_operator_unsaved_blend_packs():
    """An unsaved .blend: tables go to a temporary folder and are packed (with a warning)."""
    scene = helpers.make_test_scene(with_curves=False)
    scene.hairis.auto_bake = False
    assert bpy.data.filepath == ""
    assert bpy.ops.hairis.bake_tables() == {"FINISHED"}
    image = bpy.data.materials["Hair"].hairis.table_image
    assert image.packed_file is not None
    path = bpy.path.abspath(image.filepath)
    assert os.path.isabs(path) and os.path.isfile(path), path
    os.remove(path)  # the render must read the packed bytes
    _pixels, summary = render(scene)
    assert "tables=1" in summary, summary


def test_invalid_node_value_fails_cleanly():
    """A value the library refuses (IOR 1) fails the render with its message; fixing it works."""
    scene = helpers.make_test_scene(with_curves=False)
    scene.hairis.strategy = "UNIFORM"
    node = bpy.data.materials["Hair"].node_tree.nodes["Principled Hair BSDF"]
    helpers.socket(node, "IOR").default_value = 1.0
    expect_render_error(scene, "IOR must be > 1")
    helpers.socket(node, "IOR").default_value = 1.55
    pixels, _summary = render(scene)
    assert np.all(np.isfinite(pixels))


def test_huang_material_by_bake_and_render():
    """Blender 4.0+: the bake operator bakes a Huang material's tables (its Huang table) beside
    the Chiang material's; F12 with the Table strategy renders it with them, refuses them once
    a Huang-only input (Aspect Ratio, a lobe multiplier) changed, and auto-bakes them again;
    Cycles' own Huang sampling needs no tables."""
    helpers.skip_without_huang()
    scene = helpers.make_test_scene()
    scene.hairis.auto_bake = False
    scene.hairis.strategy = "TABLE"
    curly = bpy.data.materials["Curly"]
    node = curly.node_tree.nodes["Principled Hair BSDF"]
    node.model = "HUANG"
    lib = library()
    assert bpy.ops.hairis.bake_tables() == {"FINISHED"}
    for name in ("Hair", "Curly"):
        assert bpy.data.materials[name].hairis.table_image is not None, name
        assert tables.quick_state(lib, bpy.data.materials[name]) == "OK", name
    assert curly.hairis.baked_model == "huang2022", curly.hairis.baked_model
    curly_node = tables.principled_struct(lib, tables.material_parameters(curly))
    with lib.fiber_principled(curly_node) as fiber:
        status = tables.check_material(lib, curly, fiber)
    assert status.ok, status.message
    assert status.tables.info.get("huang_theta_o") == "24", status.tables.info
    status.tables.close()
    _pixels, summary = render(scene)
    assert summary_value(summary, "huang_sampling") == "1", summary  # Cycles', the default
    scene.hairis.huang_sampling = "STRATEGY"
    _pixels, summary = render(scene)
    assert summary_value(summary, "huang_sampling") == "0", summary
    assert re.search(r"hair \d+ tables=1 huang=1 ", summary), summary
    assert summary.count("tables=1") == 2, summary
    for socket_name, value in (("Aspect Ratio", 0.5), ("TT lobe", 0.3)):
        helpers.socket(node, socket_name).default_value = value
        assert tables.quick_state(lib, curly) == "STALE", socket_name
        expect_render_error(scene, "'Curly'", "baked for other hair parameters")
        assert bpy.ops.hairis.bake_tables(material="Curly") == {"FINISHED"}
        assert tables.quick_state(lib, curly) == "OK", socket_name
    helpers.socket(node, "Aspect Ratio").default_value = 0.7
    scene.hairis.auto_bake = True
    _pixels, summary = render(scene)
    assert re.search(r"hair \d+ tables=1 huang=1 ", summary), summary
    scene.hairis.huang_sampling = "CYCLES"  # its light samples read the tables' baked f
    _pixels, summary = render(scene)
    assert summary_value(summary, "huang_sampling") == "1", summary
    assert re.search(r"hair \d+ tables=1 huang=1 ", summary), summary
    # Without current tables and without Auto Bake, Cycles' sampler still renders (with
    # Cycles' eval): it needs no tables.
    helpers.socket(node, "Aspect Ratio").default_value = 0.6
    scene.hairis.auto_bake = False
    _pixels, summary = render(scene)
    assert re.search(r"hair \d+ tables=0 huang=1 ", summary), summary
    helpers.socket(node, "Aspect Ratio").default_value = 0.7
    scene.hairis.auto_bake = True
    scene.hairis.huang_sampling = "STRATEGY"
    scene.hairis.strategy = "UNIFORM"
    _pixels, summary = render(scene)
    assert summary_value(summary, "huang_sampling") == "0", summary
    assert "model=huang" in summary or "aspect_ratio=" in summary, summary


class StubEngine:
    """Records update_progress; test_break turns True ``after`` seconds."""

    def __init__(self, after):
        self.start = time.monotonic()
        self.after = after
        self.progress = []
        self.break_time = None

    def update_progress(self, value):
        """Records the progress."""
        self.progress.append(value)

    def test_break(self):
        """True once ``after`` seconds have passed (remembers when it first was)."""
        if time.monotonic() - self.start >= self.after:
            if self.break_time is None:
                self.break_time = time.monotonic()
            return True
        return False


def test_cancel_returns_promptly():
    """ProgressReporter + test_break: a slow render stops within 1 s of the break."""
    lib = library()
    os.environ["HAIRIS_FAKE_ROW_DELAY_MS"] = "20"
    try:
        with lib.scene() as scene:
            scene.set_world((1.0, 1.0, 1.0), 1.0)
            scene.set_camera({"width": 16, "height": 500})  # 10 s without a cancel
            stub = StubEngine(after=0.3)
            try:
                scene.render(lib.render_settings_defaults(), engine.ProgressReporter(stub))
            except native.HairisCancelled as error:
                stopped = time.monotonic()
                assert error.rgba.shape == (500, 16, 4)
            else:
                raise AssertionError("the render must be cancelled")
    finally:
        del os.environ["HAIRIS_FAKE_ROW_DELAY_MS"]
    assert stub.break_time is not None
    latency = stopped - (stub.start + stub.after)  # from when the break became true
    assert latency < 1.0, latency
    assert stub.progress == sorted(stub.progress) and stub.progress[0] == 0.0


def test_progress_reporter_rate_limit():
    """update_progress at most every interval, always at 1.0; the break is always asked."""
    clock = types.SimpleNamespace(t=0.0)
    stub = StubEngine(after=math.inf)
    reporter = engine.ProgressReporter(stub, interval=0.1, clock=lambda: clock.t)
    for step in range(10):
        clock.t = step * 0.03
        assert reporter(step / 10.0) is False
    reporter(1.0)
    assert stub.progress == [0.0, 0.4, 0.8, 1.0], stub.progress


helpers.run([
    test_every_header_function_bound,
    test_errors_carry_last_error,
    test_api_version_checked,
    test_progress_callbacks,
    test_sampler_and_eval,
    test_engine_renders_scene,
    test_table_strategy_refuses_missing_tables,
    test_dual_scattering_needs_tables_whatever_the_strategy,
    test_auto_bake_leaves_blend_data_alone,
    test_bake_operator_saved_blend,
    test_bake_operator_unsaved_blend_packs,
    test_invalid_node_value_fails_cleanly,
    test_huang_material_by_bake_and_render,
    test_cancel_returns_promptly,
    test_progress_reporter_rate_limit,
])
