"""Converged Huang images, Hairis' defaults against Cycles, over the node's range.

Eight Curves objects on a 4 × 2 grid, each in a cell of its own seen by an orthographic camera
(48 × 48 pixels per cell), each with one Huang material: Blender's default node, aspect 0.5 at
roughness 0.1, aspect 1 at roughness 0.8, Melanin with a Tint, each lobe multiplier at 0 (the
others at 1), and thick fibers wider than a pixel (Cycles' near field; every other cell is far
field). A sun, an area light and a world colour; 8 bounces; the film transparent, so that a
cell's pixels hold the hair's light alone. Cycles is matched as in the comparison tests
(helpers.match_cycles); Hairis renders with the add-on's defaults for Huang hair (Table with
Auto Bake, Huang Sampling: Cycles).

For each cell and channel: the Hairis / Cycles ratio of the hair's mean over the seeds, its z
(the difference over its standard error from the seeds' spread), and over the cell's nine
16 × 16 blocks the largest |t| and the mean t² (Welch's t over the seeds).

Runs inside Blender 4.5 or 5.0 through tests/blender/run_test.py (command in README.md);
HAIRIS_STUDY_SPP (512) samples per render, HAIRIS_STUDY_SEEDS (4) renders per engine,
HAIRIS_STUDY_OUT (this folder) for huang_coverage.json and .md; HAIRIS_STUDY_METHOD=eval
renders Hairis without tables (Cycles' eval on light samples as well as Cycles' sampler).
"""

import json
import math
import os
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
if helpers.VERSION < (4, 0, 0):
    helpers.skip("Blender %s has no Huang model" % bpy.app.version_string)

SPP = int(os.environ.get("HAIRIS_STUDY_SPP", "512"))
SEEDS = int(os.environ.get("HAIRIS_STUDY_SEEDS", "4"))
OUT = os.environ.get("HAIRIS_STUDY_OUT", HERE)
METHOD = os.environ.get("HAIRIS_STUDY_METHOD", "default")
CELL = 48
BLOCK = 16
BOUNCES = 8

# name, node inputs (beyond Blender's defaults), strand radius, strand count
CELLS = [
    ("default node", {}, 0.004, 90),
    ("aspect 0.5, roughness 0.1", {"Aspect Ratio": 0.5, "Roughness": 0.1}, 0.004, 90),
    ("aspect 1, roughness 0.8", {"Aspect Ratio": 1.0, "Roughness": 0.8}, 0.004, 90),
    ("melanin 0.2 with a tint", {"Melanin": 0.2, "Tint": (0.9, 0.45, 0.3, 1.0)}, 0.004, 90),
    ("R lobe 0", {"R lobe": 0.0}, 0.004, 90),
    ("TT lobe 0", {"TT lobe": 0.0}, 0.004, 90),
    ("TRT lobe 0", {"TRT lobe": 0.0}, 0.004, 90),
    ("near field: thick, aspect 0.7", {"Aspect Ratio": 0.7, "Melanin": 0.3}, 0.035, 10),
]


def huang_material(name, inputs):
    """A Principled Hair BSDF (Melanin) with the Huang model and ``inputs``."""
    material = helpers.make_hair_material(name, "MELANIN", **inputs)
    material.node_tree.nodes["Principled Hair BSDF"].model = "HUANG"
    return material


def strands(scene, name, material, center, radius, count, seed):
    """Wavy strands standing in one cell (x and z within ±0.4 of its centre)."""
    points = 8
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, points)[None, :]
    roots = rng.uniform(-0.3, 0.3, (count, 1))  # drawn before the wave's phases, as measured
    x = roots + 0.06 * np.sin(6.0 * t + rng.uniform(0, 6.3, (count, 1)))
    y = rng.uniform(-0.25, 0.25, (count, 1)) + 0.1 * t * rng.uniform(-1, 1, (count, 1))
    z = np.broadcast_to(-0.38 + 0.76 * t, (count, points))
    positions = np.stack(np.broadcast_arrays(x, y, z), axis=-1)
    helpers.make_curves_object(scene, name, material, positions, radius, center)


def make_scene():
    scene = helpers.reset()
    camera = helpers.make_camera(scene, location=(0.0, -5.0, 0.0), resolution=(4 * CELL, 2 * CELL),
                                 percentage=100)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 4.0
    helpers.make_world(scene, color=(0.45, 0.5, 0.6), strength=0.7)
    helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(3.0),
                       rotation=(math.radians(50), 0.0, math.radians(30)))
    helpers.make_light(scene, "AREA", "Panel", location=(-2.5, -2.0, -1.0), energy=150.0,
                       shape="RECTANGLE", size=1.0, size_y=0.6,
                       rotation=(math.radians(100), 0.0, math.radians(-50)))
    for k, (name, inputs, radius, count) in enumerate(CELLS):
        cx = -1.5 + (k % 4)
        cz = 0.5 - (k // 4)
        strands(scene, name, huang_material(name, inputs), (cx, 0.0, cz), radius, count, 11 + k)
    helpers.match_cycles(scene, SPP, BOUNCES)
    scene.render.film_transparent = True
    settings = scene.hairis
    settings.samples = SPP
    settings.max_bounces = BOUNCES
    settings.max_transparent_bounces = BOUNCES
    settings.huang_sampling = "CYCLES"
    if METHOD == "eval":
        settings.strategy = "UNIFORM"  # no tables: Cycles' eval on light samples too
        settings.auto_bake = False
    else:
        settings.strategy = "TABLE"
        settings.auto_bake = True
    settings.threads = 0
    bpy.context.view_layer.update()
    return scene


def cell_view(stack, k):
    """(seeds, CELL, CELL, 3) of cell k (rows from the top of the image)."""
    row, col = k // 4, k % 4
    top = stack.shape[1] - (row + 1) * CELL  # Blender's pixel rows start at the bottom
    return stack[:, top:top + CELL, col * CELL:(col + 1) * CELL, :]


def statistics(cycles, hairis):
    rows = []
    n = cycles.shape[0]
    for k, (name, _, _, _) in enumerate(CELLS):
        c, h = cell_view(cycles, k), cell_view(hairis, k)
        mc, mh = c.mean(axis=(1, 2)), h.mean(axis=(1, 2))  # (seeds, 3)
        diff = mh.mean(axis=0) - mc.mean(axis=0)
        se = np.sqrt(mc.var(axis=0, ddof=1) / n + mh.var(axis=0, ddof=1) / n)
        b = CELL // BLOCK
        bc = c.reshape(n, b, BLOCK, b, BLOCK, 3).mean(axis=(2, 4))
        bh = h.reshape(n, b, BLOCK, b, BLOCK, 3).mean(axis=(2, 4))
        bse = np.sqrt(bc.var(axis=0, ddof=1) / n + bh.var(axis=0, ddof=1) / n)
        lit = bse > 0
        t = np.where(lit, (bh.mean(axis=0) - bc.mean(axis=0)) / np.where(lit, bse, 1.0), 0.0)
        rows.append({"cell": name, "cycles_mean": mc.mean(axis=0).tolist(),
                     "ratio": (mh.mean(axis=0) / mc.mean(axis=0)).tolist(),
                     "relative_se": (se / mc.mean(axis=0)).tolist(),
                     "z": (diff / se).tolist(), "block_max_abs_t": float(np.abs(t).max()),
                     "block_mean_t2": float((t[lit] ** 2).mean())})
    return rows


def render(scene, engine):
    images, seconds = [], 0.0
    for seed in range(1, SEEDS + 1):
        image, s = helpers.render_pixels(scene, engine, seed, ARGS.workdir)
        images.append(image)
        seconds += s
    return np.stack(images), seconds


def main():
    scene = make_scene()
    started = time.monotonic()
    hairis, hairis_s = render(scene, "HAIRIS")
    cycles, cycles_s = render(scene, "CYCLES")
    rows = statistics(cycles, hairis)
    info = {"blender": bpy.app.version_string, "method": METHOD, "spp": SPP, "seeds": SEEDS,
            "bounces": BOUNCES, "cycles_seconds": cycles_s, "hairis_seconds": hairis_s,
            "wall_seconds": time.monotonic() - started, "machine": helpers.machine_info(),
            "cells": rows}
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "huang_coverage.json"), "w") as out:
        json.dump(info, out, indent=1)
    head = ("Blender %s, Hairis method %s, %d seeds x %d spp per engine, %d bounces; "
            "Cycles %.0f s, Hairis %.0f s (auto-bake included)."
            % (info["blender"], METHOD, SEEDS, SPP, BOUNCES, cycles_s, hairis_s))
    lines = [head,
             "", "| cell | Hairis / Cycles (R, G, B) | relative s.e. | z | blocks: max abs t, "
             "mean t^2 |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append("| %s | %s | %s | %s | %.2f, %.2f |" % (
            r["cell"], ", ".join("%.4f" % v for v in r["ratio"]),
            ", ".join("%.2f%%" % (100 * v) for v in r["relative_se"]),
            ", ".join("%.1f" % v for v in r["z"]), r["block_max_abs_t"], r["block_mean_t2"]))
    text = "\n".join(lines) + "\n"
    with open(os.path.join(OUT, "huang_coverage.md"), "w") as out:
        out.write(text)
    print(text, flush=True)


helpers.run_script(main)
