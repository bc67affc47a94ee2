#!/usr/bin/env bash
# Cost of forward sensitivities (docs/sensitivities.md) as a ratio to the plain
# exact run of the same model, in one script: the NAO legs scene (to its t_end,
# and to t = 0.28 s, before the accumulation at 0.2898 s after which every
# derivative is absent and nothing is carried) and the chain of 100 carts
# (`lcsim generate chain 100`). build/bench/table_sensitivity runs each model
# as `lcsim simulate MODEL --json` does, plain, with `--sensitivity x0` and
# with `--sensitivity f[0]`, alternately REPS times in one process, and prints
# the best wall_time_s of each, the ratios of the bests and the median ratio
# of the rounds, against the targets of issue 28 (x0 at most 3x, one
# parameter 1.5x), with the load average before and after.
#
#   bench/run_sensitivity_bench.sh [BUILD_DIR or LCSIM_BINARY] [REPS]
#   (cmake --build build --target lcsim table_sensitivity first)
set -euo pipefail
arg=${1:-build}
reps=${2:-15}
[ -f "$arg" ] && arg=$(dirname "$arg")  # build/lcsim -> build
src=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$arg/lcsim" generate chain 100 > "$tmp/chain100.yaml"
"$arg/bench/table_sensitivity" "$reps" \
  "nao_legs=$src/robots/nao_legs_scene.yaml" \
  "nao_legs_to_0.28=$src/robots/nao_legs_scene.yaml@0.28" \
  "chain100=$tmp/chain100.yaml"
