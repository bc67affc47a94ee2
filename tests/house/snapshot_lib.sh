# Helpers of the snapshot scripts (tests/house/snapshot_outputs.sh,
# tests/bullet/snapshot_bullet.sh), sourced with $out set to the snapshot's
# folder.

# JSON from stdin with its timings left out (they differ from run to run),
# keys sorted; "(not JSON)" for anything else.
strip_timing() { /usr/bin/python3 -c '
import json, sys
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items()
                if k not in ("wall_time_s", "cpu_time_s", "wall_time_per_step_s")}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
try:
    print(json.dumps(strip(json.load(sys.stdin)), indent=1, sort_keys=True))
except ValueError:
    print("(not JSON)")
'; }

run() {  # run NAME CMD...: stdout (timings stripped when JSON), stderr, exit status
  local name=$1
  shift
  "$@" >"$out/$name.raw" 2>"$out/$name.err"
  echo "exit $?" >>"$out/$name.err"
  if [[ $name == *.json ]]; then
    strip_timing <"$out/$name.raw" >"$out/$name"
  else  # text: the wall time and the output folder differ from run to run
    sed -E -e 's/wall time [0-9.e+-]+ ?m?s/wall time (timing)/g' -e "s#$out/#OUT/#g" \
      "$out/$name.raw" >"$out/$name"
  fi
  rm -f "$out/$name.raw"
}
