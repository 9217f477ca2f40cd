#!/usr/bin/env python3
"""Tests of the hairis C API through Python's ctypes, the way the Blender add-on loads it.

Usage (CTest passes every option):
    capi_ctypes_test.py --library libhairis.so [--layout-tool capi_test] [--header hairis.h]
                        [--addon-native addon/hairis/native.py] [--version X.Y.Z]
                        [unittest options]

The struct mirrors below are declared here, independently of the add-on; TestLayout compares
them (and the add-on's, when --addon-native is given) with the sizes and offsets the C
compiler gives (``capi_test --layout``). Exits non-zero on a failure; 77 (skip) when numpy is
missing.
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
from ctypes import POINTER, c_char_p, c_double, c_float, c_int, c_int32, c_size_t, c_uint32
from ctypes import c_uint64, c_void_p

try:
    import numpy as np
except ImportError:  # pragma: no cover - reported as a skip
    np = None

OPTIONS = None  # parsed command line

OK = 0
ERROR_INVALID_ARGUMENT = 1
ERROR_IO = 2
ERROR_INVALID_TABLE = 3
ERROR_CANCELLED = 4
ERROR_INTERNAL = 5

UNIFORM, ANALYTIC, GAUSSIAN, TABLE = 0, 1, 2, 3
PARAM_ABSORPTION, PARAM_MELANIN, PARAM_COLOR = 0, 1, 2


# ---- Struct mirrors of hairis.h ------------------------------------------------------------

class PrincipledHair(ctypes.Structure):
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


class MarschnerParams(ctypes.Structure):
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


class BakeOptions(ctypes.Structure):
    _fields_ = [
        ("theta_r_count", c_int),
        ("theta_i_count", c_int),
        ("phi_count", c_int),
        ("n_h_count", c_int),
        ("n_h_values", c_int * 16),
        ("source", c_int),
        ("threads", c_int),
    ]


class Camera(ctypes.Structure):
    _fields_ = [
        ("camera_to_world", c_float * 16),
        ("orthographic", c_int),
        ("frame", c_float * 12),
        ("width", c_int),
        ("height", c_int),
    ]


class RenderSettings(ctypes.Structure):
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

PROGRESS_FN = ctypes.CFUNCTYPE(c_int, c_void_p, c_float)
F = POINTER(c_float)

SIGNATURES = {
    "hairis_api_version": (c_int, []),
    "hairis_version_string": (c_char_p, []),
    "hairis_last_error": (c_char_p, []),
    "hairis_principled_hair_defaults": (None, [POINTER(PrincipledHair)]),
    "hairis_marschner_defaults": (None, [POINTER(MarschnerParams)]),
    "hairis_fiber_create_principled": (c_void_p, [POINTER(PrincipledHair)]),
    "hairis_fiber_create_marschner": (c_void_p, [POINTER(MarschnerParams)]),
    "hairis_fiber_destroy": (None, [c_void_p]),
    "hairis_fiber_model": (c_char_p, [c_void_p]),
    "hairis_fiber_parameters": (c_char_p, [c_void_p]),
    "hairis_fiber_eval": (c_int, [c_void_p, c_size_t, F, F, F, F]),
    "hairis_bake_options_defaults": (None, [POINTER(BakeOptions)]),
    "hairis_tables_bake": (c_void_p, [c_void_p, POINTER(BakeOptions), PROGRESS_FN, c_void_p]),
    "hairis_tables_write": (c_int, [c_void_p, c_char_p]),
    "hairis_tables_load_file": (c_void_p, [c_char_p]),
    "hairis_tables_load_memory": (c_void_p, [c_void_p, c_size_t]),
    "hairis_tables_destroy": (None, [c_void_p]),
    "hairis_tables_model": (c_char_p, [c_void_p]),
    "hairis_tables_parameters": (c_char_p, [c_void_p]),
    "hairis_tables_match_fiber": (c_int, [c_void_p, c_void_p]),
    "hairis_sampler_create": (c_void_p, [c_int, c_void_p, c_void_p, c_float, c_int]),
    "hairis_sampler_destroy": (None, [c_void_p]),
    "hairis_sample": (c_int, [c_void_p, c_size_t, F, F, F, F, F]),
    "hairis_pdf": (c_int, [c_void_p, c_size_t, F, F, F, F]),
    "hairis_scene_create": (c_void_p, []),
    "hairis_scene_destroy": (None, [c_void_p]),
    "hairis_scene_add_hair_material": (c_int, [c_void_p, POINTER(PrincipledHair), c_void_p]),
    "hairis_scene_add_diffuse_material": (c_int, [c_void_p, F, F]),
    "hairis_scene_add_curves": (c_int, [c_void_p, c_int, c_size_t, POINTER(c_uint32), c_size_t,
                                        F, F]),
    "hairis_scene_add_mesh": (c_int, [c_void_p, c_size_t, F, c_size_t, POINTER(c_uint32),
                                      POINTER(c_int32)]),
    "hairis_scene_add_sun": (c_int, [c_void_p, F, F, c_float, c_float]),
    "hairis_scene_add_point_light": (c_int, [c_void_p, F, F, c_float, c_float]),
    "hairis_scene_add_area_light": (c_int, [c_void_p, F, c_int, c_float, c_float, F, c_float]),
    "hairis_scene_set_world": (c_int, [c_void_p, F, c_float]),
    "hairis_scene_set_camera": (c_int, [c_void_p, POINTER(Camera)]),
    "hairis_render_settings_defaults": (None, [POINTER(RenderSettings)]),
    "hairis_render": (c_int, [c_void_p, POINTER(RenderSettings), F, PROGRESS_FN, c_void_p,
                              POINTER(RenderStats)]),
}

_LIB = None


def lib():
    """The library, loaded once, with every signature declared."""
    global _LIB
    if _LIB is None:
        raw = ctypes.CDLL(OPTIONS.library)
        for name, (restype, argtypes) in SIGNATURES.items():
            function = getattr(raw, name)
            function.restype = restype
            function.argtypes = argtypes
        _LIB = raw
    return _LIB


def last_error():
    return lib().hairis_last_error().decode("utf-8")


def ptr(array, ctype=c_float):
    return None if array is None else array.ctypes.data_as(POINTER(ctype))


def vec(*values):
    return (c_float * len(values))(*values)


def node_defaults():
    node = PrincipledHair()
    lib().hairis_principled_hair_defaults(ctypes.byref(node))
    return node


def make_fiber(**changes):
    node = node_defaults()
    for name, value in changes.items():
        setattr(node, name, value)
    return lib().hairis_fiber_create_principled(ctypes.byref(node))


def tiny_options():
    options = BakeOptions()
    lib().hairis_bake_options_defaults(ctypes.byref(options))
    options.theta_r_count = 4
    options.theta_i_count = 8
    options.phi_count = 8
    options.n_h_count = 2
    options.n_h_values[0] = 1
    options.n_h_values[1] = 2
    options.threads = 2
    return options


def unit_vectors(rng, n):
    v = rng.normal(size=(n, 3)).astype(np.float64)
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    v[:, 0] = np.clip(v[:, 0], -0.98, 0.98)  # away from the fiber axis
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    return np.ascontiguousarray(v, dtype=np.float32)


_BYTES = None  # EXR bytes of tables baked once for the default node


def default_table_bytes():
    """Bakes tables for the default node once and returns the EXR file's bytes."""
    global _BYTES
    if _BYTES is None:
        fiber = make_fiber()
        tables = lib().hairis_tables_bake(fiber, ctypes.byref(tiny_options()), PROGRESS_FN(),
                                          None)
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

class TestLayout(unittest.TestCase):
    """The ctypes mirrors have the C compiler's sizes and offsets."""

    @classmethod
    def setUpClass(cls):
        if not OPTIONS.layout_tool:
            raise unittest.SkipTest("no --layout-tool")
        output = subprocess.run([OPTIONS.layout_tool, "--layout"], check=True,
                                capture_output=True, text=True).stdout
        cls.sizes, cls.offsets = {}, {}
        for line in output.splitlines():
            parts = line.split()
            if parts[0] == "struct":
                cls.sizes[parts[1]] = int(parts[2])
            elif parts[0] == "field":
                cls.offsets[(parts[1], parts[2])] = int(parts[3])

    def check_structs(self, structs, who):
        self.assertEqual(set(structs), set(self.sizes), "%s: the set of structs" % who)
        for name, struct in structs.items():
            self.assertEqual(ctypes.sizeof(struct), self.sizes[name], "%s: sizeof %s" % (who, name))
            fields = [field[0] for field in struct._fields_]
            expected = sorted((f for (s, f) in self.offsets if s == name),
                              key=lambda f: self.offsets[(name, f)])
            self.assertEqual(fields, expected, "%s: fields of %s in order" % (who, name))
            for field in fields:
                self.assertEqual(getattr(struct, field).offset, self.offsets[(name, field)],
                                 "%s: offset of %s.%s" % (who, name, field))

    def test_mirrors_here(self):
        self.check_structs(STRUCTS, "this test")

    def test_addon_mirrors(self):
        if not OPTIONS.addon_native or not os.path.exists(OPTIONS.addon_native):
            self.skipTest("no --addon-native")
        spec = importlib.util.spec_from_file_location("hairis_addon_native", OPTIONS.addon_native)
        native = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(native)
        self.check_structs(native.STRUCTS, "addon/hairis/native.py")
        self.assertEqual(set(native.SIGNATURES), set(SIGNATURES), "the add-on binds every function")


class TestLibrary(unittest.TestCase):

    def test_version(self):
        self.assertEqual(lib().hairis_api_version(), 1)
        self.assertEqual(last_error(), "")
        version = lib().hairis_version_string().decode()
        if OPTIONS.version:
            self.assertEqual(version, OPTIONS.version)
        self.assertRegex(version, r"^\d+\.\d+\.\d+")

    def test_every_header_function_is_exported(self):
        if not OPTIONS.header:
            self.skipTest("no --header")
        with open(OPTIONS.header) as f:
            text = f.read()
        names = set(re.findall(r"HAIRIS_API\s+[^;(]*?\b(hairis_\w+)\s*\(", text))
        self.assertEqual(names, set(SIGNATURES))
        for name in names:
            self.assertTrue(hasattr(lib(), name), name)

    def test_errors_are_strings_and_per_thread(self):
        self.assertIsNone(lib().hairis_fiber_create_principled(None))
        message = last_error()
        self.assertIn("node must not be NULL", message)
        seen = []
        thread = threading.Thread(target=lambda: seen.append(last_error()))
        thread.start()
        thread.join()
        self.assertEqual(seen, [""], "another thread has its own last error")
        lib().hairis_api_version()
        self.assertEqual(last_error(), "")


class TestFibers(unittest.TestCase):

    def test_defaults(self):
        node = node_defaults()
        self.assertEqual(node.parametrization, PARAM_COLOR)
        self.assertAlmostEqual(node.ior, 1.55, places=6)
        self.assertAlmostEqual(node.offset, 0.0349065848, places=7)
        params = MarschnerParams()
        lib().hairis_marschner_defaults(ctypes.byref(params))
        self.assertAlmostEqual(params.sigma_a[0], 0.15, places=6)
        self.assertAlmostEqual(params.eccentricity, 0.9, places=6)
        self.assertEqual(last_error(), "")

    def test_create_and_strings(self):
        fiber = make_fiber()
        self.assertTrue(fiber, last_error())
        self.assertEqual(lib().hairis_fiber_model(fiber), b"chiang2016")
        parameters = lib().hairis_fiber_parameters(fiber).decode()
        self.assertTrue(parameters.startswith("sigma_a.r="), parameters)
        self.assertEqual(len(parameters.split(";")), 8)
        lib().hairis_fiber_destroy(fiber)
        params = MarschnerParams()
        lib().hairis_marschner_defaults(ctypes.byref(params))
        marschner = lib().hairis_fiber_create_marschner(ctypes.byref(params))
        self.assertTrue(marschner, last_error())
        self.assertEqual(lib().hairis_fiber_model(marschner), b"marschner2003")
        lib().hairis_fiber_destroy(marschner)

    def test_invalid_inputs_name_the_argument(self):
        cases = [
            (dict(roughness=1.5), "node.roughness"),
            (dict(ior=1.0), "node.ior"),
            (dict(coat=float("nan")), "node.coat"),
            (dict(parametrization=3), "node.parametrization"),
            (dict(random=-0.5), "node.random"),
        ]
        for changes, word in cases:
            with self.subTest(changes=changes):
                self.assertIsNone(make_fiber(**changes))
                self.assertIn(word, last_error())
        params = MarschnerParams()
        lib().hairis_marschner_defaults(ctypes.byref(params))
        params.caustic_intensity_limit = -1
        self.assertIsNone(lib().hairis_fiber_create_marschner(ctypes.byref(params)))
        self.assertIn("params.caustic_intensity_limit", last_error())

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
        self.assertEqual(lib().hairis_fiber_eval(fiber, n, ptr(wi), ptr(wo), None, ptr(out)),
                         ERROR_INVALID_ARGUMENT)
        self.assertIn("wi item 7", last_error())
        lib().hairis_fiber_destroy(fiber)

        params = MarschnerParams()
        lib().hairis_marschner_defaults(ctypes.byref(params))
        marschner = lib().hairis_fiber_create_marschner(ctypes.byref(params))
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
        seen = []

        def progress(_user, fraction):
            seen.append(fraction)
            return 0

        callback = PROGRESS_FN(progress)
        tables = lib().hairis_tables_bake(fiber, ctypes.byref(tiny_options()), callback, None)
        self.assertTrue(tables, last_error())
        self.assertEqual(last_error(), "")
        self.assertEqual(seen[-1], 1.0)
        self.assertEqual(seen, sorted(seen))
        self.assertEqual(lib().hairis_tables_match_fiber(tables, fiber), 1)
        self.assertEqual(lib().hairis_tables_parameters(tables),
                         lib().hairis_fiber_parameters(fiber))
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "t.exr")
            self.assertEqual(lib().hairis_tables_write(tables, path.encode()), OK, last_error())
            loaded = lib().hairis_tables_load_file(path.encode())
            self.assertTrue(loaded, last_error())
            self.assertEqual(lib().hairis_tables_match_fiber(loaded, fiber), 1)
            lib().hairis_tables_destroy(loaded)
            bad = os.path.join(folder, "missing", "t.exr")
            self.assertEqual(lib().hairis_tables_write(tables, bad.encode()), ERROR_IO)
            self.assertIn("missing", last_error())
        lib().hairis_tables_destroy(tables)
        other = make_fiber(coat=0.5)
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
        callback = PROGRESS_FN(lambda _user, _fraction: 1)
        self.assertIsNone(lib().hairis_tables_bake(fiber, ctypes.byref(tiny_options()),
                                                   callback, None))
        self.assertEqual(last_error(), "cancelled")
        lib().hairis_fiber_destroy(fiber)

    def test_bad_options(self):
        fiber = make_fiber()
        options = tiny_options()
        options.phi_count = 0
        self.assertIsNone(lib().hairis_tables_bake(fiber, ctypes.byref(options), PROGRESS_FN(),
                                                   None))
        self.assertIn("phi_count", last_error())
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
        for strategy in (UNIFORM, ANALYTIC, GAUSSIAN, TABLE):
            with self.subTest(strategy=strategy):
                sampler = lib().hairis_sampler_create(strategy, self.fiber, self.tables, 0.25, 2)
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
        sampler = lib().hairis_sampler_create(TABLE, None, tables, 0.5, 1)
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
        self.assertIsNone(lib().hairis_sampler_create(TABLE, self.fiber, None, 0.25, 2))
        self.assertIn("tables", last_error())
        self.assertIsNone(lib().hairis_sampler_create(12, None, None, 0.25, 2))
        self.assertIn("strategy", last_error())
        self.assertIsNone(lib().hairis_sampler_create(GAUSSIAN, None, None, -0.1, 2))
        self.assertIn("multiple_weight", last_error())
        sampler = lib().hairis_sampler_create(UNIFORM, None, None, 0.0, 1)
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

    def make_scene(self, tables, **node_changes):
        node = node_defaults()
        for name, value in node_changes.items():
            setattr(node, name, value)
        scene = lib().hairis_scene_create()
        self.assertEqual(lib().hairis_scene_add_hair_material(scene, ctypes.byref(node), tables), 0)
        self.assertEqual(lib().hairis_scene_add_diffuse_material(scene, vec(0.5, 0.5, 0.5),
                                                                 vec(0, 0, 0)), 1)
        curves, points = 6, 5
        first = np.arange(0, curves * points + 1, points, dtype=np.uint32)
        x = np.linspace(-1.5, 1.5, points)
        positions = np.array([[xx, -0.75 + 0.3 * c, 0.1 * np.sin(3 * xx)] for c in range(curves)
                              for xx in x], np.float32)
        radii = np.full(curves * points, 0.04, np.float32)
        self.assertEqual(lib().hairis_scene_add_curves(scene, 0, curves, ptr(first, c_uint32),
                                                       len(positions), ptr(positions), ptr(radii)),
                         OK, last_error())
        vertices = np.array([[-3, -3, -0.5], [3, -3, -0.5], [0, 3, -0.5]], np.float32)
        indices = np.array([0, 1, 2], np.uint32)
        materials = np.array([1], np.int32)
        self.assertEqual(lib().hairis_scene_add_mesh(scene, 3, ptr(vertices), 1,
                                                     ptr(indices, c_uint32),
                                                     ptr(materials, c_int32)), OK, last_error())
        self.assertEqual(lib().hairis_scene_add_sun(scene, vec(0.2, 0.4, 1), vec(1, 1, 1), 2.0,
                                                    0.02), OK)
        self.assertEqual(lib().hairis_scene_set_world(scene, vec(0.05, 0.05, 0.08), 1.0), OK)
        self.assertEqual(lib().hairis_scene_add_point_light(scene, vec(1, 1, 2), vec(1, 0.9, 0.8),
                                                            20.0, 0.1), OK, last_error())
        area = np.array([[1, 0, 0, -1], [0, 1, 0, 0], [0, 0, 1, 2.5], [0, 0, 0, 1]], np.float32)
        self.assertEqual(lib().hairis_scene_add_area_light(scene, ptr(area), 2, 0.5, 0.5,
                                                           vec(1, 1, 1), 30.0), OK, last_error())
        self.assertEqual(lib().hairis_scene_add_area_light(scene, ptr(area), 9, 0.5, 0.5,
                                                           vec(1, 1, 1), 30.0),
                         ERROR_INVALID_ARGUMENT)
        self.assertIn("shape", last_error())
        camera = Camera()
        camera.camera_to_world[:] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 3, 0, 0, 0, 1]
        ax, ay = 0.4, 0.3  # 4:3 like the resolution
        camera.frame[:] = [ax, ay, -1, ax, -ay, -1, -ax, -ay, -1, -ax, ay, -1]
        camera.width, camera.height = self.W, self.H
        self.assertEqual(lib().hairis_scene_set_camera(scene, ctypes.byref(camera)), OK,
                         last_error())
        return scene

    def settings(self, strategy, samples=4):
        s = RenderSettings()
        lib().hairis_render_settings_defaults(ctypes.byref(s))
        s.samples, s.max_bounces, s.strategy, s.threads, s.seed = samples, 2, strategy, 2, 3
        return s

    def test_tiny_render(self):
        tables = load_memory(default_table_bytes())
        scene = self.make_scene(tables)
        lib().hairis_tables_destroy(tables)  # the scene keeps what it needs
        for strategy in (ANALYTIC, TABLE):
            with self.subTest(strategy=strategy):
                rgba = np.full((self.H, self.W, 4), -1, np.float32)
                stats = RenderStats()
                status = lib().hairis_render(scene, ctypes.byref(self.settings(strategy)),
                                             ptr(rgba), PROGRESS_FN(), None, ctypes.byref(stats))
                self.assertEqual(status, OK, last_error())
                self.assertTrue(np.all(np.isfinite(rgba)) and np.all(rgba >= 0))
                self.assertTrue(np.all(rgba[..., 3] == 1))
                self.assertGreater(rgba[..., :3].sum(), 0)
                self.assertEqual(stats.camera_rays, self.W * self.H * 4)
        lib().hairis_scene_destroy(scene)

    def test_cancel_from_python(self):
        scene = self.make_scene(None)
        rgba = np.zeros((self.H, self.W, 4), np.float32)
        calls = []

        def progress(_user, fraction):
            calls.append(fraction)
            return 1

        status = lib().hairis_render(scene, ctypes.byref(self.settings(ANALYTIC, 1 << 16)),
                                     ptr(rgba), PROGRESS_FN(progress), None, None)
        self.assertEqual(status, ERROR_CANCELLED)
        self.assertIn("cancelled", last_error())
        self.assertGreaterEqual(len(calls), 1)
        lib().hairis_scene_destroy(scene)

    def test_table_refusals(self):
        rgba = np.zeros((self.H, self.W, 4), np.float32)
        scene = self.make_scene(None)
        status = lib().hairis_render(scene, ctypes.byref(self.settings(TABLE)), ptr(rgba),
                                     PROGRESS_FN(), None, None)
        self.assertEqual(status, ERROR_INVALID_TABLE)
        self.assertIn("material 0", last_error())
        lib().hairis_scene_destroy(scene)
        tables = load_memory(default_table_bytes())
        scene = self.make_scene(tables, radial_roughness=0.6)
        status = lib().hairis_render(scene, ctypes.byref(self.settings(TABLE)), ptr(rgba),
                                     PROGRESS_FN(), None, None)
        self.assertEqual(status, ERROR_INVALID_TABLE)
        self.assertIn("material 0", last_error())
        self.assertIn("baked for", last_error())
        lib().hairis_scene_destroy(scene)
        lib().hairis_tables_destroy(tables)

    def test_empty_scene(self):
        scene = lib().hairis_scene_create()
        rgba = np.zeros((self.H, self.W, 4), np.float32)
        status = lib().hairis_render(scene, ctypes.byref(self.settings(ANALYTIC)), ptr(rgba),
                                     PROGRESS_FN(), None, None)
        self.assertEqual(status, ERROR_INVALID_ARGUMENT)
        self.assertIn("camera", last_error())
        lib().hairis_scene_destroy(scene)


def main():
    global OPTIONS
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--library", required=True, help="libhairis.so")
    parser.add_argument("--layout-tool", help="capi_test, which prints the C layouts")
    parser.add_argument("--header", help="hairis.h")
    parser.add_argument("--addon-native", help="addon/hairis/native.py")
    parser.add_argument("--version", help="the project's version")
    OPTIONS, rest = parser.parse_known_args()
    if np is None:
        print("SKIP: numpy is not installed for %s" % sys.executable)
        return 77
    program = unittest.main(argv=[sys.argv[0]] + rest, exit=False, verbosity=2)
    result = program.result
    failed = len(result.failures) + len(result.errors)
    skipped = len(result.skipped)
    print("%d passed, %d failed, %d skipped" % (result.testsRun - failed - skipped, failed,
                                                skipped))
    return 0 if result.wasSuccessful() else 1


if __name__ == "__main__":
    sys.exit(main())
