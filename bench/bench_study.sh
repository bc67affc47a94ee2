#!/bin/bash
# Throughput of `lcsim study` (issue #16): a 2000-run study on the two carts,
# the exact method and Moreau-Jean at h = 1e-2, 1e-3, 1e-4 from 500 random
# initial states, run serially, on 2 threads and on 2 MPI ranks; the same
# study at 10x the runs (20000), where mpirun's fixed start-up is amortised;
# and the same 2000 runs as `xargs -P 2 lcsim simulate` (one process per run).
# MPI runs twice: as `mpirun -np 2` and with `--mca pml ob1 --mca btl self,vader`.
# Usage: [REPS=3] bench/bench_study.sh [build/lcsim]   (from the source directory)
# Targets: 2 workers >= 1.8x serial; the study >= 10x faster than xargs.
#
# Each figure is the median of REPS runs. "wall" is end to end (for MPI,
# mpirun's start-up and teardown included); "run" is the study's own run
# phase, the time on its summary line (from opening the journal to writing
# the table: MPI_Init and MPI_Finalize excluded). Speed-ups are serial / that.
set -euo pipefail
lcsim=$(realpath "${1:-build/lcsim}")
reps=${REPS:-3}
src=$(cd "$(dirname "$0")/.." && pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

study() {  # $1 = reference (event or none), $2 = random initial states
  cat <<YAML
model: $src/robots/two_carts.yaml
seed: 2000
reference: $1
axes:
  - count: $2
    x0.x1: {uniform: [0.0, 0.5]}
    x0.x2: {uniform: [-0.5, 0.5]}
    v0.x1: {normal: [0.0, 0.5]}
    v0.x2: {normal: [0.0, 0.5]}
  - method: [event, moreau-jean, moreau-jean, moreau-jean]
    h: [1e-3, 1e-2, 1e-3, 1e-4]
YAML
}
study event 500 > "$dir/with_reference.yaml"
study none 500 > "$dir/runs_only.yaml"
study event 5000 > "$dir/with_reference_x10.yaml"
printf 'model: %s/robots/two_carts.yaml\nreference: none\n' "$src" > "$dir/one_run.yaml"

median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

# measure OUT CMD...: runs CMD (writing the table OUT) REPS times; sets
# wall, run and cpu (user + sys of the command and its children) to medians.
measure() {
  local out=$1 walls=() runs=() cpus=() w u s
  shift
  for _ in $(seq 1 "$reps"); do
    rm -f "$out" "$out.journal"
    /usr/bin/time -f "%e %U %S" -o "$dir/time" "$@" > /dev/null 2> "$dir/stderr"
    read -r w u s < "$dir/time"
    walls+=("$w")
    cpus+=("$(echo "$u + $s" | bc -l)")
    runs+=("$(sed -n 's/.* not completed, \([0-9.]*\) s; table in .*/\1/p' "$dir/stderr" | tail -1)")
  done
  wall=$(median "${walls[@]}") run=$(median "${runs[@]}") cpu=$(median "${cpus[@]}")
}
ratio() { printf '%.2f' "$(echo "$1 / $2" | bc -l)"; }
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg) on $(nproc) cores; medians of $reps"

measure "$dir/one.csv" mpirun --allow-run-as-root -np 2 "$lcsim" study "$dir/one_run.yaml" \
  --out "$dir/one.csv"
echo "mpirun -np 2 on a 1-run study (start-up and teardown): wall $wall s"

for s in with_reference runs_only with_reference_x10; do
  f=$dir/$s.yaml
  measure "$dir/$s-1.csv" "$lcsim" study "$f" --out "$dir/$s-1.csv" --jobs 1
  w1=$wall r1=$run c1=$cpu
  measure "$dir/$s-2.csv" "$lcsim" study "$f" --out "$dir/$s-2.csv" --jobs 2
  w2=$wall r2=$run c2=$cpu
  measure "$dir/$s-mpi.csv" mpirun --allow-run-as-root -np 2 "$lcsim" study "$f" \
    --out "$dir/$s-mpi.csv"
  wm=$wall rn=$run cm=$cpu
  # The same with OpenMPI's shared-memory transport named (no UCX probing):
  # what one machine needs; it shortens MPI_Init, not the run phase.
  measure "$dir/$s-ob1.csv" mpirun --allow-run-as-root --mca pml ob1 --mca btl self,vader \
    -np 2 "$lcsim" study "$f" --out "$dir/$s-ob1.csv"
  wo=$wall ro=$run co=$cpu
  cmp "$dir/$s-1.csv" "$dir/$s-2.csv" && cmp "$dir/$s-1.csv" "$dir/$s-mpi.csv"
  cmp "$dir/$s-1.csv" "$dir/$s-ob1.csv"
  n=$(($(wc -l < "$dir/$s-1.csv") - 1))
  printf '%-19s %5d runs: serial wall %5.2f s run %5.2f s (%.0f runs/s, CPU %.2f s)\n' \
    "$s" "$n" "$w1" "$r1" "$(echo "$n / $r1" | bc -l)" "$c1"
  printf '%-25s 2 threads:   wall %5.2f s (%sx) run %5.2f s (%sx) CPU %.2f s\n' \
    "" "$w2" "$(ratio "$w1" "$w2")" "$r2" "$(ratio "$r1" "$r2")" "$c2"
  printf '%-25s 2 MPI ranks: wall %5.2f s (%sx) run %5.2f s (%sx) CPU %.2f s\n' \
    "" "$wm" "$(ratio "$w1" "$wm")" "$rn" "$(ratio "$r1" "$rn")" "$cm"
  printf '%-25s 2 ranks, ob1: wall %5.2f s (%sx) run %5.2f s (%sx) CPU %.2f s\n' \
    "" "$wo" "$(ratio "$w1" "$wo")" "$ro" "$(ratio "$r1" "$ro")" "$co"
done

# The same 2000 runs, one `lcsim simulate` process each, 2 at a time (once).
# Columns of the table: index, x0.x1, x0.x2, v0.x1, v0.x2, method, h.
tail -n +2 "$dir/runs_only-1.csv" |
  awk -F, -v m="$src/robots/two_carts.yaml" \
    '{ h = ($6 == "event") ? "" : " --h " $7; print m " --method " $6 h " --x0 " $2 "," $3 "," $4 "," $5 }' \
    > "$dir/commands.txt"
[ "$(wc -l < "$dir/commands.txt")" -eq 2000 ]
reps=1 measure "$dir/none" bash -c "xargs -P 2 -L 1 $lcsim simulate --no-progress < $dir/commands.txt"
tx=$wall cx=$cpu
measure "$dir/again.csv" "$lcsim" study "$dir/runs_only.yaml" --out "$dir/again.csv" --jobs 2
printf 'xargs -P 2 lcsim simulate: %6.2f s (CPU %.2f s); lcsim study --jobs 2 (no reference): %6.2f s (CPU %.2f s): %.1fx faster (%.1fx less CPU)\n' \
  "$tx" "$cx" "$wall" "$cpu" "$(echo "$tx / $wall" | bc -l)" "$(echo "$cx / $cpu" | bc -l)"
echo "load average after: $(cut -d' ' -f1-3 /proc/loadavg)"
