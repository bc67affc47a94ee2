#!/usr/bin/env bash
# The §3.7 two-carts run to T = 3: lcsim's exact event-driven simulation next
# to Siconos's event-driven simulation (LsodarOSI + EventDriven), same script,
# same machine. Usage: bench/run_event_bench.sh [build-dir]
set -euo pipefail
build=${1:-build}
echo "== lcsim event-driven (CPU time of the simulation; Arg 0 = no output samples)"
"$build/bench/bench_event_driven" --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true --benchmark_counters_tabular=true
if [ -x "$build/bench/peer_siconos_two_carts" ]; then
  echo "== Siconos 4.4 event-driven and Moreau–Jean on the same run (method param error_final cpu_s steps ...)"
  "$build/bench/peer_siconos_two_carts" 2>/dev/null
else
  echo "Siconos peer not built (apt-get install libsiconos-kernel-dev)"
fi
