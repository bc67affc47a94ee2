#!/usr/bin/python3
"""Draw the work-precision diagram from `lcsim sweep MODEL ... --json`.

Usage: plot_work_precision.py SWEEP.json OUT.png [--title TEXT] [--error final|max]

SWEEP.json is {"rows": [{"method", "h", "error_final", "error_max", ...,
"wall_time_s"}]}. One line per time-stepping method: error (against the exact
event-driven solution) versus wall time, log-log, each point labelled with its
step h. The event-driven run is exact, so it is drawn as a vertical line at its
wall time. Agg backend: no display needed.

The merged tables of bench/run_work_precision.sh use the same format with
optional keys per row: "tool" ("lcsim" when absent; other tools, e.g.
"siconos", are drawn dashed), "label" (the line's legend, rows with the same
label form one line; default: the method) and "time_s" (the time to plot;
default: wall_time_s). The x-axis is then the time per run of each row
(lcsim: wall time; Siconos: CPU time of its loop).
"""
import argparse
import json
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def r_tool(r):
    return r.get("tool", "lcsim")


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
        methods.setdefault(r.get("label", r["method"]), []).append(r)

    def time_of(r):
        t = r.get("time_s", r.get("wall_time_s"))
        return t if t is not None else float("nan")

    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    markers = iter("os^vD<>phHd8*")
    for method, rows in methods.items():
        if rows[0]["method"] == "event":
            t = time_of(rows[0])
            if t > 0:
                ax.axvline(t, color="k", ls=":", lw=1, label=f"{method} (exact)")
            continue
        pts = [(time_of(r), r.get(key), r["h"]) for r in rows
               if r.get(key) is not None and math.isfinite(r[key]) and r[key] > 0
               and time_of(r) > 0]
        if not pts:
            continue
        pts.sort()
        dashed = r_tool(rows[0]) != "lcsim"
        ax.loglog([p[0] for p in pts], [p[1] for p in pts], marker=next(markers, "o"),
                  ls="--" if dashed else "-", mfc="none" if dashed else None,
                  label=method)
        for t, e, h in pts:
            ax.annotate(f"h={h:g}", (t, e), textcoords="offset points", xytext=(4, 4),
                        fontsize=7)
    merged = any("tool" in r for r in data["rows"])
    ax.set_xlabel("time per run (s, median; lcsim wall, Siconos loop CPU)" if merged
                  else "wall time per run (s, median)")
    ax.set_ylabel(f"{a.error} state error (max abs) vs exact")
    title = a.title or data.get("model", "")
    ax.set_title(f"{title}: work-precision" if title else "work-precision")
    ax.grid(True, which="both", ls=":", lw=0.5)
    ax.legend(fontsize=7 if len(methods) > 6 else None)
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)


if __name__ == "__main__":
    main()
