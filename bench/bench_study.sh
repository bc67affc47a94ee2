#!/bin/bash
# Throughput of `lcsim study` (issue #16): a 2000-run study on the two carts,
# the exact method and Moreau-Jean at h = 1e-2, 1e-3, 1e-4 from 500 random
# initial states, run serially, on 2 threads and on 2 MPI ranks; and the same
# 2000 runs as `xargs -P 2 lcsim simulate` (one process per run).
# Usage: bench/bench_study.sh [build/lcsim]   (from the source directory)
# Targets: 2 workers >= 1.8x serial; the study >= 10x faster than xargs.
set -euo pipefail
lcsim=$(realpath "${1:-build/lcsim}")
src=$(cd "$(dirname "$0")/.." && pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

study() {  # $1 = reference (event or none)
  cat <<YAML
model: $src/robots/two_carts.yaml
seed: 2000
reference: $1
axes:
  - count: 500
    x0.x1: {uniform: [0.0, 0.5]}
    x0.x2: {uniform: [-0.5, 0.5]}
    v0.x1: {normal: [0.0, 0.5]}
    v0.x2: {normal: [0.0, 0.5]}
  - method: [event, moreau-jean, moreau-jean, moreau-jean]
    h: [1e-3, 1e-2, 1e-3, 1e-4]
YAML
}
study event > "$dir/with_reference.yaml"
study none > "$dir/runs_only.yaml"

# seconds CMD...: prints the wall time (s); the CPU time (user + sys, s, of
# the command and its children) goes to $dir/cpu. On a shared machine the
# CPU time tells what the speed-up would be with the cores to ourselves.
seconds() {
  /usr/bin/time -f "%e %U %S" -o "$dir/time" "$@" > /dev/null 2>&1
  read -r wall user sys < "$dir/time"
  echo "$user + $sys" | bc -l > "$dir/cpu"
  echo "$wall"
}
cpu() { cat "$dir/cpu"; }
rate() { printf '%.0f' "$(echo "2000 / $1" | bc -l)"; }
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores"

for s in with_reference runs_only; do
  f=$dir/$s.yaml
  t1=$(seconds "$lcsim" study "$f" --out "$dir/$s-1.csv" --jobs 1)
  c1=$(cpu)
  t2=$(seconds "$lcsim" study "$f" --out "$dir/$s-2.csv" --jobs 2)
  c2=$(cpu)
  tm=$(seconds mpirun --allow-run-as-root -np 2 "$lcsim" study "$f" --out "$dir/$s-mpi.csv")
  cm=$(cpu)
  cmp "$dir/$s-1.csv" "$dir/$s-2.csv" && cmp "$dir/$s-1.csv" "$dir/$s-mpi.csv"
  printf '%-15s serial %6.2f s (%s runs/s, CPU %.2f s) | 2 threads %6.2f s (%.2fx, CPU %.2f s) | 2 MPI ranks %6.2f s (%.2fx, CPU %.2f s)\n' \
    "$s" "$t1" "$(rate "$t1")" "$c1" "$t2" "$(echo "$t1 / $t2" | bc -l)" "$c2" \
    "$tm" "$(echo "$t1 / $tm" | bc -l)" "$cm"
done

# The same 2000 runs, one `lcsim simulate` process each, 2 at a time.
# Columns of the table: index, x0.x1, x0.x2, v0.x1, v0.x2, method, h.
tail -n +2 "$dir/runs_only-1.csv" |
  awk -F, -v m="$src/robots/two_carts.yaml" \
    '{ h = ($6 == "event") ? "" : " --h " $7; print m " --method " $6 h " --x0 " $2 "," $3 "," $4 "," $5 }' \
    > "$dir/commands.txt"
[ "$(wc -l < "$dir/commands.txt")" -eq 2000 ]
tx=$(seconds bash -c "xargs -P 2 -L 1 $lcsim simulate --no-progress < $dir/commands.txt")
cx=$(cpu)
t2=$(seconds "$lcsim" study "$dir/runs_only.yaml" --out "$dir/again.csv" --jobs 2)
c2=$(cpu)
printf 'xargs -P 2 lcsim simulate: %6.2f s (CPU %.2f s); lcsim study --jobs 2 (no reference): %6.2f s (CPU %.2f s): %.1fx faster (%.1fx less CPU)\n' \
  "$tx" "$cx" "$t2" "$c2" "$(echo "$tx / $t2" | bc -l)" "$(echo "$cx / $c2" | bc -l)"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
