"""Invariant tests a user writes for their own models, here on seeded random
mechanical models (M = R R' + I, K = S S', D = 0.1 P P' >= 0, random contacts E q + g
>= 0 with g > 0, f = 0, every restitution 0):

- the energy never rises through an inelastic impact (Moreau's law dissipates);
- the post-impact state is feasible: gaps >= 0 and closed contacts separate (E_J v+ >= 0);
- complementarity holds on every sample: u >= 0, y >= 0, u'y = 0;
- and the total energy never rises over the run (D >= 0, no force).

Tolerances: 1e-9 relative to the energy and state scale, far above rounding (1e-15 per
matrix exponential) and far below what a wrong mode or impulse would cause (O(1e-2) for
these data, as in tests/sim/test_event_driven.cpp).
"""

import numpy as np
import pytest

import lcsim

TOL = 1e-9


def random_model(seed, N=3, k=2):
    rng = np.random.default_rng(seed)
    R, S, P = (rng.uniform(-1, 1, (N, N)) for _ in range(3))
    model = lcsim.Model.mechanical(R @ R.T + np.eye(N), S @ S.T, rng.uniform(-1, 1, (k, N)),
                                   D=0.1 * P @ P.T, g=0.25 * (rng.uniform(-1, 1, k) + 1))
    x0 = np.concatenate([np.zeros(N), 2 * rng.uniform(-1, 1, N)])
    return model, x0


def energy(model, x):
    n = model.dofs
    q, v = x[:n], x[n:]
    return 0.5 * v @ (model.M @ v) + 0.5 * q @ (model.K @ q) - model.f @ q


@pytest.mark.parametrize("seed", range(20))
def test_random_model_invariants(seed):
    model, x0 = random_model(seed)
    run = lcsim.simulate(model, x0=x0, t_end=5.0, dt_out=0.01)
    assert run.ok, run.message
    E, g = model.E, model.g
    scale = 1 + np.abs(run.x).max()
    E0 = energy(model, x0)
    assert run.energy_initial == pytest.approx(E0, rel=1e-12)
    for ev in run.events:
        if ev.type != "impact":
            continue
        before, after = energy(model, ev.state_before), energy(model, ev.state_after)
        assert after <= before + TOL * (1 + abs(before)), f"impact at t = {ev.t} added energy"
        q, v = ev.state_after[:model.dofs], ev.state_after[model.dofs:]
        gaps = E @ q + g
        assert gaps.min() >= -TOL * scale
        closed = np.abs(gaps) <= TOL * scale
        assert (E @ v)[closed].min(initial=0.0) >= -TOL * scale, "a closed contact approaches"
    assert run.y.min() >= -TOL * scale, "a gap went negative"
    assert run.u.min() >= -TOL * scale, "a negative contact force"
    assert np.abs((run.u * run.y).sum(axis=1)).max() <= TOL * scale**2, "u'y != 0"
    energies = np.array([energy(model, x) for x in run.x])
    assert energies.max() <= E0 + TOL * (1 + abs(E0)), "the energy rose"
