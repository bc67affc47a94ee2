#!/usr/bin/python3
"""Plot an lcsim trajectory like Figure 3.3 of the thesis (two carts, §3.7).

Stacked panels against time: positions, velocities and constraint forces u (and, with
--gaps, the gaps y); events from lcsim's JSON summary are drawn as vertical dashed lines
labelled with their type.

    /usr/bin/python3 bench/plot_trajectory.py traj.csv -o traj.png \
        [--events run.json] [--title "two carts"] [--gaps]

Input: lcsim's trajectory CSV (src/io/writers.cpp). Header: ``t``; the state, either the
coordinate names followed by ``v_<name>`` for each (mechanical models) or ``x1..xn``
(general LCS); ``u_<constraint>``... or ``u1..uk``; ``y_<constraint>``... or ``y1..yk``;
``mode`` (active constraint indices joined by ';'). At a jump two rows share the same t
(before, after), so a jump shows as a vertical segment. Blank cells (e.g. no u at an
event-only row) are left out of the lines.

The JSON summary (--events) is lcsim's run summary; its key ``events`` is a list of
objects with at least ``t`` and ``type`` (impact, release, contact, accumulation, start).
Events of type ``start`` are not drawn.

Uses the Agg backend (no display needed); the output format follows the extension of -o
(png, pdf, svg).
"""

import argparse
import csv
import json
import math
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (the backend must be chosen first)


class TrajectoryError(Exception):
    """A CSV or JSON input that does not have the expected layout."""


def _number(cell, path, row, column):
    cell = cell.strip()
    if cell == "":
        return math.nan
    try:
        return float(cell)
    except ValueError:
        raise TrajectoryError(
            f"{path}: row {row}, column '{column}': '{cell}' is not a number") from None


def split_columns(header):
    """Split the header into (kind, position, velocity, force, gap) column-index lists.

    kind is 'mechanical' (positions and velocities) or 'lcs' (one list of states, returned
    as the position list, velocities empty).
    """
    if len(header) < 3 or header[0] != "t" or header[-1] != "mode":
        raise TrajectoryError("header must start with 't' and end with 'mode', got "
                              f"{header[:2]}...{header[-1:]}")
    body = list(range(1, len(header) - 1))
    names = header[1:-1]
    # Mechanical: the first n names are coordinates, the next n are v_<coordinate>.
    for n in range(1, len(names) // 2 + 1):
        if names[n:2 * n] == ["v_" + c for c in names[:n]]:
            rest = body[2 * n:]
            if len(rest) % 2 != 0:
                raise TrajectoryError(f"after {n} coordinates and their velocities, "
                                      f"{len(rest)} columns remain; expected u_ and y_ pairs")
            k = len(rest) // 2
            return "mechanical", body[:n], body[n:2 * n], rest[:k], rest[k:]
    # General LCS: x1..xn, u1..uk, y1..yk.
    n = 0
    while n < len(names) and re.fullmatch(r"x\d+", names[n]):
        n += 1
    rest = body[n:]
    if n == 0 or len(rest) % 2 != 0:
        raise TrajectoryError("cannot recognise the state columns: expected coordinates "
                              "followed by v_<coordinate>, or x1..xn")
    k = len(rest) // 2
    return "lcs", body[:n], [], rest[:k], rest[k:]


def read_trajectory(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise TrajectoryError(f"{path}: empty file")
    header = [h.strip() for h in rows[0]]
    try:
        layout = split_columns(header)
    except TrajectoryError as e:
        raise TrajectoryError(f"{path}: {e}") from None
    data = {name: [] for name in header[:-1]}
    modes = []
    for r, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != len(header):
            raise TrajectoryError(f"{path}: row {r} has {len(row)} cells, header has "
                                  f"{len(header)}")
        for j, name in enumerate(header[:-1]):
            data[name].append(_number(row[j], path, r, name))
        modes.append(row[-1].strip())
    if not modes:
        raise TrajectoryError(f"{path}: no samples after the header")
    return header, layout, data, modes


def read_events(path):
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


def plot(header, layout, data, events, title, with_gaps, output):
    kind, pos, vel, force, gap = layout
    t = data["t"]
    panels = []
    if kind == "mechanical":
        panels.append(("position", pos))
        panels.append(("velocity", vel))
    else:
        panels.append(("state x", pos))
    if force:
        panels.append(("force u", force))
    if with_gaps and gap:
        panels.append(("gap y", gap))

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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("csv", help="lcsim trajectory CSV")
    parser.add_argument("-o", "--output", required=True, help="output image (png, pdf, svg)")
    parser.add_argument("--events", help="lcsim JSON run summary with an 'events' list")
    parser.add_argument("--title", help="figure title")
    parser.add_argument("--gaps", action="store_true", help="add a panel with the gaps y")
    args = parser.parse_args(argv)
    try:
        header, layout, data, _modes = read_trajectory(args.csv)
        events = read_events(args.events) if args.events else []
        plot(header, layout, data, events, args.title, args.gaps, args.output)
    except (OSError, TrajectoryError) as e:
        print(f"plot_trajectory: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
