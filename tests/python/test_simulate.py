"""lcsim.simulate's options and results beyond the thesis cases: the general LCS
built from matrices, the time-stepping methods' options, the progress callback, and
the arrays' consistency with the events and the final state."""

import numpy as np
import pytest

import lcsim

A = np.array([[0.0, 1, 0], [0, 0, 1], [0, 0, 0]])
B = np.array([[0.0], [0], [1]])
C = np.array([[1.0, 0, 0]])


def test_lcs_from_matrices_is_the_model_file(robots):
    """The triple integrator of Example 7.3.3 built by Model.lcs runs exactly as the
    shipped file (the same CSV text), and jumps to 0 at t = 0 (its consistent state)."""
    built = lcsim.Model.lcs(A, B, C, np.zeros((1, 1)), name="triple_integrator",
                            initial=[0, -1, 0], t_end=1.0)
    loaded = lcsim.load(robots / "triple_integrator.yaml")
    a = lcsim.simulate(built, dt_out=0.1)
    b = lcsim.simulate(loaded, dt_out=0.1)
    assert a.ok and a.to_csv() == b.to_csv()
    assert not built.is_mechanical and built.state_size == 3
    np.testing.assert_array_equal(a.events[0].state_after, [0.0, 0.0, 0.0])


def test_lcs_sizes_are_checked():
    with pytest.raises(lcsim.InputError, match=r"lcs\.B"):
        lcsim.Model.lcs(A, np.ones((2, 1)), C, np.zeros((1, 1)))


def test_arrays_agree_with_events_and_final_state(robots):
    run = lcsim.simulate(lcsim.load(robots / "two_carts.yaml"), dt_out=0.1)
    n = len(run.t)
    assert run.x.shape == (n, 4) and run.u.shape == (n, 1) and run.y.shape == (n, 1)
    assert run.modes.shape == (n, 1) and run.modes.dtype == bool
    np.testing.assert_array_equal(np.hstack([run.q, run.v]), run.x)
    np.testing.assert_array_equal(run.x[-1], run.final_state)
    assert run.t[0] == 0.0 and run.t[-1] == run.t_end == 3.0
    # The impact: two samples share its time, before and after, as the event says.
    i = int(np.flatnonzero(run.t == run.events[0].t)[0])
    np.testing.assert_array_equal(run.x[i], run.events[0].state_before)
    np.testing.assert_array_equal(run.x[i + 1], run.events[0].state_after)
    assert not run.modes[i, 0] and run.modes[i + 1, 0]
    # y is the gap E q + g of each sample (the stop: x1).
    np.testing.assert_array_equal(run.y[:, 0], run.q[:, 0])


def test_time_stepping_options(robots):
    """Moreau–Jean with h and theta; its energy loss at the impact is bounded by the
    exact one (½ J) plus the theta-method's numerical dissipation, O(h) over 3 s."""
    model = lcsim.load(robots / "two_carts.yaml")
    run = lcsim.simulate(model, method="moreau-jean", h=1e-3, theta=0.5)
    assert run.ok and run.method == "moreau-jean" and run.steps == 3000
    exact = lcsim.simulate(model)
    # theta = 1/2 conserves the energy of the free motion; the impact is
    # resolved on the step grid, so the loss differs from ½ by O(h |v|) per impact.
    loss = run.energy_initial - run.energy_final
    assert loss == pytest.approx(exact.energy_initial - exact.energy_final, abs=1e-2)


def test_progress_is_called_and_its_errors_propagate(robots):
    model = lcsim.load(robots / "two_carts.yaml")
    seen = []
    run = lcsim.simulate(model, method="moreau-jean", h=1e-4, progress=seen.append)
    assert run.ok and seen and seen == sorted(seen) and 0 < seen[-1] <= 3.0

    def fail(t):
        raise KeyError("stop")

    with pytest.raises(KeyError, match="stop"):
        lcsim.simulate(model, method="moreau-jean", h=1e-4, progress=fail)


def test_warnings_are_counted_per_kind(robots):
    """Backward Euler ignores the ball's e = 0.5 and says so once: one warning of
    kind 'restitution-ignored', at t = 0, as the CLI's JSON reports it."""
    ball = lcsim.load(robots / "ball.yaml")
    run = lcsim.simulate(ball, method="euler", h=1e-3, t_end=0.5)
    assert run.ok, run.message
    assert run.warning_count == 1
    (w,) = run.warnings
    assert w["kind"] == "restitution-ignored" and w["count"] == 1 and w["first_t"] == 0.0
    assert "ignores restitution" in w["message"]


def test_friction_from_matrices_is_the_model_file(robots):
    """Model.mechanical(friction=...) builds robots/belt_friction.yaml's model (a
    contact by name, a moving surface), and the runs agree to the bit; the friction
    modes come out as FRICTION_MODES indices, the multipliers as u_t."""
    built = lcsim.Model.mechanical(
        M=np.eye(2), K=np.diag([4.0, 0.0]), E=[[0.0, 1.0]], f=[0.0, -9.81],
        names=["x", "y"], constraint_names=["belt"], name="belt_friction",
        friction=[{"contact": "belt", "tangent": [1.0, 0.0], "mu": 0.1, "velocity": 0.2}])
    shipped = lcsim.load(robots / "belt_friction.yaml")
    x0 = np.zeros(4)
    runs = [lcsim.simulate(m, x0=x0, t_end=0.5, method="moreau-jean", h=1e-3)
            for m in (built, shipped)]
    assert all(r.ok for r in runs), [r.message for r in runs]
    np.testing.assert_array_equal(runs[0].x, runs[1].x)
    np.testing.assert_array_equal(runs[0].u_t, runs[1].u_t)
    assert runs[0].friction_modes.shape == (len(runs[0].t), 1)
    assert runs[0].friction_modes.dtype == np.int8
    assert set(np.unique(runs[0].friction_modes)) <= {-1, 0, 1, 2, 3}
    assert lcsim.FRICTION_MODES == ("open", "stick", "slip+", "slip-", "slip")


def test_bad_friction_entries_name_them():
    with pytest.raises(lcsim.InputError, match=r"friction\[0\]\.contact: no constraint named"):
        lcsim.Model.mechanical(M=np.eye(2), E=[[0.0, 1.0]],
                               friction=[{"contact": "roof", "tangent": [1, 0], "mu": 0.1}])
    with pytest.raises(lcsim.InputError, match=r"friction\[0\]\.mu: must be >= 0"):
        lcsim.Model.mechanical(M=np.eye(2), E=[[0.0, 1.0]],
                               friction=[{"contact": 0, "tangent": [1, 0], "mu": -1}])
    with pytest.raises(lcsim.InputError, match=r"friction\[0\]\.speed: unknown key"):
        lcsim.Model.mechanical(M=np.eye(2), E=[[0.0, 1.0]],
                               friction=[{"contact": 0, "tangent": [1, 0], "mu": 1, "speed": 2}])
