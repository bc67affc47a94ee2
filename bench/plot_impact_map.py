#!/usr/bin/python3
"""Draw the impact map of thesis Figure 3.5 from `lcsim impacts MODEL --map ...`.

Usage: plot_impact_map.py MAP.csv OUT.png [--title TEXT] [--arrows N]

MAP.csv has five columns (one row per pre-impact velocity on a grid): the two
axes before, mode, the two axes after. The header is v1,v2,mode,v1+,v2+ for
the velocity map of a two-coordinate model, or rate_i,rate_j,mode,rate_i+,
rate_j+ for `--closed` (the approach velocities E_i v, E_j v of constraints i
and j, 0-based). The regions are coloured by the mode Moreau's rule selects;
arrows on a coarser subgrid go from the pre- to the post-impact velocity (the
re-initialisation directions of the figure). A legend names each region's
colour and the arrows. Agg backend: no display needed.
"""
import argparse
import csv

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
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
    cols = list(rows[0].keys())
    if len(cols) != 5 or cols[2] != "mode":
        raise SystemExit(f"{a.csv}: expected 5 columns with 'mode' third, got {cols}")
    v1 = np.array([float(r[cols[0]]) for r in rows])
    v2 = np.array([float(r[cols[1]]) for r in rows])
    p1 = np.array([float(r[cols[3]]) for r in rows])
    p2 = np.array([float(r[cols[4]]) for r in rows])
    modes = [r["mode"] for r in rows]
    u1, u2 = np.unique(v1), np.unique(v2)
    n1, n2 = len(u1), len(u2)
    names = sorted(set(modes), key=lambda m: (m != "unconstrained", m.count("+"), m))
    idx = np.array([names.index(m) for m in modes]).reshape(n1, n2)

    fig, ax = plt.subplots(figsize=(6.8, 4.8), dpi=90)
    ncol = max(len(names), 3)
    cmap = plt.get_cmap("Pastel1", ncol)
    ax.pcolormesh(u1, u2, idx.T, cmap=cmap, vmin=-0.5, vmax=ncol - 0.5, shading="nearest")
    s1 = max(1, (n1 - 1) // max(a.arrows - 1, 1))
    s2 = max(1, (n2 - 1) // max(a.arrows - 1, 1))
    V1, V2 = v1.reshape(n1, n2)[::s1, ::s2], v2.reshape(n1, n2)[::s1, ::s2]
    P1, P2 = p1.reshape(n1, n2)[::s1, ::s2], p2.reshape(n1, n2)[::s1, ::s2]
    ax.quiver(V1, V2, P1 - V1, P2 - V2, angles="xy", scale_units="xy", scale=1, width=0.004,
              color="0.25")
    handles = [Patch(facecolor=cmap(k), edgecolor="0.5",
                     label=("mode: " + name.replace("+", ", ") if name != "unconstrained"
                            else "no impulse (unconstrained)"))
               for k, name in enumerate(names)]
    handles.append(Line2D([], [], color="0.25", marker=">", markersize=6, lw=1.2,
                          label="arrow: velocity before \u2192 after"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=8,
              frameon=False, title="regions (impulse on)", title_fontsize=8)
    if cols[0].startswith("rate_"):
        i, j = cols[0][5:], cols[1][5:]
        ax.set_xlabel(f"approach velocity $E_{{{i}}} v$ before (constraint {i})")
        ax.set_ylabel(f"approach velocity $E_{{{j}}} v$ before (constraint {j})")
    else:
        ax.set_xlabel("$x_3 = \\dot q_1$ before")
        ax.set_ylabel("$x_4 = \\dot q_2$ before")
    ax.set_title(a.title, fontsize=9, wrap=True)
    ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(a.png, bbox_inches="tight")


if __name__ == "__main__":
    main()
