#!/usr/bin/env python3
"""The dual scattering study's report: dual_scattering.md and its images, from
dual_scattering.json and dual_scattering_images.npz (dual_scattering_study.py).

    /usr/bin/python3 bench/studies/dual_scattering_study/dual_scattering_report.py [RESULTS_DIR]

Per case (hair colour × lighting), over the hair pixels:
- the per-channel mean error of DUAL (its highest spp, both seeds) against the reference
  (Hairis PATH at ref_spp), with its standard error, and Cycles' reference against it;
- noise-corrected RMSE against time for DUAL, PATH and Cycles;
- equal time: DUAL's RMSE at Cycles' 64-spp time (log-log interpolation of its measured
  time-RMSE points) over Cycles' RMSE there;
- the crossover time: with MSE_path(t) = c_path/t (c_path fitted to PATH's and to Cycles'
  points) and MSE_dual(t) = b² + c_dual/t (b², the squared bias, is DUAL's MSE at its highest
  spp less its variance from the two seeds; c_dual = variance · time, averaged over its spps),
  path tracing has the smaller error after t* = (c_path − c_dual)/b²;
- where that bias is: its RMS per pixel and over 4×4 and 16×16 blocks (the study's
  bias_by_block), and DUAL's error over the hair pixels in five groups by brightness (quintiles
  of Cycles' reference, error_by_brightness).
Images: per case the reference, DUAL, PATH and Cycles at 64 spp and DUAL − reference
(dual_scattering_images.png), and the RMSE-time curves (dual_scattering_rmse.png).
"""

import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
CHANNELS = "RGB"
LABELS = {"DUAL": "Hairis DUAL_SCATTERING", "PATH": "Hairis PATH", "CYCLES": "Cycles 3.4"}
BRIGHTNESS_GROUPS = 5  # quintiles of the hair pixels by brightness
COLOURS = {"DUAL": "tab:red", "PATH": "tab:blue", "CYCLES": "tab:gray"}


def mean_seconds(entry):
    return float(np.mean(entry["seconds"]))


def mean_mse(entry):
    """Noise-corrected MSE averaged over the seeds."""
    return float(np.mean([s["mse_corrected"] for s in entry["seeds"]]))


def loglog_at(points, t):
    """RMSE at time t from (time, rmse) points, log-log interpolation; extrapolated with
    RMSE ∝ t^-1/2 from the nearest end (marked by the second value)."""
    points = sorted(points)
    times = np.array([p[0] for p in points])
    rmse = np.array([max(p[1], 1e-30) for p in points])
    if t <= times[0]:
        return rmse[0] * math.sqrt(times[0] / t), True
    if t >= times[-1]:
        return rmse[-1] * math.sqrt(times[-1] / t), True
    k = int(np.searchsorted(times, t)) - 1
    f = (math.log(t) - math.log(times[k])) / (math.log(times[k + 1]) - math.log(times[k]))
    return math.exp((1 - f) * math.log(rmse[k]) + f * math.log(rmse[k + 1])), False


def path_constant(entries):
    """c in MSE = c/t, a least-squares fit in log space (slope fixed at −1)."""
    values = [math.log(max(mean_mse(e), 1e-30) * mean_seconds(e)) for e in entries]
    return math.exp(float(np.mean(values)))


def dual_model(entries):
    """(b², c_dual): squared bias and variance·time of DUAL (see the module comment)."""
    top = max(entries, key=lambda e: e["spp"])
    bias2 = max(mean_mse(top) - top["variance"], 0.0)  # each seed's MSE is b² + variance
    c = float(np.mean([e["variance"] * mean_seconds(e) for e in entries]))
    return bias2, c, top


def analyse(case):
    """Numbers of one case for the tables."""
    ref_mean = np.array(case["reference"]["channel_mean"])
    r = case["renders"]
    out = {"ref_mean": ref_mean}
    bias2, c_dual, top = dual_model(r["DUAL"])
    errors = np.array([s["relative_mean_error"] for s in top["seeds"]])
    ses = np.array([s["mean_error_se"] for s in top["seeds"]]) / ref_mean
    out["dual_error"] = errors.mean(axis=0)
    out["dual_error_se"] = np.sqrt((ses ** 2).mean(axis=0) / len(top["seeds"]))
    out["dual_spp"] = top["spp"]
    out["bias2"] = bias2
    out["c_dual"] = c_dual
    scale = float(ref_mean.mean())
    out["scale"] = scale
    cycles64 = [e for e in r["CYCLES"] if e["spp"] == 64]
    curves = {m: [(mean_seconds(e), math.sqrt(mean_mse(e))) for e in r[m]] for m in r}
    out["curves"] = curves
    if cycles64:
        t_c = mean_seconds(cycles64[0])
        rmse_c = math.sqrt(mean_mse(cycles64[0]))
        rmse_d, extrapolated = loglog_at(curves["DUAL"], t_c)
        rmse_p, p_extrapolated = loglog_at(curves["PATH"], t_c)
        out["equal_time"] = {"t": t_c, "cycles": rmse_c, "dual": rmse_d, "ratio": rmse_d / rmse_c,
                             "extrapolated": extrapolated, "path": rmse_p,
                             "path_ratio": rmse_p / rmse_c, "path_extrapolated": p_extrapolated}
    out["crossover"] = {}
    for m in ("PATH", "CYCLES"):
        c_path = path_constant(r[m])
        if bias2 <= 0:
            t_star = math.inf
        elif c_path <= c_dual:
            t_star = 0.0
        else:
            t_star = (c_path - c_dual) / bias2
        out["crossover"][m] = {"c": c_path, "t": t_star}
    if "cycles_reference" in case:
        out["cycles_ref"] = case["cycles_reference"]
    return out


def percent(values, ses=None):
    if ses is None:
        return ", ".join("%+.1f%%" % (100 * v) for v in values)
    return ", ".join("%+.1f ± %.1f%%" % (100 * v, 100 * s) for v, s in zip(values, ses))


def seconds_text(t):
    if math.isinf(t):
        return "never (no bias resolved)"
    if t == 0.0:
        return "0 (path tracing is ahead at every time)"
    if t < 100:
        return "%.1f s" % t
    if t < 7200:
        return "%.0f s (%.1f min)" % (t, t / 60)
    return "%.0f s (%.1f h)" % (t, t / 3600)


def write_markdown(results, numbers, path):
    s = results["settings"]
    m = results["machine"]
    lines = ["# Dual scattering against path tracing", "",
             "Made by `dual_scattering_study` (dual_scattering_study.py in Blender %s, "
             "this report by dual_scattering_report.py) at commit %s on %d cores (%s); load "
             "average %.1f at the start and %.1f at the end (the machine is shared: times carry "
             "noise); the run took %.0f s." % (
                 m["blender_version"], m["git_commit"], m["nproc"], m["cpu_model"],
                 m["load_average_start"][0], m.get("load_average_end", [float("nan")])[0],
                 m.get("total_seconds", float("nan"))), "",
             "Scene: %s, "
             "Principled Hair%s (Melanin 0.1 blonde, 0.5 brunette, 0.9 black; Melanin Redness 0.5; "
             "Roughness%s 0.3) under a 1° sun with a world colour (`sun`) or a "
             "1.2 m square area light in a black world (`area`), %dx%d pixels, %d bounces, one "
             "thread for Hairis and for Cycles. Hairis uses the TABLE strategy for its direct "
             "term in both integrators; DUAL path-traces its first %s bounces (Exact Bounces) "
             "and closes the path by dual scattering at the next hair vertex. Errors are over "
             "the %s hair pixels (a Cycles alpha render without the sphere), relative to the "
             "reference's channel means.%s" % (
                 "the demo head's particle hair (1500 parents × 10 interpolated children, 0.52 m "
                 "long, 26 mm thick at the root: scripts/render_demo.py's) on a diffuse sphere of "
                 "1.3 m, `backsun` the sun case with the sun behind the hair"
                 if s.get("scene") == "head" else
                 "particle hair (1500 parents × 8 interpolated children) on a diffuse sphere",
                 " with the Huang model (its defaults: Aspect Ratio 0.85, Offset 2°; Hairis "
                 "samples Huang with its tables in DUAL, with Cycles' sampler in PATH)"
                 if s.get("model") == "HUANG" else "",
                 "" if s.get("model") == "HUANG" else " and Radial Roughness",
                 s["resolution"][0], s["resolution"][1], s["bounces"],
                 s.get("exact_bounces", 0),
                 "/".join(str(c["hair_pixels"]) for c in results["cases"].values()),
                 " The closing vertex adds %s." % (
                     "every order of scattering, as the paper (dual_bounce_limit none)"
                     if s.get("bounce_limit") == "none" else
                     "only the orders of scattering the path tracer reaches within the bounce "
                     "limits (dual_bounce_limit bounces)" if s.get("bounce_limit") == "bounces"
                     else "every order of scattering (before dual_bounce_limit)")), "",
             "Reference: Hairis PATH at %d spp (two halves, seeds 1000 and 1001; their difference "
             "gives the reference's own noise, which is subtracted from every MSE). Cycles at %d "
             "spp checks it (below). Every other render is done with seeds 1 and 2; times are the "
             "wall time of `bpy.ops.render.render()` after a warm-up render of each method (the "
             "tables' auto-bake and the dual-scattering averages, about %s s per material, are "
             "not timed)." % (s["ref_spp"], s["cycles_ref_spp"],
                              "12" if s.get("model") == "HUANG" else "1.2"), ""]

    lines += ["## Mean error per channel (hair pixels)", "",
              "DUAL at its highest spp (mean of two seeds, ± standard error); Cycles' reference "
              "against Hairis PATH's as a check of the reference.", "",
              "| case | DUAL − reference (R, G, B) | Cycles − PATH reference (R, G, B) | target |",
              "| --- | --- | --- | --- |"]
    for name, n in numbers.items():
        check = percent(n["cycles_ref"]["relative_difference"]) if "cycles_ref" in n else "–"
        target = ""
        if name.startswith("blonde"):
            ok = all(abs(v) <= 0.05 for v in n["dual_error"])
            target = "≤ 5%%: %s" % ("met" if ok else "missed")
        lines.append("| %s | %s | %s | %s |"
                     % (name, percent(n["dual_error"], n["dual_error_se"]), check, target))
    lines += ["", "## Equal time against Cycles at its 64-spp time", "",
              "RMSE over the hair pixels (noise-corrected) at the time Cycles needed for 64 spp, "
              "relative to the reference's mean; * marks an extrapolation (RMSE ∝ t^-1/2 from the "
              "nearest measured point).", "",
              "| case | Cycles 64 spp time | Cycles | DUAL | DUAL / Cycles | PATH / Cycles "
              "| target |",
              "| --- | --- | --- | --- | --- | --- | --- |"]
    for name, n in numbers.items():
        e = n.get("equal_time")
        if not e:
            continue
        target = ""
        if name.startswith("blonde"):
            target = "≤ 0.3: %s" % ("met" if e["ratio"] <= 0.3 else "missed")
        lines.append("| %s | %.2f s | %.4f | %.4f%s | %.2f | %.2f%s | %s |" % (
            name, e["t"], e["cycles"] / n["scale"], e["dual"] / n["scale"],
            "*" if e["extrapolated"] else "", e["ratio"], e["path_ratio"],
            "*" if e["path_extrapolated"] else "", target))
    lines += ["", "## Crossover: when path tracing wins", "",
              "MSE_path(t) = c/t fitted to each path tracer's points, MSE_dual(t) = b² + c_dual/t "
              "(b² from DUAL's highest spp less its two-seed variance). Relative RMSE of DUAL's "
              "bias alone: √b² / reference mean.", "",
              "| case | DUAL bias (relative RMSE) | DUAL c (s) | PATH c (s) | crossover vs PATH | "
              "Cycles c (s) | crossover vs Cycles |", "| --- | --- | --- | --- | --- | --- | --- |"]
    for name, n in numbers.items():
        cp, cc = n["crossover"]["PATH"], n["crossover"]["CYCLES"]
        lines.append("| %s | %.4f | %.3g | %.3g | %s | %.3g | %s |" % (
            name, math.sqrt(n["bias2"]) / n["scale"], n["c_dual"], cp["c"], seconds_text(cp["t"]),
            cc["c"], seconds_text(cc["t"])))
    blocked = {name: max(case["renders"]["DUAL"], key=lambda e: e["spp"]).get("bias_by_block")
               for name, case in results["cases"].items()}
    if any(blocked.values()):
        sizes = sorted({int(k) for b in blocked.values() if b for k in b})
        lines += ["", "## Where DUAL's bias is: per pixel and over blocks", "",
                  "DUAL's bias (relative RMS, noise-corrected: the two seeds' and the reference's "
                  "own noise subtracted) of the mean difference from the reference over blocks of "
                  "hair pixels. Per pixel it is the crossover table's; what survives averaging "
                  "over large blocks is the light transport's error, what averages out is "
                  "strand-scale (where one strand's light differs from the path tracer's, both "
                  "ways).", "",
                  "| case | " + " | ".join("%d×%d" % (k, k) for k in sizes) + " |",
                  "| --- |" + " --- |" * len(sizes)]
        for name, b in blocked.items():
            if b:
                lines.append("| %s | " % name + " | ".join(
                    "%.4f" % b[str(k)] if str(k) in b else "" for k in sizes) + " |")
    if any(n.get("by_brightness") for n in numbers.values()):
        lines += ["", "## DUAL's error by pixel brightness", "",
                  "The hair pixels in %d groups of equal count by their brightness in Cycles' "
                  "reference (independent of both images' noise), dimmest first: DUAL's relative "
                  "error of the group's mean luminance (its highest spp, seed 1), and the "
                  "reference's group mean. A positive error in dim groups with a negative one in "
                  "bright groups is light moved from where it arrives to where it does not: "
                  "a flatter image than path tracing's." % BRIGHTNESS_GROUPS, "",
                  "| case | " + " | ".join("group %d" % (k + 1) for k in range(BRIGHTNESS_GROUPS))
                  + " |", "| --- |" + " --- |" * BRIGHTNESS_GROUPS]
        for name, n in numbers.items():
            if n.get("by_brightness"):
                lines.append("| %s | " % name + " | ".join(
                    "%+.1f%% (%.3f)" % (100 * e, r) for r, e in n["by_brightness"]) + " |")
    lines += ["", "## Renders (RMSE over hair pixels, relative; seconds)", ""]
    for name, case in results["cases"].items():
        lines.append("**%s**: " % name + "; ".join(
            "%s %s" % (method, ", ".join("%d spp %.4f in %.2f s" % (
                e["spp"], math.sqrt(mean_mse(e)) / numbers[name]["scale"], mean_seconds(e))
                for e in entries)) for method, entries in case["renders"].items()))
        lines.append("")
    lines += ["![Reference, DUAL, PATH and Cycles at 64 spp, and DUAL − reference]"
              "(dual_scattering_images.png)", "",
              "![RMSE against time](dual_scattering_rmse.png)", ""]
    with open(path, "w") as handle:
        handle.write("\n".join(lines))


def tone(image):
    """Display transform: clip and sRGB-like gamma."""
    return np.clip(image, 0.0, 1.0) ** (1.0 / 2.2)


def write_images(results, images, numbers, out):
    names = list(results["cases"])
    columns = ["reference", "dual", "path", "cycles", "difference"]
    fig, axes = plt.subplots(len(names), len(columns),
                             figsize=(2.2 * len(columns), 2.3 * len(names)))
    axes = np.atleast_2d(axes)
    for row, name in enumerate(names):
        ref = images["%s_reference" % name]
        for col, what in enumerate(columns):
            ax = axes[row, col]
            ax.set_xticks([])
            ax.set_yticks([])
            if what == "difference":
                d = (images["%s_dual" % name] - ref).mean(axis=2)
                limit = max(float(np.abs(d).max()), 1e-6)
                ax.imshow(d[::-1], cmap="coolwarm", vmin=-limit, vmax=limit)
                title = "DUAL − ref (±%.2f)" % limit
            else:
                key = "%s_%s" % (name, what)
                ax.imshow(tone(images[key][::-1]))
                title = {"reference": "PATH %d spp" % results["settings"]["ref_spp"],
                         "dual": "DUAL %d spp" % numbers[name]["dual_spp"],
                         "path": "PATH 64 spp", "cycles": "Cycles 64 spp"}[what]
            if col == 0:
                ax.set_ylabel(name)
            ax.set_title(title, fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "dual_scattering_images.png"), dpi=110)
    plt.close(fig)

    fig, axes = plt.subplots(2, 3, figsize=(12, 7))
    for ax, name in zip(axes.ravel(), names):
        for method, points in numbers[name]["curves"].items():
            points = sorted(points)
            ax.loglog([p[0] for p in points], [p[1] / numbers[name]["scale"] for p in points],
                      "o-", color=COLOURS[method], label=LABELS[method])
        n = numbers[name]
        t = np.logspace(-1.5, 3, 50)
        ax.loglog(t, np.sqrt(n["bias2"] + n["c_dual"] / t) / n["scale"], ":", color=COLOURS["DUAL"])
        ax.loglog(t, np.sqrt(n["crossover"]["CYCLES"]["c"] / t) / n["scale"], ":",
                  color=COLOURS["CYCLES"])
        ax.set_title(name)
        ax.set_xlabel("seconds (1 thread)")
        ax.set_ylabel("relative RMSE (hair)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "dual_scattering_rmse.png"), dpi=90)
    plt.close(fig)


def error_by_brightness(images, name, groups=BRIGHTNESS_GROUPS):
    """DUAL's relative error (its highest spp, one seed) over the hair pixels grouped by their
    brightness, dimmest first: quantiles of Cycles' reference, whose noise is independent of
    both images (grouping by the PATH reference itself would put its negative noise in the dim
    groups and show a spurious positive error there). None without Cycles' reference."""
    keys = ["%s_%s" % (name, k) for k in ("cycles_reference", "reference", "dual", "mask")]
    if not all(k in images for k in keys):
        return None
    cycles, reference, dual, mask = (images[k] for k in keys)
    order = np.argsort(cycles[mask][:, :3].mean(axis=1))
    ref, est = reference[mask][:, :3].mean(axis=1), dual[mask][:, :3].mean(axis=1)
    out = []
    for part in np.array_split(order, groups):
        out.append((float(ref[part].mean()), float(est[part].mean() / ref[part].mean() - 1.0)))
    return out


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else HERE
    with open(os.path.join(out, "dual_scattering.json")) as handle:
        results = json.load(handle)
    images = np.load(os.path.join(out, "dual_scattering_images.npz"))
    numbers = {name: analyse(case) for name, case in results["cases"].items()}
    for name in numbers:
        numbers[name]["by_brightness"] = error_by_brightness(images, name)
    write_markdown(results, numbers, os.path.join(out, "dual_scattering.md"))
    write_images(results, images, numbers, out)
    print("wrote %s" % os.path.join(out, "dual_scattering.md"))


if __name__ == "__main__":
    main()
