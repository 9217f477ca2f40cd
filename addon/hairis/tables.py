"""Sampling tables of hair materials: where they live, whether they are current, baking.

A hair material's tables are an EXR image datablock (``material.hairis.table_image``), saved
next to the .blend as ``//hairis_<material>.exr`` or packed into it. They are *current* when
the native library loads them and ``hairis_tables_match_fiber`` says they were baked for the
fiber the material's Principled Hair BSDF describes now; otherwise they are missing, invalid
or stale. Used by the bake operator (main thread) and the render engine (render thread, which
never writes ``bpy.data``: it bakes into a per-session cache file instead).
"""

import hashlib
import os
import tempfile
from dataclasses import dataclass

import bpy

from . import hair_material, native, shader_nodes

N_H_CHOICES = (1, 2, 4, 8, 16)
"""The strand counts the add-on offers (and bakes multiple-scattering tables for)."""


class TableError(Exception):
    """A material's tables cannot be used (missing file, no image, library-linked, ...)."""


@dataclass
class TableStatus:
    """The state of a material's tables: 'OK', 'MISSING', 'INVALID', 'STALE' or 'PARTIAL'
    (usable, with ``tables`` open, but without the Huang absorption part the material's
    per-strand colour asks for: a bake adds it)."""

    state: str
    message: str
    tables: object = None

    @property
    def ok(self):
        """True when the tables are current."""
        return self.state == "OK"


def principled_struct(library, params):
    """The Principled Hair values of :class:`hair_material.HairParameters` for
    ``Library.fiber_principled`` (kept as a function for the callers that pass it around)."""
    return params.as_dict()


def material_parameters(material):
    """The material's hair parameters, or raise TableError when it is not a usable hair one."""
    node = shader_nodes.hair_node(material)
    if node is None and shader_nodes.is_hair_material(material):
        raise TableError("material %r mixes Principled Hair BSDFs through a Mix or Add Shader; "
                         "its closures' tables are not stored with the material: render with "
                         "Auto Bake, or with a strategy that needs no tables" % material.name)
    if node is None:
        raise TableError("material %r has no Principled Hair BSDF connected to its output"
                         % material.name)
    params, _warnings, error = hair_material.read_hair_node(node, material.name)
    if error is not None:
        raise TableError(error)
    return params


def hair_materials(materials=None):
    """Every material (default: all of ``bpy.data.materials`` with users) with a Principled
    Hair BSDF at its output (a Mix/Add Shader of them bakes per closure at render time)."""
    if materials is None:
        materials = [m for m in bpy.data.materials if m.users > 0]
    return [m for m in materials if shader_nodes.hair_node(m) is not None]


def bake_options(library, n_h=None, threads=0, multiple=True, refinement=1, absorption=False):
    """The default bake options, holding ``N_H_CHOICES`` (and ``n_h``) and ``threads``.

    ``multiple``: also bake a Huang fiber's multiple-scattering part, which only Dual
    Scattering reads and which costs several times the rest of the bake. ``refinement``: the
    Huang f part's quadrature refinement (Huang Bake). ``absorption``: also bake the Huang
    absorption part, which shades strands of their own colour without Cycles' noise."""
    options = library.bake_options_defaults()
    if "huang_multiple" in options:  # a library that bakes Huang tables
        options["huang_multiple"] = 1 if multiple else 0
    if "huang_f_refinement" in options:
        options["huang_f_refinement"] = int(refinement)
    if "huang_absorption" in options:
        options["huang_absorption"] = 1 if absorption else 0
    values = {int(v) for v in options["n_h"].split(",")} | set(N_H_CHOICES)
    if n_h is not None:
        values.add(int(n_h))
    options["n_h"] = ",".join(str(v) for v in sorted(v for v in values if v > 0)[:16])
    options["threads"] = int(threads)
    return options


def image_path(image):
    """The absolute file path of an image datablock ('' for none)."""
    path = image.filepath_raw or image.filepath
    if not path:
        return ""
    return os.path.normpath(bpy.path.abspath(path, library=image.library))


def image_tables(library, image):
    """Loads the tables an image datablock holds: its packed bytes, else its file."""
    if image is None:
        raise TableError("no table image")
    packed = image.packed_file
    if packed is not None:
        return library.load_tables_memory(packed.data)
    path = image_path(image)
    if not path:
        raise TableError("image %r has no file path" % image.name)
    if not os.path.isfile(path):
        raise TableError("table file %s does not exist" % path)
    return library.load_tables_file(path)


def check_material(library, material, fiber, need_multiple=False, refinement=1,
                   absorption=False):
    """Full check (load, validate, match ``fiber``) of a material's tables: a TableStatus.

    ``need_multiple``: the tables must hold multiple-scattering tables (Dual Scattering), which
    Huang tables baked before Dual Scattering covered Huang lack. ``refinement``: the Huang f
    part's quadrature refinement the scene asks for (Huang Bake). ``absorption``: the tables
    must hold the Huang absorption part (HairParameters.varies_absorption).
    """
    image = material.hairis.table_image
    if image is None:
        return TableStatus("MISSING", "material %r has no sampling tables" % material.name)
    try:
        tables = image_tables(library, image)
    except (TableError, native.HairisError) as error:
        return TableStatus("INVALID", "material %r: its tables cannot be used: %s"
                           % (material.name, error))
    if not tables.matches(fiber):
        tables.close()
        return TableStatus("STALE", "material %r: its tables were baked for other hair "
                           "parameters" % material.name)
    if tables.info.get("huang_f") == "0":
        tables.close()
        return TableStatus("STALE", "material %r: its Huang tables have no baked f, which "
                           "renders shade Huang hair with (baked with huang_f=0 or by an "
                           "earlier hairis); bake them again" % material.name)
    baked_refinement = tables.info.get("huang_f_refinement")
    if baked_refinement is not None and baked_refinement != str(refinement):
        tables.close()
        return TableStatus("STALE", "material %r: its Huang tables' f was baked at another "
                           "Huang Bake than the scene's; bake them again" % material.name)
    if need_multiple and not tables.n_h_values:
        tables.close()
        return TableStatus("STALE", "material %r: its tables have no multiple-scattering part, "
                           "which Dual Scattering samples (baked by an earlier hairis); bake "
                           "them again" % material.name)
    if absorption and tables.info.get("huang_absorption") != "1":
        return TableStatus("PARTIAL", "material %r: its Huang tables have no absorption part, "
                           "so strands of their own colour are shaded with Cycles' noisy eval; "
                           "bake them again to add it" % material.name, tables)
    return TableStatus("OK", "material %r: tables are current" % material.name, tables)


def quick_state(library, material, refinement=1):
    """A cheap check for the UI (no table load): 'OK', 'MISSING', 'STALE', 'OTHER_BAKE' (a
    Huang f baked at another Huang Bake than ``refinement``), 'NO_ABSORPTION' (Huang tables
    without the absorption part the material's per-strand colour asks for) or 'ERROR'."""
    settings = material.hairis
    image = settings.table_image
    if image is None:
        return "MISSING"
    if image.packed_file is None and not os.path.isfile(image_path(image)):
        return "MISSING"
    try:
        params = material_parameters(material)
        with library.fiber_principled(principled_struct(library, params)) as fiber:
            current = fiber.parameters
    except (TableError, native.HairisError):
        return "ERROR"
    if current != settings.baked_parameters:
        return "STALE"
    baked = settings.baked_huang_f_refinement
    if baked and baked != refinement:
        return "OTHER_BAKE"
    if baked and params.varies_absorption and not settings.baked_huang_absorption:
        return "NO_ABSORPTION"
    return "OK"


def table_filename(material):
    """``hairis_<material>.exr`` with the name made file-system safe."""
    return "hairis_%s.exr" % bpy.path.clean_name(material.name)


def output_path(material):
    """Where to write a material's tables: (absolute path, path to store, blend_saved).

    Next to the saved .blend as ``//hairis_<material>.exr``; for an unsaved .blend in a
    temporary folder (the caller packs the image and warns).
    """
    filename = table_filename(material)
    if bpy.data.filepath:
        stored = "//" + filename
        return os.path.normpath(bpy.path.abspath(stored)), stored, True
    folder = os.path.join(tempfile.gettempdir(), "hairis_tables")
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, filename)
    return path, path, False


def store_image(material, path, stored_path, pack, parameters, model, refinement=0,
                absorption=False):
    """Loads ``path`` as the material's table image (float, Non-Color) and records the bake
    (``refinement``: its Huang f refinement, 0 for other models; ``absorption``: whether it
    holds the Huang absorption part).

    Main thread only (writes ``bpy.data``). An image already pointing at ``path`` is
    reloaded; otherwise a new datablock replaces the old one (removed if nothing else uses it).
    """
    settings = material.hairis
    old = settings.table_image
    image = None
    if (old is not None and old.library is None and old.packed_file is None
            and image_path(old) == os.path.normpath(path)):
        image = old
        image.reload()
    else:
        image = bpy.data.images.load(path, check_existing=False)
    image.filepath = stored_path
    image.name = "hairis_%s" % material.name
    image.colorspace_settings.name = "Non-Color"
    if hasattr(image, "use_half_precision"):
        image.use_half_precision = False
    image.alpha_mode = "CHANNEL_PACKED"  # data: R and G are densities, A is just 1
    if pack:
        image.pack()
    settings.table_image = image
    settings.baked_parameters = parameters
    settings.baked_model = model
    settings.baked_huang_f_refinement = int(refinement)
    settings.baked_huang_absorption = bool(absorption)
    if old is not None and old != image and old.users == 0:
        bpy.data.images.remove(old)
    return image


def cache_path(parameters, refinement=1, absorption=False):
    """The per-session cache file for tables auto-baked during a render (one per Huang f
    refinement, and apart for tables with the absorption part)."""
    folder = bpy.app.tempdir or tempfile.gettempdir()
    key = parameters if refinement == 1 else "%s;huang_f_refinement=%d" % (parameters, refinement)
    if absorption:
        key += ";huang_absorption=1"
    digest = hashlib.sha1(key.encode("utf-8")).hexdigest()[:16]
    return os.path.join(folder, "hairis_autobake_%s.exr" % digest)


def fiber_cache_path(fiber, refinement=1, absorption=False):
    """``cache_path`` of ``fiber``'s tables: Huang Bake and the absorption part change only
    Huang tables, so other models keep one cache file whatever the setting."""
    huang = fiber.model == "huang2022"
    return cache_path(fiber.parameters, refinement if huang else 1, absorption and huang)


def cached_tables(library, fiber, need_multiple=False, refinement=1, absorption=False):
    """Tables from the auto-bake cache when present and matching ``fiber`` (and holding
    multiple-scattering tables if ``need_multiple``), else None."""
    path = fiber_cache_path(fiber, refinement, absorption)
    if not os.path.isfile(path):
        return None
    try:
        tables = library.load_tables_file(path)
    except native.HairisError:
        return None
    if tables.matches(fiber) and (tables.n_h_values or not need_multiple):
        return tables
    tables.close()
    return None


def write_cache(tables, fiber, refinement=1, absorption=False):
    """Writes auto-baked tables to the cache; returns the path, or None if writing failed."""
    path = fiber_cache_path(fiber, refinement, absorption)
    try:
        tables.write(path)
    except native.HairisError:
        return None
    return path
