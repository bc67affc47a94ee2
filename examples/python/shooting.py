#!/usr/bin/python3
"""Shooting through impacts with exact derivatives (issue 28, second worked example): the
initial velocity v0 that brings a bouncing ball (unit mass, floor z >= 0, gravity
f = -9.81, restitution e = 0.5, from z0 = 1 m) to the height H = 0.1 m at T = 2 s after
exactly two impacts, falling. Newton's method on z(T; v0) - H with dz(T)/dv0 read from
run.dx_dx0 (simulate(..., sensitivity=["x0"]), docs/sensitivities.md), checked against
the closed form of the ball's flight:

    w = sqrt(v0^2 + 2 g z0)          the speed at the first impact,
    t1 = (v0 + w) / g                the first impact,
    t2 = t1 + 2 e w / g              the second (the first bounce leaves at e w),
    s = T - t2,  z(T) = e^2 w s - g s^2 / 2   (0 <= s <= 2 e^2 w / g: no third impact),

and its derivative dz/dv0 = e^2 w' s + (e^2 w - g s) s' with w' = v0 / w,
s' = -(1 + (1 + 2 e) w') / g. The root of the closed form is found by bisection on the
falling branch (s >= e^2 w / g), independently of lcsim.

    PYTHONPATH=build/python /usr/bin/python3 examples/python/shooting.py
"""

import sys

import numpy as np

import lcsim

G, E, Z0, T, H = 9.81, 0.5, 1.0, 2.0, 0.1
V_START = 4.5  # Newton's start: two impacts before T, falling at T (closed form)

BALL = lcsim.Model.mechanical(M=[[1.0]], E=[[1.0]], f=[-G], restitution=[E], names=["z"],
                              constraint_names=["floor"])


def shoot(v0):
    """The run from (Z0, v0) to T: (z(T), dz(T)/dv0, number of impacts, run)."""
    run = lcsim.simulate(BALL, x0=[Z0, v0], t_end=T, sensitivity=["x0"])
    if not run.ok:
        raise RuntimeError(f"run failed at v0 = {v0}: {run.message}")
    if np.ma.is_masked(run.dx_dx0[-1, 0, 1]):
        raise RuntimeError(f"no derivative at v0 = {v0}: {run.sensitivity_losses}")
    impacts = sum(ev.type == "impact" for ev in run.events)
    return run.final_state[0], float(run.dx_dx0[-1, 0, 1]), impacts, run


def newton(v0=V_START, tol=1e-12, max_iter=20):
    """Newton on z(T; v0) = H; a step that changes the number of impacts is halved.
    Converged when the step is below tol relative to v0: Newton converges quadratically,
    so the error after that step is at rounding. Returns (v0, iterations, z(T), impacts,
    run, converged)."""
    z, dz, impacts, run = shoot(v0)
    for it in range(1, max_iter + 1):
        step, lam = -(z - H) / dz, 1.0
        while True:
            trial = shoot(v0 + lam * step)
            if trial[2] == 2 or lam < 1e-6:
                break
            lam /= 2
        v0 += lam * step
        z, dz, impacts, run = trial
        if abs(lam * step) <= tol * abs(v0):
            return v0, it, z, impacts, run, True
    return v0, max_iter, z, impacts, run, False


def closed_form(v0):
    """z(T) and dz(T)/dv0 of the flight with two impacts before T, and s = T - t2."""
    w = np.sqrt(v0 * v0 + 2 * G * Z0)
    s = T - (v0 + (1 + 2 * E) * w) / G
    dw = v0 / w
    ds = -(1 + (1 + 2 * E) * dw) / G
    z = E * E * w * s - G * s * s / 2
    return z, E * E * dw * s + (E * E * w - G * s) * ds, s, w


def closed_form_root():
    """v0 with z(T) = H on the falling branch, by bisection of the closed form. At
    V_START the ball is below H and falling at T; as v0 grows the second impact comes
    later and z(T) rises until the apex of the third flight is at T (s = e^2 w / g),
    which ends the branch. The bracket is found by walking up from V_START."""
    lo, hi = V_START, V_START
    while True:  # walk up to the apex (s = e^2 w / g) in small steps: z rises there
        z, _, s, w = closed_form(hi)
        if z >= H or s <= E * E * w / G:
            break
        lo, hi = hi, hi + 0.01
    assert closed_form(lo)[0] < H <= closed_form(hi)[0], "no root on the falling branch"
    for _ in range(200):
        mid = (lo + hi) / 2
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if closed_form(mid)[0] < H else (lo, mid)
    return (lo + hi) / 2


def main():
    v0, it, z, impacts, run, ok = newton()
    ref = closed_form_root()
    _, dz_ref, _, _ = closed_form(v0)
    print(f"ball from z0 = {Z0} m, e = {E}: reach H = {H} m at T = {T} s after two impacts")
    print(f"Newton from v0 = {V_START}: {it} iterations{'' if ok else ' NOT CONVERGED'}")
    print(f"  v0 = {v0:.15f} m/s   (closed form {ref:.15f}, difference {v0 - ref:.1e})")
    print(f"  z(T) = {z:.15f} m   (error {z - H:.1e}), impacts at "
          f"{[round(ev.t, 6) for ev in run.events if ev.type == 'impact']}")
    print(f"  dz(T)/dv0 = {run.dx_dx0[-1, 0, 1]:.15f}   (closed form {dz_ref:.15f})")
    return 0 if ok and impacts == 2 else 3


if __name__ == "__main__":
    sys.exit(main())
