#!/usr/bin/env bash
# Cost of forward sensitivities (docs/sensitivities.md) as a ratio to the plain
# exact run of the same model, in one script: the NAO legs scene (to its t_end,
# and to t = 0.28 s, before the accumulation at 0.2898 s after which every
# derivative is absent and nothing is carried) and the chain of 100 carts
# (`lcsim generate chain 100`). Each configuration runs REPS times; the figure
# is the smallest `wall_time_s` of `simulate --json` (the run alone, not the
# loading). Targets (issue 28): dx(T)/dx0 at most 3x, one parameter 1.5x.
#
#   bench/run_sensitivity_bench.sh [LCSIM_BINARY] [REPS]
set -euo pipefail
bin=${1:-build/lcsim}
reps=${2:-5}
src=$(cd "$(dirname "$0")/.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$bin" generate chain 100 > "$tmp/chain100.yaml"
best() {  # best wall time of REPS runs of: simulate ARGS --json
  local b=""
  for _ in $(seq "$reps"); do
    w=$("$bin" simulate "$@" --json 2>/dev/null |
        /usr/bin/python3 -c 'import json,sys; print(json.load(sys.stdin)["wall_time_s"])')
    b=$(/usr/bin/python3 -c "print(min(float('$w'), float('${b:-inf}')))")
  done
  echo "$b"
}
printf '%-28s %12s %12s %8s %12s %8s\n' model plain_s x0_s ratio "f[0]_s" ratio
for spec in "nao_legs:$src/robots/nao_legs_scene.yaml:" \
            "nao_legs_to_0.28:$src/robots/nao_legs_scene.yaml:--t-end 0.28" \
            "chain100:$tmp/chain100.yaml:"; do
  IFS=: read -r name path extra <<< "$spec"
  # shellcheck disable=SC2086
  p=$(best "$path" $extra)
  # shellcheck disable=SC2086
  x=$(best "$path" $extra --sensitivity x0)
  # shellcheck disable=SC2086
  f=$(best "$path" $extra --sensitivity 'f[0]')
  /usr/bin/python3 -c "print(f'{\"$name\":28s} {$p:12.6f} {$x:12.6f} {$x/$p:8.2f} {$f:12.6f} {$f/$p:8.2f}')"
done
