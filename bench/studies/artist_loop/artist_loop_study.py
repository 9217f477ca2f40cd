"""Denoise and adaptive sampling against Cycles: what an artist's F12 gives at a few sample
counts, with and without the denoiser, and with adaptive sampling at one noise threshold.

Runs inside Blender 4.5/5.0 through tests/blender/run_test.py:

    HAIRIS_STUDY_OUT=bench/studies/artist_loop/bpy45 python3 tests/blender/run_test.py \\
        --bpy-python .venvs/bpy-4.5/bin/python --expect-version 4.5 --install extension \\
        --extension-zip build/hairis-extension.zip --zip build/hairis-addon.zip \\
        --timeout 5400 bench/studies/artist_loop/artist_loop_study.py

The scene is test_cycles_compare's (helpers.make_compare_scene: particle hair on a sphere, a
Curves object, a diffuse sphere, sun, point and area lights, a world colour), Chiang hair, TABLE
with auto-bake, 4 bounces, both engines set up alike. The reference is Cycles at REF_SPP
samples (its own noise, from two halves, is reported); both engines converge to it within the
noise (test_cycles_compare). Per method and sample count, SEEDS renders give the relative RMSE
(RMSE over the reference's mean, the reference's own MSE subtracted) and the F12 wall time:

* noisy: plain F12 in each engine;
* denoised: Hairis' Denoise (the compositor's Denoise node with Hairis' Denoising Albedo and
  Normal passes) and Cycles' own denoiser (OpenImageDenoise with its albedo and normal);
* adaptive: Noise Threshold THRESHOLD (Cycles' meaning, the same value in both engines) up to
  ADAPTIVE_SPP samples, min samples automatic.

Equal time compares each Hairis figure with Cycles' at Cycles' time, scaling Hairis' RMSE by
sqrt(its time / Cycles' time) (noise ∝ time^-1/2; denoised images do not follow that law
exactly, so those ratios are indicative). Writes artist_loop_study.md and .json into
HAIRIS_STUDY_OUT (default: this folder). Environment: HAIRIS_STUDY_RESOLUTION (96x72),
HAIRIS_STUDY_REF_SPP (2048), HAIRIS_STUDY_SPPS (4,16,64), HAIRIS_STUDY_SEEDS (3).
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
    helpers.skip("Blender %s has no OpenImageDenoise in its compositor here"
                 % bpy.app.version_string)
helpers.require_library(PACKAGE)

RESOLUTION, REF_SPP, SPPS, SEEDS = helpers.study_settings((96, 72), 2048, (4, 16, 64), 3)
OUT = os.environ.get("HAIRIS_STUDY_OUT", HERE)
THRESHOLD = 0.02
ADAPTIVE_SPP = 256
BOUNCES = 4
START = time.monotonic()


def log(message):
    print("[artist_loop_study %7.1f s] %s" % (time.monotonic() - START, message), flush=True)


def configure(scene, engine, samples, denoise=False, adaptive=False):
    """Both engines at `samples`, with or without their denoiser and adaptive sampling."""
    helpers.set_samples(scene, samples)
    scene.cycles.use_denoising = denoise and engine == "CYCLES"
    if scene.cycles.use_denoising:
        scene.cycles.denoiser = "OPENIMAGEDENOISE"
        scene.cycles.denoising_input_passes = "RGB_ALBEDO_NORMAL"
    scene.hairis.use_denoising = denoise and engine == "HAIRIS"
    scene.cycles.use_adaptive_sampling = adaptive
    scene.cycles.adaptive_threshold = THRESHOLD
    scene.cycles.adaptive_min_samples = 0
    scene.hairis.use_adaptive_sampling = adaptive
    scene.hairis.adaptive_threshold = THRESHOLD
    scene.hairis.adaptive_min_samples = 0


def render(scene, engine, seed):
    return helpers.render_pixels(scene, engine, seed, ARGS.workdir)


def study():
    info = helpers.machine_info()
    scene = helpers.make_compare_scene(SPPS[0], BOUNCES, "TABLE", resolution=RESOLUTION)
    scene.hairis.auto_bake = True
    log("scene %dx%d; %s" % (RESOLUTION[0], RESOLUTION[1], info))
    for engine in ("CYCLES", "HAIRIS"):  # warm-up: tables, kernels
        configure(scene, engine, 1)
        render(scene, engine, 1)
    configure(scene, "CYCLES", REF_SPP // 2)
    halves = [render(scene, "CYCLES", seed) for seed in (1001, 1002)]
    reference = 0.5 * (halves[0][0] + halves[1][0])
    mean = float(reference.mean())
    ref_mse = float(np.mean((halves[0][0] - halves[1][0]) ** 2)) / 4.0
    ref_noise = math.sqrt(ref_mse) / mean
    log("reference: %d spp, mean %.4f, own relative RMSE %.4f" % (REF_SPP, mean, ref_noise))

    def measure(engine, samples, denoise=False, adaptive=False):
        configure(scene, engine, samples, denoise, adaptive)
        rmse, seconds = [], []
        for seed in range(1, SEEDS + 1):
            image, wall = render(scene, engine, seed)
            mse = float(np.mean((image - reference) ** 2)) - ref_mse
            rmse.append(math.sqrt(max(mse, 0.0)) / mean)
            seconds.append(wall)
        row = {"engine": engine, "spp": samples, "denoise": denoise, "adaptive": adaptive,
               "relative_rmse": float(np.mean(rmse)), "seconds": float(np.median(seconds))}
        log("%(engine)s %(spp)d spp denoise=%(denoise)s adaptive=%(adaptive)s: RMSE "
            "%(relative_rmse).4f, %(seconds).2f s" % row)
        return row

    rows = []
    for samples in SPPS:
        for denoise in (False, True):
            for engine in ("CYCLES", "HAIRIS"):
                rows.append(measure(engine, samples, denoise))
    for engine in ("CYCLES", "HAIRIS"):
        rows.append(measure(engine, ADAPTIVE_SPP, adaptive=True))
    info["load_average_end"] = list(os.getloadavg())
    return {"machine": info, "resolution": RESOLUTION, "ref_spp": REF_SPP, "seeds": SEEDS,
            "reference_noise": ref_noise, "threshold": THRESHOLD, "rows": rows}


def equal_time(hairis, cycles):
    """Hairis' RMSE at Cycles' time over Cycles' RMSE (noise ∝ time^-1/2)."""
    scaled = hairis["relative_rmse"] * math.sqrt(hairis["seconds"] / cycles["seconds"])
    return scaled / cycles["relative_rmse"]


def markdown(results):
    rows = results["rows"]

    def find(engine, spp, denoise=False, adaptive=False):
        return next(r for r in rows if r["engine"] == engine and r["spp"] == spp
                    and r["denoise"] == denoise and r["adaptive"] == adaptive)

    lines = ["# Denoise and adaptive sampling against Cycles", "",
             "Made by artist_loop_study.py in Blender %s at commit %s on %s cores; load average "
             "%.2f at the start and %.2f at the end." % (
                 results["machine"]["blender_version"], results["machine"]["git_commit"],
                 results["machine"]["nproc"], results["machine"]["load_average_start"][0],
                 results["machine"]["load_average_end"][0]), "",
             "test_cycles_compare's scene at %dx%d, 4 bounces, %d seeds per figure; reference "
             "Cycles at %d spp (own relative RMSE %.4f, subtracted). Relative RMSE against it, "
             "median F12 wall time." % (
                 results["resolution"][0], results["resolution"][1], results["seeds"],
                 results["ref_spp"], results["reference_noise"]),
             "", "| spp | Cycles noisy | Hairis noisy | Cycles denoised | Hairis denoised | "
             "Hairis / Cycles at equal time, noisy | denoised |", "|---|---|---|---|---|---|---|"]
    for spp in SPPS:
        cells = []
        for denoise in (False, True):
            for engine in ("CYCLES", "HAIRIS"):
                r = find(engine, spp, denoise)
                cells.append("%.4f (%.2f s)" % (r["relative_rmse"], r["seconds"]))
        ratios = ["%.2f" % equal_time(find("HAIRIS", spp, d), find("CYCLES", spp, d))
                  for d in (False, True)]
        lines.append("| %d | %s | %s |" % (spp, " | ".join(cells), " | ".join(ratios)))
    cycles, hairis = find("CYCLES", ADAPTIVE_SPP, adaptive=True), find("HAIRIS", ADAPTIVE_SPP,
                                                                       adaptive=True)
    lines += ["", "Adaptive sampling, Noise Threshold %g, at most %d spp: Cycles %.4f in %.2f s, "
              "Hairis %.4f in %.2f s; Hairis / Cycles at equal time %.2f." % (
                  results["threshold"], ADAPTIVE_SPP, cycles["relative_rmse"], cycles["seconds"],
                  hairis["relative_rmse"], hairis["seconds"], equal_time(hairis, cycles)), ""]
    return "\n".join(lines)


def main():
    results = study()
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "artist_loop_study.json"), "w") as out:
        json.dump(results, out, indent=1)
    text = markdown(results)
    with open(os.path.join(OUT, "artist_loop_study.md"), "w") as out:
        out.write(text)
    print(text)


helpers.run_script(main)
