#!/usr/bin/env python3
"""Summary and markdown of the render study (render_study.py), without Blender.

    /usr/bin/python3 bench/studies/render_study/render_study_report.py [folder, default: this one]

render_study.py calls :func:`finish` at the end of its run; run standalone, this recomputes
the summary of render_study.json from its per-render records and rewrites render_study.json
and render_study.md (to change the report without rendering again).
"""

import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
STRATEGIES = ("UNIFORM", "ANALYTIC", "GAUSSIAN", "TABLE", "DUAL")
"""Hairis methods: the strategies with integrator=path, and DUAL (TABLE with the dual
scattering integrator, which is biased by design: the dual scattering study measures it)."""
METHODS = STRATEGIES + ("CYCLES",)
# Beyond a strategy's measured times, RMSE is extrapolated with the Monte Carlo rate
# RMSE ∝ time^(-1/2) from its nearest point (its end segments are too noisy to extrapolate).
EXTRAPOLATION_SLOPE = -0.5


def interpolate_loglog(x, xs, ys):
    """y at x on the piecewise-linear log-log curve (xs, ys); outside it, extrapolated from
    the nearest end with EXTRAPOLATION_SLOPE. Returns (y, extrapolated)."""
    order = np.argsort(xs)
    lx, ly = np.log(np.asarray(xs, float)[order]), np.log(np.asarray(ys, float)[order])
    t = math.log(x)
    if t < lx[0]:
        return float(math.exp(ly[0] + EXTRAPOLATION_SLOPE * (t - lx[0]))), True
    if t > lx[-1]:
        return float(math.exp(ly[-1] + EXTRAPOLATION_SLOPE * (t - lx[-1]))), True
    i = min(int(np.searchsorted(lx, t, side="right")) - 1, len(lx) - 2)
    slope = (ly[i + 1] - ly[i]) / (lx[i + 1] - lx[i])
    return float(math.exp(ly[i] + slope * (t - lx[i]))), False


def loglog_slope(xs, ys):
    """Least-squares slope of log y against log x."""
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


def summarize(results):
    """Per method and spp: seed-averaged time, RMSE and bias; slopes; equal-time ratios."""
    records = results["renders"]
    spps = results["settings"]["spps"]
    pixels = results["settings"]["pixels"]
    ref_mean = results["reference"]["mean"]
    ref_channel_mean = np.array(results["reference"]["channel_mean"])
    ref_channel_mse = np.square(results["reference"]["noise_channel_rmse"])
    summary = {}
    for method, rows in records.items():
        per_spp = []
        for samples in spps:
            chosen = [r for r in rows if r["spp"] == samples]
            mse = np.mean([r["rmse"] ** 2 for r in chosen])
            corrected = np.mean([r["rmse_corrected"] ** 2 for r in chosen])
            bias = np.mean([r["bias"] for r in chosen], axis=0)
            # The seeds' images are independent but share the reference: the image noise
            # averages down over the seeds, the reference's does not.
            channel_mse = np.mean([np.square(r["channel_rmse"]) for r in chosen], axis=0)
            image_var = np.maximum(channel_mse - ref_channel_mse, 0.0)
            se = np.sqrt((image_var / len(chosen) + ref_channel_mse) / pixels)
            per_spp.append({
                "spp": samples,
                "seconds": float(np.mean([r["seconds"] for r in chosen])),
                "seconds_min": float(np.min([r["seconds"] for r in chosen])),
                "seconds_max": float(np.max([r["seconds"] for r in chosen])),
                "rmse": float(math.sqrt(mse)),
                "rmse_corrected": float(math.sqrt(corrected)),
                "relative_rmse": float(math.sqrt(mse) / ref_mean),
                "relative_rmse_corrected": float(math.sqrt(corrected) / ref_mean),
                "bias": bias.tolist(),
                "relative_bias": (bias / ref_channel_mean).tolist(),
                "bias_se": se.tolist(),
                "bias_z": (bias / se).tolist(),
            })
        spps = [p["spp"] for p in per_spp]
        summary[method] = {
            "per_spp": per_spp,
            "rmse_vs_spp_slope": loglog_slope(spps, [p["rmse_corrected"] for p in per_spp]),
            "seconds_per_sample": linear_time_fit(per_spp),
        }
    # Results of a run made before a method existed lack it.
    strategies = [m for m in STRATEGIES if m in summary]
    cycles = summary["CYCLES"]["per_spp"]
    equal_time = {}
    for method in strategies:
        own = summary[method]["per_spp"]
        rows = []
        for point in cycles:
            rmse, outside = interpolate_loglog(
                point["seconds"], [p["seconds"] for p in own],
                [p["rmse_corrected"] for p in own])
            rows.append({"cycles_spp": point["spp"], "seconds": point["seconds"],
                         "hairis_rmse": rmse, "cycles_rmse": point["rmse_corrected"],
                         "ratio": rmse / point["rmse_corrected"], "extrapolated": outside})
        equal_time[method] = rows
    summary["equal_time"] = equal_time
    return summary


def made_by(maker, m):
    """The report's first sentence: ``maker`` (the script and its Blender), then the commit,
    the machine ``m`` and its load, which the figures depend on."""
    return ("Made by %s at commit %s on %d cores (%s); load average %.2f at the start and %.2f "
            "at the end (the machine is shared, so times carry noise); the whole run took "
            "%.0f s." % (maker, m["git_commit"] or "?", m["nproc"], m["cpu_model"],
                         m["load_average_start"][0], m["load_average_end"][0],
                         m["total_seconds"]))


def linear_time_fit(per_spp):
    """Seconds = overhead + per_sample · spp, least squares; returns both."""
    spp = np.array([p["spp"] for p in per_spp], float)
    seconds = np.array([p["seconds"] for p in per_spp], float)
    per_sample, overhead = np.polyfit(spp, seconds, 1)
    return {"overhead_seconds": float(overhead), "seconds_per_spp": float(per_sample)}


def markdown(results):
    """The tables of render_study.md."""
    s = results["settings"]
    m = results["machine"]
    r = results["reference"]
    summary = results["summary"]
    strategies = [m for m in STRATEGIES if m in summary]
    methods = [m for m in METHODS if m in summary]
    lines = [
        "# Render study: Hairis strategies against Cycles",
        "",
        made_by("`render_study` (render_study.py in Blender %s, plots by "
                "plot_render_study.py)" % m["blender_version"], m),
        "",
        "Scene: tests/blender/test_cycles_compare.py's (particle hair with a Melanin Principled "
        "Hair BSDF on a diffuse sphere, Curves with a Color-parametrized one, sun, point and "
        "area lights, world colour) at %dx%d pixels, %d bounces, Cycles set up as in the "
        "README's \"Comparing with Cycles\". Hairis' TABLE uses multiple_weight %.2f and "
        "n_h %d." % (s["resolution"][0], s["resolution"][1], s["bounces"],
                     s["multiple_weight"], s["n_h"]),
        "",
        "Reference: the average of Hairis ANALYTIC and Cycles at %d spp each (seed %d; "
        "%.1f s and %.1f s). Its own noise, from the two halves, is a relative RMSE of %.4f; "
        "its MSE is subtracted from every MSE below (\"noise-corrected\"). The halves' channel "
        "means differ by %s (z = %s)." % (
            s["ref_spp"], s["ref_seed"], r["hairis_seconds"], r["cycles_seconds"],
            r["noise_relative_rmse"], fmt_percent(r["hairis_minus_cycles_relative"]),
            ", ".join("%.2f" % z for z in r["hairis_minus_cycles_z"])),
        "",
        "Each method renders every sample count with seeds %s; figures are over those seeds "
        "(MSE and time averaged). Times: wall time of `bpy.ops.render.render()` only, after "
        "one warm-up render of every method (TABLE's auto-bake, %.1f s including the 1-spp "
        "render, is not timed; later TABLE renders load the tables from the session's cache, "
        "as a .blend with baked tables does, and that load is timed)." % (
            ", ".join(str(v) for v in s["seeds"]), results["warmup_seconds"]["TABLE"]),
        "",
        "## Relative RMSE (noise-corrected RMSE / mean of the reference)",
        "",
    ]
    lines += table(["method"] + ["%d spp" % v for v in s["spps"]] + ["slope vs spp"],
                   [[method] + ["%.4f" % p["relative_rmse_corrected"]
                                for p in summary[method]["per_spp"]]
                    + ["%.2f" % summary[method]["rmse_vs_spp_slope"]] for method in methods])
    lines += ["", "Raw relative RMSE (reference noise included):", ""]
    lines += table(["method"] + ["%d spp" % v for v in s["spps"]],
                   [[method] + ["%.4f" % p["relative_rmse"] for p in summary[method]["per_spp"]]
                    for method in methods])
    lines += ["", "## Render time (s, mean over seeds; min–max)", ""]
    lines += table(["method"] + ["%d spp" % v for v in s["spps"]] + ["overhead", "per spp"],
                   [[method] + ["%.2f (%.2f–%.2f)" % (p["seconds"], p["seconds_min"],
                                                      p["seconds_max"])
                                for p in summary[method]["per_spp"]]
                    + ["%.2f s" % summary[method]["seconds_per_sample"]["overhead_seconds"],
                       "%.1f ms" % (1e3 * summary[method]["seconds_per_sample"]
                                    ["seconds_per_spp"])]
                    for method in methods])
    lines += ["", "Overhead and per-spp cost: a least-squares line through the mean times.", "",
              "## Equal time against Cycles",
              "",
              "RMSE of each strategy (log-log interpolation of its time-RMSE curve) at the time "
              "Cycles took for each of its sample counts, divided by Cycles' RMSE there; below "
              "1 is better than Cycles. The time to reach Cycles' error scales as the square of "
              "the ratio. * marks an extrapolation beyond the strategy's measured times "
              "(RMSE ∝ time^-1/2 from its nearest measured point).",
              ""]
    cycles = summary["CYCLES"]["per_spp"]
    lines += table(["strategy"] + ["Cycles %d spp (%.2f s)" % (p["spp"], p["seconds"])
                                   for p in cycles],
                   [[method] + ["%.3f%s" % (row["ratio"], "*" if row["extrapolated"] else "")
                                for row in summary["equal_time"][method]]
                    for method in strategies])
    lines += ["", "## Bias check",
              "",
              "Per channel (R, G, B): (mean(image) − mean(reference)) / mean(reference), in "
              "%, over the seeds, and z = bias / standard error. SE² = (MSE_channel − MSE_ref) / "
              "(pixels · seeds) + MSE_ref / pixels: the image's noise averages over the seeds, "
              "the reference's does not (pixels are independent; MSE_ref is the reference's "
              "own noise from its two halves). The reference is shared by all rows, so rows "
              "are correlated. Unbiased: |z| mostly below 2, none far beyond 3.",
              ""]
    rows = []
    zs = []
    for method in methods:
        for p in summary[method]["per_spp"]:
            zs += p["bias_z"]
            rows.append([method, str(p["spp"]), fmt_percent(p["relative_bias"]),
                         ", ".join("%+.2f" % z for z in p["bias_z"])])
    lines += table(["method", "spp", "relative bias (R, G, B)", "z (R, G, B)"], rows)
    zs = np.array(zs)
    lines += ["", "Over all %d (method, spp, channel) cells: mean z² %.2f (1 expected when "
              "unbiased and independent), max |z| %.2f." % z_stats(zs), ""]
    for method in methods:
        own = np.array([p["bias_z"] for p in summary[method]["per_spp"]]).ravel()
        lines.append("- %s: mean z² %.2f, max |z| %.2f over %d cells; relative bias at %d spp "
                     "%s." % ((method,) + z_stats(own)[1:] + (own.size, s["spps"][-1])
                              + (fmt_percent(summary[method]["per_spp"][-1]["relative_bias"]),)))
    others = np.array([z for method in methods if method != "UNIFORM"
                       for p in summary[method]["per_spp"] for z in p["bias_z"]])
    lines += ["", "Without UNIFORM: mean z² %.2f, max |z| %.2f over %d cells." % (
        z_stats(others)[1:] + (others.size,)), "",
        "Reading it: the seeds are the same at every sample count; Hairis draws sample i of "
        "a pixel from (seed, pixel, i) and Cycles' sequences are progressive too, so a "
        "method's rows are nested (its 4 samples are the first 4 of its 16) and correlated, "
        "and every row shares the reference. The SE comes from the image's observed "
        "scatter; for an estimator with rare, very large samples (UNIFORM: uniform "
        "directions that happen to land in a sharply peaked lobe) the few renders miss most "
        "of them, so both the mean and the SE come out low: a heavy-tailed estimator shows a "
        "negative \"bias\" whose size shrinks as the sample count grows, and an RMSE that "
        "does not fall as 1/sqrt(spp) yet; a real bias would stay the same fraction while "
        "its z grows. UNIFORM's deficit shrinks from 4 to 256 spp, but the follow-up below "
        "(when present) says whether it levels off: if UNIFORM still falls short at many "
        "more samples with 4 bounces while it agrees with ANALYTIC at 1 bounce, either the "
        "tail of products of uniform weights over several hair bounces is heavier still, or "
        "multi-bounce paths are biased under UNIFORM; neither is settled here.", ""]
    for check in results.get("extra_checks", []):
        lines.append("- Follow-up (render_study_uniform_check.py): %s: %s (%s s)." % (
            check["what"], fmt_percent(check["relative_difference"]),
            ", ".join("%.0f" % v for v in np.atleast_1d(check["seconds"]))))
    if results.get("extra_checks"):
        lines.append("")
    return "\n".join(lines)


def z_stats(zs):
    """(count, mean z², max |z|)."""
    zs = np.asarray(zs, float)
    return zs.size, float(np.mean(zs ** 2)), float(np.abs(zs).max())


def fmt_percent(values):
    """Signed percentages."""
    return ", ".join("%+.2f%%" % (100.0 * v) for v in values)


def table(header, rows):
    """A markdown table."""
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(" --- " for _ in header) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return lines


def finish(results, folder):
    """Adds the summary to ``results``; writes render_study.json and render_study.md."""
    results["summary"] = summarize(results)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "render_study.json"), "w") as out:
        json.dump(results, out, indent=1)
    with open(os.path.join(folder, "render_study.md"), "w") as out:
        out.write(markdown(results))


def main():
    """Recomputes the summary and the markdown of a results folder."""
    folder = sys.argv[1] if len(sys.argv) > 1 else HERE
    with open(os.path.join(folder, "render_study.json")) as source:
        results = json.load(source)
    finish(results, folder)
    print("render_study_report: rewrote %s" % folder)


if __name__ == "__main__":
    main()
