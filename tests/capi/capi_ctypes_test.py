#!/usr/bin/env python3
"""Tests of the hairis C API through Python's ctypes, the way the Blender add-on loads it.

Usage (CTest passes every option):
    capi_ctypes_test.py --library libhairis.so --header hairis.h --header hairis_render.h
                        [--nm nm] [--addon-native addon/hairis/native.py]
                        [--fake-library libhairis_fake.so] [--version X.Y.Z]
                        [unittest options]

The library is called through the add-on's ctypes prototypes (``PROTOTYPES`` in
addon/hairis/native.py, the one copy; --addon-native, by default found from this file).
TestPrototypes parses the headers' HAIRIS_API prototypes (a small strict parser for their
regular style, parse_prototypes) into ctypes types and fails, naming the function, when one
is missing from PROTOTYPES, extra in it, or declared otherwise. It also checks that
libhairis.so, and the add-on tests' stand-in libhairis_fake.so (--fake-library), define
exactly the headers' functions (``nm -D --defined-only``). Exits non-zero on a failure; 77
(skip) when numpy is missing.
"""

import argparse
import ctypes
import importlib.util
import os
import re
import subprocess
import sys
import tempfile
import threading
import unittest
from ctypes import CFUNCTYPE, POINTER, c_char_p, c_double, c_float, c_int, c_int32, c_size_t
from ctypes import c_uint32, c_uint64, c_void_p

try:
    import numpy as np
except ImportError:  # pragma: no cover - reported as a skip
    np = None

OPTIONS = None  # parsed command line

# The status codes: native.py's (set by main()), which TestPrototypes checks against the headers.
OK = ERROR_INVALID_ARGUMENT = ERROR_IO = ERROR_INVALID_TABLE = None
ERROR_CANCELLED = ERROR_INTERNAL = None
STATUS_NAMES = None

KINDS = ("chiang", "huang", "marschner", "bake", "sampler", "diffuse", "principled", "glossy",
         "emission", "mix", "add", "texture", "sun", "point", "area", "world", "camera", "render",
         "curve_inputs")

# ---- The prototypes: the add-on's table, loaded by main() ----------------------------------

# addon/hairis/native.py (imports no bpy): its PROTOTYPES and PROGRESS_FN are the ones the
# library is called through here, so the binding Blender uses is the one these tests exercise.
PROTOTYPES = None
PROGRESS_FN = None
UPDATE_FN = None

F = POINTER(c_float)
U32 = POINTER(c_uint32)


def load_native(path):
    """The add-on's native.py as a module of its own (its package's __init__ imports bpy)."""
    spec = importlib.util.spec_from_file_location("hairis_addon_native", path)
    native = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(native)
    return native


# ---- The headers' prototypes as ctypes types --------------------------------------------------

# C scalar types and the ctypes type of each (pointers to them: POINTER of it).
C_SCALARS = {
    "int": c_int, "float": c_float, "double": c_double, "size_t": c_size_t,
    "int32_t": c_int32, "uint32_t": c_uint32, "uint64_t": c_uint64,
}


class HeaderError(Exception):
    """A declaration the parser does not understand (it is strict on purpose)."""


def _strip(text):
    """The header without comments and preprocessor lines."""
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    return "\n".join(line for line in text.splitlines() if not line.lstrip().startswith("#"))


def _parse_type(text, handles, callbacks, where):
    """The ctypes type of a C type (`const` ignored): None for void."""
    tokens = re.findall(r"\*|[A-Za-z_]\w*|\S", text)
    if any(t != "*" and not re.match(r"[A-Za-z_]\w*$", t) for t in tokens):
        raise HeaderError("%s: cannot read the type %r" % (where, text))
    tokens = [t for t in tokens if t != "const"]
    stars = tokens.count("*")
    names = [t for t in tokens if t != "*"]
    if len(names) != 1 or (stars and tokens[-stars:] != ["*"] * stars):
        raise HeaderError("%s: cannot read the type %r" % (where, text))
    base = names[0]
    if stars > 1:
        raise HeaderError("%s: pointer to pointer in %r" % (where, text))
    if base == "void":
        return c_void_p if stars else None
    if base == "char":
        if not stars:
            raise HeaderError("%s: a char by value in %r" % (where, text))
        return c_char_p
    if base in handles:
        if not stars:
            raise HeaderError("%s: opaque %s by value" % (where, base))
        return c_void_p
    if base in callbacks:
        if stars:
            raise HeaderError("%s: pointer to a callback in %r" % (where, text))
        return callbacks[base]
    if base in C_SCALARS:
        return POINTER(C_SCALARS[base]) if stars else C_SCALARS[base]
    raise HeaderError("%s: unknown type %r" % (where, text))


def _parse_parameters(text, handles, callbacks, where):
    """The ctypes types of a parameter list "type name, ..." ("void": none)."""
    text = text.strip()
    if text == "void":
        return []
    if not text or "(" in text or "[" in text or "..." in text:
        raise HeaderError("%s: cannot read the parameters %r" % (where, text))
    types = []
    for parameter in text.split(","):
        match = re.match(r"^(.*?)\b([A-Za-z_]\w*)\s*$", parameter.strip(), re.S)
        if not match or not match.group(1).strip():
            raise HeaderError("%s: a parameter needs a type and a name: %r" % (where, parameter))
        types.append(_parse_type(match.group(1), handles, callbacks, where))
    return types


def parse_prototypes(texts):
    """{name: (restype, [argtypes])} of every HAIRIS_API function in the header texts."""
    text = "\n".join(_strip(t) for t in texts)
    handles = set(re.findall(r"typedef\s+struct\s+(hairis_\w+)\s+\1\s*;", text))
    callbacks = {}
    for ret, name, params in re.findall(
            r"typedef\s+([^;()]+?)\s*\(\s*\*\s*(hairis_\w+)\s*\)\s*\(([^;()]*)\)\s*;", text):
        where = "typedef " + name
        restype = _parse_type(ret, handles, callbacks, where)
        callbacks[name] = CFUNCTYPE(restype, *_parse_parameters(params, handles, callbacks, where))
    prototypes = {}
    for declaration in re.findall(r"\bHAIRIS_API\b([^;]*);", text):
        declaration = " ".join(declaration.split())
        match = re.match(r"^(.+?)\b(hairis_\w+)\s*\((.*)\)$", declaration)
        if not match:
            raise HeaderError("cannot read the declaration %r" % declaration)
        ret, name, params = match.groups()
        if name in prototypes:
            raise HeaderError("%s is declared twice" % name)
        prototypes[name] = (_parse_type(ret, handles, callbacks, name),
                            _parse_parameters(params, handles, callbacks, name))
    if not prototypes:
        raise HeaderError("no HAIRIS_API declarations found")
    return prototypes


def same_type(a, b):
    """Whether two ctypes types pass and return alike (callbacks by their prototype)."""
    if a is None or b is None:
        return a is b
    if isinstance(a, type) and isinstance(b, type):
        func_base = ctypes._CFuncPtr  # the base of CFUNCTYPE types
        if issubclass(a, func_base) or issubclass(b, func_base):
            return (issubclass(a, func_base) and issubclass(b, func_base) and
                    a._flags_ == b._flags_ and same_type(a._restype_, b._restype_) and
                    len(a._argtypes_) == len(b._argtypes_) and
                    all(same_type(x, y) for x, y in zip(a._argtypes_, b._argtypes_)))
        if issubclass(a, ctypes._Pointer) or issubclass(b, ctypes._Pointer):
            return (issubclass(a, ctypes._Pointer) and issubclass(b, ctypes._Pointer) and
                    same_type(a._type_, b._type_))
    return a is b


def type_name(t):
    """A readable name of a ctypes type."""
    if t is None:
        return "None"
    if isinstance(t, type) and issubclass(t, ctypes._CFuncPtr):
        parts = (t._restype_,) + tuple(t._argtypes_)
        return "CFUNCTYPE(%s)" % ", ".join(type_name(x) for x in parts)
    if isinstance(t, type) and issubclass(t, ctypes._Pointer):
        return "POINTER(%s)" % type_name(t._type_)
    return getattr(t, "__name__", repr(t))


def prototype_problems(expected, declared, who):
    """What differs between the headers' prototypes and a PROTOTYPES dict, one line each."""
    problems = []
    for name in sorted(set(expected) - set(declared)):
        problems.append("%s: %s is missing (the headers declare it)" % (who, name))
    for name in sorted(set(declared) - set(expected)):
        problems.append("%s: %s is not in the headers" % (who, name))
    for name in sorted(set(expected) & set(declared)):
        restype, argtypes = expected[name]
        try:
            got_restype, got_argtypes = declared[name]
        except (TypeError, ValueError):
            problems.append("%s: %s must be (restype, [argtypes])" % (who, name))
            continue
        if not same_type(restype, got_restype):
            problems.append("%s: %s returns %s, the headers say %s" % (
                who, name, type_name(got_restype), type_name(restype)))
        got_argtypes = list(got_argtypes)
        if len(got_argtypes) != len(argtypes):
            problems.append("%s: %s takes %d arguments, the headers say %d" % (
                who, name, len(got_argtypes), len(argtypes)))
            continue
        for i, (want, got) in enumerate(zip(argtypes, got_argtypes)):
            if not same_type(want, got):
                problems.append("%s: %s argument %d is %s, the headers say %s" % (
                    who, name, i + 1, type_name(got), type_name(want)))
    return problems


def header_texts():
    """The text of each --header."""
    texts = []
    for path in OPTIONS.header:
        with open(path) as handle:
            texts.append(handle.read())
    return texts


def header_prototypes():
    return parse_prototypes(header_texts())


# ---- The library -----------------------------------------------------------------------------

_LIB = None


def lib():
    """The library, loaded once, with every prototype declared."""
    global _LIB
    if _LIB is None:
        raw = ctypes.CDLL(OPTIONS.library)
        for name, (restype, argtypes) in PROTOTYPES.items():
            function = getattr(raw, name)
            function.restype = restype
            function.argtypes = argtypes
        _LIB = raw
    return _LIB


def last_error():
    return lib().hairis_last_error().decode("utf-8")


def ptr(array, ctype=c_float):
    return None if array is None else array.ctypes.data_as(POINTER(ctype))


def items(options):
    """{name: value} of "name=value;..."."""
    return dict(item.split("=", 1) for item in options.split(";") if item)


def defaults(kind):
    text = lib().hairis_defaults(kind.encode())
    assert text is not None, last_error()
    return text.decode()


def recording_progress(answer):
    """A progress callback that records each fraction and returns ``answer`` (1 cancels);
    returns (the fractions, the callback)."""
    fractions = []

    def progress(_user, fraction):
        fractions.append(fraction)
        return answer

    return fractions, PROGRESS_FN(progress)


def make_fiber(options=""):
    return lib().hairis_fiber_create(options.encode())


CURVE_INPUTS = ("color", "melanin", "melanin_redness", "tint", "absorption", "roughness",
                "radial_roughness", "coat", "ior", "offset", "random_color", "random_roughness",
                "random") + tuple("weight%d" % k for k in range(8))
"""hairis_render.h's curve inputs in their documented order (node inputs, closure weights)."""

TINY_BAKE = b"theta_r=4;theta_i=8;phi=8;n_h=1,2;threads=2"


def unit_vectors(rng, n):
    v = rng.normal(size=(n, 3)).astype(np.float64)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    v[:, 0] = np.clip(v[:, 0], -0.98, 0.98)  # away from the fiber axis
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return np.ascontiguousarray(v, dtype=np.float32)


_BYTES = None  # EXR bytes of tables baked once for the default fiber


def default_table_bytes():
    """Bakes tables for the default fiber once and returns the EXR file's bytes."""
    global _BYTES
    if _BYTES is None:
        fiber = make_fiber()
        tables = lib().hairis_tables_bake(fiber, TINY_BAKE, PROGRESS_FN(), None)
        assert tables, last_error()
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "default.exr")
            assert lib().hairis_tables_write(tables, path.encode()) == OK, last_error()
            with open(path, "rb") as f:
                _BYTES = f.read()
        lib().hairis_tables_destroy(tables)
        lib().hairis_fiber_destroy(fiber)
    return _BYTES


def load_memory(data):
    buffer = ctypes.create_string_buffer(data, len(data))
    return lib().hairis_tables_load_memory(buffer, len(data))


# ---- Tests -----------------------------------------------------------------------------------

class TestPrototypes(unittest.TestCase):
    """PROTOTYPES dicts against the headers; the library's exports against the headers."""

    @classmethod
    def setUpClass(cls):
        if not OPTIONS.header:
            raise unittest.SkipTest("no --header")
        cls.expected = header_prototypes()

    def test_native_status_codes_match_the_headers(self):
        block = re.search(r"/\*\* Status codes\. \*/\s*enum \{(.*?)\};", "\n".join(header_texts()),
                          re.S)
        self.assertIsNotNone(block, "no status code enum in the headers")
        declared = {int(value): name
                    for name, value in re.findall(r"(HAIRIS_\w+) = (\d+)", block.group(1))}
        self.assertEqual(declared, STATUS_NAMES)

    def test_native_prototypes_match_the_headers(self):
        problems = prototype_problems(self.expected, PROTOTYPES, "addon/hairis/native.py")
        self.assertEqual(problems, [], "\n".join(problems))

    def test_the_check_names_each_kind_of_difference(self):
        """The comparison fails, naming the function, for every kind of mistake."""
        def with_change(name, value):
            changed = dict(PROTOTYPES)
            if value is None:
                del changed[name]
            else:
                changed[name] = value
            return prototype_problems(self.expected, changed, "x")

        self.assertEqual(with_change("hairis_pdf", None),
                         ["x: hairis_pdf is missing (the headers declare it)"])
        self.assertEqual(with_change("hairis_extra", (c_int, [])),
                         ["x: hairis_extra is not in the headers"])
        self.assertEqual(with_change("hairis_tables_info", (c_void_p, [c_void_p])),
                         ["x: hairis_tables_info returns c_void_p, the headers say c_char_p"])
        self.assertEqual(with_change("hairis_sample", (c_int, [c_void_p, c_size_t, F, F, F, F])),
                         ["x: hairis_sample takes 6 arguments, the headers say 7"])
        self.assertEqual(with_change("hairis_scene_add_mesh",
                                     (c_int, [c_void_p, c_size_t, F, c_size_t, U32, U32])),
                         ["x: hairis_scene_add_mesh argument 6 is POINTER(c_uint), "
                          "the headers say POINTER(c_int)"])
        # A callback with another prototype, and a C function pointer where a callback goes.
        wrong_callback = CFUNCTYPE(c_int, c_void_p, c_double)
        problems = with_change("hairis_render", (c_int, [c_void_p, c_char_p, F, wrong_callback,
                                                         c_void_p]))
        self.assertEqual(len(problems), 1)
        self.assertIn("hairis_render argument 4", problems[0])
        self.assertEqual(with_change("hairis_render",
                                     (c_int, [c_void_p, c_char_p, F, c_void_p, c_void_p])),
                         ["x: hairis_render argument 4 is c_void_p, "
                          "the headers say CFUNCTYPE(c_int, c_void_p, c_float)"])

    def test_the_parser_reads_our_style_and_refuses_the_rest(self):
        header = """
            /* comment with HAIRIS_API inside; */
            #define HAIRIS_API __attribute__((visibility("default")))
            typedef struct hairis_thing hairis_thing;
            typedef int (*hairis_cb)(void *user, float progress);
            HAIRIS_API const char *hairis_name(const hairis_thing *thing);
            HAIRIS_API int hairis_fill(hairis_thing *t, size_t n,
                                       const uint32_t *first, hairis_cb cb, void *user);
            HAIRIS_API void hairis_none(void);
        """
        parsed = parse_prototypes([header])
        self.assertEqual(set(parsed), {"hairis_name", "hairis_fill", "hairis_none"})
        self.assertIs(parsed["hairis_name"][0], c_char_p)
        self.assertEqual(parsed["hairis_none"], (None, []))
        restype, argtypes = parsed["hairis_fill"]
        self.assertIs(restype, c_int)
        self.assertEqual(argtypes[:3], [c_void_p, c_size_t, U32])
        self.assertTrue(same_type(argtypes[3], PROGRESS_FN))
        for bad in ("HAIRIS_API int hairis_f(struct other *o);",
                    "HAIRIS_API int hairis_f(float values[3]);",
                    "HAIRIS_API int hairis_f(int (*cb)(int));",
                    "HAIRIS_API int hairis_f(const char **names);",
                    "HAIRIS_API int hairis_f(int, ...);",
                    "HAIRIS_API long hairis_f(void);",
                    "HAIRIS_API int hairis_f(float);"):
            with self.subTest(bad=bad):
                with self.assertRaises(HeaderError):
                    parse_prototypes([bad])

    def assert_exports_exactly_the_headers_functions(self, library):
        nm = OPTIONS.nm or "nm"
        output = subprocess.run([nm, "-D", "--defined-only", library], check=True,
                                capture_output=True, text=True).stdout
        exported = set()
        for line in output.splitlines():
            parts = line.split()
            if len(parts) >= 3:
                exported.add(parts[2].split("@")[0])
        self.assertTrue(exported, "nm found no symbols in %s" % library)
        others = sorted(name for name in exported if not name.startswith("hairis_"))
        self.assertEqual(others, [], "%s exports only hairis_* symbols" % library)
        self.assertEqual(sorted(exported - set(self.expected)), [],
                         "hairis_* symbols of %s the headers do not declare" % library)
        self.assertEqual(sorted(set(self.expected) - exported), [],
                         "header functions %s does not define" % library)

    def test_library_exports_exactly_the_headers_functions(self):
        self.assert_exports_exactly_the_headers_functions(OPTIONS.library)

    def test_fake_library_defines_exactly_the_headers_functions(self):
        """The add-on tests' stand-in (tests/blender/fake_hairis.c) defines every header
        function; it includes the headers, so the compiler has checked each signature."""
        if not OPTIONS.fake_library:
            self.skipTest("no --fake-library (the Blender add-on tests are not configured)")
        self.assert_exports_exactly_the_headers_functions(OPTIONS.fake_library)


class TestLibrary(unittest.TestCase):

    def test_version(self):
        self.assertEqual(lib().hairis_api_version(), 2)
        self.assertEqual(last_error(), "")
        version = lib().hairis_version_string().decode()
        if OPTIONS.version:
            self.assertEqual(version, OPTIONS.version)
        self.assertRegex(version, r"^\d+\.\d+\.\d+")

    def test_errors_are_strings_and_per_thread(self):
        self.assertIsNone(make_fiber("roughness=2"))
        message = last_error()
        self.assertIn("roughness", message)
        seen = []
        thread = threading.Thread(target=lambda: seen.append(last_error()))
        thread.start()
        thread.join()
        self.assertEqual(seen, [""], "another thread has its own last error")
        lib().hairis_api_version()
        self.assertEqual(last_error(), "")


class TestOptions(unittest.TestCase):

    def test_defaults_of_every_kind(self):
        for kind in KINDS:
            with self.subTest(kind=kind):
                self.assertTrue(items(defaults(kind)), kind)
        self.assertEqual(items(defaults("chiang"))["ior"], "1.54999995")
        self.assertEqual(items(defaults("marschner"))["sigma_a"],
                         "0.150000006,0.200000003,0.300000012")
        self.assertEqual(items(defaults("render"))["max_bounces"], "12")
        self.assertIsNone(lib().hairis_defaults(b"nonsense"))
        self.assertIn("camera", last_error())

    def test_fiber_defaults_round_trip(self):
        for kind, bare in (("chiang", ""), ("huang", "model=huang"),
                           ("marschner", "model=marschner")):
            with self.subTest(kind=kind):
                a, b = make_fiber(defaults(kind)), make_fiber(bare)
                self.assertTrue(a and b, last_error())
                self.assertEqual(lib().hairis_fiber_parameters(a), lib().hairis_fiber_parameters(b))
                lib().hairis_fiber_destroy(a)
                lib().hairis_fiber_destroy(b)

    def test_unknown_and_repeated_names(self):
        self.assertIsNone(make_fiber("roughnes=0.3"))
        message = last_error()
        self.assertIn('"roughnes"', message)
        for name in items(defaults("chiang")):
            self.assertIn(name, message)
        self.assertIsNone(make_fiber("coat=0.1;coat=0.2"))
        self.assertIn("coat is given twice", last_error())
        self.assertIsNone(lib().hairis_sampler_create(None, None, b"strategy=uniform;n_h=1;x=1"))
        self.assertIn('unknown option "x"', last_error())
        self.assertIn("multiple_weight", last_error())


class TestFibers(unittest.TestCase):

    def test_create_and_strings(self):
        fiber = make_fiber()
        self.assertTrue(fiber, last_error())
        self.assertEqual(lib().hairis_fiber_model(fiber), b"chiang2016")
        parameters = lib().hairis_fiber_parameters(fiber).decode()
        self.assertTrue(parameters.startswith("sigma_a.r="), parameters)
        self.assertEqual(len(parameters.split(";")), 8)
        lib().hairis_fiber_destroy(fiber)
        marschner = make_fiber("model=marschner")
        self.assertTrue(marschner, last_error())
        self.assertEqual(lib().hairis_fiber_model(marschner), b"marschner2003")
        lib().hairis_fiber_destroy(marschner)

    def test_invalid_inputs_name_the_argument(self):
        cases = [
            ("roughness=1.5", "roughness"),
            ("ior=1", "ior"),
            ("coat=nan", "coat"),
            ("parametrization=3", "parametrization"),
            ("random=-0.5", "random"),
            ("model=marschner;caustic_limit=-1", "caustic_limit"),
            ("model=marschner;eta=inf", "eta"),
        ]
        for options, word in cases:
            with self.subTest(options=options):
                self.assertIsNone(make_fiber(options))
                self.assertIn(word, last_error())

    @unittest.skipIf(np is None, "numpy")
    def test_eval_far_and_near(self):
        rng = np.random.default_rng(1)
        n = 300
        wi, wo = unit_vectors(rng, n), unit_vectors(rng, n)
        h = rng.uniform(-1, 1, n).astype(np.float32)
        out = np.full((n, 3), -1, np.float32)
        fiber = make_fiber()
        self.assertEqual(lib().hairis_fiber_eval(fiber, n, ptr(wi), ptr(wo), None, ptr(out)), OK)
        self.assertTrue(np.all(np.isfinite(out)) and np.all(out >= 0))
        far = out.copy()
        self.assertEqual(lib().hairis_fiber_eval(fiber, n, ptr(wi), ptr(wo), ptr(h), ptr(out)), OK)
        self.assertTrue(np.all(np.isfinite(out)) and np.all(out >= 0))
        self.assertFalse(np.array_equal(far, out), "near and far fields differ")
        wi[7, 1] = np.nan
        out[:] = -1
        self.assertEqual(lib().hairis_fiber_eval(fiber, n, ptr(wi), ptr(wo), None, ptr(out)),
                         ERROR_INVALID_ARGUMENT)
        self.assertIn("wi item 7", last_error())
        self.assertTrue(np.all(out == -1), "a refused batch writes nothing")
        lib().hairis_fiber_destroy(fiber)

        marschner = make_fiber("model=marschner")
        wi[7, 1] = 0.0
        wi[7] /= np.linalg.norm(wi[7])
        self.assertEqual(lib().hairis_fiber_eval(marschner, n, ptr(wi), ptr(wo), ptr(h), ptr(out)),
                         ERROR_INVALID_ARGUMENT)
        self.assertIn("h must be NULL", last_error())
        self.assertEqual(lib().hairis_fiber_eval(marschner, n, ptr(wi), ptr(wo), None, ptr(out)),
                         OK)
        self.assertTrue(np.all(np.isfinite(out)) and np.all(out >= 0))
        lib().hairis_fiber_destroy(marschner)


class TestTables(unittest.TestCase):

    def test_bake_with_progress_and_write_and_load(self):
        fiber = make_fiber()
        seen, callback = recording_progress(0)
        tables = lib().hairis_tables_bake(fiber, TINY_BAKE, callback, None)
        self.assertTrue(tables, last_error())
        self.assertEqual(last_error(), "")
        self.assertEqual(seen[-1], 1.0)
        self.assertEqual(seen, sorted(seen))
        self.assertEqual(lib().hairis_tables_match_fiber(tables, fiber), 1)
        self.assertEqual(lib().hairis_tables_parameters(tables),
                         lib().hairis_fiber_parameters(fiber))
        self.assertEqual(items(lib().hairis_tables_info(tables).decode()),
                         {"source": "exact", "theta_r": "4", "theta_i": "8", "phi": "8",
                          "n_h": "1,2"})
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "t.exr")
            self.assertEqual(lib().hairis_tables_write(tables, path.encode()), OK, last_error())
            loaded = lib().hairis_tables_load_file(path.encode())
            self.assertTrue(loaded, last_error())
            self.assertEqual(lib().hairis_tables_match_fiber(loaded, fiber), 1)
            self.assertEqual(lib().hairis_tables_info(loaded), lib().hairis_tables_info(tables))
            lib().hairis_tables_destroy(loaded)
            bad = os.path.join(folder, "missing", "t.exr")
            self.assertEqual(lib().hairis_tables_write(tables, bad.encode()), ERROR_IO)
            self.assertIn("missing", last_error())
        lib().hairis_tables_destroy(tables)
        other = make_fiber("coat=0.5")
        loaded = load_memory(default_table_bytes())
        self.assertTrue(loaded, last_error())
        self.assertEqual(lib().hairis_tables_model(loaded), b"chiang2016")
        self.assertEqual(lib().hairis_tables_match_fiber(loaded, fiber), 1)
        self.assertEqual(lib().hairis_tables_match_fiber(loaded, other), 0)
        self.assertEqual(last_error(), "")
        lib().hairis_tables_destroy(loaded)
        lib().hairis_fiber_destroy(other)
        lib().hairis_fiber_destroy(fiber)

    def test_cancelled_bake(self):
        fiber = make_fiber()
        calls, callback = recording_progress(1)
        self.assertIsNone(lib().hairis_tables_bake(fiber, TINY_BAKE, callback, None))
        self.assertEqual(last_error(), "cancelled")
        self.assertEqual(len(calls), 1, "no progress call after cancelling")
        # The defaults (minutes of work) are accepted and cancelled just as promptly.
        self.assertIsNone(lib().hairis_tables_bake(fiber, defaults("bake").encode(), callback,
                                                   None))
        self.assertEqual(last_error(), "cancelled")
        lib().hairis_fiber_destroy(fiber)

    def test_bad_options(self):
        fiber = make_fiber()
        for options, word in ((b"theta_r=4;theta_i=8;phi=0", "phi"),
                              (b"n_h=2,1", "increasing"),
                              (b"source=approximate", "gaussian"),
                              (b"phi_count=8", '"phi_count"')):
            with self.subTest(options=options):
                self.assertIsNone(lib().hairis_tables_bake(fiber, options, PROGRESS_FN(), None))
                self.assertIn(word, last_error())
        lib().hairis_fiber_destroy(fiber)

    def test_corrupt_buffers_are_refused(self):
        data = bytearray(default_table_bytes())
        data[len(data) // 2] ^= 0xFF
        self.assertIsNone(load_memory(bytes(data)))
        self.assertTrue(last_error().startswith("hairis table:"), last_error())
        self.assertIsNone(load_memory(b"not an exr file at all"))
        self.assertIn("EXR", last_error())
        self.assertIsNone(lib().hairis_tables_load_memory(None, 0))
        self.assertIn("data", last_error())
        self.assertIsNone(lib().hairis_tables_load_file(b"/nonexistent/hairis.exr"))
        self.assertIn("/nonexistent/hairis.exr", last_error())


@unittest.skipIf(np is None, "numpy")
class TestSampling(unittest.TestCase):

    def setUp(self):
        self.fiber = make_fiber()
        self.tables = load_memory(default_table_bytes())
        self.assertTrue(self.tables, last_error())

    def tearDown(self):
        lib().hairis_tables_destroy(self.tables)
        lib().hairis_fiber_destroy(self.fiber)

    def test_sample_and_pdf_agree_for_every_strategy(self):
        rng = np.random.default_rng(2)
        n = 5000
        wo = unit_vectors(rng, n)
        h = rng.uniform(-1, 1, n).astype(np.float32)
        u = rng.random((n, 3), dtype=np.float32)
        for strategy in ("uniform", "analytic", "gaussian", "table"):
            with self.subTest(strategy=strategy):
                options = ("strategy=%s;multiple_weight=0.25;n_h=2" % strategy).encode()
                sampler = lib().hairis_sampler_create(self.fiber, self.tables, options)
                self.assertTrue(sampler, last_error())
                wi = np.zeros((n, 3), np.float32)
                pdf = np.zeros(n, np.float32)
                status = lib().hairis_sample(sampler, n, ptr(wo), ptr(h), ptr(u), ptr(wi), ptr(pdf))
                self.assertEqual(status, OK, last_error())
                produced = pdf > 0
                self.assertGreater(produced.mean(), 0.9)
                np.testing.assert_allclose(np.linalg.norm(wi[produced], axis=1), 1.0, atol=1e-4)
                self.assertTrue(np.all(wi[~produced] == 0))
                again = np.zeros(n, np.float32)
                status = lib().hairis_pdf(sampler, n, ptr(wi), ptr(wo), ptr(h), ptr(again))
                self.assertEqual(status, OK, last_error())
                np.testing.assert_allclose(again[produced], pdf[produced], rtol=1e-5)
                lib().hairis_sampler_destroy(sampler)

    def test_table_sampler_outlives_its_tables(self):
        tables = load_memory(default_table_bytes())
        sampler = lib().hairis_sampler_create(None, tables, b"multiple_weight=0.5;n_h=1")
        self.assertTrue(sampler, last_error())
        lib().hairis_tables_destroy(tables)
        wo = np.array([[0.2, 0.0, -0.9797959]], np.float32)
        u = np.array([[0.3, 0.6, 0.9]], np.float32)
        wi = np.zeros((1, 3), np.float32)
        pdf = np.zeros(1, np.float32)
        self.assertEqual(lib().hairis_sample(sampler, 1, ptr(wo), None, ptr(u), ptr(wi), ptr(pdf)),
                         OK)
        self.assertGreater(pdf[0], 0)
        lib().hairis_sampler_destroy(sampler)

    def test_refusals(self):
        self.assertIsNone(lib().hairis_sampler_create(self.fiber, None, b"strategy=table"))
        self.assertIn("tables", last_error())
        self.assertIsNone(lib().hairis_sampler_create(None, None, b"strategy=12"))
        self.assertIn("strategy", last_error())
        self.assertIn("uniform", last_error())
        self.assertIsNone(lib().hairis_sampler_create(None, None,
                                                      b"strategy=gaussian;multiple_weight=-0.1"))
        self.assertIn("multiple_weight", last_error())
        rougher = make_fiber("roughness=0.6")
        self.assertIsNone(lib().hairis_sampler_create(rougher, self.tables, b"strategy=table"))
        self.assertIn("baked for", last_error())
        lib().hairis_fiber_destroy(rougher)
        sampler = lib().hairis_sampler_create(None, None, b"strategy=uniform")
        wo = np.array([[0, 1, 0]], np.float32)
        u = np.array([[0.5, 1.0, 0.5]], np.float32)
        wi = np.zeros((1, 3), np.float32)
        pdf = np.zeros(1, np.float32)
        self.assertEqual(lib().hairis_sample(sampler, 1, ptr(wo), None, ptr(u), ptr(wi), ptr(pdf)),
                         ERROR_INVALID_ARGUMENT)
        self.assertIn("u[1]", last_error())
        lib().hairis_sampler_destroy(sampler)


@unittest.skipIf(np is None, "numpy")
class TestRender(unittest.TestCase):
    W, H = 16, 12

    def make_scene(self, tables, fiber_options="", inputs=None, mixture=None):
        """The test scene; ``inputs`` (an options string and a function of (curves, points)
        giving the values) puts its curves through hairis_scene_add_curves_with_inputs;
        ``mixture`` (a list of (fiber options, weight)) puts them on a hair mixture of those
        fibers instead of the material of ``fiber_options``."""
        fiber = make_fiber(fiber_options)
        self.assertTrue(fiber, last_error())
        scene = lib().hairis_scene_create()
        self.assertEqual(lib().hairis_scene_add_hair_material(scene, fiber, tables), 0)
        lib().hairis_fiber_destroy(fiber)  # the scene keeps what it needs
        self.assertEqual(lib().hairis_scene_add_surface_material(
            scene, b"type=diffuse;color=0.5,0.5,0.5"), 1)
        hair = 0
        if mixture is not None:
            closures = np.arange(2, 2 + len(mixture), dtype=np.int32)
            for options, _ in mixture:
                closure = make_fiber(options)
                lib().hairis_scene_add_hair_material(scene, closure, tables)
                lib().hairis_fiber_destroy(closure)
            weights = np.array([w for _, w in mixture], np.float32)
            hair = lib().hairis_scene_add_hair_mixture(scene, len(mixture), ptr(closures, c_int32),
                                                       ptr(weights))
            self.assertEqual(hair, 2 + len(mixture), last_error())
        curves, points = 6, 5
        first = np.arange(0, curves * points + 1, points, dtype=np.uint32)
        x = np.linspace(-1.5, 1.5, points)
        positions = np.array([[xx, -0.75 + 0.3 * c, 0.1 * np.sin(3 * xx)] for c in range(curves)
                              for xx in x], np.float32)
        radii = np.full(curves * points, 0.04, np.float32)
        if inputs is None:
            self.assertEqual(lib().hairis_scene_add_curves(
                scene, hair, curves, ptr(first, c_uint32), len(positions), ptr(positions),
                ptr(radii)), OK, last_error())
        else:
            names, make_values = inputs
            values = np.ascontiguousarray(make_values(curves, len(positions)), np.float32)
            self.assertEqual(lib().hairis_scene_add_curves_with_inputs(
                scene, hair, curves, ptr(first, c_uint32), len(positions), ptr(positions),
                ptr(radii), names, values.size, ptr(values)), OK, last_error())
        vertices = np.array([[-3, -3, -0.5], [3, -3, -0.5], [0, 3, -0.5]], np.float32)
        indices = np.array([0, 1, 2], np.uint32)
        materials = np.array([1], np.int32)
        self.assertEqual(lib().hairis_scene_add_mesh(scene, 3, ptr(vertices), 1,
                                                     ptr(indices, c_uint32),
                                                     ptr(materials, c_int32)), OK, last_error())
        for light in (b"type=sun;direction=0.2,0.4,1;strength=2;angle=0.02",
                      b"type=point;position=1,1,2;color=1,0.9,0.8;power=20;radius=0.1",
                      b"type=area;matrix=1,0,0,-1,0,1,0,0,0,0,1,2.5,0,0,0,1;shape=disk;size=0.5;"
                      b"size_y=0.5;power=30"):
            self.assertEqual(lib().hairis_scene_add_light(scene, light), OK, last_error())
        self.assertEqual(lib().hairis_scene_set_world(scene, b"color=0.05,0.05,0.08"), OK)
        self.assertEqual(lib().hairis_scene_add_light(scene, b"type=area;shape=9"),
                         ERROR_INVALID_ARGUMENT)
        self.assertIn("shape", last_error())
        ax, ay = 0.4, 0.3  # 4:3 like the resolution
        frame = [ax, ay, -1, ax, -ay, -1, -ax, -ay, -1, -ax, ay, -1]
        camera = "matrix=1,0,0,0,0,1,0,0,0,0,1,3,0,0,0,1;frame=%s;width=%d;height=%d" % (
            ",".join("%.9g" % v for v in frame), self.W, self.H)
        self.assertEqual(lib().hairis_scene_set_camera(scene, camera.encode()), OK, last_error())
        return scene

    @staticmethod
    def settings(strategy, samples=4):
        return ("samples=%d;max_bounces=2;strategy=%s;threads=2;seed=3" % (
            samples, strategy)).encode()

    def test_tiny_render(self):
        tables = load_memory(default_table_bytes())
        scene = self.make_scene(tables)
        lib().hairis_tables_destroy(tables)  # the scene keeps what it needs
        for strategy in ("analytic", "table"):
            with self.subTest(strategy=strategy):
                rgba = np.full((self.H, self.W, 4), -1, np.float32)
                status = lib().hairis_render(scene, self.settings(strategy), ptr(rgba),
                                             PROGRESS_FN(), None)
                self.assertEqual(status, OK, last_error())
                self.assertTrue(np.all(np.isfinite(rgba)) and np.all(rgba >= 0))
                self.assertTrue(np.all(rgba[..., 3] == 1))
                self.assertGreater(rgba[..., :3].sum(), 0)
                stats = items(lib().hairis_last_render_stats().decode())
                self.assertEqual(int(stats["camera_rays"]), self.W * self.H * 4)
                self.assertEqual(int(stats["threads"]), 2)
                self.assertTrue(0 < float(stats["seconds"]) < 600)
        lib().hairis_scene_destroy(scene)

    def test_progressive_render_matches_hairis_render(self):
        # hairis_render_progressive through the add-on's UPDATE_FN: the same image as
        # hairis_render, updates on this thread with the samples done, passes where asked,
        # and a non-zero return stops it.
        scene = self.make_scene(None)
        settings = self.settings("analytic", 6)
        plain = np.full((self.H, self.W, 4), -1, np.float32)
        self.assertEqual(lib().hairis_render(scene, settings, ptr(plain), PROGRESS_FN(), None),
                         OK, last_error())
        rgba = np.full((self.H, self.W, 4), -1, np.float32)
        passes = np.full((self.H, self.W, 4), -1, np.float32)
        calls = []
        callback = UPDATE_FN(lambda user, progress, done, final: calls.append((done, final)) or 0)
        status = lib().hairis_render_progressive(scene, settings + b";passes=depth,normal",
                                                 ptr(rgba), ptr(passes), callback, None)
        self.assertEqual(status, OK, last_error())
        self.assertTrue(np.array_equal(rgba.view(np.uint32), plain.view(np.uint32)))
        self.assertEqual(calls[-1], (6, 1))
        self.assertEqual([c for c in calls if c[1]], [(6, 1)])
        depth = passes.reshape(-1)[:self.W * self.H]
        self.assertTrue(np.all(depth > 0))
        self.assertTrue(np.any(depth < 1e10))  # the hair and the mesh are seen
        stats = items(lib().hairis_last_render_stats().decode())
        self.assertEqual(int(stats["samples"]), 6)
        self.assertEqual(int(stats["converged_pixels"]), 0)
        stop = UPDATE_FN(lambda user, progress, done, final: 1)
        status = lib().hairis_render_progressive(scene, self.settings("analytic", 1 << 20),
                                                 ptr(rgba), None, stop, None)
        self.assertEqual(status, ERROR_CANCELLED)
        status = lib().hairis_render_progressive(scene, settings + b";passes=depth", ptr(rgba),
                                                 None, UPDATE_FN(), None)
        self.assertEqual(status, ERROR_INVALID_ARGUMENT)
        self.assertIn("passes", last_error())
        lib().hairis_scene_destroy(scene)

    def test_huang_hair_on_oriented_curves(self):
        # A Huang material renders with the uniform strategy; curves may carry normals, which
        # are checked (and their options refused by name) like every other array.
        scene = self.make_scene(None, "model=huang;aspect_ratio=0.5")
        first = np.array([0, 3], np.uint32)
        positions = np.array([[-1, 0.2, 0.3], [0, 0.2, 0.3], [1, 0.2, 0.3]], np.float32)
        radii = np.full(3, 0.1, np.float32)
        normals = np.array([[0, 0, 1], [0, 1, 1], [0, 1, 0]], np.float32)
        add = lib().hairis_scene_add_curves_with_normals
        self.assertEqual(add(scene, 0, 1, ptr(first, c_uint32), 3, ptr(positions), ptr(radii),
                             ptr(normals), b""), OK, last_error())
        self.assertEqual(add(scene, 0, 1, ptr(first, c_uint32), 3, ptr(positions), ptr(radii),
                             ptr(normals), b"frame=1"), ERROR_INVALID_ARGUMENT)
        self.assertIn('"frame"', last_error())
        normals[2, 0] = np.inf
        self.assertEqual(add(scene, 0, 1, ptr(first, c_uint32), 3, ptr(positions), ptr(radii),
                             ptr(normals), None), ERROR_INVALID_ARGUMENT)
        self.assertIn("normals[6]", last_error())
        rgba = np.full((self.H, self.W, 4), -1, np.float32)
        status = lib().hairis_render(scene, self.settings("uniform"), ptr(rgba), PROGRESS_FN(),
                                     None)
        self.assertEqual(status, OK, last_error())
        self.assertTrue(np.all(np.isfinite(rgba)) and np.all(rgba >= 0))
        self.assertGreater(rgba[..., :3].sum(), 0)
        self.assertEqual(lib().hairis_render(scene, self.settings("table"), ptr(rgba),
                                             PROGRESS_FN(), None), ERROR_INVALID_TABLE)
        self.assertIn("material 0", last_error())
        lib().hairis_scene_destroy(scene)

    def test_huang_hair_with_its_huang_table(self):
        # Huang tables bake, survive a round trip through EXR bytes in a file, and TABLE
        # renders with them; tables of another aspect ratio are refused naming the material.
        fiber = make_fiber("model=huang;aspect_ratio=0.5")
        # huang_multiple=0: the Huang table alone (capi_test.c bakes and renders the multiple part).
        options = b"huang_theta_o=6;huang_phi_o=3;huang_theta_i=12;huang_phi=16;huang_multiple=0"
        tables = lib().hairis_tables_bake(fiber, options, PROGRESS_FN(), None)
        self.assertTrue(tables, last_error())
        self.assertEqual(lib().hairis_tables_model(tables), b"huang2022")
        self.assertEqual(items(lib().hairis_tables_info(tables).decode()),
                         {"source": "exact", "huang_theta_o": "6", "huang_phi_o": "3",
                          "huang_theta_i": "12", "huang_phi": "16", "huang_f": "1",
                          "huang_f_refinement": "1", "huang_absorption": "0"})
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "huang.exr")
            self.assertEqual(lib().hairis_tables_write(tables, path.encode()), OK, last_error())
            with open(path, "rb") as handle:
                loaded = load_memory(handle.read())
        lib().hairis_tables_destroy(tables)
        self.assertTrue(loaded, last_error())
        self.assertEqual(lib().hairis_tables_match_fiber(loaded, fiber), 1)
        lib().hairis_fiber_destroy(fiber)
        rgba = np.full((self.H, self.W, 4), -1, np.float32)
        for fiber_options, expected in (("model=huang;aspect_ratio=0.5", OK),
                                        ("model=huang;aspect_ratio=0.6", ERROR_INVALID_TABLE),
                                        ("", ERROR_INVALID_TABLE)):
            with self.subTest(fiber=fiber_options):
                scene = self.make_scene(loaded, fiber_options)
                status = lib().hairis_render(scene, self.settings("table"), ptr(rgba),
                                             PROGRESS_FN(), None)
                self.assertEqual(status, expected, last_error())
                if expected == OK:
                    self.assertTrue(np.all(np.isfinite(rgba)) and np.all(rgba >= 0))
                    self.assertGreater(rgba[..., :3].sum(), 0)
                else:
                    self.assertIn("material 0", last_error())
                    self.assertIn("huang2022", last_error())
                lib().hairis_scene_destroy(scene)
        lib().hairis_tables_destroy(loaded)

    def test_cancel_from_python(self):
        scene = self.make_scene(None)
        rgba = np.zeros((self.H, self.W, 4), np.float32)
        calls, callback = recording_progress(1)
        status = lib().hairis_render(scene, self.settings("analytic", 1 << 16), ptr(rgba),
                                     callback, None)
        self.assertEqual(status, ERROR_CANCELLED)
        self.assertIn("cancelled", last_error())
        self.assertEqual(len(calls), 1)
        self.assertEqual(items(lib().hairis_last_render_stats().decode())["cancelled"], "1")
        self.assertTrue(np.all(np.isfinite(rgba)))
        lib().hairis_scene_destroy(scene)

    def test_table_refusals(self):
        rgba = np.zeros((self.H, self.W, 4), np.float32)
        scene = self.make_scene(None)
        status = lib().hairis_render(scene, self.settings("table"), ptr(rgba), PROGRESS_FN(), None)
        self.assertEqual(status, ERROR_INVALID_TABLE)
        self.assertIn("material 0", last_error())
        lib().hairis_scene_destroy(scene)
        tables = load_memory(default_table_bytes())
        scene = self.make_scene(tables, "radial_roughness=0.6")
        status = lib().hairis_render(scene, self.settings("table"), ptr(rgba), PROGRESS_FN(), None)
        self.assertEqual(status, ERROR_INVALID_TABLE)
        self.assertIn("material 0", last_error())
        self.assertIn("baked for", last_error())
        lib().hairis_scene_destroy(scene)
        lib().hairis_tables_destroy(tables)

    def render(self, scene, strategy, samples=4):
        rgba = np.full((self.H, self.W, 4), -1, np.float32)
        status = lib().hairis_render(scene, self.settings(strategy, samples), ptr(rgba),
                                     PROGRESS_FN(), None)
        self.assertEqual(status, OK, last_error())
        return rgba

    def test_curve_inputs_render_as_the_fiber_of_their_values(self):
        """Melanin 0.8 on every curve (or point) of a melanin-0.3 material renders as a
        melanin-0.8 material, bit for bit, with the analytic strategy."""
        base = "parametrization=melanin;melanin=0.3;cycles=4.5"
        expected = self.make_scene(None, "parametrization=melanin;melanin=0.8;cycles=4.5")
        per_curve = self.make_scene(None, base, (b"melanin=curve",
                                                 lambda c, p: np.full(c, 0.8)))
        per_point = self.make_scene(None, base, (b"melanin=point",
                                                 lambda c, p: np.full(p, 0.8)))
        plain = self.make_scene(None, base)
        images = [self.render(s, "analytic") for s in (expected, per_curve, per_point, plain)]
        np.testing.assert_array_equal(images[1], images[0])
        np.testing.assert_array_equal(images[2], images[0])
        self.assertFalse(np.array_equal(images[3], images[0]))
        for scene in (expected, per_curve, per_point, plain):
            lib().hairis_scene_destroy(scene)

    def test_hair_mixture_renders_its_weighted_closures(self):
        """A mixture whose other closures weigh 0 (by the material, or per curve) renders as
        its one closure, bit for bit; weights 0.5/0.5 render otherwise; the integrator=path
        image of two closures lies between the two closures' own images on average."""
        brown, grey = "parametrization=melanin;melanin=0.8", "parametrization=melanin;melanin=0.1"
        alone = self.render(self.make_scene(None, grey), "analytic", 8)
        by_material = self.make_scene(None, brown, mixture=[(brown, 0.0), (grey, 1.0)])
        per_curve = self.make_scene(None, brown, (b"weight0=curve;weight1=point",
                                                  lambda c, p: np.concatenate([np.zeros(c),
                                                                               np.ones(p)])),
                                    mixture=[(brown, 1.0), (grey, 0.0)])
        half = self.make_scene(None, brown, mixture=[(brown, 0.5), (grey, 0.5)])
        np.testing.assert_array_equal(self.render(by_material, "analytic", 8), alone)
        np.testing.assert_array_equal(self.render(per_curve, "analytic", 8), alone)
        mixed = self.render(half, "analytic", 8)
        dark = self.render(self.make_scene(None, brown), "analytic", 8)
        self.assertLess(dark[..., :3].sum(), mixed[..., :3].sum())
        self.assertLess(mixed[..., :3].sum(), alone[..., :3].sum())
        rgba = np.zeros((self.H, self.W, 4), np.float32)
        self.assertEqual(lib().hairis_render(half, b"integrator=dual_scattering", ptr(rgba),
                                             PROGRESS_FN(), None), ERROR_INVALID_ARGUMENT)
        for word in ("material 4 (hair mixture)", "dual_scattering", "integrator=path"):
            self.assertIn(word, last_error())

    def test_hair_mixture_refusals(self):
        """Bad counts, indices, weights and closures, and closure weights per strand on a
        material that is not a mixture: refused, naming what is wrong."""
        scene = lib().hairis_scene_create()
        chiang, huang = make_fiber(""), make_fiber("model=huang")
        self.assertTrue(huang, last_error())
        self.assertEqual(lib().hairis_scene_add_hair_material(scene, chiang, None), 0)
        self.assertEqual(lib().hairis_scene_add_hair_material(scene, huang, None), 1)
        self.assertEqual(lib().hairis_scene_add_surface_material(scene, b"type=diffuse"), 2)
        for fiber in (chiang, huang):
            lib().hairis_fiber_destroy(fiber)

        def mix(materials, weights):
            materials = np.ascontiguousarray(materials, np.int32)
            weights = np.ascontiguousarray(weights, np.float32)
            return lib().hairis_scene_add_hair_mixture(scene, len(materials),
                                                       ptr(materials, c_int32), ptr(weights))

        cases = [
            ([], [], ["count", "[1, 8]", "got 0"]),
            ([0] * 9, [1] * 9, ["count", "got 9"]),
            ([0, 5], [1, 1], ["closure 1", "material 5", "not in the scene"]),
            ([0, 2], [1, 1], ["closure 1", "material 2", "not a hair material"]),
            ([0, 1], [1, 1], ["closure 1", "huang2022", "chiang2016"]),
            ([0, 0], [1, -0.5], ["closure 1's weight", ">= 0"]),
            ([0, 0], [float("nan"), 1], ["closure 0's weight", "finite"]),
        ]
        for materials, weights, words in cases:
            with self.subTest(materials=materials, weights=weights):
                self.assertEqual(mix(materials, weights), -1)
                for word in words:
                    self.assertIn(word, last_error())
        self.assertEqual(mix([0, 0], [0.3, 0.7]), 3, last_error())
        self.assertEqual(mix([3], [1]), -1)
        self.assertIn("not a hair material of one fiber", last_error())
        first = np.array([0, 3, 6], np.uint32)
        positions = np.array([[x, y, 0] for y in (0, 1) for x in (0, 1, 2)], np.float32)
        radii = np.full(6, 0.1, np.float32)

        def add(names, values, material):
            values = np.ascontiguousarray(values, np.float32)
            return lib().hairis_scene_add_curves_with_inputs(
                scene, material, 2, ptr(first, c_uint32), 6, ptr(positions), ptr(radii), names,
                values.size, ptr(values))

        for names, values, material, words in [
                (b"weight0=curve", [1, 0], 0, ["weight0", "mixes 0"]),
                (b"weight2=curve", [1, 0], 3, ["weight2", "mixes 2"]),
                (b"weight1=curve", [1, -1], 3, ["weight1", "curve 1", ">= 0"]),
                (b"weight1=point", [1, 0], 3, ["value_count", "6"])]:
            with self.subTest(names=names):
                self.assertEqual(add(names, values, material), ERROR_INVALID_ARGUMENT)
                for word in words:
                    self.assertIn(word, last_error())
        self.assertEqual(add(b"weight0=curve;weight1=point", [1, 0] + [0.5] * 6, 3), OK,
                         last_error())
        lib().hairis_scene_destroy(scene)

    def test_curve_inputs_with_table_strategy(self):
        """TABLE samples the tables of the material's own fiber: strands of other roughness
        and colour render (finite, and unlike the material alone); tables of another fiber
        are still refused."""
        tables = load_memory(default_table_bytes())
        inputs = (b"roughness=curve;color=point",
                  lambda c, p: np.concatenate([np.linspace(0.1, 0.7, c),
                                               np.tile([0.3, 0.2, 0.1], p)]))
        scene = self.make_scene(tables, "", inputs)
        varied = self.render(scene, "table")
        self.assertTrue(np.all(np.isfinite(varied)) and np.all(varied >= 0))
        plain = self.make_scene(tables, "")
        self.assertFalse(np.array_equal(self.render(plain, "table"), varied))
        other = self.make_scene(tables, "roughness=0.5", inputs)
        rgba = np.zeros((self.H, self.W, 4), np.float32)
        self.assertEqual(lib().hairis_render(other, self.settings("table"), ptr(rgba),
                                             PROGRESS_FN(), None), ERROR_INVALID_TABLE)
        for s in (scene, plain, other):
            lib().hairis_scene_destroy(s)
        lib().hairis_tables_destroy(tables)

    def test_curve_input_refusals(self):
        """Unknown names and domains, wrong counts, values out of range, inputs the material
        does not read and surface materials: refused, naming what is wrong."""
        self.assertEqual(items(defaults("curve_inputs")),
                         {name: "material" for name in CURVE_INPUTS})
        self.assertEqual(list(items(defaults("curve_inputs"))), list(CURVE_INPUTS))
        scene = lib().hairis_scene_create()
        fiber = make_fiber("parametrization=melanin")
        self.assertEqual(lib().hairis_scene_add_hair_material(scene, fiber, None), 0)
        lib().hairis_fiber_destroy(fiber)
        self.assertEqual(lib().hairis_scene_add_surface_material(scene, b"type=diffuse"), 1)
        first = np.array([0, 3, 6], np.uint32)
        positions = np.array([[x, y, 0] for y in (0, 1) for x in (0, 1, 2)], np.float32)
        radii = np.full(6, 0.1, np.float32)

        def add(names, values, material=0):
            values = np.ascontiguousarray(values, np.float32)
            return lib().hairis_scene_add_curves_with_inputs(
                scene, material, 2, ptr(first, c_uint32), 6, ptr(positions), ptr(radii), names,
                values.size, ptr(values))

        cases = [
            (b"melanine=curve", [0.5, 0.5], ["melanine", "known"]),
            (b"melanin=strand", [0.5, 0.5], ["melanin", "strand", "point"]),
            (b"melanin=curve", [0.5, 0.5, 0.5], ["value_count", "2", "3"]),
            (b"melanin=point;tint=curve", [0.5] * 6 + [1] * 5, ["value_count", "12"]),
            (b"melanin=point", [0.5, 0.5, 0.5, 1.5, 0.5, 0.5], ["point 3", "melanin", "[0, 1]"]),
            (b"tint=curve", [1, 1, 1, 1, 0, 1], ["curve 1", "tint.g"]),
            (b"color=curve", [0.5] * 6, ["color", "parametrization", "melanin"]),
            (b"random=curve", [0.5, float("nan")], ["curve 1", "random"]),
        ]
        for names, values, words in cases:
            with self.subTest(names=names):
                self.assertEqual(add(names, values), ERROR_INVALID_ARGUMENT)
                for word in words:
                    self.assertIn(word, last_error())
        self.assertEqual(add(b"roughness=curve", [0.5, 0.5], material=1), ERROR_INVALID_ARGUMENT)
        self.assertIn("hair material", last_error())
        # What is accepted: no input at all, and every domain.
        self.assertEqual(add(b"", []), OK, last_error())
        self.assertEqual(add(b"melanin=point;tint=curve;random=curve",
                             [0.1] * 6 + [0.9, 0.8, 0.7] * 2 + [0.2, 0.7]), OK, last_error())
        lib().hairis_scene_destroy(scene)

    def test_empty_scene(self):
        scene = lib().hairis_scene_create()
        rgba = np.zeros((self.H, self.W, 4), np.float32)
        status = lib().hairis_render(scene, self.settings("analytic"), ptr(rgba), PROGRESS_FN(),
                                     None)
        self.assertEqual(status, ERROR_INVALID_ARGUMENT)
        self.assertIn("camera", last_error())
        lib().hairis_scene_destroy(scene)

    def test_film_transparent_and_clip(self):
        """Transparent film: a camera sample that misses adds neither the world nor alpha."""
        scene = self.make_scene(None)
        opaque = np.zeros((self.H, self.W, 4), np.float32)
        rgba = np.zeros((self.H, self.W, 4), np.float32)
        settings = self.settings("analytic")
        self.assertEqual(lib().hairis_render(scene, settings, ptr(opaque), PROGRESS_FN(), None), OK)
        self.assertTrue(np.all(opaque[..., 3] == 1))
        self.assertEqual(lib().hairis_render(scene, settings + b";film_transparent=1", ptr(rgba),
                                             PROGRESS_FN(), None), OK)
        alpha = rgba[..., 3]
        self.assertTrue(alpha.min() < 0.5 and alpha.max() == 1, "some samples miss, some hit")
        # Same seed, same paths: what is missing is the world (0.05, 0.05, 0.08) of the
        # samples that missed (the sun is behind the camera).
        world = np.array([0.05, 0.05, 0.08], np.float32)
        np.testing.assert_allclose(opaque[..., :3] - rgba[..., :3],
                                   (1 - alpha)[..., None] * world, atol=1e-5)
        self.assertEqual(lib().hairis_scene_set_camera(
            scene, b"matrix=1,0,0,0,0,1,0,0,0,0,1,3,0,0,0,1;width=16;height=12;clip_end=1"), OK)
        self.assertEqual(lib().hairis_render(scene, settings + b";film_transparent=1", ptr(rgba),
                                             PROGRESS_FN(), None), OK)
        self.assertTrue(np.all(rgba == 0), "everything is past clip_end: nothing is seen")
        lib().hairis_scene_destroy(scene)


@unittest.skipIf(np is None, "numpy")
class TestSurfaces(unittest.TestCase):
    """Surface materials, Image Textures and mesh attributes through ctypes."""

    def test_surface_defaults_are_accepted(self):
        scene = lib().hairis_scene_create()
        for kind in ("diffuse", "principled", "glossy", "emission"):
            with self.subTest(kind=kind):
                self.assertGreaterEqual(
                    lib().hairis_scene_add_surface_material(scene, defaults(kind).encode()), 0,
                    last_error())
        # Mix and Add name the materials they combine: the defaults (-1) are refused by name.
        for kind in ("mix", "add"):
            self.assertEqual(
                lib().hairis_scene_add_surface_material(scene, defaults(kind).encode()), -1)
            self.assertIn("shader1", last_error())
        self.assertGreaterEqual(lib().hairis_scene_add_surface_material(
            scene, b"type=add;shader1=0;shader2=1"), 0, last_error())
        lib().hairis_scene_destroy(scene)

    def test_texture_from_a_file_and_from_pixels(self):
        scene = lib().hairis_scene_create()
        pixels = np.array([[[0.25, 0.5, 1.0], [1.0, 0.5, 0.25]]], np.float32)  # 2 x 1, RGB
        index = lib().hairis_scene_add_texture_pixels(
            scene, b"color_space=linear;extension=clip;mapping=point;scale=2,1,1", ptr(pixels),
            2, 1, 3)
        self.assertEqual(index, 0, last_error())
        self.assertEqual(lib().hairis_scene_add_texture_pixels(
            scene, b"color_space=auto", ptr(pixels), 2, 1, 3), -1)
        self.assertIn("color_space", last_error())
        self.assertEqual(lib().hairis_scene_add_texture(scene, b"image=/no/such/file.png"), -1)
        self.assertIn("file.png", last_error())
        texture_defaults = items(defaults("texture"))
        self.assertEqual(texture_defaults["mapping"], "none")
        self.assertEqual(texture_defaults["interpolation"], "linear")
        self.assertEqual(lib().hairis_scene_add_surface_material(
            scene, b"type=principled;base_color_texture=0"), 0, last_error())
        self.assertEqual(lib().hairis_scene_add_surface_material(
            scene, b"type=glossy;color_texture=1"), -1)
        self.assertIn("color_texture", last_error())
        lib().hairis_scene_destroy(scene)

    def test_textured_principled_plane_renders_its_texture(self):
        """Each half of a UV-mapped quad shows its texel; the ratio of the halves is the ratio
        of the texels (the same BSDF, view and light on both halves)."""
        scene = lib().hairis_scene_create()
        pixels = np.array([[[0.2, 0.4, 0.6], [0.8, 0.6, 0.2]]], np.float32)
        self.assertEqual(lib().hairis_scene_add_texture_pixels(
            scene, b"color_space=linear;interpolation=closest;extension=extend", ptr(pixels),
            2, 1, 3), 0, last_error())
        material = lib().hairis_scene_add_surface_material(
            scene, b"type=principled;cycles=4.5;base_color_texture=0;ior=1;roughness=0.4")
        self.assertEqual(material, 0, last_error())
        vertices = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
        indices = np.array([0, 1, 2, 0, 2, 3], np.uint32)
        materials = np.zeros(2, np.int32)
        self.assertEqual(lib().hairis_scene_add_mesh(scene, 4, ptr(vertices), 2,
                                                     ptr(indices, c_uint32),
                                                     ptr(materials, c_int32)), OK, last_error())
        uv = np.array([[0, 0], [1, 0], [1, 1], [0, 0], [1, 1], [0, 1]], np.float32)
        self.assertEqual(lib().hairis_scene_set_mesh_attribute(scene, b"name=uv", ptr(uv), 12), OK,
                         last_error())
        self.assertEqual(lib().hairis_scene_add_light(
            scene, b"type=sun;direction=0.2,0.1,1;strength=2"), OK, last_error())
        self.assertEqual(lib().hairis_scene_set_camera(
            scene, b"matrix=1,0,0,0,0,1,0,0,0,0,1,3,0,0,0,1;orthographic=1;"
                   b"frame=0.8,0.4,-1,0.8,-0.4,-1,-0.8,-0.4,-1,-0.8,0.4,-1;width=4;height=2"), OK)
        rgba = np.zeros((2, 4, 4), np.float32)
        self.assertEqual(lib().hairis_render(scene, b"samples=2;max_bounces=0;strategy=analytic",
                                             ptr(rgba), PROGRESS_FN(), None), OK, last_error())
        left, right = rgba[:, :2, :3].mean(axis=(0, 1)), rgba[:, 2:, :3].mean(axis=(0, 1))
        np.testing.assert_allclose(left / right, pixels[0, 0] / pixels[0, 1], rtol=1e-5)
        lib().hairis_scene_destroy(scene)

    def test_mesh_attributes_need_a_mesh_and_the_right_count(self):
        scene = lib().hairis_scene_create()
        uv = np.zeros(6, np.float32)
        self.assertEqual(lib().hairis_scene_set_mesh_attribute(scene, b"name=uv", ptr(uv), 6),
                         ERROR_INVALID_ARGUMENT)
        self.assertIn("no triangles", last_error())
        self.assertGreaterEqual(lib().hairis_scene_add_surface_material(scene, b""), 0)
        vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
        indices = np.array([0, 1, 2], np.uint32)
        materials = np.zeros(1, np.int32)
        self.assertEqual(lib().hairis_scene_add_mesh(scene, 3, ptr(vertices), 1,
                                                     ptr(indices, c_uint32),
                                                     ptr(materials, c_int32)), OK)
        self.assertEqual(lib().hairis_scene_set_mesh_attribute(scene, b"name=normal", ptr(uv), 6),
                         ERROR_INVALID_ARGUMENT)
        self.assertIn("9", last_error())
        normals = np.tile(np.array([0, 0, 1], np.float32), 3)
        normals[4] = np.nan
        self.assertEqual(lib().hairis_scene_set_mesh_attribute(scene, b"name=normal",
                                                               ptr(normals), 9),
                         ERROR_INVALID_ARGUMENT)
        self.assertIn("values[4]", last_error())
        self.assertEqual(lib().hairis_scene_set_mesh_attribute(scene, b"name=uv", ptr(uv), 6), OK,
                         last_error())
        # A call that adds no triangles leaves no mesh to attach to.
        self.assertEqual(lib().hairis_scene_add_mesh(scene, 0, None, 0, None, None), OK)
        self.assertEqual(lib().hairis_scene_set_mesh_attribute(scene, b"name=uv", ptr(uv), 6),
                         ERROR_INVALID_ARGUMENT)
        lib().hairis_scene_destroy(scene)


def main():
    global OPTIONS, PROTOTYPES, PROGRESS_FN, UPDATE_FN, STATUS_NAMES
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", required=True, help="libhairis.so")
    parser.add_argument("--header", action="append", default=[],
                        help="a public header (hairis.h, hairis_render.h); repeat for each")
    parser.add_argument("--nm", help="the nm program (default: nm on PATH)")
    parser.add_argument("--addon-native", default=os.path.join(
        os.path.dirname(os.path.abspath(__file__)), "..", "..", "addon", "hairis", "native.py"),
        help="addon/hairis/native.py, whose PROTOTYPES the library is called through")
    parser.add_argument("--fake-library", help="tests/blender's libhairis_fake.so")
    parser.add_argument("--version", help="the project's version")
    OPTIONS, rest = parser.parse_known_args()
    if np is None:
        print("SKIP: numpy is not installed for %s" % sys.executable)
        return 77
    native = load_native(OPTIONS.addon_native)
    PROTOTYPES = native.PROTOTYPES
    PROGRESS_FN = native.PROGRESS_FN
    UPDATE_FN = native.UPDATE_FN
    STATUS_NAMES = native.STATUS_NAMES
    globals().update({name[len("HAIRIS_"):]: code for code, name in STATUS_NAMES.items()})
    program = unittest.main(argv=[sys.argv[0]] + rest, exit=False, verbosity=2)
    result = program.result
    failed = len(result.failures) + len(result.errors)
    skipped = len(result.skipped)
    print("%d passed, %d failed, %d skipped" % (result.testsRun - failed - skipped, failed,
                                                skipped))
    return 0 if result.wasSuccessful() else 1


if __name__ == "__main__":
    sys.exit(main())
