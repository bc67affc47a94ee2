"""Tests of the two worked examples of exact derivatives through impacts (issue 28,
docs/sensitivities.md): system_identification.py (Gauss-Newton on (e, k) of a mass on a
spring bouncing on a stop) and shooting.py (Newton on the initial velocity of a bouncing
ball). No timing is asserted: the examples print it."""

import numpy as np
import pytest

import shooting
import system_identification as sysid


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_identification_recovers_e_and_k(seed):
    """The fit with the exact Jacobian converges and recovers (e, k) within 4 standard
    deviations of the estimate. To first order in the noise, theta_hat - theta =
    (J'J)^-1 J' n with n ~ N(0, sigma^2 I), so the error is N(0, sigma^2 (J'J)^-1); the
    bias of the nonlinearity is O(sigma^2) relative (~1e-4 of the values here), far below
    the standard deviations (~1.4e-3 for e, ~8e-3 for k). 4 standard deviations: a
    correct fit misses with probability 6e-5 per parameter (the seeds are fixed, so the
    test is deterministic; measured |error| / sd <= 1.3 over seeds 1-5), while e off by
    0.01 (7 sd) fails. The standard deviations themselves are asserted small, so the
    bound says something: both parameters are identified from the impacts."""
    data, fits = sysid.fit_both(seed)
    exact, fd = fits["exact Jacobian"], fits["central differences"]
    assert exact["converged"] and fd["converged"]
    J = exact["J"]
    sd = sysid.SIGMA * np.sqrt(np.diag(np.linalg.inv(J.T @ J)))
    assert sd[0] < 0.005 and sd[1] < 0.02
    assert np.all(np.abs(exact["theta"] - sysid.TRUE) <= 4 * sd)
    # Both fits stop at a zero of J' r. The central differences' Jacobian differs from
    # the exact one by ~1e-9 (test below), which moves that zero by ~1e-9 sd-scaled:
    # agreement to 1e-7 relative is a hundredfold margin (measured <= 3.3e-10 absolute).
    np.testing.assert_allclose(fd["theta"], exact["theta"], rtol=1e-7)
    # The same iterates, but the exact Jacobian costs one run per iteration instead of
    # five (a count, not a time).
    assert exact["runs"] < fd["runs"]


def test_identification_jacobian_matches_central_differences():
    """dq/d(e, k) at the grid samples against central differences with the relative step
    1e-6: truncation h^2 |q'''| / 6 ~ 1e-11, rounding ~1e-13 max|q| / h ~ 1e-7; 1e-6 is a
    tenfold margin over the rounding (measured 5e-10, for entries up to 5)."""
    _, J = sysid.positions(sysid.TRUE, jacobian=True)
    np.testing.assert_allclose(J, sysid.fd_jacobian(sysid.TRUE), rtol=0, atol=1e-6)


def test_shooting_reaches_the_target_after_two_impacts():
    """Newton converges, the final height is the target to the run's rounding, exactly two
    impacts happen (at the closed form's t1 = (v0 + w) / g and t2 = t1 + 2 e w / g), and
    v0 and dz(T)/dv0 agree with the closed form (shooting.py's docstring).

    Tolerances: the run's states carry ~1e-13 of their scale in rounding (the estimate of
    docs/sensitivities.md's tests); the state is up to w ~ 6.3 m/s here, so z(T) is H to
    1e-13 * 6.3 * 16 = 1e-11 (margin 16; measured 3e-17, Newton's last step removing the
    rest). The closed form's own rounding is ~10 eps on terms ~1 (1e-14). An error dz in
    z(T) moves the root by dz / (dz/dv0): v0 agrees to (1e-11 + 1e-14) / (dz/dv0)
    (measured 2e-15). The impact times agree to the same rounding over g: 1e-11. The
    derivative: 1e-11, as the ball's closed forms in tests/python/test_sensitivity.py."""
    v0, iterations, z, impacts, run, converged = shooting.newton()
    assert converged
    scale = np.abs(run.x).max()
    tol_z = 1e-13 * scale * 16
    assert 5 < scale < 8 and tol_z < 2e-11
    assert abs(z - shooting.H) <= tol_z
    assert impacts == 2
    assert all(ev.type in ("start", "impact") for ev in run.events)
    ref = shooting.closed_form_root()
    z_ref, dz_ref, s, w = shooting.closed_form(ref)
    assert abs(z_ref - shooting.H) <= 1e-14
    assert 0 < dz_ref and s >= shooting.E**2 * w / shooting.G  # falling, no third impact
    assert abs(v0 - ref) <= (tol_z + 1e-14) / dz_ref
    assert abs(run.dx_dx0[-1, 0, 1] - dz_ref) <= 1e-11
    t1 = (ref + w) / shooting.G
    t2 = t1 + 2 * shooting.E * w / shooting.G
    times = [ev.t for ev in run.events if ev.type == "impact"]
    np.testing.assert_allclose(times, [t1, t2], rtol=0, atol=1e-11)


def test_scripts_run():
    """Both scripts print their table and exit 0 (converged; two impacts)."""
    assert sysid.main() == 0
    assert shooting.main() == 0
