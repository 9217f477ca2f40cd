"""Render study (issue: Performance): error against time of Hairis' strategies and Cycles.

Runs inside Blender through tests/blender/run_test.py (render_study does it and then
plots the results):

    /usr/bin/python3 tests/blender/run_test.py --blender blender --zip build/hairis-addon.zip \
        --timeout 1800 bench/studies/render_study/render_study.py

In one run, on the scene of tests/blender/test_cycles_compare.py (helpers.make_compare_scene):

1. a reference: the average of Hairis ANALYTIC and Cycles at REF_SPP samples each, so neither
   engine is favoured; half the mean squared difference of the two halves over two estimates
   the reference's own noise (MSE_ref = mean((hairis − cycles)²)/4), which is subtracted from
   every measured MSE ("noise-corrected" RMSE);
2. every Hairis strategy (UNIFORM, ANALYTIC, GAUSSIAN at multiple_weight 0.25, TABLE at 0),
   DUAL (TABLE with integrator=dual_scattering) and Cycles at each of SPPS samples per pixel,
   SEEDS seeds each (seeds other than the reference's), timing ``bpy.ops.render.render()``
   alone; a warm-up render of each strategy and of Cycles comes first, so TABLE's auto-bake
   and first-render costs are not timed;
3. RMSE against the reference over all pixels and channels, relative RMSE (RMSE / mean of the
   reference) and, per channel, the bias mean(image) − mean(reference) with its standard error
   (from the scatter of the image around the reference: sqrt(MSE_channel / pixels), which holds
   the noise of the image and of the reference);
4. equal time against Cycles: each strategy's RMSE interpolated (log-log, in its time-RMSE
   curve) at the time Cycles needed for each of its sample counts, and its ratio to Cycles'.

Writes render_study.json, render_study.md and render_study_images.npz (the
reference and the 64-spp images); plot_render_study.py makes the PNGs from them.

Environment: HAIRIS_STUDY_RESOLUTION (64x48), HAIRIS_STUDY_REF_SPP (512), HAIRIS_STUDY_SPPS
(4,16,64,256), HAIRIS_STUDY_SEEDS (1), HAIRIS_STUDY_OUT (default: this folder).
"""

import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))  # the repository
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
sys.path.insert(0, HERE)
import helpers  # noqa: E402
import render_study_report  # noqa: E402
from render_study_report import METHODS, STRATEGIES  # noqa: E402

ARGS = helpers.setup_compare()

RESOLUTION, REF_SPP, SPPS, SEEDS = helpers.study_settings((64, 48), 512, (4, 16, 64, 256), 1)
OUT = os.environ.get("HAIRIS_STUDY_OUT", HERE)
BOUNCES = 4
REF_SEED = 1000
IMAGE_SPP = 64


def log(message):
    """Prints with a timestamp, flushed (Blender buffers stdout)."""
    print("[render_study %7.1f s] %s" % (time.monotonic() - START, message), flush=True)


START = time.monotonic()


def configure(scene, method, samples):
    """Engine, strategy and sample count of ``method`` (a strategy name or CYCLES)."""
    helpers.set_samples(scene, samples)
    if method != "CYCLES":
        scene.hairis.integrator = "DUAL_SCATTERING" if method == "DUAL" else "PATH"
        scene.hairis.strategy = "TABLE" if method == "DUAL" else method
        # Each strategy at its recommended weight: 0 for TABLE (the default), 0.25 for the
        # seed's Gaussian PDFs, which are heavy-tailed without their multiple-scattering part.
        scene.hairis.multiple_weight = 0.25 if method == "GAUSSIAN" else 0.0
    return "CYCLES" if method == "CYCLES" else "HAIRIS"


def render(scene, method, samples, seed):
    """(image, seconds) of ``method`` at ``samples`` spp and ``seed``."""
    engine = configure(scene, method, samples)
    image, seconds = helpers.render_pixels(scene, engine, seed, ARGS.workdir)
    assert np.all(np.isfinite(image)), "%s rendered non-finite pixels" % method
    return image, seconds


def study():
    """Renders everything and returns the results dictionary (and the images to keep)."""
    info = helpers.machine_info()
    scene = helpers.make_compare_scene(SPPS[0], BOUNCES, "ANALYTIC", resolution=RESOLUTION)
    pixels = RESOLUTION[0] * RESOLUTION[1]
    log("scene %dx%d, %d bounces; %s" % (RESOLUTION[0], RESOLUTION[1], BOUNCES, info))

    # Warm-up: TABLE auto-bakes its tables on its first render (then loads them from the
    # session's cache, as a render of a .blend with baked tables does); Cycles and Hairis
    # load their kernels and libraries. None of this is timed below.
    warmup = {}
    for method in METHODS:
        _, seconds = render(scene, method, 1, 1)
        warmup[method] = seconds
        log("warm-up %s: %.2f s" % (method, seconds))

    hairis_ref, hairis_ref_time = render(scene, "ANALYTIC", REF_SPP, REF_SEED)
    log("reference half: Hairis ANALYTIC %d spp in %.1f s" % (REF_SPP, hairis_ref_time))
    cycles_ref, cycles_ref_time = render(scene, "CYCLES", REF_SPP, REF_SEED)
    log("reference half: Cycles %d spp in %.1f s" % (REF_SPP, cycles_ref_time))
    reference = 0.5 * (hairis_ref + cycles_ref)
    ref_mean = float(reference.mean())
    ref_channel_mean = reference.reshape(-1, 3).mean(axis=0)
    halves = hairis_ref - cycles_ref
    ref_mse = float(np.mean(halves ** 2)) / 4.0
    ref_channel_mse = np.mean(halves.reshape(-1, 3) ** 2, axis=0) / 4.0
    halves_channel = halves.reshape(-1, 3).mean(axis=0)
    halves_se = np.sqrt(np.mean(halves.reshape(-1, 3) ** 2, axis=0) / pixels)
    log("reference mean %.5f, its own RMSE %.3g (relative %.4f); Hairis - Cycles channel "
        "means %s (z %s)" % (ref_mean, math.sqrt(ref_mse), math.sqrt(ref_mse) / ref_mean,
                             halves_channel / ref_channel_mean, halves_channel / halves_se))

    records = {method: [] for method in METHODS}
    keep = {"reference": reference.astype(np.float32)}
    for samples in SPPS:
        for method in METHODS:
            for index in range(SEEDS):
                seed = 1 + index
                image, seconds = render(scene, method, samples, seed)
                difference = image - reference
                mse = float(np.mean(difference ** 2))
                channel_mse = np.mean(difference.reshape(-1, 3) ** 2, axis=0)
                bias = difference.reshape(-1, 3).mean(axis=0)
                bias_se = np.sqrt(channel_mse / pixels)
                corrected = max(mse - ref_mse, 0.0)
                records[method].append({
                    "spp": samples, "seed": seed, "seconds": seconds,
                    "rmse": math.sqrt(mse), "rmse_corrected": math.sqrt(corrected),
                    "relative_rmse": math.sqrt(mse) / ref_mean,
                    "relative_rmse_corrected": math.sqrt(corrected) / ref_mean,
                    "channel_rmse": np.sqrt(channel_mse).tolist(),
                    "image_channel_mean": image.reshape(-1, 3).mean(axis=0).tolist(),
                    "bias": bias.tolist(),
                    "relative_bias": (bias / ref_channel_mean).tolist(),
                    "bias_se": bias_se.tolist(),
                    "bias_z": (bias / bias_se).tolist(),
                })
                log("%-8s %4d spp seed %d: %6.2f s, relative RMSE %.4f (corrected %.4f), "
                    "bias z %s" % (method, samples, seed, seconds, math.sqrt(mse) / ref_mean,
                                   math.sqrt(corrected) / ref_mean,
                                   np.round(bias / bias_se, 2)))
                if samples == IMAGE_SPP and index == 0:
                    keep["%s_%d" % (method.lower(), samples)] = image.astype(np.float32)

    info["load_average_end"] = list(os.getloadavg())
    info["total_seconds"] = time.monotonic() - START
    results = {
        "description": "Hairis strategies and Cycles against a reference (the average of "
                       "Hairis ANALYTIC and Cycles at ref_spp each) on the scene of "
                       "tests/blender/test_cycles_compare.py; times are the wall time of "
                       "bpy.ops.render.render() after a warm-up render of each method (so "
                       "TABLE's auto-bake is excluded)",
        "machine": info,
        "settings": {"resolution": list(RESOLUTION), "pixels": pixels, "bounces": BOUNCES,
                     "ref_spp": REF_SPP, "ref_seed": REF_SEED, "spps": SPPS,
                     "seeds": list(range(1, SEEDS + 1)), "strategies": list(STRATEGIES),
                     "multiple_weight": float(scene.hairis.multiple_weight),
                     "n_h": int(scene.hairis.n_h), "threads": int(scene.hairis.threads)},
        "warmup_seconds": warmup,
        "reference": {
            "mean": ref_mean, "channel_mean": ref_channel_mean.tolist(),
            "hairis_seconds": hairis_ref_time, "cycles_seconds": cycles_ref_time,
            "noise_rmse": math.sqrt(ref_mse), "noise_relative_rmse": math.sqrt(ref_mse) / ref_mean,
            "noise_channel_rmse": np.sqrt(ref_channel_mse).tolist(),
            "hairis_minus_cycles_relative": (halves_channel / ref_channel_mean).tolist(),
            "hairis_minus_cycles_z": (halves_channel / halves_se).tolist(),
        },
        "renders": records,
    }
    return results, keep


def main():
    """Runs the study and writes the results."""
    results, keep = study()
    render_study_report.finish(results, OUT)
    np.savez_compressed(os.path.join(OUT, "render_study_images.npz"),
                        **{k: v.astype(np.float16) for k, v in keep.items()})
    log("wrote %s" % OUT)


helpers.run_script(main)
