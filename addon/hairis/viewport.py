"""Rendered shading in the 3D viewport: a worker thread refines the view, the main thread
draws the latest image.

Blender's main thread must never wait for a render, so :class:`ViewportRender` owns one worker
thread and the native scene, and takes requests: a new scene (:meth:`ViewportRender.set_scene`,
from ``view_update`` after a depsgraph change: the scene is exported on the main thread, which
alone may read Blender's data, and built on the worker) or a new view
(:meth:`ViewportRender.set_view`, from ``view_draw`` when the view matrix or the region size
changed: only the camera changes). A request makes the running render's update callback
return non-zero, and the worker starts again with the newest request: a quick low-resolution
pass, then the full resolution refined up to Viewport Samples. Every update copies the image
for ``view_draw`` and asks Blender to redraw. Tables that must be baked are baked on the worker,
never on the drawing thread. :meth:`ViewportRender.stop` cancels and joins the thread: the
engine calls it when the view closes, and an ``atexit`` hook when Blender quits.
"""

import atexit
import threading
import time
import traceback
import weakref

import numpy as np

from . import native

UNLIMITED_SAMPLES = 1 << 24
"""What Viewport Samples 0 (unlimited) renders."""

PREVIEW_DIVIDER = 4
"""The first pass renders at 1/PREVIEW_DIVIDER of the view's resolution, for prompt pixels."""

_LIVE = weakref.WeakSet()
"""Every running ViewportRender, so that quitting Blender stops their threads."""


class SceneJob:
    """What the worker needs to build the native scene: the exported data, the tables found on
    the main thread and the bakes left to do (``bakes``: (material index, fiber values,
    bake options, cache path) each). ``geometry`` names the geometry ``data`` holds: a job
    whose geometry is the built scene's only gives that scene new materials, lights and world
    (its BVH stays); a new object (the default) means new geometry."""

    def __init__(self, data, hair_tables=None, bakes=(), build=None, geometry=None):
        self.data = data
        self.hair_tables = dict(hair_tables or {})
        self.bakes = list(bakes)
        self.build = build
        self.geometry = geometry if geometry is not None else object()

    def close(self):
        """Releases the tables this job holds."""
        for table in self.hair_tables.values():
            table.close()
        self.hair_tables.clear()


class ViewRequest:
    """A view to render: camera options (without width and height), the region's size in
    pixels and the render settings."""

    def __init__(self, camera, width, height, settings, samples):
        self.camera = camera
        self.width = max(int(width), 1)
        self.height = max(int(height), 1)
        self.settings = dict(settings)
        self.samples = int(samples) if samples > 0 else UNLIMITED_SAMPLES


class Frame:
    """An image the worker finished: rgba (height, width, 4) bottom row first, its samples,
    and ``serial``, which grows with every new image."""

    def __init__(self, rgba, samples, serial, generation):
        self.rgba = rgba
        self.samples = samples
        self.serial = serial
        self.generation = generation


class ViewportRender:
    """The viewport's worker thread (see the module's docstring).

    ``library`` is the loaded :class:`native.Library`; ``redraw()`` is called from the worker
    after each new image (the engine's ``tag_redraw``); ``clock`` times the first pixels.
    """

    def __init__(self, library, redraw=None, clock=time.monotonic):
        self.library = library
        self.redraw = redraw or (lambda: None)
        self.clock = clock
        self._condition = threading.Condition()
        self._scene_job = None
        self._view = None
        self._generation = 0
        self._stopping = False
        self.frame = None
        self._serial = 0
        self.error = None
        self.status = ""
        self.renders = 0
        """Progressive renders started (each restart is one more)."""
        self.scene_builds = 0
        """Native scenes built (a view change builds none)."""
        self.scene_reshades = 0
        """Built scenes given new materials, lights and world (their BVH kept)."""
        self.requested_at = None
        self.first_pixels_seconds = None
        """Seconds from the latest request to its first image."""
        self.started_at = clock()
        self.first_image_seconds = None
        """Seconds from this object's start (the viewport's) to its very first image."""
        self._thread = threading.Thread(target=self._run, name="hairis-viewport", daemon=True)
        _LIVE.add(self)
        self._thread.start()

    # -- requests (main thread) --

    def set_scene(self, job):
        """Renders a new scene (a :class:`SceneJob`) from now on."""
        with self._condition:
            if self._scene_job is not None and self._scene_job is not job:
                self._scene_job.close()
            self._scene_job = job
            self._request()

    def set_view(self, view):
        """Renders a new view (a :class:`ViewRequest`) from now on."""
        with self._condition:
            self._view = view
            self._request()

    def _request(self):
        self._generation += 1
        self.requested_at = self.clock()
        self.first_pixels_seconds = None
        self.error = None
        self._condition.notify_all()

    @property
    def alive(self):
        """True while the worker thread runs."""
        return self._thread.is_alive()

    def stop(self, timeout=None):
        """Cancels the render and joins the worker (idempotent)."""
        with self._condition:
            self._stopping = True
            self._condition.notify_all()
        if self._thread is not threading.current_thread():
            self._thread.join(timeout)
        _LIVE.discard(self)

    # -- the worker --

    def _cancelled(self, generation):
        return self._stopping or self._generation != generation

    def _next(self, done):
        """Waits for a request newer than ``done``; None when stopping."""
        with self._condition:
            while not self._stopping and (self._generation == done or self._view is None
                                          or self._scene_job is None):
                self._condition.wait()
            if self._stopping:
                return None
            return self._generation, self._scene_job, self._view

    def _run(self):
        scene, built, done = None, None, 0
        try:
            while True:
                request = self._next(done)
                if request is None:
                    return
                generation, job, view = request
                try:
                    if job is not built:
                        if scene is not None and built is not None and \
                                job.geometry is built.geometry:
                            built = None
                            self._reshade(scene, job, generation)
                        else:
                            if scene is not None:
                                scene.close()
                                scene = None
                            built = None
                            scene = self._build(job, generation)
                        built = job
                    self._render(scene, view, generation)
                except native.HairisCancelled:
                    pass
                except Exception as error:  # noqa: BLE001 - reported in the viewport
                    traceback.print_exc()
                    self.error = str(error)
                    self.redraw()
                done = generation
        finally:
            if scene is not None:
                scene.close()

    def _build(self, job, generation):
        """Bakes what the job still needs and builds its native scene (on the worker)."""
        from . import engine  # the engine module imports this one

        self._bake(job, generation)
        self.status = "Building scene"
        build = job.build or engine.build_native_scene
        scene = build(self.library, job.data, job.hair_tables)
        self.scene_builds += 1
        return scene

    def _reshade(self, scene, job, generation):
        """Bakes what the job still needs and gives the built scene its materials, lights and
        world (on the worker)."""
        from . import engine  # the engine module imports this one

        self._bake(job, generation)
        engine.reshade_native_scene(scene, job.data, job.hair_tables)
        self.scene_reshades += 1

    def _bake(self, job, generation):
        """Bakes the tables the job still needs, writing each to its cache path."""
        for index, fiber_values, bake_options, cache_path in job.bakes:
            if index in job.hair_tables:
                continue
            self.status = "Baking sampling tables"
            self.redraw()
            with self.library.fiber_principled(fiber_values) as fiber:
                baked = self.library.bake_tables(
                    fiber, bake_options, lambda _p: self._cancelled(generation))
            try:
                baked.write(cache_path)
            except native.HairisError:
                pass  # only the next viewport start bakes again
            job.hair_tables[index] = baked

    def _render(self, scene, view, generation):
        """A low-resolution pass, then the full resolution up to the view's samples."""
        passes = []
        if PREVIEW_DIVIDER > 1 and view.samples > 1:
            passes.append((max(view.width // PREVIEW_DIVIDER, 1),
                           max(view.height // PREVIEW_DIVIDER, 1), 1))
        passes.append((view.width, view.height, view.samples))
        for width, height, samples in passes:
            if self._cancelled(generation):
                return
            scene.set_camera(dict(view.camera, width=width, height=height))
            settings = dict(view.settings, samples=samples)
            self.renders += 1
            self.status = "Rendering"
            scene.render_progressive(settings, self._updater(generation, samples))

    def _updater(self, generation, total):
        state = {"shown": 0}

        def update(_progress, samples_done, final, rgba, _passes):
            if self._cancelled(generation):
                return True
            if samples_done > state["shown"]:
                state["shown"] = samples_done
                with self._condition:
                    self._serial += 1
                    self.frame = Frame(rgba.copy(), samples_done, self._serial, generation)
                    now = self.clock()
                    if self.first_pixels_seconds is None and self.requested_at is not None:
                        self.first_pixels_seconds = now - self.requested_at
                    if self.first_image_seconds is None:
                        self.first_image_seconds = now - self.started_at
                self.status = "Sample %d/%d" % (samples_done, total)
                self.redraw()
            return self._cancelled(generation)

        return update


def stop_all():
    """Stops every viewport render (Blender is quitting)."""
    for render in list(_LIVE):
        render.stop(timeout=10.0)


atexit.register(stop_all)


# ---- The view as a camera ---------------------------------------------------------------------

def view_camera(view_matrix, window_matrix, is_perspective):
    """The C API's camera options (without width and height) of a 3D view: camera-to-world
    is the inverse view matrix, the frame the projection's corners at z = -1."""
    to_world = np.linalg.inv(np.asarray(view_matrix, np.float64).reshape(4, 4))
    projection = np.asarray(window_matrix, np.float64).reshape(4, 4)
    corners = ((1.0, 1.0), (1.0, -1.0), (-1.0, -1.0), (-1.0, 1.0))
    frame = []
    for x, y in corners:
        if is_perspective:
            # x_ndc = (P00 x + P02 z) / -z at z = -1.
            frame.append(((x + projection[0, 2]) / projection[0, 0],
                          (y + projection[1, 2]) / projection[1, 1], -1.0))
        else:
            frame.append(((x - projection[0, 3]) / projection[0, 0],
                          (y - projection[1, 3]) / projection[1, 1], -1.0))
    return {"matrix": to_world.reshape(-1), "orthographic": not is_perspective,
            "frame": np.asarray(frame, np.float64).reshape(-1)}


# ---- Drawing (main thread) --------------------------------------------------------------------

class Display:
    """The latest frame as a GPU texture, drawn over the whole region."""

    def __init__(self):
        self.texture = None
        self.serial = None
        self.shader = None

    def _image_shader(self):
        import gpu

        if self.shader is None:
            for name in ("IMAGE", "2D_IMAGE"):  # renamed in Blender 4.0
                try:
                    self.shader = gpu.shader.from_builtin(name)
                    break
                except ValueError:
                    continue
        return self.shader

    def upload(self, frame):
        """Makes ``frame`` the texture (16-bit floats, so values beyond their range are
        clamped)."""
        import gpu

        if frame is None or frame.serial == self.serial:
            return
        height, width = frame.rgba.shape[:2]
        pixels = np.clip(frame.rgba, -65000.0, 65000.0).reshape(-1)
        buffer = gpu.types.Buffer("FLOAT", pixels.size, pixels)
        self.texture = gpu.types.GPUTexture((width, height), format="RGBA16F", data=buffer)
        self.serial = frame.serial

    def draw(self, engine, scene, width, height):
        """Draws the texture over the region (``width`` × ``height`` pixels)."""
        import gpu
        from gpu_extras.batch import batch_for_shader

        if self.texture is None:
            return
        shader = self._image_shader()
        batch = batch_for_shader(shader, "TRI_FAN", {
            "pos": ((0, 0), (width, 0), (width, height), (0, height)),
            "texCoord": ((0, 0), (1, 0), (1, 1), (0, 1))})
        gpu.state.blend_set("ALPHA_PREMULT")
        engine.bind_display_space_shader(scene)
        shader.bind()
        shader.uniform_sampler("image", self.texture)
        batch.draw(shader)
        engine.unbind_display_space_shader()
        gpu.state.blend_set("NONE")
