"""The artist's loop against the real libhairis.so: F12 refining on screen, Cycles' sampling
settings, Render Region, passes, the compositor's Denoise and the viewport's worker thread.
Skipped (exit 77) until the library is built into the zip.
"""

import contextlib
import os
import sys
import types

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
helpers.require_library(PACKAGE)
helpers.use_library(None)
native = helpers.module("native")
engine = helpers.module("engine")
compositor = helpers.module("compositor")
viewport = helpers.module("viewport")
Engine = engine.HairisRenderEngine
WAIT = 120.0  # seconds a test waits for the worker before it fails


def make_scene(samples=64, resolution=(48, 36)):
    """Curves in front of a sphere under a sun and a sky, ANALYTIC (no tables to bake)."""
    scene = helpers.make_sphere_and_curves(resolution)
    settings = scene.hairis
    settings.strategy = "ANALYTIC"
    settings.samples = samples
    settings.use_adaptive_sampling = False
    settings.threads = 0
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    bpy.context.view_layer.update()
    return scene


def f12(scene, name):
    """F12; returns the Render Result's RGB (height, width, 3)."""
    return helpers.render_pixels(scene, "HAIRIS", scene.hairis.seed, ARGS.workdir, name)[0]


def pass_pixels(render_pass):
    """A render pass's pixels, (pixels, channels)."""
    values = np.empty(len(render_pass.rect) * render_pass.channels, np.float32)
    try:
        render_pass.rect.foreach_get(values)
    except (TypeError, ValueError):
        values = values.reshape(-1, render_pass.channels)
        render_pass.rect.foreach_get(values)
    return values.reshape(-1, render_pass.channels)


@contextlib.contextmanager
def replaced(name, value):
    """Sets the engine class's attribute ``name`` to ``value`` for the block."""
    original = getattr(Engine, name)
    setattr(Engine, name, value)
    try:
        yield
    finally:
        setattr(Engine, name, original)


class Recorder:
    """Wraps an engine method for one render, recording what each call saw."""

    def __init__(self, name, record):
        self.name = name
        self.record = record
        self.calls = []
        self.original = getattr(Engine, name)

    def __enter__(self):
        original, record, calls = self.original, self.record, self.calls

        def wrapped(engine_self, *args):
            value = original(engine_self, *args)
            calls.append(record(engine_self, *args))
            return value

        setattr(Engine, self.name, wrapped)
        return self

    def __exit__(self, *exc):
        setattr(Engine, self.name, self.original)


def show_record(_engine, result, rgba, passes, samples_done, final):
    """What one display update wrote: samples, final, and the Combined pass read back."""
    return (samples_done, final, rgba.copy(),
            pass_pixels(result.layers[0].passes["Combined"]).copy())


# ---- 1. F12 refines on screen ----------------------------------------------------------------

def test_f12_refines_on_screen():
    """The render result holds the current image before the last sample, and the finished
    image is the one a render without display updates gives, bit for bit."""
    scene = make_scene(samples=64, resolution=(32, 24))
    with Recorder("_show", show_record) as shows:
        progressive = f12(scene, "progressive")
    assert len(shows.calls) >= 2, len(shows.calls)
    early = [c for c in shows.calls if c[0] < 64 and not c[1]]
    assert early, [(c[0], c[1]) for c in shows.calls]
    for samples_done, _final, rgba, written in shows.calls:
        np.testing.assert_array_equal(written, rgba.reshape(-1, 4))
    done = [c[0] for c in shows.calls]
    assert done == sorted(done) and len(set(done)) == len(done), done
    # An early image differs from the final one (it has fewer samples).
    assert not np.array_equal(early[0][2], shows.calls[-1][2])
    with replaced("display_updates", False), Recorder("_show", show_record) as quiet:
        once = f12(scene, "once")
    assert quiet.calls == []
    np.testing.assert_array_equal(progressive, once)
    np.testing.assert_array_equal(progressive, shows.calls[-1][2][..., :3])


def test_stats_line():
    """Samples done and time left, bounded by the Time Limit; the engine's stop cancels."""
    lines, progress = [], []
    stub = types.SimpleNamespace(update_stats=lambda _a, b: lines.append(b),
                                 update_progress=progress.append, stop_requested=lambda: False)
    clock = types.SimpleNamespace(t=0.0)
    shown = []
    updater = engine.DisplayUpdater(stub, lambda *a: shown.append(a[2]), 100, 0.0,
                                    clock=lambda: clock.t)
    clock.t = 2.0
    assert updater(0.25, 25, False, None, {}) is False
    assert lines[-1] == "Sample 25/100, Remaining 00:06.00", lines
    clock.t = 3.0
    updater(0.25, 25, False, None, {})  # the same image: not written again
    assert shown == [25]
    limited = engine.DisplayUpdater(stub, lambda *a: None, 100, 5.0, clock=lambda: clock.t)
    clock.t = 4.0  # 1 s into this render: extrapolation says 3 s, the limit leaves 4 s
    limited(0.25, 25, False, None, {})
    assert lines[-1].endswith("Remaining 00:03.00"), lines
    clock.t = 7.0  # 4 s in: extrapolation says 12 s, the limit leaves 1 s
    limited(0.25, 25, False, None, {})
    assert lines[-1].endswith("Remaining 00:01.00"), lines
    stub.stop_requested = lambda: True
    assert updater(0.5, 50, False, None, {}) is True


def test_cancel_keeps_partial_image():
    """A cancel during a render: the image of the samples done stays in the result."""
    scene = make_scene(samples=1 << 20)
    calls = []

    def stop_requested(_self):
        calls.append(1)
        return len(calls) > 3

    with replaced("stop_requested", stop_requested), Recorder("_show", show_record) as shows:
        pixels = f12(scene, "cancelled")
    assert shows.calls and shows.calls[-1][0] < 1 << 20
    assert np.all(np.isfinite(pixels)) and pixels[..., :3].mean() > 0.05, pixels.mean()


# ---- 2. Settings with Cycles' meanings, Render Region ----------------------------------------

def test_sampling_settings_reach_the_library():
    """Noise Threshold (with Cycles' automatic value), Min Samples and Time Limit."""
    settings = make_scene(samples=200).hairis
    settings.use_adaptive_sampling = True
    settings.adaptive_threshold = 0.02
    settings.adaptive_min_samples = 12
    settings.time_limit = 30.0
    values = engine.progressive_settings(settings, (1, 2, 3, 4), ["depth"])
    assert abs(values["adaptive_threshold"] - 0.02) < 1e-7
    assert values["adaptive_min_samples"] == 12 and values["time_limit"] == 30.0
    assert values["region"] == "1,2,3,4" and values["passes"] == "depth"
    settings.adaptive_threshold = 0.0
    assert engine.progressive_settings(settings)["adaptive_threshold"] == 1.0 / 200
    settings.samples = 4096
    assert engine.progressive_settings(settings)["adaptive_threshold"] == 0.001
    settings.use_adaptive_sampling = False
    assert engine.progressive_settings(settings)["adaptive_threshold"] == 0.0
    fresh = helpers.reset().hairis  # the defaults are Cycles'
    assert fresh.use_adaptive_sampling and abs(fresh.adaptive_threshold - 0.01) < 1e-7
    assert fresh.adaptive_min_samples == 0 and fresh.time_limit == 0.0
    assert fresh.preview_samples == 1024


def test_adaptive_sampling_renders_fewer_samples():
    """A loose Noise Threshold stops pixels early: the stats say so, the image stays close."""
    scene = make_scene(samples=128)
    settings = scene.hairis
    settings.use_adaptive_sampling = True
    settings.adaptive_threshold = 0.5
    lib = native.load_library()
    data = helpers.module("export").export_scene(bpy.context.evaluated_depsgraph_get())
    with engine.build_native_scene(lib, data, {}) as native_scene:
        _rgba, _passes, stats = native_scene.render_progressive(
            engine.progressive_settings(settings))
    assert stats.converged_pixels > 0, stats


def test_render_region_and_crop():
    """Render Region renders only the region, as Blender rounds it; with Crop the result is
    the region, without it the full frame with the rest empty; the region's pixels are the
    full render's."""
    scene = make_scene(samples=8, resolution=(50, 40))
    full = f12(scene, "full")
    render = scene.render
    render.use_border = True
    render.border_min_x, render.border_max_x = 0.2, 0.7
    render.border_min_y, render.border_max_y = 0.1, 0.6
    x0, y0, x1, y1 = engine.render_region(render, 50, 40)
    assert (x0, y0, x1, y1) == (10, 4, 35, 24), (x0, y0, x1, y1)
    render.use_crop_to_border = True
    cropped = f12(scene, "cropped")
    assert cropped.shape == (y1 - y0, x1 - x0, 3), cropped.shape
    np.testing.assert_array_equal(cropped, full[y0:y1, x0:x1])
    render.use_crop_to_border = False
    uncropped = f12(scene, "uncropped")
    assert uncropped.shape == full.shape
    np.testing.assert_array_equal(uncropped[y0:y1, x0:x1], full[y0:y1, x0:x1])
    outside = np.ones(full.shape[:2], bool)
    outside[y0:y1, x0:x1] = False
    assert np.all(uncropped[outside] == 0.0)


def test_film_transparent_as_cycles():
    """Film > Transparent: where Cycles' camera rays miss everything, Hairis' pixels are empty
    too (alpha 0, no world), the others keep the world's light on the objects, and alpha is
    Cycles' coverage; off, every pixel has alpha 1 and the world."""
    scene = make_scene(samples=16, resolution=(48, 36))
    helpers.match_cycles(scene, 16, 4)
    opaque = helpers.render_pixels(scene, "HAIRIS", 1, ARGS.workdir, "opaque", alpha=True)[0]
    assert np.all(opaque[..., 3] == 1.0)
    scene.render.film_transparent = True
    hairis = helpers.render_pixels(scene, "HAIRIS", 1, ARGS.workdir, "hairis", alpha=True)[0]
    cycles = helpers.render_pixels(scene, "CYCLES", 1, ARGS.workdir, "cycles", alpha=True)[0]
    empty = hairis[..., 3] == 0.0
    solid = cycles[..., 3] == 1.0
    assert empty.sum() > 100 and solid.sum() > 100, (empty.sum(), solid.sum())
    np.testing.assert_array_equal(hairis[empty], 0.0)
    assert np.all(opaque[empty][:, :3] > 0.1)  # the world, which Film > Transparent removes
    # The pixels no Cycles sample covers are empty in Hairis too, but for a few at the edge
    # of a strand where one of Hairis' 16 samples (placed elsewhere) meets it.
    agree = empty[cycles[..., 3] == 0.0].mean()
    assert agree > 0.95, agree
    covered = solid & (hairis[..., 3] == 1.0)
    np.testing.assert_allclose(hairis[covered][:, :3], opaque[covered][:, :3])
    coverage = hairis[..., 3].mean() / cycles[..., 3].mean()
    print("alpha: Hairis / Cycles mean %.4f; %d empty and %d solid pixels"
          % (coverage, empty.sum(), solid.sum()))
    assert abs(coverage - 1.0) < 0.01, coverage


# ---- 3. Passes and Denoise -------------------------------------------------------------------

def write_record(_engine, result, rgba, passes=None, region=None):
    """The passes the result has after a write, read back."""
    layer = result.layers[0]
    return {p.name: pass_pixels(p).copy() for p in layer.passes}


def test_passes_as_cycles_names_them():
    """Z, Normal and the denoising passes: registered under Cycles' names when the view
    layer asks, written from the library's passes."""
    scene = make_scene(samples=4)
    layer = bpy.context.view_layer
    with Recorder("_write", write_record) as plain:
        f12(scene, "no_passes")
    assert set(plain.calls[-1]) == {"Combined"}, set(plain.calls[-1])
    layer.use_pass_z = True
    layer.use_pass_normal = True
    layer.cycles.denoising_store_passes = True
    with Recorder("_write", write_record) as written:
        f12(scene, "passes")
    passes = written.calls[-1]
    expected = {"Combined", "Depth", "Normal", "Denoising Normal", "Denoising Albedo"}
    assert expected <= set(passes), set(passes)
    depth = passes["Depth"][:, 0]
    assert depth.min() > 2.0 and depth.min() < 4.0, depth.min()  # the hair is ~3.2 m away
    assert np.any(depth >= 1e9)  # sky pixels
    normal = passes["Normal"]
    lengths = np.linalg.norm(normal, axis=1)
    hit = depth < 1e9
    # Averages of unit normals: at most 1, and 1 where every sample saw one flat surface.
    assert np.all(lengths <= 1.0 + 1e-4) and lengths[hit].max() > 0.99, lengths[hit]
    # Depth is sample 0's: where it missed, at most 3 of the 4 samples found a normal.
    assert np.all(lengths[~hit] <= 0.75 + 1e-4), lengths[~hit].max()
    albedo = passes["Denoising Albedo"]
    assert np.all(albedo >= 0.0) and albedo[hit].max() > 0.0
    layer.use_pass_z = layer.use_pass_normal = False
    layer.cycles.denoising_store_passes = False


def noise(image):
    """Mean absolute difference of horizontally neighbouring pixels."""
    return float(np.abs(np.diff(image[..., :3], axis=1)).mean())


def test_denoise_in_one_click():
    """Denoise builds Render Layers → Denoise (with albedo and normal) → output; F12's image
    is then the denoised one; off restores the plain image. Without OpenImageDenoise the
    setting does nothing."""
    scene = make_scene(samples=2, resolution=(64, 48))
    noisy = f12(scene, "noisy")
    assert noise(noisy) > 0.0
    scene.hairis.use_denoising = True
    if not compositor.denoising_available():
        tree = compositor.compositor_tree(scene, False)
        assert tree is None or compositor.DENOISE_NODE not in tree.nodes
        scene.hairis.use_denoising = False
        helpers.skip_function("this Blender has no OpenImageDenoise")
    tree = compositor.compositor_tree(scene, False)
    denoise = tree.nodes[compositor.DENOISE_NODE]
    linked = {s.name: s.links[0].from_socket.name for s in denoise.inputs if s.is_linked}
    assert linked == {"Image": "Image", "Normal": "Denoising Normal",
                      "Albedo": "Denoising Albedo"}, linked
    with Recorder("_write", write_record) as written:
        denoised = f12(scene, "denoised")
    assert {"Denoising Normal", "Denoising Albedo"} <= set(written.calls[-1])
    assert noise(denoised) < 0.6 * noise(noisy), (noise(denoised), noise(noisy))
    mean = noisy[..., :3].mean()
    assert abs(denoised[..., :3].mean() - mean) < 0.1 * mean
    scene.hairis.use_denoising = False
    assert compositor.DENOISE_NODE not in tree.nodes
    np.testing.assert_array_equal(f12(scene, "noisy_again"), noisy)


# ---- 4. The viewport's worker ----------------------------------------------------------------

def camera_of(scene):
    """The scene camera's options without the size (what a view through it gives)."""
    data = helpers.module("export").export_scene(bpy.context.evaluated_depsgraph_get())
    options = engine.camera_options(data.camera)
    del options["width"], options["height"]
    return options


def test_view_camera():
    """The view's camera: the inverse view matrix, the projection's frame at z = -1."""
    view = np.eye(4)
    view[:3, 3] = (1.0, 2.0, 3.0)
    near, far, right, top = 0.1, 100.0, 0.05, 0.03
    projection = np.zeros((4, 4))
    projection[0, 0], projection[1, 1] = near / right, near / top
    projection[2, 2] = -(far + near) / (far - near)
    projection[2, 3] = -2 * far * near / (far - near)
    projection[3, 2] = -1.0
    camera = viewport.view_camera(view, projection, True)
    np.testing.assert_allclose(np.reshape(camera["matrix"], (4, 4))[:3, 3], (-1.0, -2.0, -3.0))
    frame = np.reshape(camera["frame"], (4, 3))
    np.testing.assert_allclose(frame[0], (0.5, 0.3, -1.0))
    np.testing.assert_allclose(frame[2], (-0.5, -0.3, -1.0))
    assert camera["orthographic"] is False


def test_viewport_refines_restarts_and_stops():
    """A low-resolution image first, then the full view refined; a new view cancels and
    restarts without building the scene again; new scene data builds it again; stop() ends
    the thread."""
    scene = make_scene()
    lib = native.load_library()
    waiter = helpers.Waiter(WAIT)
    render = viewport.ViewportRender(lib, waiter)
    try:
        depsgraph = bpy.context.evaluated_depsgraph_get()
        job = viewport.SceneJob(engine._export_view(depsgraph))
        settings = engine.viewport_settings(scene.hairis)
        # The viewport builds a Low BVH, as Cycles' viewport does (F12: Medium).
        final = engine.render_settings(scene.hairis)
        assert settings["bvh_quality"] == "low" and final["bvh_quality"] == "medium", final
        camera = camera_of(scene)
        render.set_scene(job)
        render.set_view(viewport.ViewRequest(camera, 48, 36, settings, 64))
        waiter.until(lambda: render.frame is not None, "the first image")
        assert render.frame.rgba.shape == (36 // 4, 48 // 4, 4), render.frame.rgba.shape
        assert render.first_pixels_seconds is not None
        waiter.until(lambda: render.frame.rgba.shape[0] == 36 and render.frame.samples >= 2,
                     "the full-resolution image")
        first = render.frame
        assert render.scene_builds == 1
        moved = dict(camera, matrix=np.asarray(camera["matrix"]) + np.r_[
            0, 0, 0, 0.3, np.zeros(12)])
        generation = render._generation
        render.set_view(viewport.ViewRequest(moved, 48, 36, settings, 64))
        waiter.until(lambda: render.frame.generation > generation and
                     render.frame.rgba.shape[0] == 36, "the moved view")
        assert render.scene_builds == 1, render.scene_builds
        assert render.renders >= 3, render.renders  # the second view started again
        assert not np.array_equal(render.frame.rgba, first.rgba)
        render.set_scene(viewport.SceneJob(engine._export_view(depsgraph)))
        waiter.until(lambda: render.scene_builds == 2, "the new scene")
        assert render.error is None, render.error
    finally:
        render.stop()
    assert not render.alive


def update_kinds(edit):
    """The viewport's reading (engine._update_kind) of the depsgraph updates ``edit()``
    makes, one per update Blender reports."""
    seen = []

    def record(_scene, depsgraph):
        seen.append(engine._update_kind(depsgraph))

    bpy.app.handlers.depsgraph_update_post.append(record)
    try:
        edit()
        bpy.context.view_layer.update()
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(record)
    return [kind for kind in seen if kind is not None]


def hair_node():
    """The Principled Hair BSDF of make_scene's hair material."""
    nodes = bpy.data.materials["Hair"].node_tree.nodes
    return next(n for n in nodes if n.bl_idname == "ShaderNodeBsdfHairPrincipled")


def test_edits_of_shading_are_told_from_geometry():
    """A material, light or world edit reads as 'shading'; moving or reshaping an object, or
    editing a texture a modifier displaces with, as 'geometry'."""
    make_scene()

    def melanin():
        helpers.socket(hair_node(), "Melanin").default_value = 0.6

    def energy():
        bpy.data.lights["Sun"].energy = 5.0

    def world():
        helpers.socket(bpy.context.scene.world.node_tree.nodes["Background"],
                       "Strength").default_value = 2.0

    def move():
        bpy.data.objects["Sphere"].location.x += 0.1

    def reshape():
        bpy.data.objects["Sphere"].data.vertices[0].co.x += 0.1
        bpy.data.objects["Sphere"].data.update()

    def displace():
        modifier = bpy.data.objects["Sphere"].modifiers.new("Displace", "DISPLACE")
        modifier.texture = bpy.data.textures.new("Bumps", "CLOUDS")

    def bumps():  # a texture a modifier displaces with is geometry, not shading
        bpy.data.textures["Bumps"].noise_scale = 0.5

    for edit, want in ((melanin, "shading"), (energy, "shading"), (world, "shading"),
                       (move, "geometry"), (reshape, "geometry"), (displace, "geometry"),
                       (bumps, "geometry")):
        kinds = update_kinds(edit)
        assert kinds, "%s: no update reached the handler" % edit.__name__
        assert kinds[-1] == want, "%s read as %s" % (edit.__name__, kinds)


def test_export_shading_keeps_geometry_and_knows_its_limits():
    """export_shading re-reads materials, lights and world in the first export's order and
    keeps its geometry arrays; a material assigned otherwise needs the whole export."""
    make_scene()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    first = engine._export_view(depsgraph)
    helpers.socket(hair_node(), "Melanin").default_value = 0.6
    bpy.data.lights["Sun"].energy = 5.0
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    shading = helpers.module("export").export_shading(depsgraph, first)
    assert shading is not None
    assert [m.name for m in shading.materials] == [m.name for m in first.materials]
    hair = next(m for m in shading.materials if m.kind == "HAIR")
    assert abs(hair.hair.melanin - 0.6) < 1e-6, hair.hair.melanin
    assert shading.lights[0].strength == 5.0, shading.lights[0].strength
    assert shading.curves[0].positions is first.curves[0].positions
    whole = engine._export_view(depsgraph)
    assert [m.hair for m in whole.materials] == [m.hair for m in shading.materials]
    other = helpers.make_surface_material("Other", (0.1, 0.8, 0.1, 1.0))
    bpy.data.objects["Sphere"].material_slots[0].material = other
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    assert helpers.module("export").export_shading(depsgraph, first) is None


def finished_frame(render, samples, generation, waiter, what):
    """The worker's image of ``generation`` once it has all ``samples``."""
    waiter.until(lambda: render.frame is not None and render.frame.generation >= generation
                 and render.frame.rgba.shape[0] == 36 and render.frame.samples >= samples, what)
    assert render.error is None, render.error
    return render.frame.rgba.copy()


def test_viewport_reshades_a_material_edit_without_a_new_bvh():
    """A material edit gives the built scene new shading (no new build); its image is a fresh
    build's of the edited scene, bit for bit."""
    scene = make_scene(samples=8)
    lib = native.load_library()
    settings = engine.viewport_settings(scene.hairis)
    camera = camera_of(scene)
    waiter = helpers.Waiter(WAIT)
    render = viewport.ViewportRender(lib, waiter)
    try:
        first = viewport.SceneJob(engine._export_view(bpy.context.evaluated_depsgraph_get()))
        render.set_scene(first)
        render.set_view(viewport.ViewRequest(camera, 48, 36, settings, 8))
        before = finished_frame(render, 8, 0, waiter, "the first image")
        helpers.socket(hair_node(), "Melanin").default_value = 0.05
        depsgraph = bpy.context.evaluated_depsgraph_get()
        depsgraph.update()
        data = helpers.module("export").export_shading(depsgraph, first.data)
        generation = render._generation + 1
        render.set_scene(viewport.SceneJob(data, geometry=first.geometry))
        edited = finished_frame(render, 8, generation, waiter, "the edited image")
        assert render.scene_builds == 1 and render.scene_reshades == 1, (
            render.scene_builds, render.scene_reshades)
        assert not np.array_equal(edited, before)
    finally:
        render.stop()
    fresh_render = viewport.ViewportRender(lib, waiter)
    try:
        fresh_render.set_scene(viewport.SceneJob(engine._export_view(depsgraph)))
        fresh_render.set_view(viewport.ViewRequest(camera, 48, 36, settings, 8))
        fresh = finished_frame(fresh_render, 8, 0, waiter, "the fresh image")
    finally:
        fresh_render.stop()
    assert np.array_equal(edited, fresh), np.abs(edited - fresh).max()


def test_viewport_stop_while_rendering():
    """stop() in the middle of a long render returns promptly with the thread ended."""
    scene = make_scene(samples=64, resolution=(96, 72))
    render = viewport.ViewportRender(native.load_library(), helpers.Waiter(WAIT))
    depsgraph = bpy.context.evaluated_depsgraph_get()
    render.set_scene(viewport.SceneJob(engine._export_view(depsgraph)))
    render.set_view(viewport.ViewRequest(camera_of(scene), 96, 72,
                                         engine.viewport_settings(scene.hairis), 0))
    waiter = render.redraw
    waiter.until(lambda: render.frame is not None, "the first image")
    render.stop(timeout=WAIT)
    assert not render.alive


helpers.run([
    test_film_transparent_as_cycles,
    test_f12_refines_on_screen,
    test_stats_line,
    test_cancel_keeps_partial_image,
    test_sampling_settings_reach_the_library,
    test_adaptive_sampling_renders_fewer_samples,
    test_render_region_and_crop,
    test_passes_as_cycles_names_them,
    test_denoise_in_one_click,
    test_view_camera,
    test_viewport_refines_restarts_and_stops,
    test_edits_of_shading_are_told_from_geometry,
    test_export_shading_keeps_geometry_and_knows_its_limits,
    test_viewport_reshades_a_material_edit_without_a_new_bvh,
    test_viewport_stop_while_rendering,
])
