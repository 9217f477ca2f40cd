#!/usr/bin/env python3
"""CLI tests of hairis-bake: every subcommand, its outputs, determinism and its errors.

Usage: test_hairis_bake.py PATH/TO/hairis-bake
"""
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import unittest

BAKE = None
SMALL = ["--theta-r", "5", "--theta-i", "16", "--phi", "16", "--quadrature", "1", "--n-h", "1,2"]


def run(*args, env=None):
    full_env = dict(os.environ)
    full_env.update(env or {})
    return subprocess.run([BAKE, *args], capture_output=True, text=True, env=full_env, timeout=600)


def decode_log_panels(png_path, colormap, count):
    """The images of a figure of ``count`` side-by-side imshow panels in ``colormap``: per
    panel (left to right) the colormap position t in [0, 1] at the centre of each cell, as a
    function ``cells(rows, columns)`` -> array (row 0 at the bottom); and the largest distance
    of a sampled colour from the colormap. Panels are the wide runs of columns that are
    mostly non-white (the colour bar is narrow, labels are short)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.image
    import numpy as np
    pixels = matplotlib.image.imread(png_path)[:, :, :3].astype(np.float64)
    inked = pixels.sum(axis=2) < 2.9
    tall = inked.sum(axis=0) > 0.5 * pixels.shape[0]
    edges = np.flatnonzero(np.diff(np.concatenate([[0], tall.astype(int), [0]])))
    runs = [(a, b) for a, b in zip(edges[::2], edges[1::2]) if b - a > 50]
    assert len(runs) == count, runs
    lut = matplotlib.colormaps[colormap](np.linspace(0.0, 1.0, 256))[:, :3]
    panels = []
    for left, right in runs:
        rows = np.flatnonzero(inked[:, left:right].mean(axis=1) > 0.9)
        top, bottom = rows[0], rows[-1] + 1
        panels.append((left + 1, right - 1, top + 1, bottom - 1))  # inside the spines

    def cells(panel, n_rows, n_columns):
        left, right, top, bottom = panels[panel]
        ys = bottom - (np.arange(n_rows) + 0.5) * (bottom - top) / n_rows
        xs = left + (np.arange(n_columns) + 0.5) * (right - left) / n_columns
        colours = pixels[ys.astype(int)][:, xs.astype(int)]
        distance = np.linalg.norm(colours[:, :, None, :] - lut[None, None, :, :], axis=3)
        return distance.argmin(axis=2) / 255.0, float(distance.min(axis=2).max())
    return cells


class HairisBakeTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="hairis_cli_")

    def tearDown(self):
        shutil.rmtree(self.dir, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.dir, name)

    def assert_no_output(self, name):
        leftovers = [f for f in os.listdir(self.dir) if f.startswith(name)]
        self.assertEqual(leftovers, [], "a failed command left files behind")

    # --- help ---------------------------------------------------------------------------
    def test_help_on_every_subcommand(self):
        for sub in [[], ["bake"], ["inspect"], ["figures"], ["fits"]]:
            r = run(*sub, "--help")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("Usage", r.stdout)

    # --- bake and inspect -----------------------------------------------------------------
    def test_bake_then_inspect(self):
        out = self.path("t.exr")
        r = run("bake", *SMALL, "--output", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertTrue(os.path.getsize(out) > 0)
        r = run("inspect", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        for text in ["chiang2016", "theta_r nodes:   5", "theta_i cells:   16",
                     "n_h values:      1 2",
                     "far    rows 0-79: 5 theta_r nodes x 16 theta_i cells",
                     "near   rows 80-", "x 4 lobes", "valid:           yes"]:
            self.assertIn(text, r.stdout)

    def test_huang_bake_then_inspect(self):
        out, again = self.path("h.exr"), self.path("h2.exr")
        small = ["--huang-theta-o", "6", "--huang-phi-o", "3", "--huang-theta-i", "12",
                 "--huang-phi", "16"]
        r = run("bake", "--preset", "cycles-default-huang", *small, "--no-huang-multiple",
                "--threads", "1", "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("huang2022, 6 theta_o x 3 phi_o nodes, 12 x 16 cells,", r.stderr)
        self.assertNotIn("multiple part", r.stderr)
        r = run("bake", "--set", "model=huang", *small, "--no-huang-multiple", "--threads", "2",
                "-q", "-o", again)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(out, "rb") as fa, open(again, "rb") as fb:
            self.assertEqual(fa.read(), fb.read(), "the Huang bake depends on the thread count")
        r = run("inspect", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        for text in ["huang2022", "aspect_ratio", "secondary_reflection",
                     "theta_o nodes:   6", "phi_o nodes:     3 (0.00 .. 90.00 deg)",
                     "huang  rows 0-215: 3 phi_o nodes x 6 theta_o nodes x 12 theta_i cells",
                     "f  rows 216-431: the same cells", "cells:           6912",
                     "image:           16 x 432", "valid:           yes"]:
            self.assertIn(text, r.stdout)
        self.assertNotIn("far    rows", r.stdout)
        self.assertIn("(no multiple part", r.stdout)
        # Without the f part: renders fall back to Cycles' eval, and inspect says so.
        no_f = self.path("hnf.exr")
        r = run("bake", "--set", "model=huang", *small, "--no-huang-multiple", "--no-huang-f",
                "-q", "-o", no_f)
        self.assertEqual(r.returncode, 0, r.stderr)
        r = run("inspect", no_f)
        self.assertEqual(r.returncode, 0, r.stderr)
        for text in ["(no f part", "cells:           3456", "image:           16 x 216"]:
            self.assertIn(text, r.stdout)
        # A refined f part is another bake, and inspect names its refinement.
        refined = self.path("hr.exr")
        r = run("bake", "--set", "model=huang", *small, "--no-huang-multiple",
                "--huang-f-refinement", "2", "-q", "-o", refined)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(out, "rb") as fa, open(refined, "rb") as fb:
            self.assertNotEqual(fa.read(), fb.read(), "--huang-f-refinement changed nothing")
        r = run("inspect", refined)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("quadrature refinement 2", r.stdout)
        r = run("bake", "--set", "model=huang", *small, "--huang-f-refinement", "5", "-o", refined)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--huang-f-refinement", r.stderr)
        # With the multiple part (the default): after the Huang part, one column per n_h.
        multiple = self.path("hm.exr")
        r = run("bake", "--set", "model=huang", *small, "--theta-r", "4", "--theta-i", "8",
                "--n-h", "1,4", "--threads", "2", "-o", multiple)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("12 x 16 cells, multiple part 4 x 8", r.stderr)
        r = run("inspect", multiple)
        self.assertEqual(r.returncode, 0, r.stderr)
        for text in ["multiple  rows 432-463: 4 theta_r nodes (-67.50 .. 67.50 deg) x 8 theta_i "
                     "cells, columns n_h = 1 4", "cells:           6976",
                     "image:           16 x 464", "valid:           yes"]:
            self.assertIn(text, r.stdout)
        r = run("bake", "--set", "model=huang", "--source", "gaussian", "-q", "-o", again)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("huang2022", r.stderr)
        out = self.path("huang_figures")
        r = run("figures", "--table", self.path("h.exr"), "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out, "table_huang.png"), "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        import numpy as np
        values = np.load(os.path.join(out, "table_huang.npy"))
        self.assertEqual(values.shape, (3, 6, 12, 16))
        self.assertTrue((values >= 0).all() and (values > 0).any())

    def test_bake_is_deterministic_whatever_the_thread_count(self):
        a, b = self.path("a.exr"), self.path("b.exr")
        self.assertEqual(run("bake", *SMALL, "--threads", "1", "-q", "-o", a).returncode, 0)
        self.assertEqual(run("bake", *SMALL, "--threads", "2", "-q", "-o", b).returncode, 0)
        with open(a, "rb") as fa, open(b, "rb") as fb:
            self.assertEqual(fa.read(), fb.read(), "the same bake gave different bytes")

    def test_presets_param_file_and_set(self):
        params = self.path("fiber.txt")
        with open(params, "w") as f:
            f.write("# a dark Principled Hair fiber\nparametrization = melanin\nmelanin = 0.9\n")
        out = self.path("p.exr")
        r = run("bake", *SMALL, "--param-file", params, "--set", "roughness=0.4", "-q", "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        r = run("inspect", out)
        self.assertIn("roughness          0.40", r.stdout)
        for preset, model in [("blonde", "marschner2003"), ("brunette", "marschner2003")]:
            out = self.path(preset + ".exr")
            r = run("bake", "--preset", preset, "--theta-r", "3", "--theta-i", "8", "--phi", "8",
                    "--quadrature", "1", "--n-h", "1", "-q", "-o", out)
            self.assertEqual(r.returncode, 0, r.stderr)
            described = run("inspect", out).stdout
            self.assertIn(model, described)
            self.assertNotIn("near   rows", described, "a Marschner table has no near part")

    def test_gaussian_source(self):
        out = self.path("g.exr")
        self.assertEqual(run("bake", *SMALL, "--source", "gaussian", "-q", "-o", out).returncode, 0)
        self.assertIn("gaussian", run("inspect", out).stdout)

    # --- errors ------------------------------------------------------------------------------
    def test_bad_flags_name_the_flag(self):
        out = self.path("bad.exr")
        cases = [
            (["bake", "--theta-i", "0", "-o", out], "--theta-i"),
            (["bake", "--preset", "ginger", "-o", out], "--preset"),
            (["bake", "--source", "magic", "-o", out], "--source"),
            (["bake", "--n-h", "4,2", "-o", out], "strictly increasing"),
            (["bake", "--set", "ior=0.5", "-o", out], "ior"),
            (["bake", "--set", "shinyness=1", "-o", out], "unknown parameter"),
            (["bake"], "--output"),
            (["frobnicate"], "frobnicate"),
        ]
        for args, fragment in cases:
            r = run(*args)
            self.assertNotEqual(r.returncode, 0, args)
            self.assertIn(fragment, r.stderr + r.stdout, args)
        self.assert_no_output("bad.exr")

    def test_bad_parameter_file(self):
        params = self.path("fiber.txt")
        with open(params, "w") as f:
            f.write("roughness = lots\n")
        r = run("bake", "--param-file", params, "-o", self.path("x.exr"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("line 1: roughness must be a finite number", r.stderr)
        r = run("bake", "--param-file", self.path("missing.txt"), "-o", self.path("x.exr"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("--param-file", r.stderr)
        self.assert_no_output("x.exr")

    def test_bad_parameter_values_are_refused(self):
        params = self.path("fiber.txt")
        cases = [
            ("ior = 1\n", "ior must be finite and greater than 1"),
            ("roughness = 2\n", "roughness must be in [0, 1]"),
            ("radial_roughness = -0.1\n", "radial_roughness must be in [0, 1]"),
            ("roughness = nan\n", "line 1: roughness must be a finite number"),
            ("offset_deg = inf\n", "line 1: offset_deg must be a finite number"),
            ("parametrization = melanin\nmelanin = -1\n", "melanin must be in [0, 1]"),
            ("model = marschner\neta = 0.9\n", "eta must be in (1, 4]"),
            ("model = lambert\n", "line 1: model must be chiang, huang or marschner"),
            ("# fine\nno equals sign\n", "line 2: expected key = value"),
        ]
        for text, fragment in cases:
            with open(params, "w") as f:
                f.write(text)
            r = run("bake", *SMALL, "--param-file", params, "-q", "-o", self.path("x.exr"))
            self.assertNotEqual(r.returncode, 0, text)
            self.assertIn(fragment, r.stderr, text)
        self.assert_no_output("x.exr")

    def test_table_too_large_is_refused_before_baking(self):
        # Each axis is in range, the product is not: refused before anything is allocated.
        r = run("bake", "--theta-r", "1024", "--theta-i", "4096", "--phi", "4096", "-q",
                "-o", self.path("huge.exr"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("17179869184 cells; at most 67108864 are allowed", r.stderr)
        self.assert_no_output("huge.exr")

    def test_unwritable_output(self):
        locked = self.path("locked")
        os.mkdir(locked)
        os.chmod(locked, stat.S_IRUSR | stat.S_IXUSR)
        target = os.path.join(locked, "t.exr")
        r = run("bake", *SMALL, "-q", "-o", target)
        if os.geteuid() == 0:
            # root writes anywhere; use a path whose folder does not exist instead
            target = self.path("no/such/dir/t.exr")
            r = run("bake", *SMALL, "-q", "-o", target)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("cannot write", r.stderr)
        self.assertFalse(os.path.exists(target))

    def test_inspect_missing_and_corrupt(self):
        r = run("inspect", self.path("missing.exr"))
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("cannot open", r.stderr)
        good = self.path("good.exr")
        self.assertEqual(run("bake", *SMALL, "-q", "-o", good).returncode, 0)
        with open(good, "rb") as f:
            data = bytearray(f.read())
        truncated = self.path("truncated.exr")
        with open(truncated, "wb") as f:
            f.write(data[: len(data) // 2])
        r = run("inspect", truncated)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("invalid", r.stderr)
        for k in range(len(data) - 64, len(data) - 32):
            data[k] ^= 0x5A
        corrupt = self.path("corrupt.exr")
        with open(corrupt, "wb") as f:
            f.write(data)
        r = run("inspect", corrupt)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("invalid", r.stderr)

    def test_interrupted_bake_leaves_no_file(self):
        out = self.path("interrupted.exr")
        r = run("bake", "--theta-r", "8", "--theta-i", "16", "--phi", "16", "-q", "-o", out,
                env={"HAIRIS_TEST_INTERRUPT_AFTER": "2"})
        self.assertEqual(r.returncode, 130, r.stderr)
        self.assertIn("interrupted", r.stderr)
        self.assert_no_output("interrupted.exr")

    def test_existing_output_survives_a_failed_bake(self):
        out = self.path("keep.exr")
        self.assertEqual(run("bake", *SMALL, "-q", "-o", out).returncode, 0)
        with open(out, "rb") as f:
            before = f.read()
        r = run("bake", *SMALL, "-q", "-o", out, env={"HAIRIS_TEST_INTERRUPT_AFTER": "1"})
        self.assertNotEqual(r.returncode, 0)
        with open(out, "rb") as f:
            self.assertEqual(f.read(), before)

    # --- figures and fits ---------------------------------------------------------------------
    def test_fits(self):
        out = self.path("fits")
        r = run("fits", "--preset", "cycles-default", "--theta-i", "60", "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out, "fits.md")) as f:
            text = f.read()
        self.assertIn("Table 1", text)
        self.assertIn("Table 2", text)
        with open(os.path.join(out, "fits_multiple.csv")) as f:
            rows = f.read().strip().splitlines()
        self.assertEqual(len(rows), 1 + 5 * 7)

    def test_figures(self):
        out = self.path("figures")
        r = run("figures", "--preset", "cycles-default", "--theta-i", "24", "--phi", "32",
                "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        for name in ["figure1.png", "figure2.png", "figure3.png", "figure4.png", "fits.md"]:
            path = os.path.join(out, name)
            self.assertTrue(os.path.getsize(path) > 0, name)
        with open(os.path.join(out, "figure1.png"), "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

    def test_figures_for_huang_with_settings(self):
        # The fits are of the fiber drawn (settings included), and the Huang figures exist.
        out = self.path("huang_seed_figures")
        r = run("figures", "--preset", "cycles-default-huang", "--set", "roughness=0.6",
                "--theta-i", "12", "--phi", "16", "--data-only", "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out, "fits.md")) as f:
            text = f.read()
        self.assertIn("## huang2022 (preset cycles-default-huang + roughness=0.6)", text)
        import numpy as np
        fig3 = np.load(os.path.join(out, "figure3.npy"))  # S_multiple at θ_r = 0 per n_h
        self.assertEqual(fig3.shape, (5, 12))
        self.assertTrue(np.all(np.isfinite(fig3)) and np.all(fig3 >= 0))
        # More strands between the light and the fiber pass less light forward.
        totals = fig3.sum(axis=1)
        self.assertTrue(np.all(np.diff(totals) < 0), totals)

    def test_fits_csv_quotes_a_label_with_commas(self):
        out = self.path("comma_figures")
        r = run("figures", "--preset", "cycles-default", "--set", "parametrization=color",
                "--set", "color=0.1,0.2,0.3", "--theta-i", "8", "--phi", "8", "--data-only",
                "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        import csv
        with open(os.path.join(out, "fits_multiple.csv"), newline="") as f:
            rows = list(csv.reader(f))
        self.assertTrue(all(len(row) == len(rows[0]) for row in rows), rows[:3])
        self.assertEqual(rows[1][1], "cycles-default + parametrization=color + color=0.1,0.2,0.3")

    def test_figures_of_a_table(self):
        table = self.path("t.exr")
        self.assertEqual(run("bake", *SMALL, "-q", "-o", table).returncode, 0)
        out = self.path("table_figures")
        r = run("figures", "--table", table, "-o", out)
        self.assertEqual(r.returncode, 0, r.stderr)
        for name in ["table_far.png", "table_multiple.png", "table_near.png"]:
            with open(os.path.join(out, name), "rb") as f:
                self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n", name)
        import numpy as np
        far = np.load(os.path.join(out, "table_far.npy"))
        self.assertEqual(far.shape, (5, 16, 16))
        self.assertTrue((far >= 0).all() and (far > 0).any())
        # The PNG shows these numbers: each cell's colour, read back through the log colour
        # scale (six decades below the largest value), is the table's value at that cell, for
        # the five θ_r nodes left to right, θ_i upwards and φ rightwards.
        cells = decode_log_panels(os.path.join(out, "table_far.png"), "magma", 5)
        top = np.log(far.max())
        low = max(np.log(far[far > 0].min()), top - np.log(1e6))
        for r in range(5):
            shown, off_map = cells(r, 16, 16)
            self.assertLess(off_map, 0.02, "panel %d: a colour not on the colour map" % r)
            expected = np.clip((np.log(np.maximum(far[r], 1e-300)) - low) / (top - low), 0, 1)
            worst = np.abs(shown - expected).max()
            self.assertLess(worst, 2.5 / 255, "θ_r node %d: pixels differ from the table by "
                            "%.3f of the colour scale" % (r, worst))
        near = np.load(os.path.join(out, "table_near.npy"))
        self.assertEqual(near.shape[1], 4)
        # Each near row is a density over θ_i: it integrates to 1 ...
        width = np.pi / near.shape[2]
        np.testing.assert_allclose(near.sum(axis=2) * width, 1.0, rtol=1e-4)
        # ... and the R lobe follows the specular cone θ_i ≈ −θ_o (slope −1 across the nodes).
        theta_o = np.linspace(-90, 90, near.shape[0])
        centres = -90 + (np.arange(near.shape[2]) + 0.5) * 180 / near.shape[2]
        rows = np.nonzero(np.abs(theta_o) < 60)[0]
        peaks = centres[np.argmax(near[rows, 0], axis=1)]
        slope = np.polyfit(theta_o[rows], peaks, 1)[0]
        self.assertTrue(-1.15 < slope < -0.85, "R lobe peak slope %.3f" % slope)
        r = run("figures", "--table", self.path("missing.exr"), "-o", out)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("missing.exr", r.stderr)

    def test_figures_unwritable(self):
        r = run("figures", "-o", "/proc/hairis/figures")
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("cannot create", r.stderr)


if __name__ == "__main__":
    BAKE = sys.argv.pop(1)
    unittest.main(verbosity=2)
