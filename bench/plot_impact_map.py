#!/usr/bin/python3
"""Draw the impact map of thesis Figure 3.5 from `lcsim impacts MODEL --map ...`.

Usage: plot_impact_map.py MAP.csv OUT.png [--title TEXT] [--arrows N]

MAP.csv has the columns v1,v2,mode,v1+,v2+ (one row per pre-impact velocity on
a grid). The regions are coloured by the mode Moreau's rule selects; arrows on
a coarser subgrid go from v- to v+ (the re-initialisation directions of the
figure). Agg backend: no display needed.
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("png")
    ap.add_argument("--title", default="Moreau impact map")
    ap.add_argument("--arrows", type=int, default=11, help="arrows per axis")
    a = ap.parse_args()

    with open(a.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"{a.csv}: no rows")
    v1 = np.array([float(r["v1"]) for r in rows])
    v2 = np.array([float(r["v2"]) for r in rows])
    p1 = np.array([float(r["v1+"]) for r in rows])
    p2 = np.array([float(r["v2+"]) for r in rows])
    modes = [r["mode"] for r in rows]
    u1, u2 = np.unique(v1), np.unique(v2)
    n1, n2 = len(u1), len(u2)
    names = sorted(set(modes), key=lambda m: (m != "unconstrained", m.count("+"), m))
    idx = np.array([names.index(m) for m in modes]).reshape(n1, n2)

    fig, ax = plt.subplots(figsize=(5.2, 4.6), dpi=90)
    cmap = plt.get_cmap("Pastel1", max(len(names), 3))
    ax.pcolormesh(u1, u2, idx.T, cmap=cmap, vmin=-0.5, vmax=max(len(names), 3) - 0.5,
                  shading="nearest")
    for k, name in enumerate(names):
        sel = idx == k
        ax.text(v1.reshape(n1, n2)[sel].mean(), v2.reshape(n1, n2)[sel].mean(), name,
                ha="center", va="center", fontsize=9, weight="bold")
    s1 = max(1, (n1 - 1) // max(a.arrows - 1, 1))
    s2 = max(1, (n2 - 1) // max(a.arrows - 1, 1))
    V1, V2 = v1.reshape(n1, n2)[::s1, ::s2], v2.reshape(n1, n2)[::s1, ::s2]
    P1, P2 = p1.reshape(n1, n2)[::s1, ::s2], p2.reshape(n1, n2)[::s1, ::s2]
    ax.quiver(V1, V2, P1 - V1, P2 - V2, angles="xy", scale_units="xy", scale=1, width=0.004,
              color="0.25")
    ax.set_xlabel("$x_3 = \\dot q_1$ before")
    ax.set_ylabel("$x_4 = \\dot q_2$ before")
    ax.set_title(a.title, fontsize=10)
    ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(a.png)


if __name__ == "__main__":
    main()
