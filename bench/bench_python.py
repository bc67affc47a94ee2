#!/usr/bin/python3
"""The Python bindings' costs (issue 15), measured side by side in one process:

1. Per-call overhead: lcsim.simulate on the two carts of thesis §3.7 (exact method,
   events only, the model's x0, t_end = 3 s) against the same sim::simulate call timed in
   a C++ loop (lcsim._lcsim._bench_simulate), interleaved rounds, thread CPU time on both
   sides (the machine is shared: wall time varies by tens of percent between rounds).
   Target: at most 10 µs more per call.
2. Memory of a 10^5-sample trajectory (the two carts, dt_out = t_end / 10^5), in a
   fresh interpreter: resident memory (/proc/self/statm) after the run and its peak
   (ru_maxrss) above the resident memory before it, against the bytes of the returned
   arrays (t, x, u, y, modes). At most one copy: both stay near 1 x the arrays.

    PYTHONPATH=build/python /usr/bin/python3 bench/bench_python.py [--calls N]
"""

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import time

import lcsim
from lcsim import _lcsim

ROBOTS = pathlib.Path(__file__).resolve().parents[1] / "robots"


def per_call(calls, rounds):
    model = lcsim.load(ROBOTS / "two_carts.yaml")
    x0, t_end = model.initial, model.t_end
    py, cpp = [], []
    for _ in range(rounds):  # interleaved, so both see the same machine load
        start = time.thread_time()  # CPU time: what the call costs on a shared machine
        for _ in range(calls):
            lcsim.simulate(model, x0=x0, t_end=t_end)
        py.append((time.thread_time() - start) / calls)
        cpp.append(_lcsim._bench_simulate(model, x0, t_end, calls)[0])
    return statistics.median(py), statistics.median(cpp), min(py), min(cpp)



CHILD = r"""
import json, os, resource, sys
import lcsim

def rss():  # resident bytes now (/proc/self/statm, pages)
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")

model = lcsim.load(sys.argv[1])
n = int(sys.argv[2])
run = lcsim.simulate(model, dt_out=model.t_end / 100)  # everything warmed up once
del run
before = rss()
run = lcsim.simulate(model, dt_out=model.t_end / n)
after = rss()
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
arrays = sum(a.nbytes for a in (run.t, run.x, run.u, run.y, run.modes))
assert not run.x.flags.owndata
print(json.dumps({"samples": len(run.t), "before": before, "after": after, "peak": peak,
                  "array_bytes": arrays}))
"""


def memory(samples):
    r = subprocess.run([sys.executable, "-c", CHILD, str(ROBOTS / "two_carts.yaml"),
                        str(samples)], capture_output=True, text=True, check=True,
                       env=os.environ)
    return json.loads(r.stdout)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=2000)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--samples", type=int, default=100000)
    a = ap.parse_args()
    py, cpp, py_min, cpp_min = per_call(a.calls, a.rounds)
    print(f"two carts, exact method, t_end 3 s, {a.rounds} rounds x {a.calls} calls:")
    print(f"  lcsim.simulate (Python)  {py * 1e6:9.2f} µs/call (median; best {py_min * 1e6:.2f})")
    print(f"  sim::simulate (C++ loop) {cpp * 1e6:9.2f} µs/call "
          f"(median; best {cpp_min * 1e6:.2f})")
    print(f"  overhead                 {(py - cpp) * 1e6:9.2f} µs/call (median; best "
          f"{(py_min - cpp_min) * 1e6:.2f}; target <= 10)")
    m = memory(a.samples)
    arrays, kept, peak = m["array_bytes"], m["after"] - m["before"], m["peak"] - m["before"]
    print(f"{m['samples']} samples: arrays t, x, u, y, modes = {arrays / 1e6:.2f} MB; "
          f"resident after the run +{kept / 1e6:.2f} MB ({kept / arrays:.2f} x), "
          f"peak +{peak / 1e6:.2f} MB ({peak / arrays:.2f} x; a second copy would add "
          f"{arrays / 1e6:.2f} MB more)")


if __name__ == "__main__":
    main()
