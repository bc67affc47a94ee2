#!/usr/bin/env bash
# Work-precision of lcsim's three methods next to Siconos 4.4 (issue "Time-stepping and
# the measured speed–accuracy trade", §4): for each scene, `lcsim sweep` (exact
# event-driven, backward Euler, Moreau–Jean theta = 1/2 and 1) and `peer_siconos_wp`
# (MoreauJeanOSI theta = 1/2 and 1, LCP by Lemke and by PGS) at h = 1e-2 ... 1e-5, T = 3.
#
# Scenes: two_carts (run S1, robots/two_carts.yaml), hook (robots/two_carts_hook.yaml from
# (0,0,-1,2)), ball0 (robots/ball.yaml with restitution 0, written to out/ball_e0.yaml)
# and ball05 (robots/ball.yaml, e = 0.5).
#
# The exact final state: in closed form for two_carts and the balls (peer_siconos_wp
# --print-exact; lcsim's event-driven run is measured against it too), and lcsim's exact
# event-driven run (`lcsim simulate --json`, final_state) for the hook, handed to Siconos
# with --exact.
#
# Prints one merged table per scene (tool, method, theta/solver, h, error_final, time per
# step, total time), the per-step ratio Siconos / lcsim for Moreau–Jean at the same h and
# theta, and whether the event-driven run beats every time-stepping run reaching 1e-4.
# Writes out/wp/<scene>.json (merged rows, ratios, raw outputs) and out/wp/<scene>.png.
#
# Times: lcsim's wall time of the run (median of REPEAT, no samples recorded); Siconos's
# CPU time of the simulation loop (median of REPEAT for runs under 0.5 s; the JSON also
# holds its wall time). Both are single-threaded.
#
# Usage: bench/run_work_precision.sh [build-dir] [repeat] [h-list]
#   build-dir  holds lcsim and bench/peer_siconos_wp (default build-wp, a Release build)
#   repeat     timing runs per point (default 5)
#   h-list     comma-separated steps (default 1e-2,1e-3,1e-4,1e-5); e.g. 1e-2,1e-3 for a
#              quick run
# Environment: LCSIM=path/to/lcsim uses that binary instead of build-dir/lcsim (e.g. one
# built from a clean checkout while the working tree does not build, or a baseline build
# to compare before/after); PEER=path/to/peer_siconos_wp likewise for the peer.
# OPENBLAS_NUM_THREADS defaults to 1 here: both programs load OpenBLAS (lcsim through
# Ipopt, Siconos for its numerics), whose worker thread otherwise spins in sched_yield
# beside the run, and Siconos's CPU time (all threads of the process) would count it
# (measured: 3.15 against 2.90 us per step for Siconos on two_carts, h = 1e-5). Each
# scene's header line records the load average (uptime) at its start.
set -euo pipefail
export OPENBLAS_NUM_THREADS=${OPENBLAS_NUM_THREADS:-1}
cd "$(dirname "$0")/.."
build=${1:-build-wp}
repeat=${2:-5}
hlist=${3:-1e-2,1e-3,1e-4,1e-5}
t_end=3
lcsim=${LCSIM:-$build/lcsim}
peer=${PEER:-$build/bench/peer_siconos_wp}
for exe in "$lcsim" "$peer"; do
  if [[ ! -x $exe ]]; then
    echo "run_work_precision.sh: $exe not found; build it first:" >&2
    echo "  cmake -S . -B $build -DCMAKE_BUILD_TYPE=Release &&" \
      "cmake --build $build --target lcsim peer_siconos_wp" >&2
    exit 1
  fi
done
out=out/wp
mkdir -p "$out"

# The ball with an inelastic ground (e = 0): robots/ball.yaml with restitution 0.
sed -e 's/^name: ball$/name: ball_e0/' -e 's/^  restitution: \[0\.5\].*/  restitution: [0]/' \
  robots/ball.yaml > out/ball_e0.yaml
grep -q '^  restitution: \[0\]' out/ball_e0.yaml ||
  { echo "run_work_precision.sh: could not set restitution 0 in out/ball_e0.yaml" >&2; exit 1; }

for scene in two_carts hook ball0 ball05; do
  x0=()
  case $scene in
    two_carts) model=robots/two_carts.yaml ;;
    hook) model=robots/two_carts_hook.yaml; x0=(--x0 0,0,-1,2) ;;
    ball0) model=out/ball_e0.yaml ;;
    ball05) model=robots/ball.yaml ;;
  esac
  load=$(cut -d' ' -f1-3 /proc/loadavg)
  echo "== $scene ($model), load average $load ==" >&2
  # lcsim: the exact event-driven final state, then the sweeps (theta = 1/2 with event and
  # Euler, theta = 1 Moreau–Jean alone).
  "$lcsim" simulate "$model" "${x0[@]}" --t-end "$t_end" --json > "$out/${scene}_lcsim_event.json"
  "$lcsim" sweep "$model" "${x0[@]}" --t-end "$t_end" --methods event,euler,moreau-jean \
    --h "$hlist" --repeat "$repeat" --json > "$out/${scene}_lcsim_theta0.5.json"
  "$lcsim" sweep "$model" "${x0[@]}" --t-end "$t_end" --methods moreau-jean --theta 1 \
    --h "$hlist" --repeat "$repeat" --json > "$out/${scene}_lcsim_theta1.json"
  # Siconos, against the closed form or lcsim's exact final state.
  if closed=$("$peer" "$scene" --t-end "$t_end" --print-exact 2>/dev/null); then
    exact=$closed
    exact_src=closed_form
  else
    exact=$(/usr/bin/python3 -c 'import json,sys; print(",".join("%.17g" % v for v in json.load(open(sys.argv[1]))["final_state"]))' \
      "$out/${scene}_lcsim_event.json")
    exact_src=lcsim_event
  fi
  "$peer" "$scene" --t-end "$t_end" --h-list "$hlist" --repeats "$repeat" --exact "$exact" \
    --json > "$out/${scene}_siconos.json" 2> "$out/${scene}_siconos.stderr"
  /usr/bin/python3 - "$scene" "$out" "$exact" "$exact_src" "$model" "$load" "$lcsim" <<'PY'
import json, math, sys
scene, out, exact, exact_src, model, load, lcsim_exe = sys.argv[1:8]
exact = [float(v) for v in exact.split(",")]
ev_run = json.load(open(f"{out}/{scene}_lcsim_event.json"))
sweep05 = json.load(open(f"{out}/{scene}_lcsim_theta0.5.json"))
sweep1 = json.load(open(f"{out}/{scene}_lcsim_theta1.json"))
sic = json.load(open(f"{out}/{scene}_siconos.json"))

def num(x):
    return float("nan") if x is None else float(x)

rows = []
for sweep, theta in ((sweep05, 0.5), (sweep1, 1.0)):
    for r in sweep["rows"]:
        m = r["method"]
        if m == "event":
            # Measured against the closed form where there is one; else it is the reference.
            err = (max(abs(a - b) for a, b in zip(ev_run["final_state"], exact))
                   if exact_src == "closed_form" else None)
            th, label = None, "lcsim event"
        elif m == "euler":
            err, th, label = r["error_final"], None, "lcsim euler"
        else:
            err, th, label = r["error_final"], theta, f"lcsim moreau-jean θ={theta:g}"
        rows.append({"tool": "lcsim", "method": m, "theta": th, "solver": "pivot",
                     "h": r["h"], "error_final": err, "steps": r["steps"],
                     "time_s": r["wall_time_s"], "wall_time_s": r["wall_time_s"],
                     "time_per_step_s": r["wall_time_s"] / r["steps"] if r["steps"] else None,
                     "status": r.get("status", "completed"), "label": label})
for r in sic:
    rows.append({"tool": "siconos", "method": "moreau-jean", "theta": r["theta"],
                 "solver": r["solver"], "h": r["h"], "error_final": r["error_final"],
                 "steps": r["steps"], "time_s": r["cpu_seconds"],
                 "wall_time_s": r["wall_seconds"], "time_per_step_s": r["cpu_per_step"],
                 "status": r["status"] if not r["message"] else r["status"] + ": " + r["message"],
                 "label": f"siconos MJ θ={r['theta']:g} {r['solver']}"})

def fmt(x, f="%.3e"):
    return "-" if x is None or (isinstance(x, float) and math.isnan(x)) else f % x

print(f"\n== {scene}: {model}, T = 3; exact final state ({exact_src}) = "
      + ", ".join(f"{v:.10g}" for v in exact))
print(f"   lcsim: {lcsim_exe}; load average at start: {load}")
print(f"{'tool':8} {'method':12} {'θ/solver':12} {'h':>6} {'err_final':>10} "
      f"{'t/step (s)':>10} {'total (s)':>10} {'steps':>7}")
for r in rows:
    ts = ("-" if r["theta"] is None else f"{r['theta']:g}") + "/" + r["solver"]
    h = "-" if r["h"] is None else f"{r['h']:g}"
    st = "" if r["status"] in ("ok", "completed") else "  " + r["status"]
    print(f"{r['tool']:8} {r['method']:12} {ts:12} {h:>6} {fmt(r['error_final']):>10} "
          f"{fmt(r['time_per_step_s']):>10} {fmt(r['time_s']):>10} {r['steps']:7d}{st}")

# Per-step ratio Siconos / lcsim, Moreau–Jean, same h and theta (target: >= 20 with
# lcsim's error <= Siconos's).
ratios = []
lc = {(r["theta"], r["h"]): r for r in rows if r["tool"] == "lcsim" and r["method"] == "moreau-jean"}
print(f"{'θ':>4} {'solver':6} {'h':>6} {'sic/lcsim per step':>19} {'(wall)':>7} "
      f"{'err lcsim':>10} {'err siconos':>11}  target")
for r in rows:
    if r["tool"] != "siconos":
        continue
    l = lc.get((r["theta"], r["h"]))
    if not l or not l["time_per_step_s"] or r["time_per_step_s"] is None:
        continue
    ratio = r["time_per_step_s"] / l["time_per_step_s"]
    ratio_wall = (r["wall_time_s"] / r["steps"]) / l["time_per_step_s"]
    el, es = num(l["error_final"]), num(r["error_final"])
    same_or_better = el <= es * 1.01 + 1e-15
    met = ratio >= 20 and same_or_better
    ratios.append({"theta": r["theta"], "solver": r["solver"], "h": r["h"],
                   "ratio_per_step": ratio, "ratio_per_step_wall": ratio_wall,
                   "error_lcsim": el, "error_siconos": es,
                   "error_same_or_smaller": same_or_better, "target_met": met})
    print(f"{r['theta']:4g} {r['solver']:6} {r['h']:6g} {ratio:19.1f} {ratio_wall:7.1f} "
          f"{el:10.3e} {es:11.3e}  {'met' if met else 'NOT met'}")

# Does the event-driven run reach 1e-10 in less time than any time-stepping run needs
# for 1e-4?
ev = next(r for r in rows if r["method"] == "event")
ts_ok = [r for r in rows if r["method"] != "event" and r["error_final"] is not None
         and num(r["error_final"]) <= 1e-4]
fastest = min(ts_ok, key=lambda r: r["time_s"]) if ts_ok else None
ev_err = ev["error_final"]
ev_reaches = ev_err is None or ev_err <= 1e-10
verdict = {
    "event_time_s": ev["time_s"], "event_error": ev_err,
    "event_error_source": "closed form" if exact_src == "closed_form" else
                          "none (the event run is the reference)",
    "fastest_ts_reaching_1e-4": None if fastest is None else
        {k: fastest[k] for k in ("tool", "method", "theta", "solver", "h", "error_final", "time_s")},
}
verdict["event_faster"] = ev_reaches and (fastest is None or ev["time_s"] < fastest["time_s"])
if fastest is None:
    print(f"event: {fmt(ev['time_s'])} s, error {fmt(ev_err)}; no time-stepping run reaches 1e-4")
else:
    print(f"event: {fmt(ev['time_s'])} s, error {fmt(ev_err)} ({verdict['event_error_source']}); "
          f"fastest time-stepping run with error <= 1e-4: {fastest['label']} h={fastest['h']:g} "
          f"{fmt(fastest['time_s'])} s (error {fmt(fastest['error_final'])}) -> "
          f"{'event faster by %.0fx' % (fastest['time_s'] / ev['time_s']) if verdict['event_faster'] else 'event NOT faster'}")

json.dump({"model": scene, "model_file": model, "t_end": 3, "load_average": load,
           "lcsim": lcsim_exe, "exact_final_state": exact,
           "exact_source": exact_src, "rows": rows, "ratios": ratios, "event_vs_1e-4": verdict},
          open(f"{out}/{scene}.json", "w"), indent=1)
PY
  /usr/bin/python3 python/lcsim/plot.py work-precision "$out/$scene.json" "$out/$scene.png" \
    --error final --title "$scene (lcsim solid, Siconos dashed)"
  echo "   written: $out/$scene.json, $out/$scene.png" >&2
done
