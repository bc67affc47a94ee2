#!/usr/bin/env bash
# Snapshot of every output a refactoring must keep byte for byte (the house
# issue): for each shipped model and scene in robots/, `simulate --json` (less
# wall_time_s), the CSV of `simulate --out`, `analyze` (text, --json, --json --full; less timings),
# for each method that accepts the model, and `impacts --json` at the model's
# initial state where it is mechanical; for each shipped circuit in
# circuits/, `analyze` and `simulate` (JSON and CSV) with each method.
#
#   tests/house/snapshot_outputs.sh LCSIM_BINARY OUT_DIR     # one snapshot
#   diff -r OUT_BEFORE OUT_AFTER                             # compare two
#
# A command that refuses a model (exit 2) or fails (exit 3) is recorded with
# its exit status and its message, so a change in what is refused shows too.
set -uo pipefail
bin=$(realpath "$1")
out=$2
src=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"
source "$src/tests/house/snapshot_lib.sh"  # strip_timing, run
cd "$src"
for model in robots/*.yaml; do
  m=$(basename "$model" .yaml)
  [ "$m" = lcp_example ] && { run "$m.lcp.json" "$bin" lcp "$model" --json; continue; }
  run "$m.analyze.json" "$bin" analyze "$model" --json
  run "$m.analyze.full.json" "$bin" analyze "$model" --json --full
  run "$m.analyze.txt" "$bin" analyze "$model"
  run "$m.impacts.json" "$bin" impacts "$model" --json
  run "$m.impacts.txt" "$bin" impacts "$model"
  for method in event euler moreau-jean bullet; do
    run "$m.$method.json" "$bin" simulate "$model" --method "$method" --json --no-progress
    run "$m.$method.txt" "$bin" simulate "$model" --method "$method" --out "$out/$m.$method.csv" \
      --no-progress
  done
done
# The shipped circuits (SPICE netlists, docs/circuits.md): analyze, and each
# time-stepping method beside the exact one (a method that refuses a
# netlist's inputs is recorded with its message).
for netlist in circuits/*.cir; do
  c=$(basename "$netlist" .cir)
  run "$c.cir.analyze.json" "$bin" analyze "$netlist" --json
  run "$c.cir.analyze.txt" "$bin" analyze "$netlist"
  for method in event euler moreau-jean; do
    run "$c.cir.$method.json" "$bin" simulate "$netlist" --method "$method" --json --no-progress
    run "$c.cir.$method.txt" "$bin" simulate "$netlist" --method "$method" \
      --out "$out/$c.cir.$method.csv" --no-progress
  done
done
echo "snapshot_outputs: $(ls "$out" | wc -l) files in $out"
