"""Helpers for screenshots of Blender's UI (scripts/screenshot_panel.py, screenshot_table.py).

Blender runs these scripts in a real window (under xvfb-run, not in background mode). The work
is cut into steps run one per timer tick, so that the UI draws in between: a step changes what
an editor shows, the next one screenshots it.
"""
import os
import traceback

import bpy
import numpy as np


class Steps:
    """Functions run one per timer tick, in the order added; any failure exits with code 1."""

    def __init__(self, program, delay=1.5):
        self.program = program  # names the script in messages
        self.delay = delay  # seconds between steps, so Blender redraws in between
        self.queue = []

    def add(self, function):
        """Appends ``function`` (also while the steps run); usable as a decorator."""
        self.queue.append(function)
        return function

    def fail(self, message):
        """Prints and quits with exit code 1."""
        print("%s: ERROR: %s" % (self.program, message), flush=True)
        os._exit(1)

    def start(self):
        """Runs the steps from a timer, the first one ``delay`` after Blender's start."""
        bpy.context.preferences.view.show_splash = False
        bpy.app.timers.register(self._run_next, first_interval=self.delay, persistent=True)

    def _run_next(self):
        try:
            self.queue.pop(0)()
        except Exception:  # noqa: BLE001 - any failure ends Blender with exit code 1
            traceback.print_exc()
            self.fail("a step failed")
        return self.delay if self.queue else None


def window_and_screen():
    """The (only) window and its screen."""
    window = bpy.context.window_manager.windows[0]
    return window, window.screen


def main_region(area):
    """The WINDOW region of an area."""
    return next(r for r in area.regions if r.type == "WINDOW")


def largest_area(area_type=None):
    """The largest area of the layout, of ``area_type`` ('PROPERTIES', ...) when given."""
    _, screen = window_and_screen()
    areas = [a for a in screen.areas if area_type is None or a.type == area_type]
    if not areas:
        raise RuntimeError("no %s editor in the layout" % area_type)
    return max(areas, key=lambda a: a.width * a.height)


def maximise(area, hide_panels=False):
    """Maximises ``area`` to the whole window; ``hide_panels`` also hides its header and bars.

    The window's size (``blender -p``) sets the editor's. (Dragging area edges with
    screen.area_move needs the mouse outside every region, which Xvfb does not promise.)
    """
    window, screen = window_and_screen()
    with bpy.context.temp_override(window=window, screen=screen, area=area):
        result = bpy.ops.screen.screen_full_area(use_hide_panels=hide_panels)
    if result != {"FINISHED"}:
        raise RuntimeError("could not maximise the %s editor: %s" % (area.type, result))


def screenshot(area, path):
    """Screenshots ``area`` to ``path`` (full size); returns its RGBA pixels, bottom row first."""
    window, screen = window_and_screen()
    with bpy.context.temp_override(window=window, screen=screen, area=area,
                                   region=main_region(area)):
        result = bpy.ops.screen.screenshot_area(filepath=path, check_existing=False)
    if result != {"FINISHED"} or not os.path.isfile(path):
        raise RuntimeError("screenshot_area did not write %s (%s)" % (path, result))
    image = bpy.data.images.load(path, check_existing=False)
    width, height = image.size
    pixels = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)


def save_png(pixels, path, program):
    """Writes RGBA ``pixels`` (bottom row first, as ``screenshot`` returns them) as a PNG.

    A byte image stores the screenshot's sRGB values as they are (``Image.save``, unlike
    ``save_render``, applies no view transform).
    """
    rows, width = pixels.shape[:2]
    image = bpy.data.images.new(os.path.basename(path), width, rows, alpha=False)
    image.pixels.foreach_set(np.ascontiguousarray(pixels, dtype=np.float32).reshape(-1))
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)
    print("%s: wrote %s (%dx%d, %d bytes)" % (program, path, width, rows, os.path.getsize(path)),
          flush=True)
