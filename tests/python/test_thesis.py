"""The thesis's cases through Python, against their exact values.

Tolerances (as tests/sim/test_event_driven.cpp): the phases are matrix exponentials
(relative error ~1e-15 per evaluation) and events are roots found by Brent's method to
machine precision, so event times and states are good to ~1e-13; 1e-10 leaves room for
the rounding of scipy's expm (the independent reference here) and is far below any
modelling error (a wrong mode or impulse shows at O(1e-3) or more).
"""

import math

import numpy as np
import pytest
import scipy.linalg

import lcsim

TOL = 1e-10
# A of (3.1) on (x1, x2, x3, x4): the free motion of the two carts.
A = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-2, 1, 0, 0], [1, -1, 0, 0]], dtype=float)


def two_carts(hook):
    """The carts of thesis §3.7 built from numpy matrices (Figure 3.1; Example 3.8.3
    adds the hook x1 - x2 >= 0)."""
    E = np.array([[1.0, 0.0], [1.0, -1.0]]) if hook else np.array([[1.0, 0.0]])
    return lcsim.Model.mechanical(np.eye(2), np.array([[2.0, -1.0], [-1.0, 1.0]]), E,
                                  names=["x1", "x2"])


def test_two_carts_section_3_7():
    """Impact at t = 1 from e^{-A}(0,-1,-1,0); the constrained phase x2 = -cos(t-1),
    u = cos(t-1); release at 1 + pi/2 at (0,0,0,1); free motion to T = 3."""
    x0 = scipy.linalg.expm(-A) @ np.array([0.0, -1, -1, 0])
    run = lcsim.simulate(two_carts(False), x0=x0, t_end=3.0, dt_out=0.01)
    assert run.status == "completed", run.message
    assert [e.type for e in run.events] == ["impact", "release"]
    impact, release = run.events
    assert impact.t == pytest.approx(1.0, abs=TOL)
    np.testing.assert_allclose(impact.state_before, [0, -1, -1, 0], atol=TOL)
    np.testing.assert_allclose(impact.state_after, [0, -1, 0, 0], atol=TOL)
    assert impact.mode == [0]
    assert impact.impulse[0] == pytest.approx(1.0, abs=TOL)  # u^0 = -x3 = 1
    assert release.t == pytest.approx(1 + math.pi / 2, abs=TOL)
    np.testing.assert_allclose(release.state_after, [0, 0, 0, 1], atol=TOL)
    assert release.mode == []
    xT = scipy.linalg.expm(A * (3.0 - 1.0 - math.pi / 2)) @ np.array([0.0, 0, 0, 1])
    np.testing.assert_allclose(run.final_state, xT, atol=TOL)
    # The constrained phase, on the output grid (pi/2 / 0.01 = 157 points).
    inside = (run.t > 1 + 1e-9) & (run.t < 1 + math.pi / 2 - 1e-9)
    assert inside.sum() >= 150
    np.testing.assert_allclose(run.q[inside, 1], -np.cos(run.t[inside] - 1), atol=TOL)
    np.testing.assert_allclose(run.u[inside, 0], np.cos(run.t[inside] - 1), atol=TOL)
    np.testing.assert_allclose(run.q[inside, 0], 0.0, atol=TOL)
    # Inelastic impact: the energy drops by ½ x3² = ½ at t = 1, nothing else.
    assert run.energy_initial - run.energy_final == pytest.approx(0.5, abs=TOL)
    assert run.max_violation >= -1e-12


def test_shipped_two_carts_model(robots):
    """The shipped file holds the same initial state and horizon: the same events."""
    model = lcsim.load(robots / "two_carts.yaml")
    np.testing.assert_allclose(model.initial, scipy.linalg.expm(-A) @ [0, -1, -1, 0],
                               rtol=0, atol=1e-15)
    run = lcsim.simulate(model)
    assert run.t_end == 3.0
    assert [e.t for e in run.events] == pytest.approx([1.0, 1 + math.pi / 2], abs=TOL)


def test_example_3_8_3_hook_only():
    """From (0,0,-1,2) the hook alone is selected: a jump to (0,0,½,½), impulse 3/2."""
    run = lcsim.simulate(two_carts(True), x0=[0, 0, -1, 2], t_end=0.1)
    assert run.ok, run.message
    first = run.events[0]
    assert first.t == 0.0
    np.testing.assert_allclose(first.state_after, [0, 0, 0.5, 0.5], atol=TOL)
    assert first.mode == [1]
    np.testing.assert_allclose(first.impulse, [0.0, 1.5], atol=TOL)


def test_example_3_8_3_rules_on_the_hook(robots):
    """Moreau's law at the hook's state gives the same jump as the run; every law
    keeps the kinetic energy from rising (all restitutions are 0)."""
    model = lcsim.load(robots / "two_carts_hook.yaml")
    results = lcsim.impacts(model, [0, 0, -1, 2])
    assert set(results) == set(lcsim.impact_law_names())
    moreau = results["newton"]  # 'moreau', newton's old name, is an alias
    assert moreau.ok, moreau.message
    np.testing.assert_allclose(moreau.v_after, [0.5, 0.5], atol=TOL)
    np.testing.assert_allclose(moreau.impulse, [0.0, 1.5], atol=TOL)
    # T = ½ |v|²: 2.5 before, ¼ after.
    assert moreau.energy_before == pytest.approx(2.5, abs=TOL)
    assert moreau.energy_after == pytest.approx(0.25, abs=TOL)


def test_solve_lcp_closed_form():
    """M = [[2, 1], [1, 2]], q = (-1, -1): both active, z = M^{-1}(1, 1) = (1/3, 1/3)."""
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    for solver in lcsim.solver_names():
        r = lcsim.solve_lcp(M, [-1.0, -1.0], solver=solver)
        assert r.status == "solved", (solver, r.message)
        # PGS stops at its acceptance tolerance (1e-12 scaled), the pivoting
        # solvers are exact to rounding: 1e-9 covers both.
        np.testing.assert_allclose(r.z, [1 / 3, 1 / 3], atol=1e-9, err_msg=solver)


def test_analyze_two_carts():
    """E M^{-1} E' of the carts with the hook: [[1, 1], [1, 2]] (M = I), a P-matrix."""
    a = lcsim.analyze(two_carts(True))
    np.testing.assert_array_equal(a["delassus"], [[1.0, 1.0], [1.0, 2.0]])
    assert a["delassus_p_matrix"] is True
    assert a["E_rank"] == 2
