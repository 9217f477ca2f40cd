#!/usr/bin/env python3
"""Plots render_study.json (from render_study.py) with matplotlib.

    /usr/bin/python3 bench/studies/render_study/plot_render_study.py [folder, default: this one]

Writes render_study.png (relative RMSE against samples per pixel and against render time,
log-log, one line per Hairis strategy and Cycles) and, when render_study_images.npz is there,
render_study_images.png (the reference beside the 64-spp TABLE and Cycles images).
"""

import json
import os
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
STYLE = {"UNIFORM": ("tab:gray", "v"), "ANALYTIC": ("tab:blue", "o"),
         "GAUSSIAN": ("tab:green", "s"), "TABLE": ("tab:red", "D"), "DUAL": ("tab:purple", "^"),
         "CYCLES": ("black", "x")}


def srgb(linear):
    """Linear RGB to 8-bit-ready sRGB in [0, 1] (Blender's Standard view transform)."""
    x = np.clip(np.asarray(linear, np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def plot_curves(results, path):
    """RMSE against spp and against time."""
    summary = results["summary"]
    s = results["settings"]
    figure, (left, right) = plt.subplots(1, 2, figsize=(11, 4.4))
    for method, (color, marker) in STYLE.items():
        if method not in summary:  # results of a run without it
            continue
        points = summary[method]["per_spp"]
        spp = [p["spp"] for p in points]
        seconds = [p["seconds"] for p in points]
        rmse = [p["relative_rmse_corrected"] for p in points]
        label = "Cycles" if method == "CYCLES" else "Hairis " + method
        style = "--" if method == "CYCLES" else "-"
        left.loglog(spp, rmse, style, color=color, marker=marker, label=label)
        right.loglog(seconds, rmse, style, color=color, marker=marker, label=label)
    first = summary["CYCLES"]["per_spp"][0]
    spp = np.array(s["spps"], float)
    left.loglog(spp, first["relative_rmse_corrected"] * np.sqrt(spp[0] / spp), ":",
                color="0.6", label=r"$\propto 1/\sqrt{spp}$")
    left.set_xlabel("samples per pixel")
    right.set_xlabel("render time (s, wall, %d cores)" % results["machine"]["nproc"])
    for axis in (left, right):
        axis.set_ylabel("relative RMSE (noise-corrected)")
        axis.grid(True, which="both", alpha=0.3)
    left.set_title("Error against samples")
    right.set_title("Error against time")
    left.legend(fontsize=8)
    figure.suptitle("Render study: %dx%d pixels, %d bounces, reference %d+%d spp "
                    "(Hairis ANALYTIC + Cycles)" % (s["resolution"][0], s["resolution"][1],
                                                    s["bounces"], s["ref_spp"], s["ref_spp"]),
                    fontsize=10)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def plot_images(images, ref_spp, path):
    """The reference beside the 64-spp TABLE and Cycles images."""
    panels = [("reference", "Reference (%d + %d spp)" % (ref_spp, ref_spp)),
              ("table_64", "Hairis TABLE, 64 spp"),
              ("cycles_64", "Cycles, 64 spp")]
    panels = [(key, title) for key, title in panels if key in images]
    figure, axes = plt.subplots(1, len(panels), figsize=(3.6 * len(panels), 3.2))
    for axis, (key, title) in zip(np.atleast_1d(axes), panels):
        # Blender's pixels start at the bottom row.
        axis.imshow(srgb(images[key].astype(np.float32))[::-1], interpolation="nearest")
        axis.set_title(title, fontsize=9)
        axis.axis("off")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)


def main():
    """Reads the results folder (argument or this folder) and writes the PNGs."""
    folder = sys.argv[1] if len(sys.argv) > 1 else HERE
    with open(os.path.join(folder, "render_study.json")) as source:
        results = json.load(source)
    plot_curves(results, os.path.join(folder, "render_study.png"))
    images = os.path.join(folder, "render_study_images.npz")
    if os.path.isfile(images):
        with np.load(images) as data:
            plot_images({k: data[k] for k in data.files}, results["settings"]["ref_spp"],
                        os.path.join(folder, "render_study_images.png"))
    print("plot_render_study: wrote PNGs to %s" % folder)


if __name__ == "__main__":
    main()
