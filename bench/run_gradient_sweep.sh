#!/usr/bin/env bash
# The time-stepping derivative against the exact one (issue 28, item 4;
# docs/sensitivities.md "The time-stepping derivative"): `lcsim sweep
# --sensitivity` for backward Euler and Moreau–Jean at each h, err_grad (the
# max-abs error of dx(T)/dtheta against the exact method's) beside the state
# error err_max, on
#   - the two carts (robots/two_carts.yaml) to T = 0.9 s, before their impact
#     at t = 1 (no event: the derivative converges with h),
#   - the same to T = 3 s (impact at t = 1, a held phase, release),
#   - the ball (robots/ball.yaml) to T = 1.1 s, after two bounces.
# Prints each table; with matplotlib installed, also draws err_grad against h
# per model and method into OUT_DIR/gradient_sweep.png.
#
#   bench/run_gradient_sweep.sh [LCSIM_BINARY] [OUT_DIR]
set -euo pipefail
bin=${1:-build/lcsim}
out=${2:-.}
src=$(cd "$(dirname "$0")/.." && pwd)
hs=1e-2,5e-3,2.5e-3,1.25e-3,6.25e-4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
run() {  # name model t_end columns
  echo "== $1 (T = $3, columns $4)"
  "$bin" sweep "$2" --t-end "$3" --methods event,euler,moreau-jean --h "$hs" --repeat 1 \
    --sensitivity "$4" 2>/dev/null
  "$bin" sweep "$2" --t-end "$3" --methods event,euler,moreau-jean --h "$hs" --repeat 1 \
    --sensitivity "$4" --json 2>/dev/null > "$tmp/$1.json"
}
run two_carts_T0.9 "$src/robots/two_carts.yaml" 0.9 'x0,K[0][1],f[1]'
run two_carts_T3 "$src/robots/two_carts.yaml" 3 'x0,K[0][1],f[1]'
run ball_T1.1 "$src/robots/ball.yaml" 1.1 'x0,f[0]'
/usr/bin/python3 - "$tmp" "$out" <<'PY'
import glob, json, os, sys
try:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    print("matplotlib not installed: no plot"); sys.exit(0)
files = sorted(glob.glob(os.path.join(sys.argv[1], "*.json")))
fig, axes = plt.subplots(1, len(files), figsize=(5 * len(files), 4), squeeze=False)
for ax, f in zip(axes[0], files):
    j = json.load(open(f))
    for m in ("euler", "moreau-jean"):
        rows = [r for r in j["rows"] if r["method"] == m and r.get("error_gradient") is not None]
        if rows:
            ax.loglog([r["h"] for r in rows], [r["error_gradient"] for r in rows], "o-", label=m)
    ax.set_title(os.path.basename(f)[:-5]); ax.set_xlabel("h (s)"); ax.set_ylabel("err_grad")
    ax.grid(True, which="both", alpha=0.3); ax.legend()
path = os.path.join(sys.argv[2], "gradient_sweep.png")
fig.tight_layout(); fig.savefig(path, dpi=100)
print("plot:", path)
PY
