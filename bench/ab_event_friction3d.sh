#!/usr/bin/env bash
# The exact method's box and point mass (table_event_friction3d) before and
# after a change, run alternately in one shell so the load of the shared
# machine falls on both alike: each round runs BEFORE then AFTER and prints
# their event rows (fastest of R runs) with the 1-minute load average.
#
#   bench/ab_event_friction3d.sh BEFORE_BIN AFTER_BIN [R=2000] [ROUNDS=3]
#
# BEFORE_BIN: a copy of build/bench/table_event_friction3d built at the base.
set -euo pipefail
before=$1
after=$2
R=${3:-2000}
rounds=${4:-3}
for i in $(seq "$rounds"); do
  for which in before after; do
    bin=${!which}
    echo "round $i $which (load $(cut -d' ' -f1 /proc/loadavg))"
    "$bin" "$R" | grep -F '| event |'
  done
done
