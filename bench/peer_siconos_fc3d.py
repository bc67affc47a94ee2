#!/usr/bin/python3
"""lcsim's polyhedral friction cone at an impact against Siconos's fc3d (issue 27).

Siconos's fc3d_driver (NSGS, the exact circular cone, De Saxcé's formulation) and lcsim's
impact law 'inelastic' (impact::moreau_friction_cone, the pyramid of 2d edges) on the same
impacts, in one process:

1. A point mass hitting a rough floor with its tangential velocity at the angle psi from
   the first tangent: where the post-impact sliding velocity lies along an edge (psi = 0)
   the two agree to the solvers' tolerance; on a bisector lcsim's friction impulse is
   cos(pi/(2d)) of Siconos's (the pyramid's face is nearer the axis than the circle).
2. Seeded random impacts with several coupled contacts (N = 3k + 2, M SPD over two
   decades, orthonormal frames): the gap between the two post-impact velocities, relative
   to the velocity change, against the pyramid's anisotropy 1 - cos(pi/(2d)).

    cmake --build build --target lcsim_python
    PYTHONPATH=build/python /usr/bin/python3 bench/peer_siconos_fc3d.py [--trials N]
"""

import argparse
import math
import os
import tempfile

import numpy as np
import siconos.numerics as sn

import lcsim


def model_yaml(M, E, T1, T2, mu, d, v):
    rows = lambda A: "[" + ", ".join("[" + ", ".join(repr(float(x)) for x in r) + "]"
                                     for r in A) + "]"
    lst = lambda x: "[" + ", ".join(repr(float(a)) for a in x) + "]"
    fr = "".join(f"    - {{contact: {i}, tangents: [{lst(T1[i])}, {lst(T2[i])}], "
                 f"mu: {mu[i]!r}, d: {d}}}\n" for i in range(len(mu)))
    n = M.shape[0]
    return (f"name: fc3d\nmechanical:\n  M: {rows(M)}\n  E: {rows(E)}\n  friction:\n{fr}"
            f"initial: {lst(np.concatenate([np.zeros(n), v]))}\n")


def lcsim_impact(M, E, T1, T2, mu, d, v):
    with tempfile.NamedTemporaryFile("w", suffix=".yaml", delete=False) as f:
        f.write(model_yaml(M, E, T1, T2, mu, d, v))
        path = f.name
    try:
        r = lcsim.impacts(lcsim.load(path), rules=["inelastic"])["inelastic"]
    finally:
        os.unlink(path)
    return r


def siconos_impact(M, E, T1, T2, mu, v):
    k = E.shape[0]
    G = np.vstack([np.vstack([E[i], T1[i], T2[i]]) for i in range(k)])
    Minv = np.linalg.inv(M)
    W = G @ Minv @ G.T
    q = G @ v
    p = sn.FrictionContactProblem(3, k, W, q, np.asarray(mu, dtype=float))
    so = sn.SolverOptions(sn.SICONOS_FRICTION_3D_NSGS)
    so.dparam[sn.SICONOS_DPARAM_TOL] = 1e-14
    so.iparam[sn.SICONOS_IPARAM_MAX_ITER] = 100000
    r, u = np.zeros(3 * k), np.zeros(3 * k)
    info = sn.fc3d_driver(p, r, u, so)
    return info, v + Minv @ G.T @ r, r


def point_mass(d, mu=0.5, V=2.0, s=3.0):
    print(f"1. point mass on a rough floor, d = {d}, mu = {mu}, V = {V} m/s, "
          f"|u-| = {s} m/s: tangential impulse |P_T| (N s)")
    print("   psi/(pi/d)   lcsim        siconos      ratio        cos(pi/(2d)) angle (rad)")
    M, E = np.eye(3), np.array([[0.0, 0.0, 1.0]])
    T1, T2 = np.array([[1.0, 0.0, 0.0]]), np.array([[0.0, 1.0, 0.0]])
    for frac in (0.0, 0.25, 0.5, 1.0, 1.5):
        psi = frac * math.pi / d
        v = np.array([s * math.cos(psi), s * math.sin(psi), -V])
        r = lcsim_impact(M, E, T1, T2, [mu], d, v)
        info, _, rs = siconos_impact(M, E, T1, T2, [mu], v)
        pl = math.hypot(r.friction_impulse[0], r.friction_impulse2[0])
        ps = math.hypot(rs[1], rs[2])
        # The angle between the two friction impulses.
        ang = abs(math.remainder(math.atan2(r.friction_impulse2[0], r.friction_impulse[0]) -
                                 math.atan2(rs[2], rs[1]), 2 * math.pi))
        print(f"   {frac:<12g}{pl:<13.10f}{ps:<13.10f}{pl / ps:<13.10f}"
              f"{math.cos(math.pi / (2 * d)):<13.10f}{ang:.3g}  (siconos info {info})")


def random_impacts(trials, d, seed=27):
    rng = np.random.default_rng(seed)
    gaps, solved, skipped = [], 0, 0
    for _ in range(trials):
        k = int(rng.integers(2, 5))
        n = 3 * k + 2
        A = rng.standard_normal((n, n))
        M = 0.1 * A @ A.T + np.diag(10 ** (2 * rng.random(n) - 1))
        E = rng.standard_normal((k, n))
        T1, T2 = np.zeros((k, n)), np.zeros((k, n))
        for i in range(k):
            Q, _ = np.linalg.qr(np.column_stack([E[i], rng.standard_normal((n, 2))]))
            scale = np.linalg.norm(E[i])  # Siconos's cone is in the frame's units
            E[i] = Q[:, 0] * scale * np.sign(Q[:, 0] @ E[i])
            T1[i], T2[i] = Q[:, 1] * scale, Q[:, 2] * scale
        mu = list(0.1 + 0.4 * rng.random(k))
        v = rng.standard_normal(n)
        r = lcsim_impact(M, E, T1, T2, mu, d, v)
        info, vs, _ = siconos_impact(M, E, T1, T2, mu, v)
        if not r.ok or info != 0:
            skipped += 1
            continue
        dv = np.linalg.norm(vs - v, np.inf)
        if dv == 0.0:  # every contact separating: nothing to compare
            skipped += 1
            continue
        solved += 1
        gaps.append(np.linalg.norm(r.v_after - vs, np.inf) / dv)
    print(f"2. {trials} random coupled impacts (2-4 contacts), d = {d}: {solved} compared, "
          f"{skipped} skipped (Painlevé, a solver's failure, no impulse); "
          f"|v+ lcsim - v+ siconos| / |dv|: median {np.median(gaps):.3g}, worst "
          f"{max(gaps):.3g}; the pyramid's anisotropy: magnitude 1 - cos(pi/(2d)) = "
          f"{1 - math.cos(math.pi / (2 * d)):.3g}, direction pi/(2d) = {math.pi / (2 * d):.3g}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--trials", type=int, default=200)
    a = ap.parse_args()
    for d in (2, 4, 8):
        point_mass(d)
    for d in (2, 4, 8, 16):
        random_impacts(a.trials, d)


if __name__ == "__main__":
    main()
