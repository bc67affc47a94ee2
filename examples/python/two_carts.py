#!/usr/bin/python3
"""The two carts with a stop of thesis §3.7 in Python: load the model file, run the
exact event-driven method to the model's horizon (3 s), print the events and the
energy, and draw the trajectory like the thesis's Figure 3.3.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/two_carts.py \
        [robots/two_carts.yaml] [two_carts.png]
"""

import pathlib
import sys

import lcsim
import lcsim.plot

HERE = pathlib.Path(__file__).resolve().parent


def main(model_path, png):
    model = lcsim.load(model_path)  # lcsim.InputError names the file, key and value
    run = lcsim.simulate(model, dt_out=0.01)  # the model's x0 and t_end; exact method
    if not run.ok:  # numerical trouble is a status, not an exception
        print(f"run {run.status}: {run.message}", file=sys.stderr)
        return 3
    for e in run.events:
        print(f"t = {e.t:.12f}  {e.type:8}  {e.state_before} -> {e.state_after}  "
              f"mode {e.mode}")
    print(f"energy {run.energy_initial:.12g} -> {run.energy_final:.12g} J "
          f"({len(run.t)} samples; q {run.q.shape}, v {run.v.shape})")
    lcsim.plot.trajectory(run, png, title="Two carts with a stop (thesis §3.7)")
    print(f"wrote {png}")
    return 0


if __name__ == "__main__":
    args = sys.argv[1:]
    model_path = args[0] if args else HERE.parents[1] / "robots" / "two_carts.yaml"
    png = args[1] if len(args) > 1 else "two_carts.png"
    sys.exit(main(model_path, png))
