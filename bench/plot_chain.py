#!/usr/bin/python3
"""Time per step against N for the cart chain (bench/run_chain_bench.sh).

Usage: plot_chain.py results.csv chain.png
Draws a log-log plot (Agg) of microseconds per step against N, one line per
tool/solver/window, prints the table and the ratios against the targets:
lcsim Moreau-Jean slope <= 1.1 from N = 100 to 10000, N = 10000 in <= 2 ms per
step, and at N = 100 at least 50x faster than Siconos per step.
"""
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    src, png = sys.argv[1], sys.argv[2]
    rows = list(csv.DictReader(open(src)))
    series = {}
    print(f"{'tool':8} {'solver':20} {'N':>6} {'window':10} {'us/step':>12} {'peak MB':>9}")
    for r in rows:
        us = float(r["us_per_step"]) if r["us_per_step"] not in ("", "nan") else math.nan
        rss = float(r["peak_rss_kb"]) / 1024 if r["peak_rss_kb"] else math.nan
        print(f"{r['tool']:8} {r['solver']:20} {int(r['N']):>6} {r['window']:10} {us:>12.4g} {rss:>9.0f}")
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
    print(f"\nwrote {png}")


if __name__ == "__main__":
    main()
