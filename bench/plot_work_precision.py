#!/usr/bin/python3
"""Draw the work-precision diagram from `lcsim sweep MODEL ... --json`.

Usage: plot_work_precision.py SWEEP.json OUT.png [--title TEXT] [--error final|max]

SWEEP.json is {"rows": [{"method", "h", "error_final", "error_max", ...,
"wall_time_s"}]}. One line per time-stepping method: error (against the exact
event-driven solution) versus wall time, log-log, each point labelled with its
step h. The event-driven run is exact, so it is drawn as a vertical line at its
wall time. Agg backend: no display needed.
"""
import argparse
import json
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("json")
    ap.add_argument("png")
    ap.add_argument("--title", default="")
    ap.add_argument("--error", choices=["final", "max"], default="final")
    a = ap.parse_args()

    with open(a.json) as f:
        data = json.load(f)
    key = "error_" + a.error
    methods = {}
    for r in data["rows"]:
        methods.setdefault(r["method"], []).append(r)

    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    markers = iter("os^vD<>")
    for method, rows in methods.items():
        if method == "event":
            t = rows[0]["wall_time_s"]
            if t > 0:
                ax.axvline(t, color="k", ls="--", lw=1, label="event (exact)")
            continue
        pts = [(r["wall_time_s"], r[key], r["h"]) for r in rows
               if r[key] is not None and math.isfinite(r[key]) and r[key] > 0
               and r["wall_time_s"] > 0]
        if not pts:
            continue
        pts.sort()
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker=next(markers, "o"),
                  label=method)
        for t, e, h in pts:
            ax.annotate(f"h={h:g}", (t, e), textcoords="offset points", xytext=(4, 4),
                        fontsize=7)
    ax.set_xlabel("wall time per run (s, median)")
    ax.set_ylabel(f"{a.error} state error (max abs) vs exact")
    title = a.title or data.get("model", "")
    ax.set_title(f"{title}: work-precision" if title else "work-precision")
    ax.grid(True, which="both", ls=":", lw=0.5)
    ax.legend()
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)


if __name__ == "__main__":
    main()
