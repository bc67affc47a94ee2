#!/usr/bin/env bash
# The cart chain (lcsim generate chain N --stops; x_i = 0.1 (i mod 3), v_i = -1,
# h = 1e-3, theta = 0.5) timed per step for lcsim's Moreau–Jean, Bullet (rb6)
# and Siconos (MoreauJeanOSI, Lemke and PGS), with the peak memory of each
# process (/usr/bin/time -v: Debian package `time`). Writes
# out/chain/results.csv (tool, solver, N, window, us_per_step, peak_rss_kb) and
# out/chain/chain.png (python/lcsim/plot.py chain), and prints the table and ratios.
#
# Also the whole command line on the generated file (`lcsim generate chain N
# --stops`, then `lcsim simulate` with Moreau–Jean for 200 steps): file size,
# wall time and peak memory of loading and simulating (rows tool = lcsim-cli,
# window = file: us_per_step is the whole run's wall time / 200).
#
# Usage: bench/run_chain_bench.sh [BUILD_DIR]   (default: build)
#   LCSIM_CHAIN_N="10 100 1000 10000"  lcsim and Bullet sizes
#   SICONOS_CHAIN_N="10 100"           Siconos sizes (N = 100 with Lemke takes
#                                       about a minute; N = 1000 hours)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
OUT=out/chain
mkdir -p "$OUT"
if [ ! -x /usr/bin/time ]; then
  echo "run_chain_bench: /usr/bin/time missing: apt-get install time" >&2
  exit 2
fi
LCSIM_N=${LCSIM_CHAIN_N:-"10 100 1000 10000"}
SICONOS_N=${SICONOS_CHAIN_N:-"10 100"}
CSV=$OUT/results.csv
echo "tool,solver,N,window,us_per_step,peak_rss_kb" >"$CSV"

peak_kb() { sed -n 's/.*Maximum resident set size (kbytes): //p' "$1"; }

# Google Benchmark JSON -> CSV rows: tool, solver, N, window, us per step, peak RSS.
gb_rows() {  # json, tool, solver, rss
  /usr/bin/python3 - "$@" <<'PY' >>"$CSV"
import json, sys
path, tool, solver, rss = sys.argv[1:5]
for b in json.load(open(path))["benchmarks"]:
    name = b["name"].split("/")[0]
    if "Setup" in name:
        window = "setup"
    elif "Event" in name:
        window = "per_event"
        if "refused" in b.get("label", ""):
            print(f"{tool},event-driven,{int(b['N'])},refused,nan,{rss}")
            continue
    else:
        window = "impacts" if "Impacts" in name else "free"
    scale = {"ns": 1e-3, "us": 1.0, "ms": 1e3, "s": 1e6}[b["time_unit"]]
    s = "event-driven" if window == "per_event" else solver
    print(f"{tool},{s},{int(b['N'])},{window},{b['real_time'] * scale:.6g},{rss}")
PY
}

for n in $LCSIM_N; do
  echo "lcsim moreau-jean N=$n" >&2
  /usr/bin/time -v -o "$OUT/time_lcsim_$n.txt" "$BUILD/bench/bench_chain" \
    --benchmark_filter="MoreauJean.*/$n/" --benchmark_format=json >"$OUT/lcsim_$n.json"
  gb_rows "$OUT/lcsim_$n.json" lcsim moreau-jean "$(peak_kb "$OUT/time_lcsim_$n.txt")"
  echo "bullet rb6 N=$n" >&2
  /usr/bin/time -v -o "$OUT/time_bullet_$n.txt" "$BUILD/bench/bench_chain" \
    --benchmark_filter="Bullet.*/$n/" --benchmark_format=json >"$OUT/bullet_$n.json"
  gb_rows "$OUT/bullet_$n.json" bullet sequential-impulse "$(peak_kb "$OUT/time_bullet_$n.txt")"
  echo "lcsim command line N=$n" >&2
  "$BUILD/lcsim" generate chain "$n" --stops --out "$OUT/chain_$n.yaml"
  start=$(date +%s.%N)
  /usr/bin/time -v -o "$OUT/time_cli_$n.txt" "$BUILD/lcsim" simulate "$OUT/chain_$n.yaml" \
    --method moreau-jean --h 1e-3 --theta 0.5 --t-end 0.2 --json >/dev/null
  wall=$(/usr/bin/python3 -c "print(f'{$(date +%s.%N) - $start:.3f}')")
  us=$(/usr/bin/python3 -c "print(f'{$wall * 1e6 / 200:.6g}')")
  echo "lcsim-cli,moreau-jean,$n,file,$us,$(peak_kb "$OUT/time_cli_$n.txt")" >>"$CSV"
  echo "  file $(stat -c %s "$OUT/chain_$n.yaml") bytes, ${wall}s, peak $(peak_kb "$OUT/time_cli_$n.txt") kB" >&2
done
for n in 10 100 300 500 1000; do
  echo "lcsim event-driven N=$n" >&2
  /usr/bin/time -v -o "$OUT/time_event_$n.txt" "$BUILD/bench/bench_chain" \
    --benchmark_filter="EventDriven.*/$n/" --benchmark_format=json >"$OUT/event_$n.json"
  gb_rows "$OUT/event_$n.json" lcsim event-driven "$(peak_kb "$OUT/time_event_$n.txt")"
done
if [ -x "$BUILD/bench/peer_siconos_chain" ]; then
  for solver in lemke pgs; do
    for n in $SICONOS_N; do
      echo "siconos $solver N=$n" >&2
      line=$(/usr/bin/time -v -o "$OUT/time_siconos_${solver}_$n.txt" \
        "$BUILD/bench/peer_siconos_chain" "$n" "$solver")
      echo "$line" >&2
      rss=$(peak_kb "$OUT/time_siconos_${solver}_$n.txt")
      free=$(sed -n 's/.*free_us_per_step=\([^ ]*\).*/\1/p' <<<"$line")
      imp=$(sed -n 's/.*impacts_us_per_step=\([^ ]*\).*/\1/p' <<<"$line")
      echo "siconos,$solver,$n,free,$free,$rss" >>"$CSV"
      echo "siconos,$solver,$n,impacts,$imp,$rss" >>"$CSV"
    done
  done
else
  echo "run_chain_bench: $BUILD/bench/peer_siconos_chain not built (Siconos missing): skipped" >&2
fi
/usr/bin/python3 python/lcsim/plot.py chain "$CSV" "$OUT/chain.png"
