"""Screenshots of a sampling-table file in Blender's Image Editor, for the README.

Run by scripts/screenshot_table (under xvfb-run, with a clean environment) as
    blender --factory-startup -p 0 0 640 960 --python-exit-code 1 \
        --python scripts/screenshot_table.py -- --table T.exr --inspect INSPECT.txt \
        --parts far,near --workdir <tmp> --output docs
where INSPECT.txt is what `hairis-bake inspect T.exr` printed and --parts the file's
hairis:parts attribute. NOT in background mode: it needs the window, whose size (-p) is the
Image Editor's. From timers, so that the UI draws in between, it loads the table as an image the
way the add-on does (float, Non-Color, alpha Channel Packed), shows it in an Image Editor
maximised to the whole window (no header or bars), screenshots it after View All (fit), writes
<output>/table_overview.png, then for every part: zooms and pans the editor onto a slice of the
part's rows (the row ranges of the inspect output's "parts:" lines), shows one channel, and
writes the slice's rectangle of the screenshot to <output>/table_<part>_<what>.png. Any failure
exits with code 1.

A slice shows one channel (the editor's Display Channels) with the image's View as Render on
(without it the editor ignores the scene's view transform and exposure) and the Standard view
transform, with the exposure that shows the slice's largest value of that channel as white;
Filmic Log instead for values spanning many orders of magnitude, or levels (Use Curves' black
and white levels at the slice's smallest and largest value) for values that differ little.
A channel that is constant over its slice is reported and not pictured. Zoomed by a whole
factor, each texel is a block of screen pixels; a picture leaves out one pixel on every side,
where Blender 3.4 may draw a neighbouring texel or the line that frames the image. Parts
without a layout below get a generic view: their first rows (as many as the image is wide) in
R, G, B and A.
"""
import argparse
import math
import os
import re
import sys
from collections import namedtuple

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from screenshot_ui import (Steps, largest_area, main_region, maximise,  # noqa: E402
                           save_png, screenshot, window_and_screen)

PROGRAM = "screenshot_table"
STEPS = Steps(PROGRAM)
MAX_SIDE = 512  # screen pixels: a slice is zoomed by a whole factor to at most this, or the view
OVERVIEW_MARGIN = 16  # screen pixels of the editor's background around the overview's image
CHANNELS = {"RED": 0, "GREEN": 1, "BLUE": 2, "ALPHA": 3}
LOBES = 4  # near part: R, TT, TRT, TRRT+ rows per θ_o node
FAR_THETA_R_DEG = 30.0  # far part: the θ_r node pictured is the one nearest this
NEAR_RUN = 24  # near part: how many θ_o nodes are pictured, from the one nearest 0°

Part = namedtuple("Part", "name first end description")  # image rows first..end-1, from the top
# rows, columns: (first, end); view: how values become greys (VIEWS)
Shot = namedtuple("Shot", "part what rows columns channel view caption")
# The view transform, and log2 of the value it shows as white: Standard 1; Filmic Log's log2
# allocation [-12.47, 12.53] stretched by 1/0.66 (Blender 3.4's config.ocio) ends at
# -12.47 + 0.66 * 25. "Levels": Standard, the slice's smallest value black (Use Curves' black
# level), its largest white (white level), for values that differ little.
VIEWS = {"Standard": ("Standard", 0.0), "Filmic Log": ("Filmic Log", -12.473931188 + 0.66 * 25.0),
         "Levels": ("Standard", None)}


def parse_args():
    """The arguments after ``--``."""
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    parser = argparse.ArgumentParser()
    parser.add_argument("--table", required=True, help="the table file (EXR)")
    parser.add_argument("--inspect", required=True, help="hairis-bake inspect's output for it")
    parser.add_argument("--parts", required=True, help="the file's hairis:parts attribute")
    parser.add_argument("--workdir", required=True, help="temporary folder (screenshots)")
    parser.add_argument("--output", required=True, help="folder for the PNGs")
    parser.add_argument("--keep", default="", help="folder to keep the uncropped screenshots in")
    return parser.parse_args(argv)


ARGS = parse_args()


def read_inspect(path, names):
    """The parts ``names`` lists, with the rows the inspect output gives them, and the image size.

    The inspect output lists the parts under "parts:" as lines "  NAME rows FIRST-LAST: ...".
    """
    with open(path, encoding="utf-8") as file:
        text = file.read()
    rows = {m.group(1): Part(m.group(1), int(m.group(2)), int(m.group(3)) + 1, m.group(4))
            for m in re.finditer(r"^ {2}(\S+) +rows (\d+)-(\d+): (.*)$", text, re.MULTILINE)}
    size = re.search(r"^image: +(\d+) x (\d+) ", text, re.MULTILINE)
    if size is None:
        raise RuntimeError("no 'image: W x H' line in %s" % path)
    missing = [name for name in names if name not in rows]
    if missing:
        raise RuntimeError("hairis:parts lists %s but the inspect output gives no rows for %s"
                           % (",".join(names), ", ".join(missing)))
    return [rows[name] for name in names], (int(size.group(1)), int(size.group(2)))


def counts(part, pattern, fields):
    """The integers (or floats) ``pattern`` finds in the part's inspect description."""
    match = re.search(pattern, part.description)
    if match is None:
        raise RuntimeError("the %s part's description (%r) does not read %r: its layout changed?"
                           % (part.name, part.description, pattern))
    return [kind(match.group(i + 1)) for i, kind in enumerate(fields)]


def far_shots(part, pixels):
    """One θ_r node of the far part (θ_i rows, φ columns) in R and in G."""
    n_r, n_i, n_phi = counts(part, r"(\d+) theta_r nodes x (\d+) theta_i cells, (\d+) phi cells",
                             (int, int, int))
    if part.end - part.first != n_r * n_i:
        raise RuntimeError("far: %d rows for %d x %d" % (part.end - part.first, n_r, n_i))
    centres = [-90.0 + (r + 0.5) * 180.0 / n_r for r in range(n_r)]  # cell centres
    node = min(range(n_r), key=lambda r: abs(centres[r] - FAR_THETA_R_DEG))
    rows = (part.first + node * n_i, part.first + (node + 1) * n_i)
    where = "θ_r node %d (%.1f°), rows %d-%d, columns 0-%d" % (
        node, centres[node], rows[0], rows[1] - 1, n_phi - 1)
    return [Shot("far", "direct", rows, (0, n_phi), "RED", "Standard",
                 where + ": R, the direct distribution"),
            Shot("far", "multiple", rows, (0, n_phi), "GREEN", "Filmic Log",
                 where + ": G, the multiple-scattering distribution, one band per n_h")]


def near_shots(part, pixels):
    """A run of θ_o nodes of the near part (4 lobe rows each, θ_i columns) in R, G, B and A."""
    nodes, low, high, n_i = counts(
        part, r"(\d+) theta_o nodes \(([-\d.]+) \.\. ([-\d.]+) deg\) x 4 lobes, "
        r"(\d+) theta_i cells", (int, float, float, int))
    if part.end - part.first != nodes * LOBES:
        raise RuntimeError("near: %d rows for %d nodes" % (part.end - part.first, nodes))
    angle = [low + k * (high - low) / max(1, nodes - 1) for k in range(nodes)]
    run = min(NEAR_RUN, nodes)
    first = min(min(range(nodes), key=lambda k: abs(angle[k])), nodes - run)
    rows = (part.first + first * LOBES, part.first + (first + run) * LOBES)
    where = "θ_o nodes %d-%d (%.1f° to %.1f°), rows %d-%d, columns 0-%d" % (
        first, first + run - 1, angle[first], angle[first + run - 1], rows[0], rows[1] - 1, n_i)
    columns = (0, n_i + 1)
    return [Shot("near", "mass", rows, columns, "RED", "Standard", where + ": R, the cell masses"),
            Shot("near", "edge", rows, columns, "GREEN", "Standard",
                 where + ": G, M_p at the cell edges"),
            Shot("near", "integral", rows, columns, "BLUE", "Levels",
                 where + ": B, the lobe integrals"),
            Shot("near", "cone", rows, columns, "ALPHA", "Standard", where + ": A, the cone flags")]


def generic_shots(part, pixels):
    """The part's first rows, as many as the image is wide, up to its last non-zero column."""
    used = np.nonzero(np.abs(pixels[part.first:part.end]).max(axis=(0, 2)) > 0)[0]
    columns = (0, int(used[-1]) + 1 if used.size else pixels.shape[1])
    rows = (part.first, min(part.end, part.first + pixels.shape[1]))
    where = "%s, rows %d-%d, columns 0-%d" % (part.name, rows[0], rows[1] - 1, columns[1] - 1)
    return [Shot(part.name, channel.lower(), rows, columns, channel, "Standard",
                 where + ": " + channel) for channel in CHANNELS]


SHOTS = {"far": far_shots, "near": near_shots}  # how each known part is pictured


# ---- The Image Editor -----------------------------------------------------------------------

def editor():
    """The Image Editor (the layout's largest area, made one in the first step)."""
    return largest_area("IMAGE_EDITOR")


def run_op(operator, **properties):
    """Runs an image-editor operator in the editor's main region."""
    area = editor()
    window, screen = window_and_screen()
    with bpy.context.temp_override(window=window, screen=screen, area=area,
                                   region=main_region(area)):
        result = operator(**properties)
    if result != {"FINISHED"}:
        raise RuntimeError("%s did not finish: %s" % (operator.idname_py(), result))


def to_screen(column, row):
    """Where the image's pixel corner (column, row from the top) is in the editor's screenshot."""
    area = editor()
    region = main_region(area)
    image = area.spaces.active.image
    width, height = image.size
    x, y = region.view2d.view_to_region(column / width, 1.0 - row / height, clip=False)
    return x + region.x - area.x, y + region.y - area.y


def frame(shot):
    """Zooms by a whole factor (when the slice fits) and pans so ``shot``'s slice is centred."""
    region = main_region(editor())
    image = editor().spaces.active.image
    width, height = image.size
    columns = shot.columns[1] - shot.columns[0]
    rows = shot.rows[1] - shot.rows[0]
    fit = min(region.width / columns, region.height / rows)
    zoom = max(1, math.floor(min(fit, MAX_SIDE / max(columns, rows)))) if fit >= 1 else fit
    run_op(bpy.ops.image.view_all, fit_view=False)  # centres the image (no pan)
    run_op(bpy.ops.image.view_zoom_ratio, ratio=zoom)
    # The slice's centre (image pixels from the bottom left) on a whole screen pixel, so that
    # texel edges fall between screen pixels (up to Blender 3.4's drawing; see save_slice).
    centre_x = round(zoom * (shot.columns[0] + shot.columns[1]) / 2) / zoom
    centre_y = round(zoom * (height - (shot.rows[0] + shot.rows[1]) / 2)) / zoom
    run_op(bpy.ops.image.view_pan, offset=(centre_x - width / 2, centre_y - height / 2))
    return zoom


def show(channel, view=None, exposure=0.0, levels=None):
    """Shows one channel (or 'COLOR_ALPHA'); no ``view`` keeps the image as loaded.

    ``levels`` (black, white), when given, are the view's curve mapping's black and white levels.

    The editor applies the scene's view transform and exposure to an image only when its View
    as Render is on; otherwise it shows the values with the display's sRGB curve.
    """
    area = editor()
    space = area.spaces.active
    space.image.use_view_as_render = view is not None
    if view is not None:
        settings = bpy.context.scene.view_settings
        settings.view_transform = view
        settings.look = "None"
        settings.gamma = 1.0
        settings.exposure = exposure
        settings.use_curve_mapping = levels is not None
        if levels is not None:
            settings.curve_mapping.black_level = (levels[0],) * 3
            settings.curve_mapping.white_level = (levels[1],) * 3
            settings.curve_mapping.update()
        # No dither noise (invisible, but it would blur the texel blocks and bloat the PNGs).
        bpy.context.scene.render.dither_intensity = 0.0
    space.display_channels = channel
    area.tag_redraw()


def crop_and_save(pixels, left, bottom, right, top, path):
    """Writes the screenshot's rectangle [left, right) x [bottom, top) (from the bottom left)."""
    height, width = pixels.shape[:2]
    if left < 0 or bottom < 0 or right > width or top > height or left >= right or bottom >= top:
        raise RuntimeError("%s: the rectangle %s is not inside the %dx%d editor"
                           % (path, (left, bottom, right, top), width, height))
    save_png(pixels[bottom:top, left:right], path, PROGRAM)


def full_screenshot(name):
    """The editor's screenshot, saved as ``name`` in the keep or work folder."""
    return screenshot(editor(), os.path.join(ARGS.keep or ARGS.workdir, name))


# ---- Steps (timers) -------------------------------------------------------------------------

STATE = {}


@STEPS.add
def setup():
    """Loads the table, makes the largest area an Image Editor showing it, maximises that."""
    for folder in (ARGS.workdir, ARGS.output, ARGS.keep):
        if folder:
            os.makedirs(folder, exist_ok=True)
    names = [name for name in ARGS.parts.split(",") if name]
    parts, size = read_inspect(ARGS.inspect, names)
    image = bpy.data.images.load(os.path.abspath(ARGS.table), check_existing=False)
    # As the add-on's tables.store_image loads a table: float data, A not an opacity.
    image.colorspace_settings.name = "Non-Color"
    if hasattr(image, "use_half_precision"):
        image.use_half_precision = False
    image.alpha_mode = "CHANNEL_PACKED"
    if tuple(image.size) != size or not image.is_float:
        raise RuntimeError("Blender reads %s as %dx%d%s; inspect says %dx%d"
                           % (ARGS.table, image.size[0], image.size[1],
                              "" if image.is_float else " bytes", size[0], size[1]))
    width, height = size
    flat = np.empty(width * height * 4, dtype=np.float32)
    image.pixels.foreach_get(flat)
    STATE["pixels"] = flat.reshape(height, width, 4)[::-1]  # top row first, as the parts count
    STATE["parts"] = parts
    area = largest_area()
    area.type = "IMAGE_EDITOR"
    space = area.spaces.active
    space.image = image
    space.show_gizmo = False
    maximise(area, hide_panels=True)


@STEPS.add
def frame_overview():
    """View All (fit), the whole image as loaded, colour and alpha."""
    show("COLOR_ALPHA")
    run_op(bpy.ops.image.view_all, fit_view=True)


@STEPS.add
def overview():
    """Writes the overview and queues two steps per slice: frame it, screenshot it."""
    pixels = full_screenshot("overview_full.png")
    left, bottom = to_screen(0, STATE["pixels"].shape[0])
    right, top = to_screen(STATE["pixels"].shape[1], 0)
    height, width = pixels.shape[:2]
    crop_and_save(pixels, max(0, left - OVERVIEW_MARGIN), max(0, bottom - OVERVIEW_MARGIN),
                  min(width, right + OVERVIEW_MARGIN), min(height, top + OVERVIEW_MARGIN),
                  os.path.join(ARGS.output, "table_overview.png"))
    print("%s: overview: the whole %dx%d image, View All (fit), Color & Alpha, as loaded"
          % (PROGRAM, STATE["pixels"].shape[1], STATE["pixels"].shape[0]), flush=True)
    for part in STATE["parts"]:
        print("%s: part %s: rows %d-%d" % (PROGRAM, part.name, part.first, part.end - 1))
        for shot in SHOTS.get(part.name, generic_shots)(part, STATE["pixels"]):
            values = STATE["pixels"][shot.rows[0]:shot.rows[1], shot.columns[0]:shot.columns[1],
                                     CHANNELS[shot.channel]]
            if values.min() == values.max():
                print("%s:   %s_%s: not pictured, %s is %g in every pixel of %s"
                      % (PROGRAM, shot.part, shot.what, shot.channel, values.min(), shot.caption),
                      flush=True)
                continue
            STEPS.add(lambda shot=shot, low=float(values.min()), top=float(values.max()):
                      frame_slice(shot, low, top))
            STEPS.add(lambda shot=shot: save_slice(shot))
    STEPS.add(finish)


def frame_slice(shot, smallest, largest):
    """Frames the slice and shows its channel as its view (VIEWS) says."""
    STATE["zoom"] = frame(shot)
    view, white_log2 = VIEWS[shot.view]
    if white_log2 is None:
        STATE["display"] = "%s view, levels %.4g to %.4g" % (view, smallest, largest)
        show(shot.channel, view, 0.0, (smallest, largest))
    else:
        exposure = round(white_log2 - math.log2(largest), 2)
        STATE["display"] = "%s view, exposure %+.2f" % (view, exposure)
        show(shot.channel, view, exposure)


def save_slice(shot):
    """Writes the slice's rectangle of the screenshot."""
    pixels = full_screenshot("%s_%s_full.png" % (shot.part, shot.what))
    left, top = to_screen(shot.columns[0], shot.rows[0])
    right, bottom = to_screen(shot.columns[1], shot.rows[1])
    zoom = STATE["zoom"]
    columns, rows = shot.columns[1] - shot.columns[0], shot.rows[1] - shot.rows[0]
    if abs(right - left - zoom * columns) > 1 or abs(top - bottom - zoom * rows) > 1:
        raise RuntimeError("%s_%s: the slice is %dx%d on screen, not %gx%g at zoom %g"
                           % (shot.part, shot.what, right - left, top - bottom,
                              zoom * columns, zoom * rows, zoom))
    if zoom >= 3:
        # Blender 3.4 draws the image up to a screen pixel away from where its View2D maps it
        # (texel edges half a pixel off, rounded either way): one pixel less on every side
        # keeps the neighbouring rows and columns and the editor's frame line out.
        left, bottom, right, top = left + 1, bottom + 1, right - 1, top - 1
    crop_and_save(pixels, left, bottom, right, top,
                  os.path.join(ARGS.output, "table_%s_%s.png" % (shot.part, shot.what)))
    print("%s:   %s_%s: %s; zoom %g, View as Render, %s"
          % (PROGRAM, shot.part, shot.what, shot.caption, zoom, STATE["display"]), flush=True)


def finish():
    """Quits."""
    bpy.ops.wm.quit_blender()


STEPS.start()
