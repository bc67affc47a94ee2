#!/usr/bin/python3
"""The impact rules compared on the hook of thesis Example 3.8.3: two carts at
x1 = x2 = 0 with a stop (x1 >= 0) and a hook (x1 - x2 >= 0), both gaps closing at once
(y1' = -1, y2' = -3). Moreau's rule selects the hook alone; the other laws of lcsim
(lcsim.impact_law_names()) are printed beside it, with the kinetic energy before and
after and whether the result is admissible. Then the impact map of Figure 3.5.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/impact_rules.py \
        [robots/two_carts_hook.yaml] [impact_map.png]
"""

import pathlib
import sys

import lcsim
import lcsim.plot

HERE = pathlib.Path(__file__).resolve().parent


def main(model_path, png):
    model = lcsim.load(model_path)
    x0 = [0.0, 0.0, -1.0, 2.0]  # (x1, x2, x1', x2')
    print(f"{'rule':20} {'v after':26} {'impulse':24} {'T before':>9} {'T after':>9}  note")
    failed = 0
    for name, r in lcsim.impacts(model, x0).items():
        note = ("" if r.admissible else "NOT ADMISSIBLE ") if r.ok else "FAILED "
        failed += not r.ok
        print(f"{name:20} {str(r.v_after.round(6)):26} {str(r.impulse.round(6)):24} "
              f"{r.energy_before:9.4f} {r.energy_after:9.4f}  {note}{r.message}")
    grid = lcsim.impact_map(model, v1=(-2, 2), v2=(-2, 2), n=41)
    lcsim.plot.impact_map(grid, png, title="two carts with a hook: Moreau impact map")
    print(f"wrote {png}")
    return 3 if failed else 0


if __name__ == "__main__":
    args = sys.argv[1:]
    model_path = args[0] if args else HERE.parents[1] / "robots" / "two_carts_hook.yaml"
    png = args[1] if len(args) > 1 else "impact_map.png"
    sys.exit(main(model_path, png))
