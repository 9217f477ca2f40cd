"""Draws a table file's parts from the .npy data `hairis-bake figures --table` writes.

table_far.png: the direct-scattering distribution over (θ_i, φ) at five θ_r nodes (log scale);
table_multiple.png: the multiple-scattering distribution over θ_i per n_h (rows) and θ_r (x);
table_near.png (Chiang): per lobe, the near field's θ_i density per θ_o node (the rows TABLE
samples single scattering from), with the nodes that draw from the fiber's cone marked;
table_huang.png (Huang, whose files hold only this part): the Huang table's density over
(θ_i, φ_i − φ_o) per φ_o node (rows) at five θ_o nodes (columns), log scale.
"""

import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import LogNorm  # noqa: E402

LOBES = ["R", "TT", "TRT", "TRRT+"]


def positive_norm(data):
    """A log colour scale over the positive values (six decades at most)."""
    positive = data[data > 0]
    top = float(positive.max()) if positive.size else 1.0
    bottom = max(float(positive.min()) if positive.size else top * 1e-6, top * 1e-6)
    return LogNorm(vmin=bottom, vmax=top)


def save(fig, d, name, title):
    """Gives the figure its title and writes it to ``d`` as <name>.png."""
    fig.suptitle(title, fontsize=10)
    fig.savefig(os.path.join(d, name + ".png"), dpi=110)
    plt.close(fig)


def draw_far(d, label):
    far = np.load(os.path.join(d, "table_far.npy"))
    nodes = np.degrees(np.load(os.path.join(d, "table_theta_r.npy")))
    picks = np.unique(np.linspace(0, len(nodes) - 1, 5).round().astype(int))
    fig, axes = plt.subplots(1, len(picks), figsize=(3.2 * len(picks), 3.4), squeeze=False,
                             constrained_layout=True)
    norm = positive_norm(far[picks])
    for ax, r in zip(axes[0], picks):
        image = ax.imshow(np.maximum(far[r], norm.vmin), origin="lower", aspect="auto",
                          extent=[-180, 180, -90, 90], norm=norm, cmap="magma")
        ax.set_title("θ_r = %.1f°" % nodes[r], fontsize=9)
        ax.set_xlabel("φ = φ_i − φ_o (°)", fontsize=8)
    axes[0][0].set_ylabel("θ_i (°)", fontsize=8)
    fig.colorbar(image, ax=axes[0].tolist(), fraction=0.02)
    save(fig, d, "table_far",
         "far part, R: direct-scattering distribution f·cos θ_i per sr — " + label)


def draw_multiple(d, label):
    multiple = np.load(os.path.join(d, "table_multiple.npy"))
    nodes = np.degrees(np.load(os.path.join(d, "table_theta_r.npy")))
    n_h = np.load(os.path.join(d, "table_n_h.npy")).astype(int)
    fig, axes = plt.subplots(1, len(n_h), figsize=(3.0 * len(n_h), 3.2), squeeze=False,
                             constrained_layout=True)
    for k, ax in enumerate(axes[0]):
        image = ax.imshow(multiple[:, k, :].T, origin="lower", aspect="auto", cmap="viridis",
                          extent=[nodes[0], nodes[-1], -90, 90])
        ax.set_title("n_h = %d" % n_h[k], fontsize=9)
        ax.set_xlabel("θ_r (°)", fontsize=8)
        fig.colorbar(image, ax=ax, fraction=0.05)
    axes[0][0].set_ylabel("θ_i (°)", fontsize=8)
    save(fig, d, "table_multiple",
         "far part, G: multiple-scattering distribution per sr — " + label)


def draw_near(d, label):
    near = np.load(os.path.join(d, "table_near.npy"))
    cone = np.load(os.path.join(d, "table_near_cone.npy"))
    fig, axes = plt.subplots(1, 4, figsize=(13, 3.6), constrained_layout=True)
    for p, ax in enumerate(axes):
        rows = near[:, p, :]
        norm = positive_norm(rows)
        image = ax.imshow(np.maximum(rows, norm.vmin).T, origin="lower", aspect="auto",
                          cmap="magma", norm=norm, extent=[-90, 90, -90, 90])
        drawn = np.linspace(-90, 90, near.shape[0])[cone[:, p] > 0]
        if drawn.size:
            ax.plot(drawn, np.full(drawn.shape, 88.0), "c|", markersize=6,
                    label="drawn from the cone")
            ax.legend(fontsize=7, loc="lower right")
        ax.set_title(LOBES[p], fontsize=9)
        ax.set_xlabel("θ_o (°)", fontsize=8)
        fig.colorbar(image, ax=ax, fraction=0.05)
    axes[0].set_ylabel("θ_i (°)", fontsize=8)
    save(fig, d, "table_near",
         "near part: each lobe's M_p·cos θ_i density over θ_i per θ_o node — " + label)


def draw_huang(d, label):
    values = np.load(os.path.join(d, "table_huang.npy"))
    theta_o = np.degrees(np.load(os.path.join(d, "table_huang_theta_o.npy")))
    phi_o = np.degrees(np.load(os.path.join(d, "table_huang_phi_o.npy")))
    picks = np.unique(np.linspace(0, len(theta_o) - 1, 5).round().astype(int))
    # Each slice as a density per steradian: values over the slice's sum × a cell's solid angle.
    n_i, n_p = values.shape[2], values.shape[3]
    edges = np.sin(np.linspace(-np.pi / 2, np.pi / 2, n_i + 1))
    solid = (edges[1:] - edges[:-1])[:, None] * (2 * np.pi / n_p)
    total = (values * solid).sum(axis=(2, 3), keepdims=True)
    density = np.where(total > 0, values / np.where(total > 0, total, 1.0), 0.0)
    fig, axes = plt.subplots(len(phi_o), len(picks), figsize=(3.2 * len(picks), 2.8 * len(phi_o)),
                             squeeze=False, constrained_layout=True)
    norm = positive_norm(density[:, picks])
    for q in range(len(phi_o)):
        for ax, r in zip(axes[q], picks):
            image = ax.imshow(np.maximum(density[q, r], norm.vmin), origin="lower",
                              aspect="auto", extent=[-180, 180, -90, 90], norm=norm,
                              cmap="magma")
            ax.set_title("φ_o %.0f°, θ_o %.1f°" % (phi_o[q], theta_o[r]), fontsize=9)
            ax.set_xlabel("φ_i − φ_o (deg)")
            ax.set_ylabel("θ_i (deg)")
    fig.colorbar(image, ax=axes, shrink=0.8, label="density per sr")
    save(fig, d, "table_huang", "huang part: the density TABLE samples per view node — " + label)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir")
    parser.add_argument("--model", default="")
    args = parser.parse_args()
    if os.path.exists(os.path.join(args.dir, "table_huang.npy")):
        draw_huang(args.dir, args.model)
        return 0
    draw_far(args.dir, args.model)
    draw_multiple(args.dir, args.model)
    if os.path.exists(os.path.join(args.dir, "table_near.npy")):
        draw_near(args.dir, args.model)
    return 0


if __name__ == "__main__":
    sys.exit(main())
