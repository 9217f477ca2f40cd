#!/usr/bin/env python3
"""Draws the seed's Figures 1-4 from the .npy data `hairis-bake figures` writes.

Usage: figures.py DIR [--model NAME]. Writes DIR/figure1.png .. figure4.png. Needs numpy and
matplotlib (Debian 12: python3-numpy, python3-matplotlib).
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

THETA_R = [-90, -60, -30, 0, 30, 60, 90]
PHI_R = [180, 90, 0, -90, -180]
STRANDS = [1, 2, 4, 8, 16]
EXTENT = [-90, 90, -180, 180]  # θ_i on x, φ_i on y, degrees


def theta_centres(n):
    return -90.0 + 180.0 * (np.arange(n) + 0.5) / n


def grid_figure(panels, rows, cols, row_labels, col_labels, title, path, norm):
    fig, axes = plt.subplots(rows, cols, figsize=(2.0 * cols + 1.2, 2.0 * rows + 0.8),
                             sharex=True, sharey=True, squeeze=False)
    image = None
    for r in range(rows):
        for c in range(cols):
            ax = axes[r][c]
            # Rows of the data are θ_i, columns φ_i: show θ_i across, φ_i up.
            # Zeros (outside the lobes) have no logarithm: clip them to the scale's floor.
            data = panels[r][c]
            if isinstance(norm, LogNorm):
                data = np.maximum(data, norm.vmin)
            image = ax.imshow(data.T, origin="lower", extent=EXTENT, aspect="auto",
                              cmap="inferno", norm=norm)
            if r == 0:
                ax.set_title(col_labels[c], fontsize=9)
            if c == 0:
                ax.set_ylabel(row_labels[r] + "\nφ_i (°)", fontsize=8)
            if r == rows - 1:
                ax.set_xlabel("θ_i (°)", fontsize=8)
            ax.set_xticks([-90, 0, 90])
            ax.set_yticks([-180, 0, 180])
            ax.tick_params(labelsize=7)
    fig.suptitle(title, fontsize=10)
    fig.colorbar(image, ax=axes, shrink=0.8, label="S per steradian")
    fig.savefig(path, dpi=110)
    plt.close(fig)


def positive_norm(data):
    positive = data[data > 0]
    vmax = float(data.max()) if data.size else 1.0
    vmin = max(float(np.percentile(positive, 5)) if positive.size else vmax * 1e-6, vmax * 1e-6)
    return LogNorm(vmin=vmin, vmax=vmax)


def band(profile, n_phi=90):
    """A θ_i profile drawn as an image over (θ_i, φ_i): uniform in azimuth."""
    return np.repeat(profile[:, None], n_phi, axis=1)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("dir")
    parser.add_argument("--model", default="")
    args = parser.parse_args()
    d = args.dir
    label = f" — {args.model}" if args.model else ""

    fig1 = np.load(os.path.join(d, "figure1.npy"))
    rows = [[fig1[r, c] for c in range(7)] for r in range(5)]
    grid_figure(rows, 5, 7, [f"φ_r = {p}°" for p in PHI_R],
                [f"θ_r = {t}°" for t in THETA_R],
                "Figure 1: direct scattering S_direct(θ_i, φ_i | θ_r, φ_r)" + label +
                " (log scale; θ_r = ±90° evaluated at ±89°)",
                os.path.join(d, "figure1.png"), positive_norm(fig1))

    fig2 = np.load(os.path.join(d, "figure2.npy"))
    rows = [[band(fig2[c]) for c in range(7)]]
    grid_figure(rows, 1, 7, ["n_h = 2"], [f"θ_r = {t}°" for t in THETA_R],
                "Figure 2: multiple scattering through n_h = 2 strands" + label +
                " (azimuthally uniform)", os.path.join(d, "figure2.png"), positive_norm(fig2))

    fig3 = np.load(os.path.join(d, "figure3.npy"))
    fig, axes = plt.subplots(2, 5, figsize=(15, 6), sharex=True, sharey=True,
                             constrained_layout=True)
    for k, n_h in enumerate(STRANDS):
        image = band(fig3[k])
        top = axes[0][k].imshow(image.T, origin="lower", extent=EXTENT, aspect="auto", cmap="gray",
                                vmin=0.0, vmax=0.2)
        bottom = axes[1][k].imshow(image.T, origin="lower", extent=EXTENT, aspect="auto",
                                   cmap="gray")
        axes[0][k].set_title(f"n_h = {n_h}", fontsize=9)
        axes[1][k].set_xlabel("θ_i (°)", fontsize=8)
        bar = fig.colorbar(bottom, ax=axes[1][k], fraction=0.08, format="%.0e")
        bar.ax.tick_params(labelsize=7)
    axes[0][0].set_ylabel("fixed scale [0, 0.2]\nφ_i (°)", fontsize=8)
    axes[1][0].set_ylabel("automatic scale\nφ_i (°)", fontsize=8)
    fig.colorbar(top, ax=axes[0].tolist(), fraction=0.02)
    fig.suptitle("Figure 3: θ_r = 0, multiple scattering per n_h" + label, fontsize=10)
    fig.savefig(os.path.join(d, "figure3.png"), dpi=110)
    plt.close(fig)

    profiles = np.load(os.path.join(d, "figure4_profiles.npy"))
    fits = np.load(os.path.join(d, "figure4_fits.npy"))
    theta = theta_centres(profiles.shape[2])
    rad = np.radians(theta)
    fig, axes = plt.subplots(4, 3, figsize=(11, 10), sharex=True)
    for k, n_h in enumerate([1, 2, 4, 8]):
        for c, theta_r in enumerate([-60, 0, 60]):
            ax = axes[k][c]
            s, sigma, mean = fits[k, c]
            gauss = s * np.exp(-0.5 * ((rad - mean) / sigma) ** 2) / (sigma * np.sqrt(2 * np.pi))
            ax.plot(theta, profiles[k, c], color="tab:blue", label="distribution")
            ax.plot(theta, gauss, color="tab:green", label="fitted Gaussian")
            ax.set_title(f"n_h = {n_h}, θ_r = {theta_r}°: σ = {sigma:.2f}, "
                         f"μ = {np.degrees(mean):.1f}°",
                         fontsize=8)
            ax.tick_params(labelsize=7)
            if k == 3:
                ax.set_xlabel("θ_i (°)")
    axes[0][0].legend(fontsize=7)
    fig.suptitle("Figure 4: multiple-scattering slices and fitted Gaussians" + label, fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(d, "figure4.png"), dpi=110)
    plt.close(fig)
    return 0


if __name__ == "__main__":
    sys.exit(main())
