"""ctypes binding of the hairis C API (``lib/include/hairis/hairis.h``).

Every function and struct of the header is bound here with its exact signature and field
layout. :func:`load_library` finds ``libhairis.so`` (the ``HAIRIS_LIBRARY`` environment
variable, else ``lib/`` inside this package), checks ``hairis_api_version() == 1`` and
returns a :class:`Library` whose methods raise :class:`HairisError` (carrying
``hairis_last_error()``) on every failing call. Nothing here imports ``bpy``: the module can be
used, and tested, outside Blender.

Handles (fibers, tables, samplers, scenes) are wrapped in small classes that release the C
object on :meth:`close`, on leaving a ``with`` block, or when garbage collected.
"""

import ctypes
import os
import sys
from ctypes import POINTER, c_char_p, c_double, c_float, c_int, c_int32, c_size_t, c_uint32
from ctypes import c_uint64, c_void_p

import numpy as np

API_VERSION = 1
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

# hairis_strategy.
STRATEGY_UNIFORM = 0
STRATEGY_ANALYTIC = 1
STRATEGY_GAUSSIAN = 2
STRATEGY_TABLE = 3
STRATEGIES = {
    "UNIFORM": STRATEGY_UNIFORM,
    "ANALYTIC": STRATEGY_ANALYTIC,
    "GAUSSIAN": STRATEGY_GAUSSIAN,
    "TABLE": STRATEGY_TABLE,
}

# hairis_parametrization.
PARAM_ABSORPTION = 0
PARAM_MELANIN = 1
PARAM_COLOR = 2

# hairis_area_shape.
AREA_SQUARE = 0
AREA_RECTANGLE = 1
AREA_DISK = 2
AREA_ELLIPSE = 3
AREA_SHAPES = {
    "SQUARE": AREA_SQUARE,
    "RECTANGLE": AREA_RECTANGLE,
    "DISK": AREA_DISK,
    "ELLIPSE": AREA_ELLIPSE,
}


# ---- Structs ---------------------------------------------------------------------------------

class PrincipledHair(ctypes.Structure):
    """``hairis_principled_hair``: the inputs of Blender's Principled Hair BSDF node."""

    _fields_ = [
        ("parametrization", c_int),
        ("color", c_float * 3),
        ("melanin", c_float),
        ("melanin_redness", c_float),
        ("tint", c_float * 3),
        ("absorption_coefficient", c_float * 3),
        ("roughness", c_float),
        ("radial_roughness", c_float),
        ("coat", c_float),
        ("ior", c_float),
        ("offset", c_float),
        ("random_color", c_float),
        ("random_roughness", c_float),
        ("random", c_float),
    ]

    def to_dict(self):
        """The fields as a dict of Python numbers (arrays as tuples)."""
        return {name: _field_value(getattr(self, name)) for name, _ in self._fields_}

    def update(self, values):
        """Sets the fields named in the mapping ``values`` (unknown names raise KeyError)."""
        names = {name for name, _ in self._fields_}
        for name, value in values.items():
            if name not in names:
                raise KeyError("hairis_principled_hair has no field %r" % name)
            _set_field(self, name, value)
        return self


class MarschnerParams(ctypes.Structure):
    """``hairis_marschner_params``: Marschner 2003 fiber parameters."""

    _fields_ = [
        ("eta", c_float),
        ("sigma_a", c_float * 3),
        ("alpha_r", c_float),
        ("alpha_tt", c_float),
        ("alpha_trt", c_float),
        ("beta_r", c_float),
        ("beta_tt", c_float),
        ("beta_trt", c_float),
        ("eccentricity", c_float),
        ("glint_scale", c_float),
        ("caustic_width", c_float),
        ("caustic_fade", c_float),
        ("caustic_intensity_limit", c_float),
    ]

    def to_dict(self):
        """The fields as a dict of Python numbers (arrays as tuples)."""
        return {name: _field_value(getattr(self, name)) for name, _ in self._fields_}


class BakeOptions(ctypes.Structure):
    """``hairis_bake_options``: resolution and content of a table bake."""

    _fields_ = [
        ("theta_r_count", c_int),
        ("theta_i_count", c_int),
        ("phi_count", c_int),
        ("n_h_count", c_int),
        ("n_h_values", c_int * 16),
        ("source", c_int),
        ("threads", c_int),
    ]

    def n_h_list(self):
        """The n_h values in use, as a list."""
        return list(self.n_h_values[:max(0, min(self.n_h_count, 16))])

    def set_n_h_list(self, values):
        """Sets ``n_h_values``/``n_h_count`` from an increasing sequence of at most 16 ints."""
        values = [int(v) for v in values]
        if len(values) > 16:
            raise ValueError("at most 16 n_h values, got %d" % len(values))
        self.n_h_count = len(values)
        for i in range(16):
            self.n_h_values[i] = values[i] if i < len(values) else 0


class Camera(ctypes.Structure):
    """``hairis_camera``: a camera as Blender describes it (row-major camera-to-world)."""

    _fields_ = [
        ("camera_to_world", c_float * 16),
        ("orthographic", c_int),
        ("frame", c_float * 12),
        ("width", c_int),
        ("height", c_int),
    ]


class RenderSettings(ctypes.Structure):
    """``hairis_render_settings``: the add-on's ``scene.hairis``."""

    _fields_ = [
        ("samples", c_int),
        ("max_bounces", c_int),
        ("strategy", c_int),
        ("multiple_weight", c_float),
        ("n_h", c_int),
        ("seed", c_uint64),
        ("threads", c_int),
    ]


class RenderStats(ctypes.Structure):
    """``hairis_render_stats``: what a render did."""

    _fields_ = [
        ("seconds", c_double),
        ("camera_rays", c_uint64),
        ("dropped_samples", c_uint64),
        ("peak_memory_bytes", c_uint64),
    ]


STRUCTS = {
    "hairis_principled_hair": PrincipledHair,
    "hairis_marschner_params": MarschnerParams,
    "hairis_bake_options": BakeOptions,
    "hairis_camera": Camera,
    "hairis_render_settings": RenderSettings,
    "hairis_render_stats": RenderStats,
}
"""The C struct names and their ctypes mirrors."""

PROGRESS_FN = ctypes.CFUNCTYPE(c_int, c_void_p, c_float)
"""``hairis_progress_fn``: ``int (*)(void *user, float progress)``; non-zero cancels."""

_F = POINTER(c_float)
_VOID = None

# name: (restype, argtypes). Keep in the header's order.
SIGNATURES = {
    # Library
    "hairis_api_version": (c_int, []),
    "hairis_version_string": (c_char_p, []),
    "hairis_last_error": (c_char_p, []),
    # Fibers
    "hairis_principled_hair_defaults": (_VOID, [POINTER(PrincipledHair)]),
    "hairis_marschner_defaults": (_VOID, [POINTER(MarschnerParams)]),
    "hairis_fiber_create_principled": (c_void_p, [POINTER(PrincipledHair)]),
    "hairis_fiber_create_marschner": (c_void_p, [POINTER(MarschnerParams)]),
    "hairis_fiber_destroy": (_VOID, [c_void_p]),
    "hairis_fiber_model": (c_char_p, [c_void_p]),
    "hairis_fiber_parameters": (c_char_p, [c_void_p]),
    "hairis_fiber_eval": (c_int, [c_void_p, c_size_t, _F, _F, _F, _F]),
    # Tables
    "hairis_bake_options_defaults": (_VOID, [POINTER(BakeOptions)]),
    "hairis_tables_bake": (c_void_p, [c_void_p, POINTER(BakeOptions), PROGRESS_FN, c_void_p]),
    "hairis_tables_write": (c_int, [c_void_p, c_char_p]),
    "hairis_tables_load_file": (c_void_p, [c_char_p]),
    "hairis_tables_load_memory": (c_void_p, [c_void_p, c_size_t]),
    "hairis_tables_destroy": (_VOID, [c_void_p]),
    "hairis_tables_model": (c_char_p, [c_void_p]),
    "hairis_tables_parameters": (c_char_p, [c_void_p]),
    "hairis_tables_match_fiber": (c_int, [c_void_p, c_void_p]),
    # Sampling
    "hairis_sampler_create": (c_void_p, [c_int, c_void_p, c_void_p, c_float, c_int]),
    "hairis_sampler_destroy": (_VOID, [c_void_p]),
    "hairis_sample": (c_int, [c_void_p, c_size_t, _F, _F, _F, _F, _F]),
    "hairis_pdf": (c_int, [c_void_p, c_size_t, _F, _F, _F, _F]),
    # Scenes and rendering
    "hairis_scene_create": (c_void_p, []),
    "hairis_scene_destroy": (_VOID, [c_void_p]),
    "hairis_scene_add_hair_material": (c_int, [c_void_p, POINTER(PrincipledHair), c_void_p]),
    "hairis_scene_add_diffuse_material": (c_int, [c_void_p, _F, _F]),
    "hairis_scene_add_curves": (c_int, [c_void_p, c_int, c_size_t, POINTER(c_uint32), c_size_t,
                                        _F, _F]),
    "hairis_scene_add_mesh": (c_int, [c_void_p, c_size_t, _F, c_size_t, POINTER(c_uint32),
                                      POINTER(c_int32)]),
    "hairis_scene_add_sun": (c_int, [c_void_p, _F, _F, c_float, c_float]),
    "hairis_scene_add_point_light": (c_int, [c_void_p, _F, _F, c_float, c_float]),
    "hairis_scene_add_area_light": (c_int, [c_void_p, _F, c_int, c_float, c_float, _F, c_float]),
    "hairis_scene_set_world": (c_int, [c_void_p, _F, c_float]),
    "hairis_scene_set_camera": (c_int, [c_void_p, POINTER(Camera)]),
    "hairis_render_settings_defaults": (_VOID, [POINTER(RenderSettings)]),
    "hairis_render": (c_int, [c_void_p, POINTER(RenderSettings), _F, PROGRESS_FN, c_void_p,
                              POINTER(RenderStats)]),
}
"""Every function of hairis.h: name → (restype, argtypes)."""


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

def _field_value(value):
    if isinstance(value, ctypes.Array):
        return tuple(value)
    return value


def _set_field(struct, name, value):
    current = getattr(struct, name)
    if isinstance(current, ctypes.Array):
        values = list(value)
        if len(values) != len(current):
            raise ValueError("field %s needs %d values, got %d" % (name, len(current), len(values)))
        for i, v in enumerate(values):
            current[i] = v
    else:
        setattr(struct, name, value)


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


def _vec3(values, what):
    array = np.ascontiguousarray(values, dtype=np.float32).reshape(-1)
    if array.size != 3:
        raise ValueError("%s needs 3 values, got %d" % (what, array.size))
    return array


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
        for name, (restype, argtypes) in SIGNATURES.items():
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

    def principled_hair_defaults(self):
        """The Principled Hair BSDF node's Blender 3.4 defaults."""
        node = PrincipledHair()
        self.raw.hairis_principled_hair_defaults(ctypes.byref(node))
        return node

    def marschner_defaults(self):
        """The seed's Marschner defaults."""
        params = MarschnerParams()
        self.raw.hairis_marschner_defaults(ctypes.byref(params))
        return params

    def bake_options_defaults(self):
        """The default table resolution."""
        options = BakeOptions()
        self.raw.hairis_bake_options_defaults(ctypes.byref(options))
        return options

    def render_settings_defaults(self):
        """The default render settings."""
        settings = RenderSettings()
        self.raw.hairis_render_settings_defaults(ctypes.byref(settings))
        return settings

    # -- objects --

    def fiber_principled(self, node):
        """A Chiang 2016 fiber from a :class:`PrincipledHair` (or a dict of its fields)."""
        if not isinstance(node, PrincipledHair):
            node = self.principled_hair_defaults().update(node)
        pointer = self.raw.hairis_fiber_create_principled(ctypes.byref(node))
        return Fiber(self, self._handle("hairis_fiber_create_principled", pointer))

    def fiber_marschner(self, params):
        """A Marschner 2003 fiber from :class:`MarschnerParams`."""
        pointer = self.raw.hairis_fiber_create_marschner(ctypes.byref(params))
        return Fiber(self, self._handle("hairis_fiber_create_marschner", pointer))

    def bake_tables(self, fiber, options=None, progress=None):
        """Bakes tables for ``fiber``; ``progress(p) -> bool`` may cancel (HairisCancelled)."""
        if options is None:
            options = self.bake_options_defaults()
        adapter = _Progress(progress)
        pointer = self.raw.hairis_tables_bake(fiber, ctypes.byref(options), adapter.function, None)
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
        data = bytes(data)
        buffer = ctypes.create_string_buffer(data, len(data))
        pointer = self.raw.hairis_tables_load_memory(buffer, len(data))
        return Tables(self, self._handle("hairis_tables_load_memory", pointer))

    def sampler(self, strategy, fiber=None, tables=None, multiple_weight=0.0, n_h=2):
        """A direction sampler; ``strategy`` is a name ('TABLE', ...) or a hairis_strategy."""
        if isinstance(strategy, str):
            strategy = STRATEGIES[strategy]
        pointer = self.raw.hairis_sampler_create(int(strategy), fiber, tables,
                                                 float(multiple_weight), int(n_h))
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

    def add_hair_material(self, node, tables=None):
        """Adds a hair material from a :class:`PrincipledHair` (or a dict); returns its index."""
        if not isinstance(node, PrincipledHair):
            node = self._library.principled_hair_defaults().update(node)
        index = self._library.raw.hairis_scene_add_hair_material(self, ctypes.byref(node), tables)
        if index < 0:
            raise self._library._error("hairis_scene_add_hair_material")
        if tables is not None:
            self._tables.append(tables)
        return index

    def add_diffuse_material(self, albedo, emission=(0.0, 0.0, 0.0)):
        """Adds a Lambert material with an emission; returns its index."""
        albedo = _vec3(albedo, "albedo")
        emission = _vec3(emission, "emission")
        index = self._library.raw.hairis_scene_add_diffuse_material(
            self, _ptr(albedo, c_float), _ptr(emission, c_float))
        if index < 0:
            raise self._library._error("hairis_scene_add_diffuse_material")
        return index

    def add_curves(self, material, first, positions, radii):
        """Adds curves: ``first`` (curves+1) offsets, world ``positions`` (p, 3), ``radii`` (p)."""
        first = _array(first, np.uint32, (), "first").reshape(-1)
        positions = _array(positions, np.float32, (3,), "positions")
        radii = _array(radii, np.float32, (), "radii").reshape(-1)
        if first.size < 1:
            raise ValueError("first needs curve_count + 1 entries")
        if radii.size != positions.shape[0]:
            raise ValueError("radii needs %d values, got %d" % (positions.shape[0], radii.size))
        status = self._library.raw.hairis_scene_add_curves(
            self, int(material), first.size - 1, _ptr(first, c_uint32), positions.shape[0],
            _ptr(positions, c_float), _ptr(radii, c_float))
        self._library._status("hairis_scene_add_curves", status)

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

    def add_sun(self, direction, color, strength, angle):
        """A sun; ``direction`` points from the scene towards the sun."""
        direction = _vec3(direction, "direction")
        color = _vec3(color, "color")
        status = self._library.raw.hairis_scene_add_sun(
            self, _ptr(direction, c_float), _ptr(color, c_float), float(strength), float(angle))
        self._library._status("hairis_scene_add_sun", status)

    def add_point_light(self, position, color, power, radius):
        """A point light of ``power`` W and ``radius`` m."""
        position = _vec3(position, "position")
        color = _vec3(color, "color")
        status = self._library.raw.hairis_scene_add_point_light(
            self, _ptr(position, c_float), _ptr(color, c_float), float(power), float(radius))
        self._library._status("hairis_scene_add_point_light", status)

    def add_area_light(self, light_to_world, shape, size_x, size_y, color, power):
        """An area light: row-major 4×4 object matrix, shape (name or enum), sizes, power."""
        matrix = np.ascontiguousarray(light_to_world, dtype=np.float32).reshape(-1)
        if matrix.size != 16:
            raise ValueError("light_to_world needs 16 values, got %d" % matrix.size)
        if isinstance(shape, str):
            shape = AREA_SHAPES[shape]
        color = _vec3(color, "color")
        status = self._library.raw.hairis_scene_add_area_light(
            self, _ptr(matrix, c_float), int(shape), float(size_x), float(size_y),
            _ptr(color, c_float), float(power))
        self._library._status("hairis_scene_add_area_light", status)

    def set_world(self, color, strength):
        """A constant background radiance colour·strength."""
        color = _vec3(color, "color")
        status = self._library.raw.hairis_scene_set_world(self, _ptr(color, c_float),
                                                          float(strength))
        self._library._status("hairis_scene_set_world", status)

    def set_camera(self, camera):
        """Sets the :class:`Camera` (which also fixes the output resolution)."""
        status = self._library.raw.hairis_scene_set_camera(self, ctypes.byref(camera))
        self._library._status("hairis_scene_set_camera", status)
        self.width = int(camera.width)
        self.height = int(camera.height)

    def render(self, settings, progress=None, out=None):
        """Renders; returns (rgba (height, width, 4) bottom row first, :class:`RenderStats`).

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
        stats = RenderStats()
        adapter = _Progress(progress)
        status = self._library.raw.hairis_render(self, ctypes.byref(settings), _ptr(out, c_float),
                                                 adapter.function, None, ctypes.byref(stats))
        if status != OK or adapter.error is not None:
            error = self._library._error("hairis_render", status if status != OK else None,
                                         adapter)
            error.rgba = out
            error.stats = stats
            raise error
        return out, stats


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
