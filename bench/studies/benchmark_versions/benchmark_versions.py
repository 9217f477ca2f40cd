"""Google Benchmark results of two builds side by side in one run: new against old.

    python3 bench/studies/benchmark_versions/benchmark_versions.py OLD_BINARY NEW_BINARY \\
        [--filter REGEX] [--rounds N]

Runs the benchmarks both binaries have (matching --filter), alternating old and new for
--rounds rounds so that a busy machine slows both alike, and reports per benchmark the median
CPU time of each and the ratio new / old. Writes HAIRIS_STUDY_OUT (default: this folder)
/benchmark_versions.{json,md}.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def names(binary, pattern):
    """The benchmark names of ``binary`` that match ``pattern``."""
    out = subprocess.run([binary, "--benchmark_list_tests", "--benchmark_filter=" + pattern],
                         check=True, capture_output=True, text=True).stdout
    return [line.strip() for line in out.splitlines() if line.strip()]


def run(binary, pattern):
    """CPU time in ns per iteration of each benchmark matching ``pattern``, one run."""
    out = subprocess.run([binary, "--benchmark_filter=" + pattern, "--benchmark_format=json",
                          "--benchmark_min_time=0.3"],
                         check=True, capture_output=True, text=True).stdout
    scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}
    return {b["name"]: b["cpu_time"] * scale[b["time_unit"]]
            for b in json.loads(out)["benchmarks"] if b.get("run_type") == "iteration"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old")
    parser.add_argument("new")
    parser.add_argument("--filter", default="sample_and_pdf|chiang_near_field")
    parser.add_argument("--rounds", type=int, default=5)
    args = parser.parse_args()
    shared = sorted(set(names(args.old, args.filter)) & set(names(args.new, args.filter)))
    if not shared:
        sys.exit("no benchmark matches %r in both binaries" % args.filter)
    pattern = "^(" + "|".join(shared) + ")$"
    times = {"old": {n: [] for n in shared}, "new": {n: [] for n in shared}}
    for round_index in range(args.rounds):
        for side, binary in (("old", args.old), ("new", args.new)):
            for name, ns in run(binary, pattern).items():
                if name in times[side]:
                    times[side][name].append(ns)
        print("round %d of %d done" % (round_index + 1, args.rounds), file=sys.stderr)
    rows = []
    for name in shared:
        old = statistics.median(times["old"][name])
        new = statistics.median(times["new"][name])
        rows.append({"name": name, "old_ns": old, "new_ns": new, "ratio": new / old,
                     "old_runs": times["old"][name], "new_runs": times["new"][name]})
    out = os.environ.get("HAIRIS_STUDY_OUT", HERE)
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "benchmark_versions.json"), "w") as f:
        json.dump({"old": args.old, "new": args.new, "rounds": args.rounds, "rows": rows}, f,
                  indent=1)
    lines = ["# Benchmarks: new against old, one run", "",
             "CPU time per iteration, median of %d alternating rounds; old = %s, new = %s." % (
                 args.rounds, args.old, args.new), "",
             "| benchmark | old (ns) | new (ns) | new / old |", "|---|---|---|---|"]
    for r in rows:
        lines.append("| %s | %.0f | %.0f | %.2f |" % (
            r["name"], r["old_ns"], r["new_ns"], r["ratio"]))
    with open(os.path.join(out, "benchmark_versions.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
