#!/usr/bin/env python3
"""Exact Bounces against bias and noise: one table from dual scattering studies
(dual_scattering_study.py) run with HAIRIS_DUAL_EXACT = 0, 1, 2, ... into folders of
their own, writes bench/studies/dual_scattering_study/dual_exact_bounces.md.

    /usr/bin/python3 bench/studies/dual_scattering_study/dual_exact_sweep.py OUT.md DIR [DIR ...]

Per case and Exact Bounces: DUAL's per-channel mean error, its bias (relative RMS per pixel and
over 16×16 blocks, noise-corrected), its relative RMSE at 64 spp against PATH's, its time per
sample over PATH's (same run), and its RMSE over Cycles' at Cycles' 64-spp time.
"""

import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dual_scattering_report as report  # noqa: E402


def at_spp(entries, spp):
    return next(e for e in entries if e["spp"] == spp)


def main(out, folders):
    rows = []
    for folder in folders:
        with open(os.path.join(folder, "dual_scattering.json")) as handle:
            results = json.load(handle)
        exact = results["settings"].get("exact_bounces", 0)
        for name, case in results["cases"].items():
            n = report.analyse(case)
            r = case["renders"]
            top = max(r["DUAL"], key=lambda e: e["spp"])
            dual64, path64 = at_spp(r["DUAL"], 64), at_spp(r["PATH"], 64)
            rows.append((name, exact, n, top["bias_by_block"],
                         math.sqrt(report.mean_mse(dual64)) / n["scale"],
                         math.sqrt(report.mean_mse(path64)) / n["scale"],
                         report.mean_seconds(dual64) / report.mean_seconds(path64),
                         results["machine"]["git_commit"], results["settings"]["ref_spp"]))
    rows.sort(key=lambda row: (row[0], row[1]))
    lines = ["# Dual scattering: Exact Bounces against bias and noise", "",
             "Made by `dual_exact_sweep.py` from dual scattering studies "
             "(`HAIRIS_DUAL_EXACT=N dual_scattering_study`, one folder per N; commit %s, "
             "%s-spp PATH reference). DUAL path-traces the first N bounces and closes the path by "
             "dual scattering at the next hair vertex; errors are over the hair pixels, relative "
             "to the reference's mean. Times are wall times of one-thread renders on a shared "
             "machine: compare within a row." % (
                 ", ".join(sorted({row[7] for row in rows})),
                 "/".join(str(v) for v in sorted({row[8] for row in rows}))), "",
             "| case | Exact Bounces | DUAL − reference (R, G, B) | bias per pixel | "
             "bias 16×16 | RMSE 64 spp: DUAL / PATH | time per sample: DUAL / PATH | "
             "DUAL / Cycles at equal time |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for name, exact, n, bias, dual, path, time, _commit, _ref in rows:
        e = n.get("equal_time", {})
        lines.append("| %s | %d | %s | %.3f | %.3f | %.3f / %.3f | %.2f | %s |" % (
            name, exact, report.percent(n["dual_error"], n["dual_error_se"]), bias["1"],
            bias["16"], dual, path, time, "%.2f" % e["ratio"] if e else "–"))
    with open(out, "w") as handle:
        handle.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    main(sys.argv[1], sys.argv[2:])
