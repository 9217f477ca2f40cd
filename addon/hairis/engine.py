"""The Hairis render engine: export, check or bake tables, render through the C API.

The engine keeps no global state: everything a render needs (the loaded library, exported
arrays, tables, the native scene) lives in local variables of :meth:`render` and is released
before it returns. Failures are reported with ``self.report({'ERROR'}, ...)`` and
``error_set`` (so ``bpy.ops.render.render()`` raises and the image editor shows the message);
Blender keeps running.
"""

import os
import time
import traceback
import weakref

import bpy
import numpy as np

from . import compat, compositor, export, native, tables, viewport

DUMP_ENV = "HAIRIS_EXPORT_DUMP"
"""When set, each render writes its exported scene to this ``.npz`` path (debugging, tests)."""


class RenderFailed(Exception):
    """A render cannot proceed; the message is shown to the user."""


class ProgressReporter:
    """The C progress callback: forwards progress to ``update_progress``, cancels on
    ``test_break()``.

    ``update_progress`` is rate-limited to every ``interval`` seconds; ``test_break`` is asked
    on every call so a cancel is seen at the next callback. ``start``/``end`` map [0, 1] onto
    a part of the progress bar.
    """

    def __init__(self, engine, start=0.0, end=1.0, interval=0.1, clock=time.monotonic):
        self.engine = engine
        self.start = start
        self.end = end
        self.interval = interval
        self.clock = clock
        self.last = None

    def __call__(self, progress):
        now = self.clock()
        progress = min(max(float(progress), 0.0), 1.0)
        if self.last is None or progress >= 1.0 or now - self.last >= self.interval:
            self.engine.update_progress(self.start + (self.end - self.start) * progress)
            self.last = now
        return bool(self.engine.test_break())


def camera_options(camera):
    """The C API's camera options from :class:`scene_data.CameraData`."""
    return {"matrix": np.asarray(camera.camera_to_world, dtype=np.float64).reshape(-1),
            "orthographic": bool(camera.orthographic),
            "frame": np.asarray(camera.frame, dtype=np.float64).reshape(-1),
            "width": int(camera.width), "height": int(camera.height)}


def light_options(light):
    """The C API's light options from :class:`scene_data.LightData`."""
    values = {"type": light.kind.lower(), "color": light.color, "cycles": light.cycles}
    if light.kind == "SUN":
        values.update(direction=light.direction, strength=float(light.strength),
                      angle=float(light.angle))
    elif light.kind == "POINT":
        values.update(position=light.position, power=float(light.strength),
                      radius=float(light.radius), soft_falloff=bool(light.soft_falloff))
    elif light.kind == "SPOT":
        values.update(matrix=np.asarray(light.matrix, np.float64).reshape(-1),
                      power=float(light.strength), radius=float(light.radius),
                      spot_size=float(light.spot_size), spot_blend=float(light.spot_blend),
                      soft_falloff=bool(light.soft_falloff))
    else:
        values.update(matrix=np.asarray(light.matrix, np.float64).reshape(-1),
                      shape=str(light.shape).lower(), size=float(light.size_x),
                      size_y=float(light.size_y), power=float(light.strength))
    return values


def render_settings(settings):
    """The C API's render settings from ``scene.hairis``, the scene's Film > Transparent and
    Cycles bounce limits per kind (:func:`cycles_bounce_limits`), its biased Cycles settings
    (:func:`cycles_biased_settings`), and how the running Blender's Cycles traces curves
    (:func:`compat.curve_backfaces`, the scene's Curves > Shape: :func:`compat.curve_shape`,
    and Subdivisions: :func:`curve_subdivisions`), builds its BVH (:func:`bvh_quality`) and
    limits transparent crossings (:func:`compat.transparent_limit`)."""
    scene = getattr(settings, "id_data", None)
    render = getattr(scene, "render", None)
    return {"integrator": settings.integrator.lower(),
            "samples": int(settings.samples), "max_bounces": int(settings.max_bounces),
            "max_transparent_bounces": int(settings.max_transparent_bounces),
            "transparent_limit": compat.transparent_limit(),
            "strategy": settings.strategy.lower(),
            "huang_sampling": settings.huang_sampling.lower(),
            "dual_hair_volume": settings.dual_hair_volume.lower(),
            "dual_exact_bounces": int(settings.dual_exact_bounces),
            "dual_bounce_limit": settings.dual_bounce_limit.lower(),
            "multiple_weight": float(settings.multiple_weight), "n_h": int(settings.n_h),
            "seed": int(settings.seed), "threads": int(settings.threads),
            "curve_backfaces": compat.curve_backfaces(),
            "curve_shape": compat.curve_shape(scene)[0],
            "curve_subdivisions": curve_subdivisions(scene),
            "bvh_quality": bvh_quality(scene),
            "film_transparent": bool(getattr(render, "film_transparent", False)),
            **cycles_bounce_limits(scene), **cycles_biased_settings(scene)}


def viewport_settings(settings):
    """:func:`render_settings` for the viewport: a Low BVH, as Cycles' viewport asks Embree for."""
    return dict(render_settings(settings), bvh_quality="low")


def curve_subdivisions(scene):
    """Cycles' Curves > Subdivisions (its default 2 without Cycles' settings), which sets how
    finely Embree intersects ribbons."""
    curves = getattr(scene, "cycles_curves", None) if scene is not None else None
    return min(max(int(getattr(curves, "subdivisions", 2)), 0), 24)


def bvh_quality(scene):
    """The BVH Cycles builds for a final render: 'high' with Performance > Use Spatial Splits,
    else 'medium' (the viewport's is 'low', as Cycles' dynamic BVH)."""
    cycles = getattr(scene, "cycles", None)
    return "high" if getattr(cycles, "debug_use_spatial_splits", False) else "medium"


def cycles_bounce_limits(scene):
    """The scene's Cycles bounce limits per kind (Light Paths > Max Bounces: Diffuse, Glossy,
    Transmission), which a path obeys besides Hairis' total, as Cycles' paths do; none without
    Cycles' settings (the library's defaults are Cycles' defaults)."""
    cycles = getattr(scene, "cycles", None)
    if cycles is None:
        return {}
    return {"max_diffuse_bounces": int(cycles.diffuse_bounces),
            "max_glossy_bounces": int(cycles.glossy_bounces),
            "max_transmission_bounces": int(cycles.transmission_bounces)}


PIXEL_FILTERS = {"BOX": "box", "GAUSSIAN": "gaussian", "BLACKMAN_HARRIS": "blackman_harris"}
"""Cycles' Film > Pixel Filter types and the library's names for them."""


def cycles_biased_settings(scene):
    """The scene's Cycles settings that shape its image beyond the light transport, as Cycles'
    sync reads them: Film > Exposure, Filter Glossy, Clamping Direct and Indirect, and the
    Pixel Filter (a Box is always 1 px wide, whatever the hidden width says); none without
    Cycles' settings."""
    cycles = getattr(scene, "cycles", None)
    if cycles is None:
        return {}
    kind = PIXEL_FILTERS.get(str(cycles.pixel_filter_type), "blackman_harris")
    return {"exposure": float(cycles.film_exposure),
            "filter_glossy": float(cycles.blur_glossy),
            "clamp_direct": float(cycles.sample_clamp_direct),
            "clamp_indirect": float(cycles.sample_clamp_indirect),
            "pixel_filter": kind,
            "pixel_filter_width": 1.0 if kind == "box" else float(cycles.filter_width)}


def adaptive_threshold(settings):
    """The Noise Threshold the library gets: 0 (off) without adaptive sampling, else the
    setting, or where that is 0 Cycles' automatic threshold from the sample count."""
    if not settings.use_adaptive_sampling:
        return 0.0
    if settings.adaptive_threshold > 0.0:
        return float(settings.adaptive_threshold)
    return max(0.001, 1.0 / max(int(settings.samples), 1))


def progressive_settings(settings, region=None, passes=()):
    """:func:`render_settings` with the final render's Noise Threshold, Min Samples, Time
    Limit, the Render Region (x0, y0, x1, y1 pixels, bottom row 0) and the library's passes."""
    values = render_settings(settings)
    values.update(adaptive_threshold=adaptive_threshold(settings),
                  adaptive_min_samples=int(settings.adaptive_min_samples),
                  time_limit=float(settings.time_limit))
    if region is not None:
        values["region"] = "%d,%d,%d,%d" % tuple(region)
    if passes:
        values["passes"] = ",".join(passes)
    return values


PASSES = (
    ("depth", "Depth", "Z", "VALUE"),
    ("normal", "Normal", "XYZ", "VECTOR"),
    ("denoising_normal", "Denoising Normal", "XYZ", "VECTOR"),
    ("denoising_albedo", "Denoising Albedo", "RGB", "COLOR"),
)
"""The library's passes: its name, Blender's pass name and channels as Cycles registers them."""


def enabled_passes(scene, view_layer):
    """The library names of the passes the view layer asks for, as Cycles reads them: Z and
    Normal from the view layer, the denoising passes from Cycles' Store Denoising Passes or
    Hairis' Denoise."""
    names = []
    if view_layer.use_pass_z:
        names.append("depth")
    if view_layer.use_pass_normal:
        names.append("normal")
    cycles = getattr(view_layer, "cycles", None)
    store = bool(getattr(cycles, "denoising_store_passes", False))
    if store or (scene.hairis.use_denoising and compositor.denoising_available()):
        names += ["denoising_normal", "denoising_albedo"]
    return names


def pass_channels(name):
    """The number of channels of the library's pass ``name``."""
    for library_name, _blender_name, channels, _kind in PASSES:
        if library_name == name:
            return len(channels)
    raise KeyError(name)


def render_region(render, width, height):
    """The Render Region in pixels (x0, y0, x1, y1, bottom row 0), as Blender rounds it, or
    None when the whole frame renders."""
    if not render.use_border:
        return None
    x0, x1 = (int(np.float32(v) * np.float32(width))
              for v in (render.border_min_x, render.border_max_x))
    y0, y1 = (int(np.float32(v) * np.float32(height))
              for v in (render.border_min_y, render.border_max_y))
    return x0, y0, x1, y1


def format_seconds(seconds):
    """A duration as Blender's stats line writes it (mm:ss.ss, or hh:mm:ss.ss)."""
    seconds = max(float(seconds), 0.0)
    hours, rest = divmod(seconds, 3600.0)
    minutes, rest = divmod(rest, 60.0)
    if hours >= 1.0:
        return "%02d:%02d:%05.2f" % (hours, minutes, rest)
    return "%02d:%05.2f" % (minutes, rest)


def remaining_seconds(progress, elapsed, time_limit=0.0):
    """The time left, extrapolated from the progress so far and bounded by the Time Limit;
    None before any progress."""
    left = None
    if progress > 0.0:
        left = elapsed * (1.0 - progress) / progress
    if time_limit > 0.0:
        limit_left = max(time_limit - elapsed, 0.0)
        left = limit_left if left is None else min(left, limit_left)
    return left


class DisplayUpdater:
    """The progressive render's update callback for F12: writes the image into the render
    result whenever it has more samples, puts samples and time left in the stats line and
    cancels when the engine's ``stop_requested()`` says so."""

    def __init__(self, engine, show, samples, time_limit=0.0, clock=time.monotonic):
        self.engine = engine
        self.show = show
        self.samples = int(samples)
        self.time_limit = float(time_limit)
        self.clock = clock
        self.start = clock()
        self.shown = 0

    def __call__(self, progress, samples_done, final, rgba, passes):
        if samples_done > self.shown:
            self.show(rgba, passes, samples_done, final)
            self.shown = samples_done
        progress = min(max(float(progress), 0.0), 1.0)
        self.engine.update_progress(progress)
        text = "Sample %d/%d" % (samples_done, self.samples)
        left = remaining_seconds(progress, self.clock() - self.start, self.time_limit)
        if left is not None and not final:
            text += ", Remaining %s" % format_seconds(left)
        self.engine.update_stats("", text)
        return bool(self.engine.stop_requested())


def dual_scattering_warning(exact_bounces, bounce_limit="BOUNCES"):
    """What a render with Dual Scattering reports: that it is biased, and which way the
    settings push the bias."""
    text = ("Dual Scattering is experimental and biased: its closed form stands in for the "
            "light that crosses other strands")
    if exact_bounces < 3:
        text += (", and with fewer than 3 Exact Bounces it shades flatter than path tracing "
                 "(shaded regions brighter, lit ones darker)")
    if bounce_limit == "NONE":
        text += (", and Bounce Limit None adds every order of scattering, so light hair comes "
                 "out brighter than path tracing with the same Max Bounces")
    return text


def add_surface_nodes(scene, nodes, texture_index):
    """Adds a surface material's nodes (export's positions → the library's indices); returns
    the index of its root."""
    added = []
    for node in nodes:
        values = dict(node)
        for key in ("base_color_texture", "color_texture"):
            if values.get(key, -1) >= 0:
                values[key] = texture_index(values[key])
        for key in ("shader1", "shader2"):
            if key in values:
                values[key] = added[values[key]]
        added.append(scene.add_surface_material(values))
    return added[-1]


def _add_materials(scene, data, hair_tables):
    """Adds ``data``'s materials (and the textures they use) to ``scene`` in their order."""
    textures = {}  # position in data.textures → the library's texture index

    def texture_index(position):
        if position not in textures:
            texture = data.textures[position]
            values = texture.options()
            if texture.path is not None:
                textures[position] = scene.add_texture(dict(values, image=texture.path))
            else:
                textures[position] = scene.add_texture(values, texture.pixels)
        return textures[position]

    indices = []
    for i, material in enumerate(data.materials):
        try:
            if material.kind == "HAIR":
                indices.append(scene.add_hair_material(material.hair.as_dict(),
                                                       hair_tables.get(i)))
            elif material.kind == "HAIR_MIX":
                indices.append(scene.add_hair_mixture(
                    [indices[k] for k in material.mixture.closures],
                    material.mixture.material_weights()))
            elif material.kind == "SURFACE":
                indices.append(add_surface_nodes(scene, material.nodes, texture_index))
            else:
                indices.append(scene.add_diffuse_material(material.albedo, material.emission))
        except native.HairisError as error:
            raise RenderFailed("material %r: %s" % (material.name, error.message)) from error
    return np.array(indices or [0], dtype=np.int32)


def _add_lights_and_world(scene, data):
    """Adds ``data``'s lights and sets its world."""
    for light in data.lights:
        scene.add_light(light_options(light))
    environment = data.world_environment
    if environment is None:
        scene.set_world(data.world_color, data.world_strength)
    elif environment.path is not None:
        scene.set_world_options(dict(environment.options(), image=environment.path))
    else:
        scene.set_world_pixels(environment.options(), environment.pixels)


def build_native_scene(library, data, hair_tables):
    """A ``native.Scene`` holding everything in ``data`` (SceneData).

    ``hair_tables`` maps a hair material's index in ``data.materials`` to its Tables (or
    lacks it: no tables). Without ``data.camera`` the caller sets the camera. The caller closes
    the returned scene.
    """
    scene = library.scene()
    try:
        remap = _add_materials(scene, data, hair_tables)
        for curves in data.curves:
            if curves.inputs:
                scene.add_curves_with_inputs(int(remap[curves.material]), curves.first,
                                             curves.positions, curves.radii, curves.inputs)
            else:
                scene.add_curves(int(remap[curves.material]), curves.first, curves.positions,
                                 curves.radii, curves.normals)
        for mesh in data.meshes:
            scene.add_mesh(mesh.positions, mesh.indices, remap[mesh.materials])
            if mesh.normals is not None:
                scene.set_mesh_attribute("normal", mesh.normals)
            if mesh.uvs is not None:
                scene.set_mesh_attribute("uv", mesh.uvs)
        _add_lights_and_world(scene, data)
        if data.camera is not None:
            scene.set_camera(camera_options(data.camera))
    except BaseException:
        scene.close()
        raise
    return scene


def reshade_native_scene(scene, data, hair_tables):
    """Gives ``scene`` (built from a SceneData of the same geometry) ``data``'s materials,
    lights and world; the library keeps the BVH it built."""
    scene.reset_shading()
    _add_materials(scene, data, hair_tables)
    _add_lights_and_world(scene, data)


SHADING_DATA = ("Material", "World", "Light", "ShaderNodeTree", "Image")
"""bpy.types of the data blocks whose edits change the viewport's shading but no geometry
(bpy.types.Texture is not one: modifiers displace with it)."""


def _update_kind(depsgraph):
    """What a depsgraph update changed in the scene the viewport renders: None (nothing: the
    scene's settings and cameras count as nothing, since view_draw follows the view and the
    render settings), 'shading' (materials, lights, the world) or 'geometry' (anything else).
    An edit of a material also flags the objects using it as changed in geometry (materials
    can displace), so that flag counts only when no material changed with it."""
    shading_types = tuple(getattr(bpy.types, name) for name in SHADING_DATA)
    kind, reshaped = None, False
    for update in depsgraph.updates:
        data = update.id
        if isinstance(data, bpy.types.Object):
            if data.type == "CAMERA":
                continue  # the viewport renders the view, not the scene camera
            if data.type != "LIGHT":
                if update.is_updated_transform:
                    return "geometry"
                reshaped = reshaped or update.is_updated_geometry
            kind = "shading"
        elif isinstance(data, bpy.types.Scene):
            if update.is_updated_geometry or update.is_updated_transform:
                return "geometry"
            if update.is_updated_shading:
                kind = "shading"
            # else a setting: view_draw compares the render settings
        elif isinstance(data, shading_types):
            kind = "shading"
        elif update.is_updated_geometry or update.is_updated_transform:
            return "geometry"  # object data: a mesh, curves, particle settings, ...
        elif update.is_updated_shading:
            kind = "shading"
        else:
            return "geometry"
    materials = (bpy.types.Material, bpy.types.ShaderNodeTree)
    if reshaped and not any(isinstance(u.id, materials) for u in depsgraph.updates):
        return "geometry"
    return kind


class _ViewExporter(export._Exporter):
    """The exporter without the scene camera: the viewport renders the 3D view's."""

    def export_camera(self):
        """Nothing: the view's camera is set on the native scene."""


def _export_view(depsgraph):
    """The scene of the viewport's depsgraph without a camera."""
    data = _ViewExporter(depsgraph, None).run()
    data.camera = None
    return data


class HairisRenderEngine(bpy.types.RenderEngine):
    """Hairis: a hair path tracer with importance-sampled fiber scattering."""

    bl_idname = "HAIRIS"
    bl_label = "Hairis"
    bl_use_preview = False
    bl_use_shading_nodes_custom = False
    bl_use_eevee_viewport = False

    def __init__(self, *args, **kwargs):
        # Blender 4.x+ passes arguments to RenderEngine subclasses; they must reach the base.
        super().__init__(*args, **kwargs)

    display_updates = True
    """Whether F12 shows the image while it refines (off: the render result is written once,
    at the end; tests compare the two)."""

    def render(self, depsgraph):
        """Renders one view layer of ``depsgraph`` into the Combined pass (and the passes the
        view layer asks for), refining the image on screen as samples arrive."""
        width, height = self.resolution_x, self.resolution_y
        result = self.begin_result(0, 0, width, height)
        try:
            try:
                self._render(depsgraph, result, width, height)
            except native.HairisCancelled as cancelled:
                # The partial image is kept: what the last update wrote, and what is left.
                if getattr(cancelled, "rgba", None) is not None:
                    self._write(result, cancelled.rgba, getattr(cancelled, "passes", None))
                self.update_stats("", "Cancelled")
            except (RenderFailed, export.ExportError, tables.TableError,
                    native.HairisError) as error:
                self._fail(str(error))
            except Exception as error:  # noqa: BLE001 - Blender must keep running
                traceback.print_exc()
                self._fail("Hairis internal error: %s: %s (details in the console)"
                           % (type(error).__name__, error))
        finally:
            self.end_result(result)

    def update_render_passes(self, scene=None, renderlayer=None):
        """Registers Combined and the passes the view layer enables (as Cycles names them)."""
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", "COLOR")
        wanted = enabled_passes(scene, renderlayer)
        for name, blender_name, channels, kind in PASSES:
            if name in wanted:
                self.register_pass(scene, renderlayer, blender_name, len(channels), channels,
                                   kind)

    def _write(self, result, rgba, passes=None, region=None):
        """Copies the library's image (and passes) into the render result: the Render
        Region's pixels when one is set (the result covers only the region)."""
        region = region or getattr(self, "_region", None)
        x0, y0, x1, y1 = region or (0, 0, rgba.shape[1], rgba.shape[0])
        layer = result.layers[0]
        try:
            compat.set_pass_pixels(layer.passes["Combined"], rgba[y0:y1, x0:x1])
            for name, values in (passes or {}).items():
                blender_name = next(p[1] for p in PASSES if p[0] == name)
                target = layer.passes.get(blender_name)
                if target is not None:
                    compat.set_pass_pixels(target, values[y0:y1, x0:x1])
        except Exception as error:  # noqa: BLE001
            raise RenderFailed("Hairis could not write the render result: %s" % error) \
                from error

    def _show(self, result, rgba, passes, samples_done, final):
        """Writes the current image into the result and tells Blender to redraw it."""
        self._write(result, rgba, passes)
        self.update_result(result)

    def stop_requested(self):
        """True once the user cancelled the render (``test_break``)."""
        return bool(self.test_break())

    def _fail(self, message):
        self.report({"ERROR"}, message)
        try:
            self.error_set(message)
        except AttributeError:  # error_set is missing before Blender 2.9x
            pass
        self.update_stats("", "Error: " + message)

    def _render(self, depsgraph, result, width, height):
        problem = compat.version_problem()
        if problem:
            raise RenderFailed(problem)
        scene = depsgraph.scene
        settings = scene.hairis
        self._region = render_region(scene.render, width, height)
        if self._region is not None:
            # The result covers the region as Blender rounds it: its size is the truth.
            x0, y0 = self._region[:2]
            self._region = (x0, y0, x0 + result.resolution_x, y0 + result.resolution_y)

        self.update_stats("", "Exporting scene")
        data = export.export_scene(depsgraph, self.camera_override)
        dump = os.environ.get(DUMP_ENV)
        if dump:
            data.save_npz(dump)
        for warning in data.warnings + [compat.curve_shape(scene)[1]]:
            if warning:
                self.report({"WARNING"}, warning)
        if (data.camera.width, data.camera.height) != (width, height):
            raise RenderFailed("render size %d×%d differs from the exported camera's %d×%d"
                               % (width, height, data.camera.width, data.camera.height))
        if self.test_break():
            return

        library = native.load_library()
        hair_tables = self._resolve_tables(library, data, settings)
        if settings.integrator == "DUAL_SCATTERING":
            self.report({"WARNING"}, dual_scattering_warning(settings.dual_exact_bounces,
                                                             settings.dual_bounce_limit))
        passes = [name for name, _b, _c, _k in PASSES
                  if name in enabled_passes(scene, depsgraph.view_layer)]
        values = progressive_settings(settings, self._region, passes)
        try:
            with build_native_scene(library, data, hair_tables) as native_scene:
                self.update_stats("", "Rendering %d samples (%s%s)"
                                  % (settings.samples, settings.strategy.lower(),
                                     ", dual scattering"
                                     if settings.integrator == "DUAL_SCATTERING" else ""))
                update = None
                if self.display_updates:
                    update = DisplayUpdater(
                        self, lambda rgba, images, done, final:
                        self._show(result, rgba, images, done, final),
                        settings.samples, settings.time_limit)
                rgba, images, stats = native_scene.render_progressive(values, update, passes)
        finally:
            for table in hair_tables.values():
                table.close()
        self._write(result, rgba, images)
        peak = stats.peak_memory_bytes / (1024.0 * 1024.0)
        self.update_memory_stats(memory_used=peak, memory_peak=peak)
        self.update_stats("", "Rendered %d samples in %s"
                          % (getattr(stats, "samples", settings.samples),
                             format_seconds(stats.seconds)))
        if stats.dropped_samples:
            self.report({"WARNING"}, "%d samples with NaN or infinite values were dropped"
                        % stats.dropped_samples)

    # -- viewport --

    def view_update(self, context, depsgraph):
        """Exports the scene for the viewport when it is new or its data changed: an edit of
        materials, lights or the world alone exports only those, and the worker keeps the
        geometry it built; view changes alone are :meth:`view_draw`'s."""
        render = getattr(self, "_viewport", None)
        kind = _update_kind(depsgraph) if render is not None else "geometry"
        if kind is None:
            return
        try:
            problem = compat.version_problem()
            if problem:
                raise RenderFailed(problem)
            if render is None:
                library = native.load_library()
                # A weak reference: the worker must not keep the engine alive (its __del__
                # stops the worker).
                redraw = weakref.WeakMethod(self._tag_redraw)
                render = self._viewport = viewport.ViewportRender(
                    library, lambda: redraw() is not None and redraw()())
                self._display = viewport.Display()
                self._view_key = None
            shown = getattr(self, "_viewport_job", None)
            job = None
            if kind == "shading" and shown is not None:
                data = export.export_shading(depsgraph, shown.data)
                if data is not None:
                    job = self._scene_job(render.library, depsgraph, data, shown.geometry)
            if job is None:
                job = self._scene_job(render.library, depsgraph)
            render.set_scene(job)
            self._viewport_job = job
            self._viewport_error = None
        except (RenderFailed, export.ExportError, tables.TableError,
                native.HairisError) as error:
            self._viewport_error = str(error)
        except Exception as error:  # noqa: BLE001 - Blender must keep running
            traceback.print_exc()
            self._viewport_error = "Hairis internal error: %s: %s" % (type(error).__name__,
                                                                      error)
        self.tag_redraw()

    def view_draw(self, context, depsgraph):
        """Draws the newest viewport image; a new view (matrix, projection or size) restarts
        the render with only the camera changed."""
        region = context.region
        message = getattr(self, "_viewport_error", None)
        render = getattr(self, "_viewport", None)
        if render is not None and message is None:
            region3d = context.region_data
            pixel_size = max(int(self.get_preview_pixel_size(depsgraph.scene)), 1)
            width, height = region.width // pixel_size, region.height // pixel_size
            view_matrix = np.array(region3d.view_matrix, np.float64)
            window_matrix = np.array(region3d.window_matrix, np.float64)
            settings = depsgraph.scene.hairis
            values = viewport_settings(settings)
            key = (view_matrix.tobytes(), window_matrix.tobytes(), width, height,
                   settings.preview_samples, sorted(values.items()))
            if key != self._view_key:
                self._view_key = key
                camera = viewport.view_camera(view_matrix, window_matrix,
                                              region3d.is_perspective)
                render.set_view(viewport.ViewRequest(camera, width, height, values,
                                                     settings.preview_samples))
            message = render.error
            frame = render.frame
            if frame is not None:
                self._display.upload(frame)
                self._display.draw(self, depsgraph.scene, region.width, region.height)
            self.update_stats("", message or render.status)
        elif message:
            self.update_stats("", "Error: " + message)

    def _tag_redraw(self):
        try:
            self.tag_redraw()
        except ReferenceError:  # the engine is being freed
            pass

    def _scene_job(self, library, depsgraph, data=None, geometry=None):
        """The viewport's :class:`viewport.SceneJob`: the scene exported now (without a
        camera) or ``data`` (an update of the materials, lights and world of the job whose
        ``geometry`` it keeps), current or cached tables, and what the worker must bake."""
        if data is None:
            data = _export_view(depsgraph)
        settings = depsgraph.scene.hairis
        bakes = []

        def bake_later(index, material, fiber, _status):
            absorption = material.hair.varies_absorption
            cached = tables.cached_tables(
                library, fiber, need_multiple=settings.integrator == "DUAL_SCATTERING",
                refinement=settings.huang_f_refinement, absorption=absorption)
            if cached is not None:
                return cached
            bakes.append((index, material.hair.as_dict(),
                          tables.bake_options(library, n_h=int(settings.n_h),
                                              threads=settings.threads,
                                              multiple=settings.integrator == "DUAL_SCATTERING",
                                              refinement=settings.huang_f_refinement,
                                              absorption=absorption),
                          tables.fiber_cache_path(fiber, settings.huang_f_refinement,
                                                  absorption)))
            return None

        found = self._resolve_tables(library, data, settings, bake_later)
        return viewport.SceneJob(data, found, bakes, geometry=geometry)

    def free_viewport(self):
        """Stops the viewport's worker thread (the view closed or the engine goes)."""
        render = getattr(self, "_viewport", None)
        self._viewport = None
        self._viewport_job = None
        if render is not None:
            render.stop()

    def __del__(self):
        try:
            self.free_viewport()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass

    def _resolve_tables(self, library, data, settings, bake=None):
        """Tables per hair material index: current ones, auto-baked ones, or an error.

        ``bake(index, material, fiber, status)`` stands in for the auto bake (the viewport
        leaves it to its worker): it returns tables or None (baked later).

        Only the TABLE strategy and the Dual Scattering integrator use tables (other settings
        get none). They refuse materials without current tables unless Auto Bake is on, never
        rendering them silently wrong.
        """
        found = {}
        problems = []
        if not settings.needs_tables:
            return found
        try:
            for index, material in data.hair_materials():
                # Cycles' own Huang sampler needs no tables (Dual Scattering does); with them,
                # light samples are shaded with the baked expectation of Cycles' eval.
                optional = (material.hair.model == "HUANG" and settings.huang_sampling == "CYCLES"
                            and settings.integrator != "DUAL_SCATTERING")
                node = tables.principled_struct(library, material.hair)
                try:
                    fiber = library.fiber_principled(node)
                except native.HairisError as error:
                    raise RenderFailed("material %r: %s" % (material.name, error.message)) \
                        from error
                with fiber:
                    if material.source is not None:
                        status = tables.check_material(
                            library, material.source, fiber,
                            need_multiple=settings.integrator == "DUAL_SCATTERING",
                            refinement=settings.huang_f_refinement,
                            absorption=material.hair.varies_absorption)
                    else:
                        status = tables.TableStatus("MISSING", "material %r has no sampling "
                                                    "tables" % material.name)
                    if status.state == "PARTIAL" and settings.auto_bake:
                        status.tables.close()  # a bake below adds the absorption part
                    elif status.state == "PARTIAL":
                        # Usable: strands of their own colour fall back to Cycles' eval.
                        self.report({"WARNING"}, status.message)
                        found[index] = status.tables
                        continue
                    if status.ok:
                        found[index] = status.tables
                    elif settings.auto_bake and bake is not None:
                        baked = bake(index, material, fiber, status)
                        if baked is not None:
                            found[index] = baked
                    elif settings.auto_bake:
                        try:
                            found[index] = self._auto_bake(library, material, fiber, settings,
                                                           status)
                        except native.HairisCancelled:
                            raise
                        except native.HairisError as error:
                            raise RenderFailed("material %r: %s" % (material.name, error.message)) \
                                from error
                    elif not optional:
                        problems.append(status.message)
        except BaseException:
            for table in found.values():
                table.close()
            raise
        if problems:
            for table in found.values():
                table.close()
            raise RenderFailed(
                "%s needs current sampling tables: %s. Bake them (Material "
                "Properties > Hairis Sampling Tables > Bake) or enable Auto Bake"
                % ("the Table strategy" if settings.strategy == "TABLE"
                   else "Dual Scattering", "; ".join(problems)))
        return found

    def _auto_bake(self, library, material, fiber, settings, status):
        absorption = material.hair.varies_absorption
        cached = tables.cached_tables(library, fiber,
                                      need_multiple=settings.integrator == "DUAL_SCATTERING",
                                      refinement=settings.huang_f_refinement,
                                      absorption=absorption)
        if cached is not None:
            self.report({"INFO"}, "%s: using tables auto-baked earlier in this session"
                        % status.message)
            return cached
        self.update_stats("", "Baking sampling tables for %s" % material.name)
        options = tables.bake_options(library, n_h=int(settings.n_h), threads=settings.threads,
                                      multiple=settings.integrator == "DUAL_SCATTERING",
                                      refinement=settings.huang_f_refinement,
                                      absorption=absorption)
        baked = library.bake_tables(fiber, options, ProgressReporter(self))
        tables.write_cache(baked, fiber, settings.huang_f_refinement, absorption)
        self.report({"INFO"}, "%s: baked them for this render (Bake Sampling Tables stores them "
                    "with the .blend)" % status.message)
        return baked


register, unregister = bpy.utils.register_classes_factory((HairisRenderEngine,))
