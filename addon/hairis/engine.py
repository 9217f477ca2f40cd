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

import bpy
import numpy as np

from . import compat, export, native, tables

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
    """The C API's camera options from :class:`export.CameraData`."""
    return {"matrix": np.asarray(camera.camera_to_world, dtype=np.float64).reshape(-1),
            "orthographic": bool(camera.orthographic),
            "frame": np.asarray(camera.frame, dtype=np.float64).reshape(-1),
            "width": int(camera.width), "height": int(camera.height)}


def light_options(light):
    """The C API's light options from :class:`export.LightData`."""
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
    """The C API's render settings from ``scene.hairis``, and how the running Blender's
    Cycles traces curves (:func:`compat.curve_backfaces`) and limits transparent crossings
    (:func:`compat.transparent_limit`)."""
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
            "curve_backfaces": compat.curve_backfaces()}


def dual_scattering_warning(exact_bounces, bounce_limit="BOUNCES"):
    """What a render with Dual Scattering reports: its bias as the studies measured it."""
    text = ("Dual Scattering is experimental and biased (README, Dual scattering): with %d "
            "Exact Bounces" % exact_bounces)
    if exact_bounces >= 3:
        text += (" its mean is within about 5% of path tracing on the studies' hair, thin or "
                 "thick, straight or of varied directions: light straight hair (as on the "
                 "demo head) up to 5% darker, dense light hair of varied directions up to 5% "
                 "brighter")
    else:
        text += (", fewer than the default 3, its shading is flatter than path tracing's: "
                 "shaded regions brighter, lit ones darker (at 0, by 15-30% region by "
                 "region on the study's blonde hair)")
    if bounce_limit == "NONE":
        text += ("; Bounce Limit None adds every order of scattering, so light hair comes out "
                 "brighter than path tracing with the same Max Bounces (+14% on the demo "
                 "head's blonde at 8)")
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


def build_native_scene(library, data, hair_tables):
    """A ``native.Scene`` holding everything in ``data`` (SceneData).

    ``hair_tables`` maps a hair material's index in ``data.materials`` to its Tables (or
    lacks it: no tables). The caller closes the returned scene.
    """
    scene = library.scene()
    try:
        indices = []
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

        for i, material in enumerate(data.materials):
            if material.kind == "HAIR":
                try:
                    indices.append(scene.add_hair_material(material.hair.as_dict(),
                                                           hair_tables.get(i)))
                except native.HairisError as error:
                    raise RenderFailed("material %r: %s" % (material.name, error.message)) \
                        from error
            elif material.kind == "SURFACE":
                try:
                    indices.append(add_surface_nodes(scene, material.nodes, texture_index))
                except native.HairisError as error:
                    raise RenderFailed("material %r: %s" % (material.name, error.message)) \
                        from error
            else:
                indices.append(scene.add_diffuse_material(material.albedo, material.emission))
        remap = np.array(indices or [0], dtype=np.int32)
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
        for light in data.lights:
            scene.add_light(light_options(light))
        environment = data.world_environment
        if environment is None:
            scene.set_world(data.world_color, data.world_strength)
        elif environment.path is not None:
            scene.set_world_options(dict(environment.options(), image=environment.path))
        else:
            scene.set_world_pixels(environment.options(), environment.pixels)
        scene.set_camera(camera_options(data.camera))
    except BaseException:
        scene.close()
        raise
    return scene


class HairisRenderEngine(bpy.types.RenderEngine):
    """Hairis: a hair path tracer with importance-sampled fiber scattering."""

    bl_idname = "HAIRIS"
    bl_label = "Hairis"
    bl_use_preview = False
    bl_use_shading_nodes_custom = False
    bl_use_eevee_viewport = True

    def __init__(self, *args, **kwargs):
        # Blender 4.x+ passes arguments to RenderEngine subclasses; they must reach the base.
        super().__init__(*args, **kwargs)

    def render(self, depsgraph):
        """Renders one view layer of ``depsgraph`` into the Combined pass."""
        width, height = self.resolution_x, self.resolution_y
        result = self.begin_result(0, 0, width, height)
        try:
            pixels = None
            try:
                pixels = self._render(depsgraph, width, height)
            except native.HairisCancelled as cancelled:
                pixels = getattr(cancelled, "rgba", None)
                self.update_stats("", "Cancelled")
            except (RenderFailed, export.ExportError, tables.TableError,
                    native.HairisError) as error:
                self._fail(str(error))
            except Exception as error:  # noqa: BLE001 - Blender must keep running
                traceback.print_exc()
                self._fail("Hairis internal error: %s: %s (details in the console)"
                           % (type(error).__name__, error))
            if pixels is not None:
                try:
                    compat.set_pass_pixels(result.layers[0].passes["Combined"], pixels)
                except Exception as error:  # noqa: BLE001
                    self._fail("Hairis could not write the render result: %s" % error)
        finally:
            self.end_result(result)

    def _fail(self, message):
        self.report({"ERROR"}, message)
        try:
            self.error_set(message)
        except AttributeError:  # error_set is missing before Blender 2.9x
            pass
        self.update_stats("", "Error: " + message)

    def _render(self, depsgraph, width, height):
        problem = compat.version_problem()
        if problem:
            raise RenderFailed(problem)
        scene = depsgraph.scene
        settings = scene.hairis
        if scene.render.use_border:
            raise RenderFailed("Render Region is not supported by Hairis: disable Output "
                               "Properties > Format > Render Region")

        self.update_stats("", "Exporting scene")
        data = export.export_scene(depsgraph, self.camera_override)
        dump = os.environ.get(DUMP_ENV)
        if dump:
            data.save_npz(dump)
        for warning in data.warnings:
            self.report({"WARNING"}, warning)
        if (data.camera.width, data.camera.height) != (width, height):
            raise RenderFailed("render size %d×%d differs from the exported camera's %d×%d"
                               % (width, height, data.camera.width, data.camera.height))
        if self.test_break():
            return None

        library = native.load_library()
        hair_tables = self._resolve_tables(library, data, settings)
        if settings.integrator == "DUAL_SCATTERING":
            self.report({"WARNING"}, dual_scattering_warning(settings.dual_exact_bounces,
                                                             settings.dual_bounce_limit))
        try:
            with build_native_scene(library, data, hair_tables) as native_scene:
                self.update_stats("", "Rendering %d samples (%s%s)"
                                  % (settings.samples, settings.strategy.lower(),
                                     ", dual scattering"
                                     if settings.integrator == "DUAL_SCATTERING" else ""))
                rgba, stats = native_scene.render(render_settings(settings),
                                                  ProgressReporter(self))
        finally:
            for table in hair_tables.values():
                table.close()
        peak = stats.peak_memory_bytes / (1024.0 * 1024.0)
        self.update_memory_stats(memory_used=peak, memory_peak=peak)
        self.update_stats("", "Rendered in %.2f s" % stats.seconds)
        if stats.dropped_samples:
            self.report({"WARNING"}, "%d samples with NaN or infinite values were dropped"
                        % stats.dropped_samples)
        return rgba

    def _resolve_tables(self, library, data, settings):
        """Tables per hair material index: current ones, auto-baked ones, or an error.

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
                if (material.hair.model == "HUANG" and settings.huang_sampling == "CYCLES"
                        and settings.integrator != "DUAL_SCATTERING"):
                    continue  # Cycles' own Huang sampler needs no tables (Dual Scattering does)
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
                            need_multiple=settings.integrator == "DUAL_SCATTERING")
                    else:
                        status = tables.TableStatus("MISSING", "material %r has no sampling "
                                                    "tables" % material.name)
                    if status.ok:
                        found[index] = status.tables
                    elif settings.auto_bake:
                        try:
                            found[index] = self._auto_bake(library, material, fiber, settings,
                                                           status)
                        except native.HairisCancelled:
                            raise
                        except native.HairisError as error:
                            raise RenderFailed("material %r: %s" % (material.name, error.message)) \
                                from error
                    else:
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
        cached = tables.cached_tables(library, fiber,
                                      need_multiple=settings.integrator == "DUAL_SCATTERING")
        if cached is not None:
            self.report({"INFO"}, "%s: using tables auto-baked earlier in this session"
                        % status.message)
            return cached
        self.update_stats("", "Baking sampling tables for %s" % material.name)
        options = tables.bake_options(library, n_h=int(settings.n_h), threads=settings.threads)
        baked = library.bake_tables(fiber, options, ProgressReporter(self))
        tables.write_cache(baked, fiber)
        self.report({"INFO"}, "%s: baked them for this render (Bake Sampling Tables stores them "
                    "with the .blend)" % status.message)
        return baked


register, unregister = bpy.utils.register_classes_factory((HairisRenderEngine,))
