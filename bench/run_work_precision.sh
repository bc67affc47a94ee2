#!/usr/bin/env bash
# Work-precision of the time-stepping schemes against the exact event-driven
# run: backward Euler (Algorithm 7.3.1) and Moreau–Jean (theta = 1/2) at
# h = 1e-2 ... 1e-5 on the two-carts run (§3.7) and the hook run (Example
# 3.8.3). Writes out/work_precision_<model>.json and .png.
# Usage: bench/run_work_precision.sh [build-dir] [repeat]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
repeat=${2:-5}
mkdir -p out
for model in two_carts two_carts_hook; do
  "$build/lcsim" sweep "robots/$model.yaml" --methods event,euler,moreau-jean \
    --h 1e-2,1e-3,1e-4,1e-5 --repeat "$repeat" --json \
    --plot "out/work_precision_$model.png" > "out/work_precision_$model.json"
  echo "== $model: out/work_precision_$model.json, out/work_precision_$model.png"
  /usr/bin/python3 - "out/work_precision_$model.json" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
print(f"{'method':12} {'h':>7} {'err_final':>10} {'err_max':>10} {'violation':>10} "
      f"{'E_drift':>10} {'steps':>7} {'lcp':>7} {'wall_s':>9}")
for r in d["rows"]:
    h = "-" if r["h"] is None else f"{r['h']:g}"
    print(f"{r['method']:12} {h:>7} {r['error_final']:10.3e} {r['error_max']:10.3e} "
          f"{r['max_violation']:10.3e} {r['energy_drift']:10.3e} {r['steps']:7d} "
          f"{r['lcp_solves']:7d} {r['wall_time_s']:9.3e}")
PY
done
