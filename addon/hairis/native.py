"""ctypes binding of the hairis C API (``lib/include/hairis/hairis.h`` and ``hairis_render.h``).

Every function of the headers is declared in :data:`PROTOTYPES` (checked against the headers
by ``tests/capi/capi_ctypes_test.py``). Parameter sets cross the C API as option strings
"name=value;..." (:func:`options`), so there are no structs to mirror: a parameter the library
adds is a name with a default. :func:`load_library` finds ``libhairis.so`` (the
``HAIRIS_LIBRARY`` environment variable, else ``lib/`` inside this package), checks
``hairis_api_version() == API_VERSION`` and returns a :class:`Library` whose methods raise
:class:`HairisError` (carrying ``hairis_last_error()``) on every failing call. Nothing here
imports ``bpy``: the module can be used, and tested, outside Blender.

Handles (fibers, tables, samplers, scenes) are wrapped in small classes that release the C
object on :meth:`close`, on leaving a ``with`` block, or when garbage collected.
"""

import ctypes
import math
import os
import sys
from ctypes import POINTER, c_char_p, c_float, c_int, c_int32, c_size_t, c_uint32, c_void_p

import numpy as np

API_VERSION = 2
"""The HAIRIS_API_VERSION this binding was written for."""

LIBRARY_ENV = "HAIRIS_LIBRARY"
"""Environment variable naming the shared library to load instead of the bundled one."""

DEEPBIND_ENV = "HAIRIS_DEEPBIND"
"""Set to 0 to load the library without RTLD_DEEPBIND (see :func:`load_mode`)."""

# Status codes.
OK = 0
ERROR_INVALID_ARGUMENT = 1
ERROR_IO = 2
ERROR_INVALID_TABLE = 3
ERROR_CANCELLED = 4
ERROR_INTERNAL = 5

STATUS_NAMES = {
    OK: "HAIRIS_OK",
    ERROR_INVALID_ARGUMENT: "HAIRIS_ERROR_INVALID_ARGUMENT",
    ERROR_IO: "HAIRIS_ERROR_IO",
    ERROR_INVALID_TABLE: "HAIRIS_ERROR_INVALID_TABLE",
    ERROR_CANCELLED: "HAIRIS_ERROR_CANCELLED",
    ERROR_INTERNAL: "HAIRIS_ERROR_INTERNAL",
}

STRATEGIES = ("UNIFORM", "ANALYTIC", "GAUSSIAN", "TABLE")
"""The add-on's strategy names; the C API spells them in lower case."""

PARAMETRIZATIONS = ("ABSORPTION", "MELANIN", "COLOR")
"""Blender's Principled Hair parametrizations; the C API spells them in lower case."""

AREA_SHAPES = ("SQUARE", "RECTANGLE", "DISK", "ELLIPSE")
"""Blender's area light shapes; the C API spells them in lower case."""

PROGRESS_FN = ctypes.CFUNCTYPE(c_int, c_void_p, c_float)
"""``hairis_progress_fn``: ``int (*)(void *user, float progress)``; non-zero cancels."""

UPDATE_FN = ctypes.CFUNCTYPE(c_int, c_void_p, c_float, c_int, c_int)
"""``hairis_update_fn``: ``int (*)(void *user, float progress, int samples_done, int final)``;
non-zero stops the render."""

_F = POINTER(c_float)
_VOID = None

PROTOTYPES = {
    # hairis.h: library
    "hairis_api_version": (c_int, []),
    "hairis_version_string": (c_char_p, []),
    "hairis_last_error": (c_char_p, []),
    "hairis_defaults": (c_char_p, [c_char_p]),
    # fibers
    "hairis_fiber_create": (c_void_p, [c_char_p]),
    "hairis_fiber_destroy": (_VOID, [c_void_p]),
    "hairis_fiber_model": (c_char_p, [c_void_p]),
    "hairis_fiber_parameters": (c_char_p, [c_void_p]),
    "hairis_fiber_eval": (c_int, [c_void_p, c_size_t, _F, _F, _F, _F]),
    # tables
    "hairis_tables_bake": (c_void_p, [c_void_p, c_char_p, PROGRESS_FN, c_void_p]),
    "hairis_tables_write": (c_int, [c_void_p, c_char_p]),
    "hairis_tables_load_file": (c_void_p, [c_char_p]),
    "hairis_tables_load_memory": (c_void_p, [c_void_p, c_size_t]),
    "hairis_tables_destroy": (_VOID, [c_void_p]),
    "hairis_tables_model": (c_char_p, [c_void_p]),
    "hairis_tables_parameters": (c_char_p, [c_void_p]),
    "hairis_tables_info": (c_char_p, [c_void_p]),
    "hairis_tables_match_fiber": (c_int, [c_void_p, c_void_p]),
    # sampling
    "hairis_sampler_create": (c_void_p, [c_void_p, c_void_p, c_char_p]),
    "hairis_sampler_destroy": (_VOID, [c_void_p]),
    "hairis_sample": (c_int, [c_void_p, c_size_t, _F, _F, _F, _F, _F]),
    "hairis_pdf": (c_int, [c_void_p, c_size_t, _F, _F, _F, _F]),
    "hairis_sampler_eval": (c_int, [c_void_p, c_size_t, _F, _F, _F, _F]),
    # hairis_render.h
    "hairis_scene_create": (c_void_p, []),
    "hairis_scene_destroy": (_VOID, [c_void_p]),
    "hairis_scene_add_hair_material": (c_int, [c_void_p, c_void_p, c_void_p]),
    "hairis_scene_add_hair_mixture": (c_int, [c_void_p, c_size_t, POINTER(c_int), _F]),
    "hairis_scene_add_surface_material": (c_int, [c_void_p, c_char_p]),
    "hairis_scene_add_texture": (c_int, [c_void_p, c_char_p]),
    "hairis_scene_add_texture_pixels": (c_int, [c_void_p, c_char_p, _F, c_size_t, c_size_t,
                                                c_int]),
    "hairis_scene_add_curves": (c_int, [c_void_p, c_int, c_size_t, POINTER(c_uint32), c_size_t,
                                        _F, _F]),
    "hairis_scene_add_curves_with_inputs": (c_int, [c_void_p, c_int, c_size_t, POINTER(c_uint32),
                                                    c_size_t, _F, _F, c_char_p, c_size_t, _F]),
    "hairis_scene_add_curves_with_normals": (c_int, [c_void_p, c_int, c_size_t, POINTER(c_uint32),
                                                     c_size_t, _F, _F, _F, c_char_p]),
    "hairis_scene_add_mesh": (c_int, [c_void_p, c_size_t, _F, c_size_t, POINTER(c_uint32),
                                      POINTER(c_int32)]),
    "hairis_scene_set_mesh_attribute": (c_int, [c_void_p, c_char_p, _F, c_size_t]),
    "hairis_scene_add_light": (c_int, [c_void_p, c_char_p]),
    "hairis_scene_set_world": (c_int, [c_void_p, c_char_p]),
    "hairis_scene_set_world_pixels": (c_int, [c_void_p, c_char_p, _F, c_size_t, c_size_t,
                                              c_int]),
    "hairis_scene_reset_shading": (c_int, [c_void_p]),
    "hairis_scene_set_camera": (c_int, [c_void_p, c_char_p]),
    "hairis_render": (c_int, [c_void_p, c_char_p, _F, PROGRESS_FN, c_void_p]),
    "hairis_render_progressive": (c_int, [c_void_p, c_char_p, _F, _F, UPDATE_FN, c_void_p]),
    "hairis_last_render_stats": (c_char_p, []),
}
"""Every function of the headers: name → (restype, argtypes)."""


CURVE_INPUTS = ("color", "melanin", "melanin_redness", "tint", "absorption", "roughness",
                "radial_roughness", "coat", "ior", "offset", "random_color", "random_roughness",
                "random") + tuple("weight%d" % k for k in range(8))
"""hairis_defaults("curve_inputs")' names in its order: the order of a curve set's values (the
node inputs, then a hair mixture's closure weights)."""

CURVE_INPUT_COMPONENTS = {"color": 3, "tint": 3, "absorption": 3}
"""Components of the colour inputs (the others have one)."""


# ---- Option strings --------------------------------------------------------------------------

def _value_text(value):
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        value = float(value)
        if not math.isfinite(value):
            return repr(value)  # refused by the library, naming the option
        return "%.9g" % value
    if isinstance(value, str):
        return value
    return ",".join(_value_text(v) for v in np.asarray(value, dtype=np.float64).reshape(-1))


def options(values):
    """An option string "name=value;..." from a dict (numbers to 9 significant digits,
    sequences comma-separated, booleans 0/1); a string is passed through."""
    if values is None:
        return ""
    if isinstance(values, str):
        return values
    return ";".join("%s=%s" % (name, _value_text(value)) for name, value in values.items())


def parse_options(text):
    """A dict of strings from an option string."""
    result = {}
    for item in (text or "").split(";"):
        if "=" in item:
            name, value = item.split("=", 1)
            result[name.strip()] = value.strip()
    return result


class RenderStats:
    """What a render did (``hairis_last_render_stats``): one attribute per name, an int or a
    float (seconds, camera_rays, rays, shadow_rays, dropped_samples, peak_memory_bytes, ...)."""

    def __init__(self, text):
        self.names = []
        for name, value in parse_options(text).items():
            try:
                number = int(value)
            except ValueError:
                number = float(value)
            setattr(self, name, number)
            self.names.append(name)

    def __repr__(self):
        return "<RenderStats %s>" % ", ".join("%s=%r" % (n, getattr(self, n)) for n in self.names)


CHIANG_ONLY = ("radial_roughness", "coat", "cycles")
"""Principled Hair values only the Chiang model reads."""

HUANG_ONLY = ("aspect_ratio", "reflection", "transmission", "secondary_reflection")
"""Principled Hair values only the Huang model reads (Blender 4.0+)."""


def principled_options(params):
    """Fiber options of a Principled Hair node from a dict of ``hair_material.HairParameters``'
    fields (model 'CHIANG' (default) or 'HUANG'; parametrization as an index into
    PARAMETRIZATIONS or a name; angles in radians). The other model's values are left out."""
    values = dict(params)
    model = str(values.pop("model", "CHIANG")).lower()
    for name in (CHIANG_ONLY if model == "huang" else HUANG_ONLY):
        values.pop(name, None)
    out = {"model": model}
    if "cycles" in values:
        out["cycles"] = values.pop("cycles")
    parametrization = values.pop("parametrization", "COLOR")
    if not isinstance(parametrization, str):
        parametrization = PARAMETRIZATIONS[int(parametrization)]
    out["parametrization"] = parametrization.lower()
    if "absorption_coefficient" in values:
        values["absorption"] = values.pop("absorption_coefficient")
    out.update(values)
    return out


# ---- Errors ----------------------------------------------------------------------------------

class HairisError(RuntimeError):
    """A hairis call failed; ``message`` is ``hairis_last_error()`` (or our own description).

    Attributes: ``function`` (the C function), ``code`` (a status code, or None for calls
    that signal failure with NULL or −1), ``message``.
    """

    def __init__(self, function, message, code=None):
        self.function = function
        self.code = code
        self.message = message or "no error message"
        if code is not None:
            text = "%s failed (%s): %s" % (function, STATUS_NAMES.get(code, code), self.message)
        else:
            text = "%s failed: %s" % (function, self.message)
        super().__init__(text)


class HairisCancelled(HairisError):
    """The progress callback asked to stop (HAIRIS_ERROR_CANCELLED)."""


class LibraryUnavailable(HairisError):
    """The native library could not be found, loaded, or has the wrong API version.

    ``path`` is where it was looked for, ``reason`` why it was refused; ``str()`` reads
    "hairis native library not found at <path>: <reason>".
    """

    def __init__(self, path, reason):
        self.path = path
        self.reason = reason
        self.function = "load_library"
        self.code = None
        self.message = "hairis native library not found at %s: %s" % (path, reason)
        RuntimeError.__init__(self, self.message)


# ---- Helpers ---------------------------------------------------------------------------------

def _decode(value):
    if value is None:
        return ""
    return value.decode("utf-8", errors="replace")


def _array(values, dtype, shape_tail, what):
    """A C-contiguous numpy array of ``dtype`` whose shape ends with ``shape_tail``."""
    array = np.ascontiguousarray(values, dtype=dtype)
    if shape_tail:
        if array.ndim == 1 and array.size % int(np.prod(shape_tail)) == 0:
            array = array.reshape((-1,) + tuple(shape_tail))
        if tuple(array.shape[1:]) != tuple(shape_tail):
            raise ValueError("%s must have shape (n, %s), got %s"
                             % (what, ", ".join(map(str, shape_tail)), array.shape))
    return array


def _ptr(array, ctype):
    if array is None:
        return None
    return array.ctypes.data_as(POINTER(ctype))


def default_library_path():
    """Where the bundled library lives: ``lib/libhairis.so`` next to this module."""
    if sys.platform.startswith("win"):
        name = "hairis.dll"
    elif sys.platform == "darwin":
        name = "libhairis.dylib"
    else:
        name = "libhairis.so"
    return os.path.join(os.path.dirname(os.path.abspath(__file__)), "lib", name)


def _sanitizer_loaded():
    """True when an ASan/TSan runtime is in the process (they refuse RTLD_DEEPBIND)."""
    try:
        process = ctypes.CDLL(None)
    except OSError:
        return False
    return any(hasattr(process, name) for name in ("__asan_init", "__tsan_init"))


def load_mode():
    """The dlopen flags for libhairis: RTLD_LOCAL, and RTLD_DEEPBIND on Linux.

    Blender 4.x/5.x bundle their own Embree 4, OpenEXR and OpenImageIO; in the Blender
    executable they are in the global symbol scope, which the dynamic linker searches before a
    library's own dependencies, so Embree 3's same-named C functions (``rtc*``) that libhairis
    calls would bind to Embree 4's. RTLD_DEEPBIND makes libhairis and the dependencies loaded
    with it look in their own scope first. Not with a sanitizer runtime (which refuses it) or
    with ``HAIRIS_DEEPBIND=0``.
    """
    mode = ctypes.DEFAULT_MODE
    deepbind = getattr(os, "RTLD_DEEPBIND", 0)
    if (deepbind and sys.platform.startswith("linux")
            and os.environ.get(DEEPBIND_ENV, "1").strip() != "0" and not _sanitizer_loaded()):
        mode |= deepbind
    return mode


def library_path():
    """The library to load: ``$HAIRIS_LIBRARY`` when set (and non-empty), else the bundled one."""
    override = os.environ.get(LIBRARY_ENV, "").strip()
    return override if override else default_library_path()


class _Progress:
    """Adapts a Python callable ``callback(progress) -> bool`` (True cancels) to PROGRESS_FN.

    Exceptions raised by the callback cancel the C call and are re-raised afterwards. The C
    side may call from several threads; the GIL serializes the calls.
    """

    def __init__(self, callback):
        self.callback = callback
        self.cancel_requested = False
        self.error = None
        # PROGRESS_FN() with no argument is a NULL function pointer (ctypes refuses None).
        self.function = PROGRESS_FN(self._call) if callback is not None else PROGRESS_FN()

    def _call(self, _user, progress):
        if self.cancel_requested:
            return 1
        try:
            if self.callback(float(progress)):
                self.cancel_requested = True
        except BaseException as error:  # noqa: B902 - must never propagate into C
            self.error = error
            self.cancel_requested = True
        return 1 if self.cancel_requested else 0

    def reraise(self):
        """Re-raises an exception the callback raised, if any."""
        if self.error is not None:
            raise self.error


# ---- The library -----------------------------------------------------------------------------

class Library:
    """The loaded hairis library: checked Python wrappers over the C functions.

    ``raw`` is the ctypes ``CDLL`` with argtypes/restype set for every function, for callers
    who want the C functions themselves.
    """

    def __init__(self, path):
        self.path = path
        if not os.path.exists(path):
            raise LibraryUnavailable(path, "no such file")
        self.mode = load_mode()
        try:
            self.raw = ctypes.CDLL(path, mode=self.mode)
        except OSError as error:
            raise LibraryUnavailable(path, str(error)) from None
        missing = []
        for name, (restype, argtypes) in PROTOTYPES.items():
            try:
                function = getattr(self.raw, name)
            except AttributeError:
                missing.append(name)
                continue
            function.restype = restype
            function.argtypes = argtypes
        if missing:
            raise LibraryUnavailable(path, "missing symbols: " + ", ".join(missing))
        version = self.raw.hairis_api_version()
        if version != API_VERSION:
            raise LibraryUnavailable(
                path, "API version %d, this add-on needs API version %d" % (version, API_VERSION))
        self.api_version = version
        self.version = _decode(self.raw.hairis_version_string())

    def __repr__(self):
        return "<hairis.native.Library %s %r>" % (self.version, self.path)

    # -- error plumbing --

    def last_error(self):
        """``hairis_last_error()`` for the calling thread ("" after a successful call)."""
        return _decode(self.raw.hairis_last_error())

    def _error(self, function, code=None, progress=None):
        message = self.last_error()
        cancelled = code == ERROR_CANCELLED or (progress is not None and progress.cancel_requested)
        if progress is not None:
            progress.reraise()
        if cancelled:
            return HairisCancelled(function, message or "cancelled", code)
        return HairisError(function, message, code)

    def _status(self, function, status, progress=None):
        if status != OK:
            raise self._error(function, status, progress)

    def _handle(self, function, pointer, progress=None):
        if not pointer:
            raise self._error(function, None, progress)
        return pointer

    # -- defaults --

    def defaults(self, kind):
        """Every option of ``kind`` ("chiang", "bake", "render", "sun", ...) with its default,
        as a dict of strings."""
        text = self.raw.hairis_defaults(kind.encode())
        if text is None:
            raise self._error("hairis_defaults")
        return parse_options(_decode(text))

    def render_settings_defaults(self):
        """The default render settings (a dict of strings)."""
        return self.defaults("render")

    def bake_options_defaults(self):
        """The default bake options (a dict of strings)."""
        return self.defaults("bake")

    # -- objects --

    def fiber(self, values):
        """A fiber from fiber options (a dict or an option string; hairis.h)."""
        pointer = self.raw.hairis_fiber_create(options(values).encode())
        return Fiber(self, self._handle("hairis_fiber_create", pointer))

    def fiber_principled(self, params):
        """A Chiang or Huang fiber from a Principled Hair node's values (see
        :func:`principled_options`)."""
        return self.fiber(principled_options(params))

    def bake_tables(self, fiber, values=None, progress=None):
        """Bakes tables for ``fiber`` with bake options (dict or string); ``progress(p) -> bool``
        may cancel (HairisCancelled)."""
        adapter = _Progress(progress)
        text = options(values).encode()
        pointer = self.raw.hairis_tables_bake(fiber, text, adapter.function, None)
        if pointer:
            # A callback error after the last progress call must not be lost.
            if adapter.error is not None:
                self.raw.hairis_tables_destroy(pointer)
                adapter.reraise()
            return Tables(self, pointer)
        raise self._error("hairis_tables_bake", None, adapter)

    def load_tables_file(self, path):
        """Loads and validates tables from an EXR file."""
        pointer = self.raw.hairis_tables_load_file(os.fsencode(path))
        return Tables(self, self._handle("hairis_tables_load_file", pointer))

    def load_tables_memory(self, data):
        """Loads and validates tables from EXR bytes (e.g. a packed image's data)."""
        data = bytes(data)  # no copy of bytes; the library reads them during the call only
        pointer = self.raw.hairis_tables_load_memory(data, len(data))
        return Tables(self, self._handle("hairis_tables_load_memory", pointer))

    def sampler(self, strategy, fiber=None, tables=None, multiple_weight=0.0, n_h=2):
        """A direction sampler; ``strategy`` is one of STRATEGIES."""
        text = options({"strategy": str(strategy).lower(),
                        "multiple_weight": float(multiple_weight), "n_h": int(n_h)})
        pointer = self.raw.hairis_sampler_create(fiber, tables, text.encode())
        return Sampler(self, self._handle("hairis_sampler_create", pointer), fiber, tables)

    def scene(self):
        """An empty scene."""
        pointer = self.raw.hairis_scene_create()
        return Scene(self, self._handle("hairis_scene_create", pointer))


class _Handle:
    """An owned C handle, released by ``close()`` / ``with`` / garbage collection."""

    _destroy = None

    def __init__(self, library, pointer):
        self._library = library
        self._pointer = pointer

    @property
    def _as_parameter_(self):
        if not self._pointer:
            raise ValueError("%s is closed" % type(self).__name__)
        return c_void_p(self._pointer)

    @property
    def closed(self):
        """True once the C object was released."""
        return not self._pointer

    def close(self):
        """Releases the C object (idempotent)."""
        pointer, self._pointer = self._pointer, None
        if pointer:
            getattr(self._library.raw, self._destroy)(pointer)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass


class Fiber(_Handle):
    """A fiber model (``hairis_fiber``)."""

    _destroy = "hairis_fiber_destroy"

    @property
    def model(self):
        """"chiang2016" or "marschner2003"."""
        return _decode(self._library.raw.hairis_fiber_model(self))

    @property
    def parameters(self):
        """The parameters as "name=value;..." (what table metadata records)."""
        return _decode(self._library.raw.hairis_fiber_parameters(self))

    def eval(self, wi, wo, h=None):
        """f(ω_i, ω_o)·|cos θ_i| as an (n, 3) array; ``h`` None means far field."""
        wi = _array(wi, np.float32, (3,), "wi")
        wo = _array(wo, np.float32, (3,), "wo")
        if wi.shape != wo.shape:
            raise ValueError("wi and wo must have the same shape, got %s and %s"
                             % (wi.shape, wo.shape))
        n = wi.shape[0]
        if h is not None:
            h = _array(h, np.float32, (), "h").reshape(-1)
            if h.size != n:
                raise ValueError("h needs %d values, got %d" % (n, h.size))
        out = np.zeros((n, 3), np.float32)
        status = self._library.raw.hairis_fiber_eval(self, n, _ptr(wi, c_float), _ptr(wo, c_float),
                                                     _ptr(h, c_float), _ptr(out, c_float))
        self._library._status("hairis_fiber_eval", status)
        return out


class Tables(_Handle):
    """Baked sampling tables (``hairis_tables``)."""

    _destroy = "hairis_tables_destroy"

    @property
    def model(self):
        """The model the tables were baked for."""
        return _decode(self._library.raw.hairis_tables_model(self))

    @property
    def parameters(self):
        """The fiber parameters the tables were baked for."""
        return _decode(self._library.raw.hairis_tables_parameters(self))

    @property
    def info(self):
        """What the tables hold (strings): source, theta_r, theta_i, phi, n_h; for huang2022
        tables source, huang_theta_o, huang_phi_o, huang_theta_i, huang_phi, and theta_r,
        theta_i, n_h when they hold the multiple part (Dual Scattering needs it)."""
        return parse_options(_decode(self._library.raw.hairis_tables_info(self)))

    @property
    def n_h_values(self):
        """The strand counts of the multiple-scattering tables."""
        text = self.info.get("n_h", "")
        return [int(v) for v in text.split(",") if v]

    def matches(self, fiber):
        """True when the tables were baked for exactly this fiber's parameters."""
        return self._library.raw.hairis_tables_match_fiber(self, fiber) == 1

    def write(self, path):
        """Writes the tables to an EXR file (atomically)."""
        status = self._library.raw.hairis_tables_write(self, os.fsencode(path))
        self._library._status("hairis_tables_write", status)


class Sampler(_Handle):
    """A direction sampler (``hairis_sampler``); keeps its fiber and tables alive."""

    _destroy = "hairis_sampler_destroy"

    def __init__(self, library, pointer, fiber=None, tables=None):
        super().__init__(library, pointer)
        self._keep = (fiber, tables)

    def sample(self, wo, u, h=None):
        """Draws one ω_i per row of ``wo`` (n, 3) with ``u`` (n, 3); returns (wi, pdf)."""
        wo = _array(wo, np.float32, (3,), "wo")
        u = _array(u, np.float32, (3,), "u")
        n = wo.shape[0]
        if u.shape[0] != n:
            raise ValueError("u needs %d rows, got %d" % (n, u.shape[0]))
        if h is not None:
            h = _array(h, np.float32, (), "h").reshape(-1)
            if h.size != n:
                raise ValueError("h needs %d values, got %d" % (n, h.size))
        wi = np.zeros((n, 3), np.float32)
        pdf = np.zeros(n, np.float32)
        status = self._library.raw.hairis_sample(self, n, _ptr(wo, c_float), _ptr(h, c_float),
                                                 _ptr(u, c_float), _ptr(wi, c_float),
                                                 _ptr(pdf, c_float))
        self._library._status("hairis_sample", status)
        return wi, pdf

    def pdf(self, wi, wo, h=None):
        """The solid-angle density with which :meth:`sample` produces each ω_i."""
        wi = _array(wi, np.float32, (3,), "wi")
        wo = _array(wo, np.float32, (3,), "wo")
        n = wi.shape[0]
        if wo.shape[0] != n:
            raise ValueError("wo needs %d rows, got %d" % (n, wo.shape[0]))
        if h is not None:
            h = _array(h, np.float32, (), "h").reshape(-1)
            if h.size != n:
                raise ValueError("h needs %d values, got %d" % (n, h.size))
        out = np.zeros(n, np.float32)
        status = self._library.raw.hairis_pdf(self, n, _ptr(wi, c_float), _ptr(wo, c_float),
                                              _ptr(h, c_float), _ptr(out, c_float))
        self._library._status("hairis_pdf", status)
        return out


class Scene(_Handle):
    """A render scene (``hairis_scene``); keeps the tables added to it alive."""

    _destroy = "hairis_scene_destroy"

    def __init__(self, library, pointer):
        super().__init__(library, pointer)
        self._tables = []
        self.width = None
        self.height = None

    def add_hair_material(self, fiber, tables=None):
        """Adds a hair material of ``fiber`` (a :class:`Fiber`, or Principled Hair values for
        :meth:`Library.fiber_principled`) with its ``tables``; returns its index."""
        owned = None
        if not isinstance(fiber, Fiber):
            fiber = owned = self._library.fiber_principled(fiber)
        try:
            index = self._library.raw.hairis_scene_add_hair_material(self, fiber, tables)
        finally:
            if owned is not None:
                owned.close()
        if index < 0:
            raise self._library._error("hairis_scene_add_hair_material")
        if tables is not None:
            self._tables.append(tables)
        return index

    def add_diffuse_material(self, albedo, emission=(0.0, 0.0, 0.0)):
        """Adds a Lambert material with an emission; returns its index."""
        text = options({"type": "diffuse", "color": albedo, "emission": emission})
        index = self._library.raw.hairis_scene_add_surface_material(self, text.encode())
        if index < 0:
            raise self._library._error("hairis_scene_add_surface_material")
        return index

    def add_surface_material(self, values):
        """Adds a surface material from its options (hairis_render.h: type diffuse,
        principled, glossy, emission, mix or add); returns its index."""
        index = self._library.raw.hairis_scene_add_surface_material(self, options(values).encode())
        if index < 0:
            raise self._library._error("hairis_scene_add_surface_material")
        return index

    def add_texture(self, values, pixels=None):
        """Adds an Image Texture from texture options: with ``image`` (a path) in them, or with
        ``pixels`` (height, width, channels) floats, bottom row first; returns its index."""
        text = options(values).encode()
        if pixels is None:
            index = self._library.raw.hairis_scene_add_texture(self, text)
            function = "hairis_scene_add_texture"
        else:
            pixels = np.ascontiguousarray(pixels, np.float32)
            if pixels.ndim == 2:
                pixels = pixels[:, :, None]
            if pixels.ndim != 3:
                raise ValueError("pixels must be (height, width, channels), got shape %s"
                                 % (pixels.shape,))
            height, width, channels = pixels.shape
            index = self._library.raw.hairis_scene_add_texture_pixels(
                self, text, _ptr(pixels, c_float), width, height, channels)
            function = "hairis_scene_add_texture_pixels"
        if index < 0:
            raise self._library._error(function)
        return index

    def set_mesh_attribute(self, name, values):
        """Per-corner data of the mesh added last: ``name`` 'normal' ((corners, 3)) or 'uv'
        ((corners, 2)), in the order of its triangle indices."""
        values = np.ascontiguousarray(values, np.float32).reshape(-1)
        status = self._library.raw.hairis_scene_set_mesh_attribute(
            self, options({"name": name}).encode(), _ptr(values, c_float), values.size)
        self._library._status("hairis_scene_set_mesh_attribute", status)

    def add_curves(self, material, first, positions, radii, normals=None):
        """Adds curves: ``first`` (curves+1) offsets, world ``positions`` (p, 3), ``radii`` (p)
        and optionally the curve ``normals`` (p, 3) that orient elliptical Huang fibers."""
        first = _array(first, np.uint32, (), "first").reshape(-1)
        positions = _array(positions, np.float32, (3,), "positions")
        radii = _array(radii, np.float32, (), "radii").reshape(-1)
        if first.size < 1:
            raise ValueError("first needs curve_count + 1 entries")
        if radii.size != positions.shape[0]:
            raise ValueError("radii needs %d values, got %d" % (positions.shape[0], radii.size))
        if normals is None:
            status = self._library.raw.hairis_scene_add_curves(
                self, int(material), first.size - 1, _ptr(first, c_uint32), positions.shape[0],
                _ptr(positions, c_float), _ptr(radii, c_float))
            self._library._status("hairis_scene_add_curves", status)
            return
        normals = _array(normals, np.float32, (3,), "normals")
        if normals.shape[0] != positions.shape[0]:
            raise ValueError("normals needs %d rows, got %d"
                             % (positions.shape[0], normals.shape[0]))
        status = self._library.raw.hairis_scene_add_curves_with_normals(
            self, int(material), first.size - 1, _ptr(first, c_uint32), positions.shape[0],
            _ptr(positions, c_float), _ptr(radii, c_float), _ptr(normals, c_float), b"")
        self._library._status("hairis_scene_add_curves_with_normals", status)

    def add_hair_mixture(self, materials, weights):
        """Adds a hair material mixing the hair ``materials`` (indices) with ``weights``, as
        Cycles renders a Mix or Add Shader of Principled Hair BSDFs; returns its index."""
        materials = np.ascontiguousarray(materials, dtype=np.int32).reshape(-1)
        weights = np.ascontiguousarray(weights, dtype=np.float32).reshape(-1)
        if materials.size != weights.size:
            raise ValueError("one weight per material: %d materials, %d weights"
                             % (materials.size, weights.size))
        index = self._library.raw.hairis_scene_add_hair_mixture(
            self, materials.size, _ptr(materials, c_int), _ptr(weights, c_float))
        if index < 0:
            raise self._library._error("hairis_scene_add_hair_mixture")
        return index

    def add_curves_with_inputs(self, material, first, positions, radii, inputs):
        """Adds curves as :meth:`add_curves` whose hair material's node inputs vary:
        ``inputs`` maps a name of :data:`CURVE_INPUTS` to ('curve' | 'point', values of shape
        (curves or points, components))."""
        first = _array(first, np.uint32, (), "first").reshape(-1)
        positions = _array(positions, np.float32, (3,), "positions")
        radii = _array(radii, np.float32, (), "radii").reshape(-1)
        if first.size < 1:
            raise ValueError("first needs curve_count + 1 entries")
        curve_count, point_count = first.size - 1, positions.shape[0]
        names, chunks = {}, []
        for name in CURVE_INPUTS:
            if name not in inputs:
                continue
            domain, values = inputs[name]
            count = {"curve": curve_count, "point": point_count}.get(domain)
            if count is None:
                raise ValueError("input %r: domain must be 'curve' or 'point', got %r"
                                 % (name, domain))
            components = CURVE_INPUT_COMPONENTS.get(name, 1)
            values = _array(values, np.float32, (), name).reshape(-1)
            if values.size != count * components:
                raise ValueError("input %r needs %d values (%d %ss of %d), got %d"
                                 % (name, count * components, count, domain, components,
                                    values.size))
            names[name] = domain
            chunks.append(values)
        unknown = set(inputs) - set(CURVE_INPUTS)
        if unknown:
            raise ValueError("unknown curve inputs %s (known: %s)"
                             % (sorted(unknown), ", ".join(CURVE_INPUTS)))
        values = np.ascontiguousarray(np.concatenate(chunks) if chunks else np.zeros(0),
                                      dtype=np.float32)
        status = self._library.raw.hairis_scene_add_curves_with_inputs(
            self, int(material), curve_count, _ptr(first, c_uint32), point_count,
            _ptr(positions, c_float), _ptr(radii, c_float), options(names).encode(), values.size,
            _ptr(values, c_float))
        self._library._status("hairis_scene_add_curves_with_inputs", status)

    def add_mesh(self, positions, indices, materials):
        """Adds a world-space triangle mesh; ``materials`` holds one index per triangle."""
        positions = _array(positions, np.float32, (3,), "positions")
        indices = _array(indices, np.uint32, (3,), "indices")
        materials = _array(materials, np.int32, (), "materials").reshape(-1)
        if materials.size != indices.shape[0]:
            raise ValueError("materials needs %d values, got %d"
                             % (indices.shape[0], materials.size))
        status = self._library.raw.hairis_scene_add_mesh(
            self, positions.shape[0], _ptr(positions, c_float), indices.shape[0],
            _ptr(indices, c_uint32), _ptr(materials, c_int32))
        self._library._status("hairis_scene_add_mesh", status)

    def add_light(self, values):
        """Adds a light from light options (hairis_render.h: type sun, point, spot or area)."""
        status = self._library.raw.hairis_scene_add_light(self, options(values).encode())
        self._library._status("hairis_scene_add_light", status)

    def add_sun(self, direction, color, strength, angle):
        """A sun; ``direction`` points from the scene towards the sun."""
        self.add_light({"type": "sun", "direction": direction, "color": color,
                        "strength": float(strength), "angle": float(angle)})

    def add_point_light(self, position, color, power, radius):
        """A point light of ``power`` W and ``radius`` m."""
        self.add_light({"type": "point", "position": position, "color": color,
                        "power": float(power), "radius": float(radius)})

    def add_area_light(self, light_to_world, shape, size_x, size_y, color, power):
        """An area light: row-major 4×4 object matrix, shape (one of AREA_SHAPES), sizes, power."""
        self.add_light({"type": "area", "matrix": light_to_world, "shape": str(shape).lower(),
                        "size": float(size_x), "size_y": float(size_y), "color": color,
                        "power": float(power)})

    def add_spot_light(self, light_to_world, color, power, radius, spot_size, spot_blend):
        """A spot light: row-major 4×4 object matrix (it shines along its −Z), power in W,
        radius (shadow_soft_size) in m, spot_size (full cone angle, radians), spot_blend."""
        self.add_light({"type": "spot", "matrix": light_to_world, "color": color,
                        "power": float(power), "radius": float(radius),
                        "spot_size": float(spot_size), "spot_blend": float(spot_blend)})

    def set_world(self, color, strength):
        """A constant background radiance colour·strength."""
        self.set_world_options({"color": color, "strength": float(strength)})

    def set_world_options(self, values):
        """The world from world options (hairis_render.h: a constant, or image=<path> with
        the environment's mapping and sampling)."""
        status = self._library.raw.hairis_scene_set_world(self, options(values).encode())
        self._library._status("hairis_scene_set_world", status)

    def set_world_pixels(self, values, pixels):
        """An environment world from an image as an array: ``pixels`` (height, width,
        channels) floats, bottom row first (Blender's ``Image.pixels`` reshaped), with world
        options (no image; color_space 'linear' or 'srgb')."""
        pixels = np.ascontiguousarray(pixels, np.float32)
        if pixels.ndim == 2:
            pixels = pixels[:, :, None]
        if pixels.ndim != 3:
            raise ValueError("pixels must be (height, width, channels), got shape %s"
                             % (pixels.shape,))
        height, width, channels = pixels.shape
        status = self._library.raw.hairis_scene_set_world_pixels(
            self, options(values).encode(), _ptr(pixels, c_float), width, height, channels)
        self._library._status("hairis_scene_set_world_pixels", status)

    def reset_shading(self):
        """Removes the materials, textures, lights and world, keeping the geometry and its
        BVH: add them again, materials in their first order, to render an edit of them."""
        status = self._library.raw.hairis_scene_reset_shading(self)
        self._library._status("hairis_scene_reset_shading", status)
        self._tables = []

    def set_camera(self, camera):
        """Sets the camera from camera options (a dict: matrix, orthographic, frame, width,
        height, clip_start, clip_end), which also fix the output resolution."""
        status = self._library.raw.hairis_scene_set_camera(self, options(camera).encode())
        self._library._status("hairis_scene_set_camera", status)
        self.width = int(camera["width"])
        self.height = int(camera["height"])

    def render(self, settings, progress=None, out=None):
        """Renders with render settings (dict or string); returns (rgba (height, width, 4)
        bottom row first, :class:`RenderStats`).

        ``progress(p) -> bool`` is called with p in [0, 1]; returning True cancels, which
        raises :class:`HairisCancelled` whose ``rgba`` attribute holds the partial image.
        """
        if self.width is None:
            raise HairisError("hairis_render", "the scene has no camera (call set_camera first)")
        if out is None:
            out = np.zeros((self.height, self.width, 4), np.float32)
        elif (out.shape != (self.height, self.width, 4) or out.dtype != np.float32
              or not out.flags.c_contiguous):
            raise ValueError("out must be a C-contiguous float32 (%d, %d, 4) array"
                             % (self.height, self.width))
        adapter = _Progress(progress)
        status = self._library.raw.hairis_render(self, options(settings).encode(),
                                                 _ptr(out, c_float), adapter.function, None)
        stats = RenderStats(_decode(self._library.raw.hairis_last_render_stats()))
        if status != OK or adapter.error is not None:
            error = self._library._error("hairis_render", status if status != OK else None,
                                         adapter)
            error.rgba = out
            error.stats = stats
            raise error
        return out, stats

    def render_progressive(self, settings, update=None, passes=(), out=None):
        """Renders refining the whole image (``hairis_render_progressive``); returns (rgba
        (height, width, 4), {pass: (height, width, channels)}, :class:`RenderStats`), bottom
        row first.

        ``passes`` names the library's passes (depth 1 channel; normal, denoising_albedo,
        denoising_normal 3), also set as the ``passes`` option. ``update(progress,
        samples_done, final, rgba, passes) -> bool`` sees the current average image (valid
        only during the call); True stops the render, which raises :class:`HairisCancelled`
        whose ``rgba`` and ``passes`` hold the partial image.
        """
        if self.width is None:
            raise HairisError("hairis_render_progressive",
                              "the scene has no camera (call set_camera first)")
        shape = (self.height, self.width, 4)
        if out is None:
            out = np.zeros(shape, np.float32)
        elif out.shape != shape or out.dtype != np.float32 or not out.flags.c_contiguous:
            raise ValueError("out must be a C-contiguous float32 %s array" % (shape,))
        passes = list(passes)
        channels = [PASS_CHANNELS[name] for name in passes]
        buffer = np.zeros(self.width * self.height * sum(channels), np.float32)
        images, offset = {}, 0
        for name, count in zip(passes, channels):
            size = self.width * self.height * count
            images[name] = buffer[offset:offset + size].reshape(self.height, self.width, count)
            offset += size
        values = parse_options(options(settings)) if not isinstance(settings, dict) \
            else dict(settings)
        if passes:
            values["passes"] = ",".join(passes)
        adapter = _Update(update, out, images)
        status = self._library.raw.hairis_render_progressive(
            self, options(values).encode(), _ptr(out, c_float),
            _ptr(buffer, c_float) if buffer.size else None, adapter.function, None)
        stats = RenderStats(_decode(self._library.raw.hairis_last_render_stats()))
        if status != OK or adapter.error is not None:
            error = self._library._error("hairis_render_progressive",
                                         status if status != OK else None, adapter)
            error.rgba = out
            error.passes = images
            error.stats = stats
            raise error
        return out, images, stats


PASS_CHANNELS = {"depth": 1, "normal": 3, "denoising_albedo": 3, "denoising_normal": 3}
"""The channels of each pass of ``hairis_render_progressive``."""


class _Update(_Progress):
    """Adapts ``update(progress, samples_done, final, rgba, passes) -> bool`` to
    ``hairis_update_fn`` (None: no callback); errors are kept as :class:`_Progress` keeps
    them."""

    def __init__(self, callback, rgba, passes):
        self.rgba = rgba
        self.passes = passes
        self.callback = callback
        self.cancel_requested = False
        self.error = None
        self.function = UPDATE_FN(self._call) if callback is not None else UPDATE_FN()

    def _call(self, _user, progress, samples_done, final):
        if self.cancel_requested:
            return 1
        try:
            if self.callback(float(progress), int(samples_done), bool(final), self.rgba,
                             self.passes):
                self.cancel_requested = True
        except BaseException as error:  # noqa: B902 - must never propagate into C
            self.error = error
            self.cancel_requested = True
        return 1 if self.cancel_requested else 0


# ---- Loading ---------------------------------------------------------------------------------

def load_library(path=None):
    """Loads the library (``path``, else :func:`library_path`); raises LibraryUnavailable.

    Loading is cheap after the first time (the dynamic loader keeps the library mapped), so
    callers load where they need it instead of keeping a global handle.
    """
    return Library(path or library_path())


class LibraryStatus:
    """What :func:`library_status` found: ``ok``, ``path``, ``version`` and a ``message``."""

    def __init__(self, ok, path, message, version=None):
        self.ok = ok
        self.path = path
        self.message = message
        self.version = version

    def __repr__(self):
        return "<LibraryStatus ok=%r %s>" % (self.ok, self.message)


def library_status(path=None):
    """Tries to load the library and says how it went, without raising."""
    path = path or library_path()
    try:
        library = Library(path)
    except LibraryUnavailable as error:
        return LibraryStatus(False, path, str(error))
    except Exception as error:  # noqa: BLE001 - a status report must never raise
        return LibraryStatus(False, path, "hairis native library not found at %s: %s"
                             % (path, error))
    return LibraryStatus(True, path, "hairis %s (API %d) loaded from %s"
                         % (library.version, library.api_version, path), library.version)
