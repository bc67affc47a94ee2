#!/usr/bin/python3
"""The ideal diode bridge (Siconos's DiodeBridge, issue 29): lcsim beside
Siconos and ngspice, all three against the closed form, in one script.

circuits/diode_bridge.cir: 1 uF || 10 mH charged to 10 V feeding 1 kOhm
through a full-wave bridge of four ideal diodes, to 5 ms. An ideal bridge
always presents its load to the tank, so V(a) is the parallel RLC's
exp(-alpha t) (10 cos(wd t) + B sin(wd t)), alpha = 1/(2RC), B = -alpha 10/wd.

- lcsim: the netlist as shipped (ideal diodes, exact event-driven method),
  timed as a whole process (best of three) and inside the run (--json's
  wall_time_s); error over its samples (--dt-out 1e-6) and events.
- Siconos 4.4 (python3-siconos): the bridge as an LCS given by matrices, as
  Siconos's example builds it by hand (here lcsim's own derivation by hand,
  tests/lcs/test_ldcp.cpp, in physical units), LinearComplementaritySystemsNSDS
  with EulerMoreauOSI(theta = 0.5) at h = 1e-6 s (the example's settings);
  the loop timed (not the import); error over its steps.
- ngspice (Debian, `ngspice -b`): the same netlist with SPICE's exponential
  diode made sharper step by step, at .tran 1u 5m uic and default options;
  timed as a whole process (best of three); error over its output points.

Usage: bench/circuits_bridge.py [LCSIM_BINARY]  (default build/lcsim)
Not a test: nothing here is asserted; the table is printed.
"""
import csv
import json
import math
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
C, L, R, V0, T_END = 1e-6, 10e-3, 1e3, 10.0, 5e-3
ALPHA = 1 / (2 * R * C)
WD = math.sqrt(1 / (L * C) - ALPHA**2)


def closed_form(t):
    b = -ALPHA * V0 / WD
    return math.exp(-ALPHA * t) * (V0 * math.cos(WD * t) + b * math.sin(WD * t))


def zeros():
    out, t = [], math.atan(WD / ALPHA) / WD
    while t < T_END:
        out.append(t)
        t += math.pi / WD
    return out


def timed(cmd, check=True):
    # check=False for ngspice -b: it exits 1 after a .control block's run.
    best = math.inf
    for _ in range(3):  # the best of three: the machine is shared
        t0 = time.perf_counter()
        subprocess.run(cmd, check=check, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        best = min(best, time.perf_counter() - t0)
    return best


def run_lcsim(binary, tmp):
    out = tmp / "lcsim.csv"
    cmd = [binary, "simulate", str(ROOT / "circuits/diode_bridge.cir"), "--dt-out", "1e-6",
           "--out", str(out), "--no-progress"]
    wall = timed(cmd)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    err = max(abs(float(r["V(a)"]) - closed_form(float(r["t"]))) for r in rows)
    json_wall = timed(cmd[:-3] + ["--json"])  # the same run, its summary only (no CSV)
    run = subprocess.run(cmd[:-3] + ["--json"], check=True, capture_output=True, text=True)
    summary = json.loads(run.stdout)
    events = [e["t"] for e in summary["events"] if e["type"] != "start"]
    ev_err = max(abs(a - b) for a, b in zip(events, zeros())) if len(events) == len(zeros()) \
        else math.inf
    return wall, err, len(rows), summary["wall_time_s"], len(events), ev_err, json_wall


def run_siconos():
    import numpy as np
    import siconos.kernel as sk
    # x = (v, i); diode 1 (a -> p) in voltage form, 2..4 in current form.
    A = np.array([[0, -1 / C], [1 / L, 0]])
    B = np.array([[0, 1 / C, 0, -1 / C], [0, 0, 0, 0]])
    Cm = np.array([[0, 0], [1, 0], [0, 0], [-1, 0]], dtype=float)
    D = np.array([[0, -1, 1, 1], [1, 0, 0, 0], [-1, 0, R, R], [-1, 0, R, R]], dtype=float)
    h = 1e-6
    t0 = time.perf_counter()
    saved = os.dup(1)  # Siconos prints its system's display on stdout: kept out of the table
    sys.stdout.flush()
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        nsds = sk.LinearComplementaritySystemsNSDS(0.0, T_END, np.array([V0, 0.0]), A, B, Cm, D,
                                                   np.zeros(2), np.zeros(4))
        os.dup2(saved, 1)
    os.close(saved)
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, h), sk.EulerMoreauOSI(0.5), sk.LCP())
    ds = nsds.dynamicalSystem(0)
    ts, vs = [0.0], [V0]
    while sim.hasNextEvent():
        sim.computeOneStep()
        ts.append(sim.nextTime())
        vs.append(ds.x()[0])
        sim.nextStep()
    wall = time.perf_counter() - t0
    err = max(abs(v - closed_form(t)) for t, v in zip(ts, vs))
    return wall, err, len(ts), abs(vs[-1] - closed_form(ts[-1]))


NETLIST = """diode bridge for ngspice
C1 a 0 1u IC=10
L1 a 0 10m
D1 a p dx
D2 0 p dx
D3 m a dx
D4 m 0 dx
R1 p m 1k
.model dx D(IS={is_} N={n})
{options}
.tran 1u 5m uic
.control
set wr_singlescale
run
rusage trantime
wrdata {out} v(a)
.endc
.end
"""


def run_ngspice(tmp, is_, n, options):
    cir, out = tmp / "ng.cir", tmp / "ng.dat"
    cir.write_text(NETLIST.format(is_=is_, n=n, options=options, out=out))
    if out.exists():
        out.unlink()
    wall = timed(["ngspice", "-b", str(cir)], check=False)
    if not out.exists():
        raise subprocess.CalledProcessError(1, "ngspice")
    # ngspice's own time of the .tran analysis (rusage trantime), start-up excluded
    log = subprocess.run(["ngspice", "-b", str(cir)], capture_output=True, text=True).stdout
    tran = min((float(x) for x in re.findall(r"Transient analysis time = ([0-9.eE+-]+)", log)),
               default=math.nan)
    err, points = 0.0, 0
    for line in out.read_text().split("\n"):
        parts = line.split()
        if len(parts) >= 2:
            try:
                t, v = float(parts[0]), float(parts[1])
            except ValueError:
                continue
            err = max(err, abs(v - closed_form(t)))
            points += 1
    return wall, tran, err, points


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "build/lcsim")
    with tempfile.TemporaryDirectory() as d:
        tmp = pathlib.Path(d)
        lw, le, lp, li, ne, ee, jw = run_lcsim(binary, tmp)
        print(f"lcsim (exact, ideal diodes): wall {lw * 1e3:.1f} ms as a process writing its CSV "
              f"({jw * 1e3:.1f} ms with --json only, {li * 1e3:.3f} ms inside the run), {lp} "
              f"samples, max |V(a) error| {le:.3g} V, {ne} events, max event time error {ee:.3g} s")
        sw, se, sp, send = run_siconos()
        print(f"Siconos (EulerMoreauOSI theta=0.5, h=1e-6): loop {sw * 1e3:.1f} ms, {sp} points, "
              f"max |V(a) error| {se:.3g} V, at 5 ms {send:.3g} V")
        print("ratios: whole processes (lcsim writing its CSV at 1 us, ngspice its wrdata), "
              "and .tran alone (ngspice's rusage trantime / lcsim's wall_time_s)")
        print(f"{'ngspice diode':18s} {'options':18s} {'wall ms':>8s} {'tran ms':>8s} "
              f"{'points':>7s} {'max error V':>12s} {'process ratio':>13s} {'tran ratio':>10s}")
        for is_, n in [(1e-14, 1.0), (1e-9, 0.1), (1e-6, 0.01), (1e-4, 0.001)]:
            for options in ["", ".options reltol=1e-6"]:
                try:
                    w, tr, e, p = run_ngspice(tmp, is_, n, options)
                except subprocess.CalledProcessError:
                    print(f"IS={is_:g} N={n:g}: ngspice failed")
                    continue
                print(f"{'IS=%g N=%g' % (is_, n):18s} {options or 'default':18s} "
                      f"{w * 1e3:8.1f} {tr * 1e3:8.1f} {p:7d} {e:12.3g} {w / lw:13.2f} "
                      f"{tr / li:10.1f}")


if __name__ == "__main__":
    main()
