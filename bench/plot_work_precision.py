#!/usr/bin/python3
"""Draw the work-precision diagram from `lcsim sweep MODEL ... --json`.

Usage: plot_work_precision.py SWEEP.json OUT.png [--title TEXT] [--error final|max]

SWEEP.json is {"rows": [{"method", "h", "error_final", "error_max", ...,
"wall_time_s", "status", "reference_law", "warnings"}]}. One line per
time-stepping method: error (against the exact event-driven run of its
reference law, named in the legend) versus wall time, log-log, each point
labelled with its step h; a point whose run warned is ringed. The event-driven
run is exact, so it is drawn as a vertical line at its wall time. Rows that
failed or were refused (status not "completed") have no error: they are drawn
as crosses on a band at the top of the axes, at their h's place on the time
axis if they have a time, else at the left edge, and listed in the legend with
their status. The axes are fitted to the finite data with a margin. Agg
backend: no display needed.

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

    fig, ax = plt.subplots(figsize=(7.6, 5.0))
    markers = iter("os^vD<>phHd8*")
    finite_pts, bad_rows = [], []
    for method, rows in methods.items():
        if rows[0]["method"] == "event":
            t = time_of(rows[0])
            if t > 0:
                ax.axvline(t, color="k", ls=":", lw=1,
                           label=f"{method} (exact, {rows[0].get('reference_law', '')})")
            continue
        bad_rows += [r for r in rows if r.get("status", "completed") != "completed"]
        pts = [(time_of(r), r.get(key), r["h"], r.get("warnings", 0)) for r in rows
               if r.get("status", "completed") == "completed"
               and r.get(key) is not None and math.isfinite(r[key]) and r[key] > 0
               and time_of(r) > 0]
        if not pts:
            continue
        pts.sort()
        finite_pts += pts
        dashed = r_tool(rows[0]) != "lcsim"
        ref = rows[0].get("reference_law")
        label = f"{method} vs {ref}" if ref else method
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
    times = [p[0] for p in finite_pts] + [time_of(r) for rows in methods.values()
                                           for r in rows if time_of(r) > 0]
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
        # A band at the top: x in data coordinates (or the left edge), y in
        # axes fraction, one height per row so labels do not overlap.
        lo, _ = ax.get_xlim()
        height = iter(0.96 - 0.05 * i for i in range(len(bad_rows)))
        for kind, mk, col in (("failed", "x", "tab:red"), ("refused", "X", "tab:purple")):
            sel = [r for r in bad_rows if r["status"].startswith(kind)]
            if not sel:
                continue
            xs = [time_of(r) if time_of(r) > 0 else lo * 1.3 for r in sel]
            ys = [next(height) for _ in sel]
            ax.plot(xs, ys, ls="none", marker=mk, ms=9, color=col,
                    transform=ax.get_xaxis_transform(), clip_on=False,
                    label=f"{kind} (no error): " + ", ".join(
                        f"{r['method']} h={r['h']:g}" for r in sel))
            for x, y, r in zip(xs, ys, sel):
                ax.annotate(f"{r['method']} h={r['h']:g} {kind}", (x, y),
                            xycoords=("data", "axes fraction"), textcoords="offset points",
                            xytext=(7, -3), fontsize=7, color=col)
    merged = any("tool" in r for r in data["rows"])
    ax.set_xlabel("time per run (s, median; lcsim wall, Siconos loop CPU)" if merged
                  else "wall time per run (s, median)")
    ax.set_ylabel(f"{a.error} state error (max abs) vs exact run")
    title = a.title or data.get("model", "")
    ax.set_title(f"{title}: work-precision" if title else "work-precision", fontsize=10)
    ax.grid(True, which="both", ls=":", lw=0.5)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    fig.tight_layout()
    fig.savefig(a.png, dpi=120, bbox_inches="tight")


if __name__ == "__main__":
    main()
