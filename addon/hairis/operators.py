"""Operators: ``hairis.bake_tables`` bakes the sampling tables of hair materials.

``execute`` bakes synchronously (scripts, background mode) with the window manager's progress
indicator. ``invoke`` (a click in the UI) runs the same bakes in a worker thread — the C bake
releases the GIL — and stays modal: a timer updates the progress, Esc cancels through the
bake's progress callback, and the images are stored on the main thread as each bake finishes.
"""

import os
import queue
import threading
from dataclasses import dataclass

import bpy
from bpy.props import BoolProperty, StringProperty

from . import compat, native, tables


@dataclass
class BakeJob:
    """One material to bake: everything the worker needs, copied off ``bpy.data``."""

    material_name: str
    node: object
    path: str
    stored_path: str
    blend_saved: bool
    absorption: bool = False
    """The material's Huang absorption varies per strand: bake the absorption part too."""


def collect_jobs(library, material_name="", force=False, refinement=1):
    """(jobs, messages): hair materials whose tables are missing or stale (all if ``force``).

    Messages are (level, text) pairs for materials skipped or refused.
    """
    messages = []
    if material_name:
        material = bpy.data.materials.get(material_name)
        if material is None:
            return [], [("ERROR", "no material named %r" % material_name)]
        candidates = [material]
    else:
        candidates = tables.hair_materials()
    jobs = []
    for material in candidates:
        if material.library is not None:
            messages.append(("WARNING", "material %r is linked from a library; bake it there"
                             % material.name))
            continue
        try:
            params = tables.material_parameters(material)
        except tables.TableError as error:
            messages.append(("ERROR", str(error)))
            continue
        node = tables.principled_struct(library, params)
        if not force:
            try:
                with library.fiber_principled(node) as fiber:
                    status = tables.check_material(library, material, fiber,
                                                   refinement=refinement,
                                                   absorption=params.varies_absorption)
            except native.HairisError as error:
                messages.append(("ERROR", "material %r: %s" % (material.name, error)))
                continue
            if status.tables is not None:
                status.tables.close()
            if status.ok:
                continue
        path, stored, saved = tables.output_path(material)
        jobs.append(BakeJob(material.name, node, path, stored, saved, params.varies_absorption))
    return jobs, messages


def run_job(library, job, options, progress=None):
    """Bakes and writes one job's tables (no ``bpy``: safe in a worker thread).

    Returns (parameters, model, Huang f refinement or 0) of the written tables.
    """
    if job.absorption and "huang_absorption" in library.bake_options_defaults():
        options = dict(options, huang_absorption=1)
    with library.fiber_principled(job.node) as fiber:
        with library.bake_tables(fiber, options, progress) as baked:
            folder = os.path.dirname(job.path)
            if folder:
                os.makedirs(folder, exist_ok=True)
            baked.write(job.path)
            return baked.parameters, baked.model, int(baked.info.get("huang_f_refinement", 0))


def finish_job(operator, job, parameters, model, refinement=0):
    """Stores a finished job's file as the material's table image (main thread)."""
    material = bpy.data.materials.get(job.material_name)
    if material is None:
        operator.report({"WARNING"}, "material %r was removed during the bake" % job.material_name)
        return
    tables.store_image(material, job.path, job.stored_path, not job.blend_saved, parameters,
                       model, refinement, job.absorption)
    if not job.blend_saved:
        operator.report({"WARNING"}, "the .blend is not saved: tables of %r were written to %s and "
                        "packed into the file; save the .blend and bake again to keep them next "
                        "to it" % (job.material_name, job.path))


class HAIRIS_OT_bake_tables(bpy.types.Operator):
    """Bake hairis sampling tables for hair materials whose tables are missing or stale"""

    bl_idname = "hairis.bake_tables"
    bl_label = "Bake Sampling Tables"
    bl_options = {"REGISTER"}

    material: StringProperty(
        name="Material", description="Bake only this material (empty: every hair material)",
        default="")
    force: BoolProperty(
        name="Force", description="Bake even when the tables are current", default=False)

    def _prepare(self, context):
        """(library, jobs, bake options), or the operator's result ({'CANCELLED'} or
        {'FINISHED'}) when it stops before baking."""
        problem = compat.version_problem()
        if problem:
            self.report({"ERROR"}, problem)
            return {"CANCELLED"}
        try:
            library = native.load_library()
        except native.LibraryUnavailable as error:
            self.report({"ERROR"}, str(error))
            return {"CANCELLED"}
        settings = context.scene.hairis
        jobs, messages = collect_jobs(library, self.material, self.force,
                                      settings.huang_f_refinement)
        for level, text in messages:
            self.report({level}, text)
        if any(level == "ERROR" for level, _ in messages) and not jobs:
            return {"CANCELLED"}
        if not jobs:
            self.report({"INFO"}, "sampling tables are current")
            return {"FINISHED"}
        options = tables.bake_options(library, n_h=int(settings.n_h), threads=settings.threads,
                                      refinement=settings.huang_f_refinement)
        return library, jobs, options

    def execute(self, context):
        """Bakes synchronously, with the window manager's progress indicator."""
        prepared = self._prepare(context)
        if isinstance(prepared, set):
            return prepared
        library, jobs, options = prepared
        wm = context.window_manager
        wm.progress_begin(0.0, float(len(jobs)))
        failed = 0
        try:
            for number, job in enumerate(jobs):
                def progress(value, number=number):
                    wm.progress_update(number + value)
                    return False
                try:
                    baked = run_job(library, job, options, progress)
                except native.HairisError as error:
                    failed += 1
                    self.report({"ERROR"}, "material %r: %s" % (job.material_name, error))
                    continue
                finish_job(self, job, *baked)
        finally:
            wm.progress_end()
        if failed:
            return {"CANCELLED"} if failed == len(jobs) else {"FINISHED"}
        self.report({"INFO"}, "baked sampling tables for %d material%s"
                    % (len(jobs), "" if len(jobs) == 1 else "s"))
        return {"FINISHED"}

    def invoke(self, context, event):
        """Bakes in a worker thread while staying modal (Esc cancels)."""
        if context.window is None or bpy.app.background:
            return self.execute(context)
        prepared = self._prepare(context)
        if isinstance(prepared, set):
            return prepared
        library, jobs, options = prepared
        self._jobs = jobs
        self._results = queue.Queue()
        self._cancel = threading.Event()
        self._progress = [0, 0.0]
        self._done = 0
        self._failed = 0
        self._thread = threading.Thread(target=self._work, args=(library, jobs, options),
                                        name="hairis-bake", daemon=True)
        wm = context.window_manager
        wm.progress_begin(0.0, float(len(jobs)))
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        self._thread.start()
        self.report({"INFO"}, "baking sampling tables for %d material%s (Esc cancels)"
                    % (len(jobs), "" if len(jobs) == 1 else "s"))
        return {"RUNNING_MODAL"}

    def _work(self, library, jobs, options):
        for number, job in enumerate(jobs):
            if self._cancel.is_set():
                break

            def progress(value, number=number):
                self._progress[:] = [number, value]
                return self._cancel.is_set()
            try:
                payload = run_job(library, job, options, progress)
            except native.HairisCancelled:
                self._results.put(("CANCELLED", job, None))
                break
            except native.HairisError as error:
                self._results.put(("ERROR", job, str(error)))
                continue
            except Exception as error:  # noqa: BLE001 - reported on the main thread
                self._results.put(("ERROR", job, "%s: %s" % (type(error).__name__, error)))
                continue
            self._results.put(("DONE", job, payload))
        self._results.put(("END", None, None))

    def modal(self, context, event):
        """Drains finished bakes, updates the progress, cancels on Esc."""
        if event.type == "ESC":
            self._cancel.set()
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        wm = context.window_manager
        number, value = self._progress
        wm.progress_update(number + value)
        while True:
            try:
                kind, job, payload = self._results.get_nowait()
            except queue.Empty:
                return {"RUNNING_MODAL"}
            if kind == "DONE":
                self._done += 1
                finish_job(self, job, *payload)
            elif kind == "ERROR":
                self._failed += 1
                self.report({"ERROR"}, "material %r: %s" % (job.material_name, payload))
            elif kind == "CANCELLED":
                self.report({"WARNING"}, "bake cancelled")
            elif kind == "END":
                return self._finish(context)

    def _finish(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        self._thread.join()
        for area in context.screen.areas if context.screen else ():
            area.tag_redraw()
        if self._done:
            self.report({"INFO"}, "baked sampling tables for %d material%s"
                        % (self._done, "" if self._done == 1 else "s"))
        return {"FINISHED"} if self._done else {"CANCELLED"}


classes = (HAIRIS_OT_bake_tables,)


register, unregister = bpy.utils.register_classes_factory(classes)
