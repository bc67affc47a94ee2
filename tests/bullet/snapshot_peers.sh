#!/usr/bin/env bash
# Snapshot of every peer run (Bullet, MuJoCo) the project ships, for a
# refactoring of src/bullet or src/mujoco that must keep the peers' behaviour
# byte for byte: for each model
# and scene in robots/ (lcp_example is an LCP, not a model), `simulate
# --method bullet` (JSON less wall_time_s, and the CSV of --out) and `compare
# --peer bullet` (JSON less timings, and the peer's samples of --peer-out) with
# each of Bullet's friction models (cone, box, one-direction), and once more
# with stop ERP 1 and 20 solver iterations (the rb6 limits' and the solvers'
# settings); `compare --peer mujoco` with each of MuJoCo's cones (pyramidal,
# elliptic). examples/ holds no model files (its YAML files are studies).
#
#   tests/bullet/snapshot_peers.sh LCSIM_BINARY OUT_DIR    # one snapshot
#   diff -r OUT_BEFORE OUT_AFTER                           # compare two
#
# A command that refuses a model (exit 2) or fails (exit 3) is recorded with
# its exit status and its message, so a change in what is refused shows too;
# refused.txt lists them.
set -uo pipefail
bin=$(realpath "$1")
out=$(mkdir -p "$2" && realpath "$2")
src=$(cd "$(dirname "$0")/../.." && pwd)
source "$src/tests/house/snapshot_lib.sh"  # strip_timing, run
cd "$src"
for model in robots/*.yaml; do
  m=$(basename "$model" .yaml)
  [ "$m" = lcp_example ] && continue
  run "$m.simulate.json" "$bin" simulate "$model" --method bullet --json --no-progress
  run "$m.simulate.txt" "$bin" simulate "$model" --method bullet --out "$out/$m.simulate.csv" \
    --no-progress
  for friction in cone box one-direction; do
    run "$m.compare.$friction.json" "$bin" compare "$model" --peer bullet --json \
      --bullet-friction "$friction" --peer-out "$out/$m.compare.$friction.csv"
  done
  run "$m.compare.erp1.json" "$bin" compare "$model" --peer bullet --json --stop-erp 1 \
    --iterations 20 --peer-out "$out/$m.compare.erp1.csv"
  for cone in pyramidal elliptic; do
    run "$m.mujoco.$cone.json" "$bin" compare "$model" --peer mujoco --json --mujoco-cone "$cone" \
      --peer-out "$out/$m.mujoco.$cone.csv"
  done
done
# Each refused or failed command: its file, exit status and first line.
for err in "$out"/*.err; do
  status=$(tail -1 "$err")
  [ "$status" != "exit 0" ] && echo "$(basename "$err" .err): $status: $(head -1 "$err")"
done >"$out/refused.txt"
echo "snapshot_peers: $(ls "$out" | wc -l) files in $out, $(grep -c . "$out/refused.txt") refused"
