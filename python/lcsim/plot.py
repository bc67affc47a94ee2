#!/usr/bin/python3
"""lcsim's figures, in one place: the trajectory of a run (thesis Figure 3.3 style), the
impact map (Figure 3.5), the work-precision diagram of a sweep, and the cart-chain
timing plot. Each function takes the Python results (lcsim.simulate, lcsim.impact_map,
lcsim.sweep) or the files the command line writes (CSV, JSON); the command line's
`--plot` runs this file (it needs matplotlib, not the extension module):

    /usr/bin/python3 -m lcsim.plot trajectory traj.csv -o traj.png [--events run.json]
    /usr/bin/python3 -m lcsim.plot impact-map map.csv map.png [--title T] [--arrows N]
    /usr/bin/python3 -m lcsim.plot work-precision sweep.json wp.png [--error max|events|final]
    /usr/bin/python3 -m lcsim.plot chain results.csv chain.png

Agg backend: no display needed; the format follows the output's extension.
"""

import argparse
import csv
import io
import json
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
import numpy as np  # noqa: E402

# ---- Trajectories (lcsim's trajectory CSV, src/io/writers.cpp) ----------------------
#
# Header: ``t``; the state, either the coordinate names followed by ``v_<name>`` for
# each (mechanical models) or ``x1..xn`` (general LCS); ``u_<constraint>``... or
# ``u1..uk``; ``y_<constraint>``... or ``y1..yk``; ``mode`` (active constraint indices
# joined by ';'). At a jump two rows share the same t (before, after), so a jump shows
# as a vertical segment. Blank cells are left out of the lines. Events (lcsim's JSON run
# summary, key ``events``, objects with ``t`` and ``type``) are drawn as dashed lines,
# except those of type ``start``.

class TrajectoryError(Exception):
    """A CSV or JSON input that does not have the expected layout."""


def _number(cell, path, row, column):
    """A CSV cell as a float (blank: NaN); TrajectoryError names the row and column."""
    cell = cell.strip()
    if cell == "":
        return math.nan
    try:
        return float(cell)
    except ValueError:
        raise TrajectoryError(
            f"{path}: row {row}, column '{column}': '{cell}' is not a number") from None


class Layout:
    """Where each kind of column of a trajectory CSV is (indices into the header).

    kind: 'mechanical' (positions `pos`, velocities `vel`) or 'lcs' (its states in `pos`,
    `vel` empty); `force` the multipliers u_<pair>, `gap` the y_<pair>; `friction` the
    tangential multipliers ut_ / ut2_ (numbers); `text` the friction modes fm_ (words, not
    drawn); `outputs` a list of (panel label, indices) for a circuit's V(node) and
    I(element) columns (and any other named output)."""

    def __init__(self, kind, pos, vel, force, gap):
        self.kind, self.pos, self.vel, self.force, self.gap = kind, pos, vel, force, gap
        self.friction, self.text, self.outputs = [], [], []

    def __iter__(self):  # (kind, pos, vel, force, gap), as before
        return iter((self.kind, self.pos, self.vel, self.force, self.gap))


def _pairs(names, start):
    """The pairs u_<c>... y_<c>... from names[start]: their count k (0 if none there)."""
    k = 0
    while start + k < len(names) and names[start + k].startswith("u_"):
        k += 1
    while k > 0 and names[start + k:start + 2 * k] != ["y_" + n[2:] for n in names[start:start + k]]:
        k -= 1
    return k


def split_columns(header):
    """The columns of a trajectory CSV by kind (a Layout; iterating it gives the tuple
    (kind, position, velocity, force, gap) of column indices).

    The header is t, the state (coordinates then v_<coordinate>, or an LCS's states: x1..xn
    or a circuit's C1.v, L1.i, ...), the pairs u_<c> then y_<c>, a frictional model's ut_ /
    ut2_ / fm_ columns, a circuit's outputs V(node), I(element), and mode."""
    if len(header) < 3 or header[0] != "t" or header[-1] != "mode":
        raise TrajectoryError("header must start with 't' and end with 'mode', got "
                              f"{header[:2]}...{header[-1:]}")
    names = header[1:-1]
    index = lambda i: i + 1  # names[i] is header[i + 1]
    layout = None
    # Mechanical: the first n names are coordinates, the next n are v_<coordinate>.
    for n in range(1, len(names) // 2 + 1):
        if names[n:2 * n] == ["v_" + c for c in names[:n]]:
            k = _pairs(names, 2 * n)
            layout = Layout("mechanical", [index(i) for i in range(n)],
                            [index(i) for i in range(n, 2 * n)],
                            [index(i) for i in range(2 * n, 2 * n + k)],
                            [index(i) for i in range(2 * n + k, 2 * n + 2 * k)])
            rest = range(2 * n + 2 * k, len(names))
            break
    if layout is None:  # an LCS: its states up to the first pairs (or outputs)
        n = 0
        while n < len(names) and not (names[n].startswith("u_") and _pairs(names, n) > 0) \
                and not re.fullmatch(r"[VI]\(.+\)", names[n]):
            n += 1
        if n == 0:
            raise TrajectoryError("cannot recognise the state columns: expected coordinates "
                                  "followed by v_<coordinate>, or the states of an LCS")
        k = _pairs(names, n)
        layout = Layout("lcs", [index(i) for i in range(n)], [],
                        [index(i) for i in range(n, n + k)],
                        [index(i) for i in range(n + k, n + 2 * k)])
        rest = range(n + 2 * k, len(names))
    panels = {}
    for i in rest:
        name = names[i]
        if name.startswith(("ut_", "ut2_")):
            layout.friction.append(index(i))
        elif name.startswith("fm_"):
            layout.text.append(index(i))
        else:
            label = ("voltage (V)" if name.startswith("V(") else
                     "current (A)" if name.startswith("I(") else "output")
            panels.setdefault(label, []).append(index(i))
    layout.outputs = list(panels.items())
    return layout


def read_trajectory(path, text=None):
    """The CSV at `path` (or its `text`) as (header, layout, data, modes)."""
    with (io.StringIO(text) if text is not None else open(path, newline="")) as f:
        rows = list(csv.reader(f))
    if not rows:
        raise TrajectoryError(f"{path}: empty file")
    header = [h.strip() for h in rows[0]]
    try:
        layout = split_columns(header)
    except TrajectoryError as e:
        raise TrajectoryError(f"{path}: {e}") from None
    data = {name: [] for name in header[:-1]}
    words = set(layout.text)  # the friction modes: kept as they are written
    modes = []
    for r, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != len(header):
            raise TrajectoryError(f"{path}: row {r} has {len(row)} cells, header has "
                                  f"{len(header)}")
        for j, name in enumerate(header[:-1]):
            data[name].append(row[j].strip() if j in words else _number(row[j], path, r, name))
        modes.append(row[-1].strip())
    if not modes:
        raise TrajectoryError(f"{path}: no samples after the header")
    return header, layout, data, modes


def read_events(path):
    """The (t, type) of the events in a JSON run summary (a path or a dict)."""
    if isinstance(path, dict):
        summary = path
    else:
        with open(path) as f:
            try:
                summary = json.load(f)
            except json.JSONDecodeError as e:
                raise TrajectoryError(f"{path}: not JSON ({e})") from None
    events = summary.get("events") if isinstance(summary, dict) else None
    if not isinstance(events, list):
        raise TrajectoryError(f"{path}: no 'events' list")
    out = []
    for i, e in enumerate(events):
        if not isinstance(e, dict) or "t" not in e or "type" not in e:
            raise TrajectoryError(f"{path}: events[{i}] lacks 't' or 'type'")
        if e["type"] != "start":
            out.append((float(e["t"]), str(e["type"])))
    return out


def _draw_trajectory(header, layout, data, events, title, with_gaps, output):
    """The stacked panels of `trajectory` from a parsed CSV and (t, type) events."""
    kind, pos, vel, force, gap = layout
    t = data["t"]
    panels = []
    if kind == "mechanical":
        panels.append(("position", pos))
        panels.append(("velocity", vel))
    else:
        panels.append(("state x", pos))
    if force:
        panels.append(("force u" if kind == "mechanical" else "pair u", force))
    if layout.friction:
        panels.append(("friction ut", layout.friction))
    if with_gaps and gap:
        panels.append(("gap y" if kind == "mechanical" else "pair y", gap))
    panels.extend(layout.outputs)

    fig, axes = plt.subplots(len(panels), 1, sharex=True,
                             figsize=(9, 2.2 * len(panels) + 1.0), squeeze=False)
    axes = axes[:, 0]
    for ax, (label, columns) in zip(axes, panels):
        for j in columns:
            name = header[j]
            # Blank cells are left out, so the line joins the neighbouring samples.
            points = [(a, b) for a, b in zip(t, data[name]) if math.isfinite(b)]
            ax.plot([a for a, _ in points], [b for _, b in points], label=name,
                    linewidth=1.4)
        ax.set_ylabel(label)
        ax.grid(True, linewidth=0.4, alpha=0.5)
        # Legends outside the axes, so they hide neither curves nor event lines.
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)

    # Events: one dashed line per distinct time, labelled with the type(s) there.
    by_time = {}
    for te, kind_e in events:
        key = round(te, 12)
        by_time.setdefault(key, (te, []))[1].append(kind_e)
    finite_t = [x for x in t if math.isfinite(x)]
    span = (max(finite_t) - min(finite_t)) or 1.0
    level, last, top_level = 0, -math.inf, -1
    for te, kinds in sorted(by_time.values()):
        for ax in axes:
            ax.axvline(te, color="0.35", linestyle="--", linewidth=0.9, zorder=0)
        # Labels sit above the top panel; close events are staggered so they stay legible.
        level = level + 1 if te - last < 0.08 * span else 0
        last = te
        top_level = max(top_level, level % 3)
        axes[0].annotate(" + ".join(kinds), xy=(te, 1.0), xycoords=("data", "axes fraction"),
                         xytext=(0, 2 + 10 * (level % 3)), textcoords="offset points",
                         va="bottom", ha="center", fontsize=8, color="0.25")

    axes[-1].set_xlabel("t (s)")
    axes[-1].set_xlim(min(finite_t), max(finite_t))
    if title:
        axes[0].set_title(title, pad=6 + 12 * (top_level + 1))
    fig.tight_layout()
    fig.savefig(output, dpi=150)
    plt.close(fig)


def trajectory(run, output, events=None, title=None, gaps=False):
    """Draws a trajectory like the thesis's Figure 3.3: positions, velocities, forces u
    (and the gaps y with `gaps`) against time, events as dashed lines.

    `run` is an lcsim.Trajectory (its events are drawn) or the path of a trajectory CSV
    written by `lcsim simulate --out`; `events` a JSON run summary (path or dict, as
    `lcsim simulate --json` prints) for a CSV. `output`: png, pdf or svg."""
    if isinstance(run, (str, os.PathLike)):
        header, layout, data, _ = read_trajectory(run)
        marks = read_events(events) if events is not None else []
    else:
        header, layout, data, _ = read_trajectory("trajectory", text=run.to_csv())
        marks = [(e.t, e.type) for e in run.events if e.type != "start"]
    _draw_trajectory(header, layout, data, marks, title, gaps, output)


# ---- The impact map (thesis Figure 3.5, `lcsim impacts MODEL --map ...`) ---------------
#
# Five columns, one row per pre-impact velocity on a grid: the two axes before, mode, the
# two axes after. The header is v1,v2,mode,v1+,v2+ for the velocity map of a
# two-coordinate model, or rate_i,rate_j,mode,rate_i+,rate_j+ for `--closed` (the
# approach velocities E_i v, E_j v of constraints i and j, 0-based). Regions are coloured
# by the mode Moreau's rule selects; arrows on a coarser subgrid go from the pre- to the
# post-impact velocity; a legend names each region's colour and the arrows.

def impact_map(csv_map, output, title="Moreau impact map", arrows=11):
    """Draws an impact map: `csv_map` is the CSV text lcsim.impact_map returns (or
    `lcsim impacts --map` prints), or the path of such a file."""
    text = csv_map if "\n" in str(csv_map) else open(csv_map, newline="").read()
    rows = list(csv.DictReader(io.StringIO(text)))
    if not rows:
        raise ValueError("impact map: no rows")
    cols = list(rows[0].keys())
    if len(cols) != 5 or cols[2] != "mode":
        raise ValueError(f"impact map: expected 5 columns with 'mode' third, got {cols}")
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
    s1 = max(1, (n1 - 1) // max(arrows - 1, 1))
    s2 = max(1, (n2 - 1) // max(arrows - 1, 1))
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
    ax.set_title(title, fontsize=9, wrap=True)
    ax.set_aspect("equal")
    fig.tight_layout()
    fig.savefig(output, bbox_inches="tight")
    plt.close(fig)


# ---- The work-precision diagram (`lcsim sweep MODEL ... --json`) ---------------------
#
# {"rows": [{"method", "h", "error_final", "error_max", ..., "wall_time_s", "status",
# "reference_law", "warnings"}]}. One line per time-stepping method: error (against the
# exact event-driven run of its reference law, named in the legend) versus wall time,
# log-log, each point labelled with its step h; a point whose run warned is ringed. The
# event-driven run is exact: a vertical line at its wall time. Rows that failed or were
# refused have no error: crosses on a band at the top of the axes, listed in the legend.
# The merged tables of bench/run_work_precision.sh add optional keys per row: "tool"
# ("lcsim" when absent; others drawn dashed), "label" (rows with the same label form one
# line; default: the method) and "time_s" (the time to plot; default: wall_time_s).


def r_tool(r):
    """The tool a sweep row comes from ("lcsim" unless the row names another)."""
    return r.get("tool", "lcsim")


def work_precision(sweep, output, title="", error="max"):
    """Draws the work-precision diagram of a sweep: `sweep` is the dict lcsim.sweep
    returns (or `lcsim sweep --json` prints), or the path of such a JSON file; `error`
    is "max" (over the whole run: the default, since a damped run at rest by t_end
    hides its errors from the final state), "events" or "final". A sweep asked for
    sensitivities (rows with "error_gradient") gets a second panel beside it: the
    error of dx(T)/dtheta against the exact derivative, on the same time axis (the
    speed-accuracy trade of a gradient, docs/sensitivities.md). Returns the row keys
    drawn, one per panel."""
    if isinstance(sweep, dict):
        data = sweep
    else:
        with open(sweep) as f:
            data = json.load(f)
    keys = ["error_" + error]
    if any("error_gradient" in r for r in data["rows"]):
        keys.append("error_gradient")
    methods = {}
    for r in data["rows"]:
        methods.setdefault(r.get("label", r["method"]), []).append(r)
    fig, axes = plt.subplots(1, len(keys), figsize=(7.6 * len(keys), 5.0), squeeze=False)
    title = title or data.get("model", "")
    for ax, key in zip(axes[0], keys):
        _work_precision_panel(ax, data, methods, key)
        what = "gradient" if key == "error_gradient" else "work-precision"
        ax.set_title(f"{title}: {what}" if title else what, fontsize=10)
    fig.tight_layout()
    fig.savefig(output, dpi=120, bbox_inches="tight")
    plt.close(fig)
    return keys


def _time_of(r):
    t = r.get("time_s", r.get("wall_time_s"))
    return t if t is not None else float("nan")


def _work_precision_lines(ax, methods, key):
    """One line per time-stepping method (key against time); the exact run a vertical
    line. Returns the finite points drawn and the rows that failed or were refused."""
    markers = iter("os^vD<>phHd8*")
    finite_pts, bad_rows = [], []
    for method, rows in methods.items():
        if rows[0]["method"] == "event":
            t = _time_of(rows[0])
            if t > 0:
                ax.axvline(t, color="k", ls=":", lw=1,
                           label=f"{method} (exact, {rows[0].get('reference_law', '')})")
            continue
        bad_rows += [r for r in rows if r.get("status", "completed") != "completed"]
        pts = [(_time_of(r), r.get(key), r["h"], r.get("warnings", 0)) for r in rows
               if r.get("status", "completed") == "completed"
               and r.get(key) is not None and math.isfinite(r[key]) and r[key] > 0
               and _time_of(r) > 0]
        if not pts:
            continue
        pts.sort()
        finite_pts += pts
        dashed = r_tool(rows[0]) != "lcsim"
        ref = rows[0].get("reference_law")
        label = f"{method} vs {ref}" if ref else method
        if any(r.get("error_floor") for r in rows):
            # The run integrates other dynamics than the exact run (Bullet's
            # nonlinear multibody against the linear model): a floor, not a step error.
            label += " (floor: linearisation gap)"
        line, = ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker=next(markers, "o"),
                          ls="--" if dashed else "-", mfc="none" if dashed else None,
                          label=label)
        warned = [p for p in pts if p[3]]
        if warned:
            ax.loglog([p[0] for p in warned], [p[1] for p in warned], ls="none", marker="o",
                      ms=12, mfc="none", mec=line.get_color(), mew=0.8)
        for t, e, h, _ in pts:
            ax.annotate(f"h={h:g}", (t, e), textcoords="offset points", xytext=(4, 4),
                        fontsize=7)
    return finite_pts, bad_rows


def _work_precision_failures(ax, bad_rows):
    """Rows that failed or were refused have no error: crosses on a band at the top
    (x in data coordinates, or the left edge; one height per row so labels do not
    overlap)."""
    lo, _ = ax.get_xlim()
    height = iter(0.96 - 0.05 * i for i in range(len(bad_rows)))
    for kind, mk, col in (("failed", "x", "tab:red"), ("refused", "X", "tab:purple")):
        sel = [r for r in bad_rows if r["status"].startswith(kind)]
        if not sel:
            continue
        xs = [_time_of(r) if _time_of(r) > 0 else lo * 1.3 for r in sel]
        ys = [next(height) for _ in sel]
        ax.plot(xs, ys, ls="none", marker=mk, ms=9, color=col,
                transform=ax.get_xaxis_transform(), clip_on=False,
                label=f"{kind} (no error): " + ", ".join(
                    f"{r['method']} h={r['h']:g}" for r in sel))
        for x, y, r in zip(xs, ys, sel):
            ax.annotate(f"{r['method']} h={r['h']:g} {kind}", (x, y),
                        xycoords=("data", "axes fraction"), textcoords="offset points",
                        xytext=(7, -3), fontsize=7, color=col)


def _work_precision_panel(ax, data, methods, key):
    """One panel of the diagram: `key` of each row against its time."""
    finite_pts, bad_rows = _work_precision_lines(ax, methods, key)
    times = [p[0] for p in finite_pts] + [_time_of(r) for rows in methods.values()
                                           for r in rows if _time_of(r) > 0]
    if times:  # at least a decade wide, so the log axis has labelled ticks
        lo, hi = min(times) / 3, max(times) * 3
        mid = math.sqrt(lo * hi)
        ax.set_xscale("log")
        ax.set_xlim(min(lo, mid / 10), max(hi, mid * 10))
    ax.set_yscale("log")
    if finite_pts:
        es = [p[1] for p in finite_pts]
        ax.set_ylim(min(es) / 5, max(es) * 20)
    else:
        ax.set_ylim(1e-12, 1.0)
        ax.text(0.5, 0.5, "no completed row: no error to plot", transform=ax.transAxes,
                ha="center", va="center", fontsize=9, color="0.4")
    if any(r.get("warnings", 0) for rows in methods.values() for r in rows
           if r["method"] != "event"):
        ax.plot([], [], ls="none", marker="o", ms=10, mfc="none", mec="0.3",
                label="ringed: the run warned")
    if bad_rows:
        _work_precision_failures(ax, bad_rows)
    merged = any("tool" in r for r in data["rows"])
    ax.set_xlabel("time per run (s, median; lcsim wall, Siconos loop CPU)" if merged
                  else "wall time per run (s, median)")
    if key == "error_gradient":
        ax.set_ylabel("dx(T)/dtheta error (max abs) vs the exact derivative")
    else:
        ax.set_ylabel(f"{key[len('error_'):]} state error (max abs) vs exact run")
    ax.grid(True, which="both", ls=":", lw=0.5)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)


# ---- The cart chain's timing (bench/run_chain_bench.sh) ------------------------------


def chain(src, png):
    """Time per step against N for the cart chain: a log-log plot of microseconds per
    step, one line per tool/solver/window, and on stdout the table and the ratios
    against the targets (lcsim Moreau-Jean slope <= 1.1 from N = 100 to 10000, N = 10000
    in <= 2 ms per step, at N = 100 at least 50x faster than Siconos per step)."""
    with open(src, newline="") as f:
        rows = list(csv.DictReader(f))
    series = {}
    print(f"{'tool':8} {'solver':20} {'N':>6} {'window':10} {'us/step':>12} {'peak MB':>9}")
    for r in rows:
        us = float(r["us_per_step"]) if r["us_per_step"] not in ("", "nan") else math.nan
        rss = float(r["peak_rss_kb"]) / 1024 if r["peak_rss_kb"] else math.nan
        print(f"{r['tool']:8} {r['solver']:20} {int(r['N']):>6} {r['window']:10} "
              f"{us:>12.4g} {rss:>9.0f}")
        if r["window"] in ("free", "impacts") and not math.isnan(us):
            series.setdefault((r["tool"], r["solver"], r["window"]), []).append((int(r["N"]), us))

    def at(tool, solver, window, n):
        return dict(series.get((tool, solver, window), [])).get(n, math.nan)

    print()
    for window in ("free", "impacts"):
        a, b = at("lcsim", "moreau-jean", window, 100), at("lcsim", "moreau-jean", window, 10000)
        slope = math.log(b / a) / math.log(100.0) if a > 0 and b > 0 else math.nan
        print(f"lcsim {window:8}: slope N=100..10000 = {slope:.3f} (target <= 1.1); "
              f"N=10000: {b / 1000:.3f} ms/step (target <= 2)")
        for solver in ("lemke", "pgs"):
            s = at("siconos", solver, window, 100)
            print(f"  N=100 Siconos {solver} / lcsim = {s / a:.1f}x (target >= 50)")
        bu = at("bullet", "sequential-impulse", window, 100)
        print(f"  N=100 Bullet / lcsim = {bu / a:.1f}x")

    fig, ax = plt.subplots(figsize=(7, 5))
    for (tool, solver, window), pts in sorted(series.items()):
        pts.sort()
        ax.loglog([p[0] for p in pts], [p[1] for p in pts],
                  marker="o", linestyle="-" if window == "impacts" else "--",
                  label=f"{tool} {solver} ({window})")
    ns = [10, 10000]
    ax.loglog(ns, [0.05 * n for n in ns], color="grey", linewidth=0.8, label="slope 1")
    ax.set_xlabel("carts N")
    ax.set_ylabel("time per step (µs)")
    ax.set_title("Cart chain with stops, h = 1e-3: time per step")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png, dpi=120)
    plt.close(fig)
    print(f"\nwrote {png}")


def main(argv=None):
    """The command line: `python3 -m lcsim.plot KIND ...` (see the module's doc)."""
    ap = argparse.ArgumentParser(prog="lcsim.plot", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="kind", required=True)
    t = sub.add_parser("trajectory", help="a trajectory CSV (Figure 3.3 style)")
    t.add_argument("csv")
    t.add_argument("output_pos", nargs="?", help="output image (or -o)")
    t.add_argument("-o", "--output", help="output image (png, pdf, svg)")
    t.add_argument("--events", help="lcsim JSON run summary with an 'events' list")
    t.add_argument("--title")
    t.add_argument("--gaps", action="store_true", help="add a panel with the gaps y")
    m = sub.add_parser("impact-map", help="an impact map CSV (Figure 3.5)")
    m.add_argument("csv")
    m.add_argument("png")
    m.add_argument("--title", default="Moreau impact map")
    m.add_argument("--arrows", type=int, default=11, help="arrows per axis")
    w = sub.add_parser("work-precision", help="a sweep's JSON")
    w.add_argument("json")
    w.add_argument("png")
    w.add_argument("--title", default="")
    w.add_argument("--error", choices=["max", "events", "final"], default="max")
    c = sub.add_parser("chain", help="the cart chain's results CSV")
    c.add_argument("csv")
    c.add_argument("png")
    a = ap.parse_args(argv)
    try:
        if a.kind == "trajectory":
            output = a.output or a.output_pos
            if not output:
                ap.error("trajectory: give the output image (-o)")
            trajectory(a.csv, output, events=a.events, title=a.title, gaps=a.gaps)
        elif a.kind == "impact-map":
            impact_map(a.csv, a.png, title=a.title, arrows=a.arrows)
        elif a.kind == "work-precision":
            work_precision(a.json, a.png, title=a.title, error=a.error)
        else:
            chain(a.csv, a.png)
    except (OSError, ValueError, KeyError, TrajectoryError) as e:
        print(f"lcsim.plot {a.kind}: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
