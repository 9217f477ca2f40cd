"""Render study on Huang hair: Hairis' exact strategies against Cycles at equal time.

Runs inside Blender 4.x/5.0 through tests/blender/run_test.py:

    HAIRIS_STUDY_OUT=bench/studies/render_study/bpy45 python3 tests/blender/run_test.py \\
        --bpy-python .venvs/bpy-4.5/bin/python --install extension \\
        --extension-zip build/hairis-extension.zip --timeout 5400 \\
        bench/studies/render_study/render_study_huang.py

The scene is tests/blender/test_cycles_huang.py's (helpers.make_huang_scene). Methods:
UNIFORM and TABLE (Hairis' strategies with their exact pdfs, MIS'd with light sampling),
HAIRIS_CYCLES_SAMPLING (Hairis with Cycles' chained microfacet sampler and pdf 1, as Cycles
MISes Huang, its light samples shaded with the tables' baked f: the add-on's defaults),
HAIRIS_CYCLES_EVAL (the same with Cycles' one-sample eval on light samples, as without tables)
and CYCLES.

One reference per engine. Cycles' BSDF samples carry its chained sampler's weight, whose
mean is 0.89-0.99 of its eval's energy (docs/huang.md §8), so Cycles (and Hairis with Cycles'
sampling) converge to another image than Hairis' exact strategies, about 1% away; a shared
reference would charge that difference to both as error. Hairis' reference is TABLE, Cycles'
is CYCLES, each the average of two halves of REF_SPP/2 samples with seeds of their own;
the halves give the reference's own noise (MSE_ref = mean((a - b)^2) / 4), subtracted from
every MSE measured against it. HAIRIS_CYCLES_SAMPLING and HAIRIS_CYCLES_EVAL are measured
against Cycles' reference.
The difference of the two references is reported.

Equal time: each method's noise-corrected RMSE, interpolated in its log-log time-RMSE curve,
at the time Cycles took for each of its sample counts, divided by Cycles' RMSE there.

Writes render_study_huang.json and render_study_huang.md into HAIRIS_STUDY_OUT
(default: this folder). Environment: HAIRIS_STUDY_RESOLUTION (64x48), HAIRIS_STUDY_REF_SPP (2048),
HAIRIS_STUDY_SPPS (4,16,64,256), HAIRIS_STUDY_SEEDS (3), HAIRIS_STUDY_SCENE (compare: the
scene above; default, rough01, random: three more, see SCENES), HAIRIS_STUDY_PROFILE (a method:
profile its renders at SPPS instead of the study).
"""

import json
import math
import os
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))  # the repository
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
sys.path.insert(0, HERE)
import helpers  # noqa: E402
from render_study_report import (  # noqa: E402
    fmt_percent, interpolate_loglog, loglog_slope, made_by, table)

ARGS, PACKAGE = helpers.setup()
if helpers.VERSION < (4, 0, 0):
    helpers.skip("Blender %s has no Huang model" % bpy.app.version_string)
helpers.require_library(PACKAGE)

RESOLUTION, REF_SPP, SPPS, SEEDS = helpers.study_settings((64, 48), 2048, (4, 16, 64, 256), 3)
OUT = os.environ.get("HAIRIS_STUDY_OUT", HERE)
SCENE = os.environ.get("HAIRIS_STUDY_SCENE", "compare")
SCENES = {
    "compare": "tests/blender/test_cycles_huang.py's (Huang hair of aspect 0.85 on Curves and on "
               "particle hair, thick fibers of aspect 0.5 with lobes (1, 0.5, 0.2), sun, point, "
               "area light, world colour)",
    "default": "Blender's default Huang node (every input at its default) on 400 particle "
               "strands on a diffuse sphere, sun, point, area light, world colour",
    "rough01": "a Curves object of 150 strands with Huang hair at roughness 0.1 (aspect 0.85, "
               "blond), sun, point, area light, world colour",
    "random": "an aspect 0.5 Huang fiber under Melanin Concentration (0.4) with Random Color "
              "0.8 and Random unlinked (per strand) on 400 particle strands on a diffuse "
              "sphere, sun, point, area light, world colour",
}
if SCENE not in SCENES:
    raise SystemExit("HAIRIS_STUDY_SCENE must be one of %s (got %r)" % (", ".join(SCENES), SCENE))
BOUNCES = 4
METHODS = ("UNIFORM", "TABLE", "HAIRIS_CYCLES_SAMPLING", "HAIRIS_CYCLES_EVAL", "CYCLES")
REFERENCE_OF = {"UNIFORM": "HAIRIS", "TABLE": "HAIRIS", "HAIRIS_CYCLES_SAMPLING": "CYCLES",
                "HAIRIS_CYCLES_EVAL": "CYCLES",
                "CYCLES": "CYCLES"}
START = time.monotonic()


def log(message):
    """Prints with a timestamp, flushed (Blender buffers stdout)."""
    print("[render_study_huang %7.1f s] %s" % (time.monotonic() - START, message), flush=True)


def render(scene, method, samples, seed):
    """(image, seconds) of ``method`` at ``samples`` spp and ``seed``."""
    helpers.set_samples(scene, samples)
    if method == "CYCLES":
        engine = "CYCLES"
    else:
        engine = "HAIRIS"
        scene.hairis.integrator = "PATH"
        scene.hairis.strategy = ("UNIFORM" if method in ("UNIFORM", "HAIRIS_CYCLES_EVAL")
                                 else "TABLE")
        scene.hairis.huang_sampling = ("CYCLES" if method.startswith("HAIRIS_CYCLES")
                                       else "STRATEGY")
    image, seconds = helpers.render_pixels(scene, engine, seed, ARGS.workdir)
    assert np.all(np.isfinite(image)), "%s rendered non-finite pixels" % method
    return image, seconds


def reference(scene, method, seeds):
    """The average of two REF_SPP/2 renders, its noise MSE (total and per channel), seconds."""
    a, ta = render(scene, method, REF_SPP // 2, seeds[0])
    b, tb = render(scene, method, REF_SPP // 2, seeds[1])
    halves = (a - b).reshape(-1, 3)
    return {"image": 0.5 * (a + b), "mse": float(np.mean(halves ** 2)) / 4.0,
            "channel_mse": np.mean(halves ** 2, axis=0) / 4.0, "seconds": ta + tb}


def summarize(records, references):
    """Per method and spp: seed means of time and corrected RMSE; equal-time ratios."""
    summary = {}
    for method, rows in records.items():
        ref = references[REFERENCE_OF[method]]
        per_spp = []
        for samples in SPPS:
            chosen = [r for r in rows if r["spp"] == samples]
            mse = float(np.mean([r["mse"] for r in chosen]))
            corrected = max(mse - ref["mse"], 0.0)
            per_spp.append({
                "spp": samples,
                "seconds": float(np.mean([r["seconds"] for r in chosen])),
                "rmse_corrected": math.sqrt(corrected),
                "relative_rmse_corrected": math.sqrt(corrected) / ref["mean"],
                "relative_bias": np.mean([r["relative_bias"] for r in chosen], axis=0).tolist(),
            })
        summary[method] = {"per_spp": per_spp, "rmse_vs_spp_slope": loglog_slope(
            SPPS, [max(p["rmse_corrected"], 1e-12) for p in per_spp])}
    cycles = summary["CYCLES"]["per_spp"]
    for method in METHODS[:-1]:
        own = summary[method]["per_spp"]
        rows = []
        for point in cycles:
            rmse, outside = interpolate_loglog(point["seconds"], [p["seconds"] for p in own],
                                               [p["rmse_corrected"] for p in own])
            rows.append({"cycles_spp": point["spp"], "seconds": point["seconds"],
                         "ratio": rmse / point["rmse_corrected"], "extrapolated": outside})
        summary[method]["equal_time"] = rows
    return summary


def markdown(results):
    """render_study_huang.md."""
    m, s, summary = results["machine"], results["settings"], results["summary"]
    refs = results["references"]
    lines = [
        "# Render study on Huang hair: Hairis against Cycles",
        "",
        made_by("render_study_huang.py in Blender %s" % m["blender_version"], m),
        "",
        "Scene %s: %s, at %dx%d pixels, %d bounces, Cycles matched as in the "
        "README's \"Comparing with Cycles\"; seeds %s per sample count." % (
            s["scene"], SCENES[s["scene"]], s["resolution"][0], s["resolution"][1], s["bounces"],
            ", ".join(str(v) for v in s["seeds"])),
        "",
        "References, one per engine (see the script's header for why): Hairis TABLE and "
        "Cycles, each two halves of %d spp (%.0f s and %.0f s). Their own noise is a relative "
        "RMSE of %.4f and %.4f, subtracted from every MSE against them. Hairis' reference "
        "differs from Cycles' by %s per channel (Cycles' sampler's weight is not its eval)." % (
            s["ref_spp"] // 2, refs["HAIRIS"]["seconds"], refs["CYCLES"]["seconds"],
            refs["HAIRIS"]["noise_relative_rmse"], refs["CYCLES"]["noise_relative_rmse"],
            fmt_percent(results["hairis_minus_cycles_relative"])),
        "",
        "## Relative RMSE (noise-corrected, against the method's own engine's reference)",
        "",
    ]
    lines += table(["method", "reference"] + ["%d spp" % v for v in s["spps"]] + ["slope"],
                   [[k, REFERENCE_OF[k]] + ["%.4f" % p["relative_rmse_corrected"]
                                            for p in summary[k]["per_spp"]]
                    + ["%.2f" % summary[k]["rmse_vs_spp_slope"]] for k in METHODS])
    lines += ["", "## Render time (s, mean over seeds)", ""]
    lines += table(["method"] + ["%d spp" % v for v in s["spps"]],
                   [[k] + ["%.2f" % p["seconds"] for p in summary[k]["per_spp"]]
                    for k in METHODS])
    lines += ["", "## Equal time: RMSE / Cycles' RMSE at Cycles' time",
              "", "* marks an extrapolation beyond the method's measured times (RMSE ∝ "
              "time^-1/2 from its nearest point). Below 1 is better than Cycles.", ""]
    cycles = summary["CYCLES"]["per_spp"]
    lines += table(["method"] + ["Cycles %d spp (%.2f s)" % (p["spp"], p["seconds"])
                                 for p in cycles],
                   [[k] + ["%.3f%s" % (r["ratio"], "*" if r["extrapolated"] else "")
                           for r in summary[k]["equal_time"]] for k in METHODS[:-1]])
    lines += ["", "## Bias against the method's reference (R, G, B; mean over seeds)", ""]
    lines += table(["method", "spp", "relative bias"],
                   [[k, str(p["spp"]), fmt_percent(p["relative_bias"])]
                    for k in METHODS for p in summary[k]["per_spp"]])
    lines.append("")
    return "\n".join(lines)


def make_scene():
    """The study's scene (HAIRIS_STUDY_SCENE, see SCENES)."""
    if SCENE == "compare":
        return helpers.make_huang_scene(SPPS[0], BOUNCES, "STRATEGY", resolution=RESOLUTION)
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -3.2, 0.0), resolution=RESOLUTION, percentage=100)
    helpers.make_world(scene, color=(0.4, 0.5, 0.7), strength=0.8)
    skin = helpers.make_diffuse_material("Skin", (0.7, 0.5, 0.4, 1.0))
    if SCENE == "rough01":
        blond = helpers.make_huang_material("Blond", (0.55, 0.4, 0.25, 1.0), 0.85, roughness=0.1)
        helpers.make_fresh_curves(scene, "Curls", blond, 150, 8, 0.006, 3, (0.0, 0.0, -0.6), 0.5)
    else:
        hair, node = helpers.make_bsdf_material("Hair", "ShaderNodeBsdfHairPrincipled")
        node.model = "HUANG"
        if SCENE == "random":
            node.parametrization = "MELANIN"
            helpers.socket(node, "Melanin").default_value = 0.4
            helpers.socket(node, "Random Color").default_value = 0.8
            helpers.socket(node, "Aspect Ratio").default_value = 0.5
        helpers.make_particle_hair(scene, count=400, location=(0.0, 0.6, -0.3), scale=0.9,
                                   hair_material=hair, skin_material=skin)
    helpers.make_comparison_lights(scene)
    helpers.match_cycles(scene, SPPS[0], BOUNCES)
    settings = scene.hairis
    settings.samples = SPPS[0]
    settings.max_bounces = BOUNCES
    settings.max_transparent_bounces = BOUNCES
    settings.auto_bake = True
    settings.threads = 0
    bpy.context.view_layer.update()
    return scene


def study():
    """Renders everything; returns the results dictionary."""
    info = helpers.machine_info()
    scene = make_scene()
    pixels = RESOLUTION[0] * RESOLUTION[1]
    log("scene %dx%d, %d bounces; %s" % (RESOLUTION[0], RESOLUTION[1], BOUNCES, info))
    for method in METHODS:  # warm-up: TABLE auto-bakes its Huang tables, kernels load
        log("warm-up %s: %.2f s" % (method, render(scene, method, 1, 1)[1]))
    references = {"HAIRIS": reference(scene, "TABLE", (1001, 1002)),
                  "CYCLES": reference(scene, "CYCLES", (1001, 1002))}
    for name, ref in references.items():
        ref["mean"] = float(ref["image"].mean())
        ref["channel_mean"] = ref["image"].reshape(-1, 3).mean(axis=0)
        log("reference %s: mean %.5f, own relative RMSE %.4f, %.1f s"
            % (name, ref["mean"], math.sqrt(ref["mse"]) / ref["mean"], ref["seconds"]))
    records = {method: [] for method in METHODS}
    for samples in SPPS:
        for method in METHODS:
            ref = references[REFERENCE_OF[method]]
            for index in range(SEEDS):
                image, seconds = render(scene, method, samples, 1 + index)
                difference = image - ref["image"]
                bias = difference.reshape(-1, 3).mean(axis=0)
                records[method].append({
                    "spp": samples, "seed": 1 + index, "seconds": seconds,
                    "mse": float(np.mean(difference ** 2)),
                    "relative_bias": (bias / ref["channel_mean"]).tolist()})
                log("%-22s %4d spp seed %d: %6.2f s, relative RMSE %.4f" % (
                    method, samples, 1 + index, seconds,
                    math.sqrt(records[method][-1]["mse"]) / ref["mean"]))
    info["load_average_end"] = list(os.getloadavg())
    info["total_seconds"] = time.monotonic() - START
    hairis_minus_cycles = (references["HAIRIS"]["channel_mean"]
                           / references["CYCLES"]["channel_mean"] - 1.0)
    return {
        "machine": info,
        "settings": {"scene": SCENE, "resolution": list(RESOLUTION), "pixels": pixels,
                     "bounces": BOUNCES,
                     "ref_spp": REF_SPP, "spps": SPPS, "seeds": list(range(1, SEEDS + 1))},
        "references": {name: {"mean": ref["mean"], "seconds": ref["seconds"],
                              "noise_relative_rmse": math.sqrt(ref["mse"]) / ref["mean"],
                              "channel_mean": ref["channel_mean"].tolist()}
                       for name, ref in references.items()},
        "hairis_minus_cycles_relative": hairis_minus_cycles.tolist(),
        "renders": records,
        "summary": summarize(records, references),
    }


def profile(method):
    """Where the time of ``method``'s renders goes: cProfile over SEEDS renders at each of
    SPPS after a warm-up, the functions by their own and cumulative time, printed."""
    import cProfile
    import pstats
    scene = make_scene()
    render(scene, method, 1, 1)  # warm-up: auto-bake, kernels, the decoded tables
    for samples in SPPS:
        profiler = cProfile.Profile()
        seconds = []
        for index in range(SEEDS):
            profiler.enable()
            seconds.append(render(scene, method, samples, 1 + index)[1])
            profiler.disable()
        log("%s %d spp: render seconds %s" % (method, samples, ", ".join(
            "%.3f" % t for t in seconds)))
        stats = pstats.Stats(profiler).sort_stats("cumulative")
        stats.print_stats(25)


def main():
    """Runs the study and writes the results (HAIRIS_STUDY_PROFILE=<method>: profiles that
    method's renders instead)."""
    method = os.environ.get("HAIRIS_STUDY_PROFILE")
    if method:
        if method not in METHODS:
            raise SystemExit("HAIRIS_STUDY_PROFILE must be one of %s (got %r)"
                             % (", ".join(METHODS), method))
        profile(method)
        return
    results = study()
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "render_study_huang.json"), "w") as out:
        json.dump(results, out, indent=1)
    with open(os.path.join(OUT, "render_study_huang.md"), "w") as out:
        out.write(markdown(results))
    log("wrote %s" % OUT)


helpers.run_script(main)
