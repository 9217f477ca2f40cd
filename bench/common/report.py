#!/usr/bin/env python3
"""Plots and the summary of scripts/bench: reads the JSON files of a bench folder (bench/ or
scripts/bench's HAIRIS_BENCH_OUT: micro/ and studies/<study>/) and writes

- micro/benchmarks.md: the Google Benchmark figures as a table;
- studies/strategy_study/strategy_study.png: near-field relative variance against θ_r, per
  fiber and strategy;
- studies/strategy_study/resolution.png: the table-resolution sweeps (variance against memory);
- summary.md: issue 6's targets, each with the measured value and whether it is met.

Usage: /usr/bin/python3 bench/common/report.py [bench]
"""

import json
import os
import platform
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def load(folder, name):
    """The parsed JSON file ``name`` in ``folder``, or None when it is missing."""
    path = os.path.join(folder, name)
    if not os.path.isfile(path):
        return None
    with open(path) as f:
        return json.load(f)


def machine():
    """CPU model, core count and memory of this machine, for the reports."""
    cpu = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
        with open("/proc/meminfo") as f:
            kib = int(f.readline().split()[1])
        memory = "%.1f GiB" % (kib / 1024.0 ** 2)
    except OSError:
        memory = "unknown memory"
    return "%s, %d cores, %s" % (cpu, os.cpu_count() or 0, memory)


def benchmark_rows(data):
    """(name, label, ns per iteration, items per second) of each benchmark."""
    rows = []
    scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
    for b in data.get("benchmarks", []):
        if b.get("run_type") == "aggregate":
            continue
        ns = b["real_time"] * scale[b.get("time_unit", "ns")]
        rows.append((b["name"], b.get("label", ""), ns, b.get("items_per_second")))
    return rows


def write_benchmarks(folder, data):
    rows = benchmark_rows(data)
    with open(os.path.join(folder, "benchmarks.md"), "w") as f:
        f.write("# Google Benchmark (`build/bench/hairis_benchmarks`)\n\n")
        f.write("Machine: %s. Wall time per iteration, one thread unless the label says "
                "otherwise.\n\n| benchmark | what | time | per second |\n|---|---|---|---|\n"
                % machine())
        for name, label, ns, items in rows:
            if ns < 1e5:
                time = "%.0f ns" % ns
            else:
                time = "%.1f ms" % (ns / 1e6) if ns < 1e9 else "%.2f s" % (ns / 1e9)
            rate = "%.2f M" % (items / 1e6) if items else ""
            f.write("| %s | %s | %s | %s |\n" % (name, label, time, rate))
    return rows


def plot_strategies(folder, study):
    fibers = list(study["near_field_variance"].keys())
    theta = study["theta_r_deg"]
    figure, axes = plt.subplots(2, 3, figsize=(13, 7.5), sharex=True, sharey=True)
    for ax, fiber in zip(axes.flat, fibers):
        for name, values in study["near_field_variance"][fiber].items():
            style = "-" if "table" in name else "--"
            ax.semilogy(theta, [max(v, 1e-9) for v in values], style, marker="o", ms=3,
                        label=name)
        ax.set_title(fiber, fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("θ_r (degrees)")
    for ax in axes[:, 0]:
        ax.set_ylabel("relative variance per sample")
    axes[0, 0].legend(fontsize=7, loc="upper center")
    figure.suptitle("Near field: relative variance of the albedo estimate per strategy "
                    "(lower is better)")
    figure.tight_layout()
    figure.savefig(os.path.join(folder, "strategy_study.png"), dpi=90)
    plt.close(figure)


def plot_resolution(folder, study):
    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    sweep = study["near_field_resolution"]
    for cells in sorted({s["cells"] for s in sweep}):
        points = sorted((s["kib"], s["variance"], s["nodes"]) for s in sweep if s["cells"] == cells)
        left.loglog([p[0] for p in points], [p[1] for p in points], marker="o",
                    label="%d θ_i cells" % cells)
        for kib, variance, nodes in points:
            left.annotate(str(nodes), (kib, variance), fontsize=7)
    left.set_xlabel("memory (KiB); labels: θ_o nodes")
    left.set_ylabel("median relative variance")
    left.set_title("Near-field table (between nodes)")
    left.legend(fontsize=8)
    left.grid(True, which="both", alpha=0.3)
    far = study["far_field_resolution"]
    right.loglog([s["mib"] for s in far], [s["variance"] for s in far], marker="o")
    for s in far:
        right.annotate("×".join(str(v) for v in s["size"]), (s["mib"], s["variance"]), fontsize=7)
    right.set_xlabel("table floats (MiB)")
    right.set_title("Far-field 2D tables (h-averaged f)")
    right.grid(True, which="both", alpha=0.3)
    figure.tight_layout()
    figure.savefig(os.path.join(folder, "resolution.png"), dpi=90)
    plt.close(figure)


def find(rows, prefix):
    """The first benchmark row whose name starts with ``prefix``."""
    return next((r for r in rows if r[0].startswith(prefix)), None)


def write_summary(folder, rows, study, export, render):
    lines = ["# Issue 6 targets, measured", "",
             "Machine: %s. Reproduce: `scripts/bench`." % machine(),
             "", "| target | measured | met |", "|---|---|---|"]

    def add(target, measured, met):
        lines.append("| %s | %s | %s |" % (target, measured, "yes" if met else "**no**"))

    if study:
        names = study["strategies"]
        median = dict(zip(names, study["near_field_median"]))
        table = median.get("table, near-field (w=0)")
        analytic, uniform = median.get("analytic"), median.get("uniform")
        if table is not None and analytic and uniform:
            add("table variance ≤ 0.5× analytic (near field, median over θ_r, median over six "
                "fibers)", "%.2g vs %.2g (%.4f×)" % (table, analytic, table / analytic),
                table <= 0.5 * analytic)
            add("table variance ≤ 1/50 of uniform",
                "%.2g vs %.2g (1/%.0f)" % (table, uniform, uniform / table),
                table <= uniform / 50)
    if rows:
        analytic = find(rows, "sample_and_pdf/analytic")
        for key, what in (("sample_and_pdf/table_near_direct", "near-field table"),
                          ("sample_and_pdf/table_far_direct", "far-field 2D table")):
            table = find(rows, key)
            if table and analytic:
                add("%s sample+pdf ≥ 2× faster than analytic" % what,
                    "%.0f ns vs %.0f ns (%.1f×)" % (table[2], analytic[2], analytic[2] / table[2]),
                    analytic[2] >= 2 * table[2])
                add("%s ≥ 40 M samples/s on one core" % what, "%.2f M/s" % (1e3 / table[2]),
                    1e3 / table[2] >= 40)
        bake = find(rows, "bake_default_tables/2")
        if bake:
            add("default bake ≤ 2 s on 2 cores", "%.2f s" % (bake[2] / 1e9), bake[2] / 1e9 <= 2.0)
    equal = (render or {}).get("summary", {}).get("equal_time")
    if equal:
        # Hairis' best strategy at each of Cycles' render times.
        for k, cycles in enumerate(next(iter(equal.values()))):
            best = min(((name, rows[k]) for name, rows in equal.items()),
                       key=lambda e: e[1]["ratio"])
            add("equal time (%.1f s, Cycles at %d spp): Hairis' best RMSE ≤ Cycles'"
                % (cycles["seconds"], cycles["cycles_spp"]),
                "%s: %.2f× Cycles' RMSE%s" % (best[0], best[1]["ratio"],
                                              " (extrapolated)" if best[1]["extrapolated"] else ""),
                best[1]["ratio"] <= 1.0)
    if export:
        big = [r for r in export.get("runs", []) if r.get("strands", 0) >= 1000000]
        if big:
            peak = max(m["peak_rss_mb"] for m in big[0]["marks"])
            add("1M strands render within 8 GB", "%.0f MB peak RSS (Blender included)" % peak,
                peak <= 8192)
    with open(os.path.join(folder, "summary.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def main():
    folder = (sys.argv[1] if len(sys.argv) > 1
              else os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    micro = os.path.join(folder, "micro")
    studies = os.path.join(folder, "studies")
    strategy = os.path.join(studies, "strategy_study")
    benchmarks = load(micro, "benchmarks.json")
    study = load(strategy, "strategy_study.json")
    rows = write_benchmarks(micro, benchmarks) if benchmarks else []
    if study:
        plot_strategies(strategy, study)
        plot_resolution(strategy, study)
    write_summary(folder, rows, study,
                  load(os.path.join(studies, "export_study"), "export_study.json"),
                  load(os.path.join(studies, "render_study"), "render_study.json"))


if __name__ == "__main__":
    main()
