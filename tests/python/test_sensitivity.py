"""Forward sensitivities from Python (simulate(..., sensitivity=[...])): run.dx_dx0 and
run.dx_dp as numpy masked arrays, the same numbers as the CLI's JSON, masked where the
derivative does not exist (docs/sensitivities.md). The numbers themselves are checked
against closed forms and finite differences in tests/sim/test_sensitivity.cpp."""

import json
import subprocess

import numpy as np
import pytest

import lcsim


def test_ball_derivatives_match_closed_form(robots):
    """The ball from 1 m at rest, e = 0.5, to T = 1.1 (two bounces): with w = sqrt(2 g z0),
    t2 = (1 + 2 e) w / g and z(T) = c s - g s^2 / 2, c = e^2 w, s = T - t2, so
    dz/dz0 = e^2 g s / w - (c - g s) (1 + 2 e) / w and dz/de = 2 e w s - (c - g s) 2 w / g.
    Rounding-level agreement (1e-11, as the C++ test)."""
    model = lcsim.load(robots / "ball.yaml")
    run = lcsim.simulate(model, t_end=1.1, dt_out=0.1, sensitivity=["x0", "e[ground]"])
    assert run.ok and run.sensitivity_columns == ["x0[0]", "x0[1]", "e[ground]"]
    n = len(run.t)
    assert run.dx_dx0.shape == (n, 2, 2) and run.dx_dp["e[ground]"].shape == (n, 2)
    assert not np.ma.is_masked(run.dx_dx0)
    g, e, z0, T = 9.81, 0.5, 1.0, 1.1
    w = np.sqrt(2 * g * z0)
    s = T - (1 + 2 * e) * w / g
    c = e * e * w
    dz_dz0 = e * e * g * s / w - (c - g * s) * (1 + 2 * e) / w
    dz_de = 2 * e * w * s - (c - g * s) * 2 * w / g
    assert abs(run.dx_dx0[-1, 0, 0] - dz_dz0) < 1e-11
    assert abs(run.dx_dp["e[ground]"][-1, 0] - dz_de) < 1e-11
    assert run.events[1].dt[2] == pytest.approx(2 * w / g, abs=1e-12)  # dt2/de = 2 w / g


def test_grazing_start_is_masked():
    """The ball resting on the ground at t = 0: dx/dx0 does not exist (masked), and the
    loss names the contact; dx/df exists (the contact force stays positive)."""
    model = lcsim.Model.mechanical(M=[[1.0]], E=[[1.0]], f=[-9.81], restitution=[0.5],
                                   constraint_names=["ground"])
    run = lcsim.simulate(model, x0=[0.0, 0.0], t_end=1.0, dt_out=0.5,
                         sensitivity=["x0", "f[0]"])
    assert run.ok
    assert run.dx_dx0.mask.all()
    assert not np.ma.is_masked(run.dx_dp["f[0]"])
    np.testing.assert_array_equal(run.dx_dp["f[0]"][-1], [0.0, 0.0])
    assert [(l["contact"], l["t"]) for l in run.sensitivity_losses] == [("ground", 0.0)]


def test_same_numbers_as_the_cli(robots, lcsim_binary):
    path = robots / "two_carts.yaml"
    run = lcsim.simulate(lcsim.load(path), sensitivity=["x0", "K[0][1]"])
    out = subprocess.run([str(lcsim_binary), "simulate", str(path), "--json",
                          "--sensitivity", "x0,K[0][1]"], capture_output=True, text=True,
                         check=True)
    cli = json.loads(out.stdout)["sensitivity"]
    assert cli["columns"] == run.sensitivity_columns
    np.testing.assert_array_equal(np.array(cli["final"])[:, :4], run.dx_dx0[-1])
    np.testing.assert_array_equal(np.array(cli["final"])[:, 4], run.dx_dp["K[0][1]"][-1])


def test_refusals_are_input_errors(robots):
    model = lcsim.load(robots / "two_carts.yaml")
    with pytest.raises(lcsim.InputError, match="no coordinate 'x9'"):
        lcsim.simulate(model, sensitivity=["f[x9]"])
    with pytest.raises(lcsim.InputError, match="does not compute"):
        lcsim.simulate(model, method="moreau-jean", sensitivity=["g[stop]"])


def test_circuit_entries_same_numbers_as_the_cli(robots, lcsim_binary):
    """A general LCS's entries by the states' and the pair's names (docs/sensitivities.md):
    D[D1][D1] (the diode's series resistance) and A[C1.v][L1.i] on the half-wave RLC, the
    same numbers as the CLI; a loss names the pair (the rectifier's start on its diode's
    switching surface: 'D1'); an entry on a scheme is refused."""
    path = robots.parent / "circuits" / "half_wave_rlc.cir"
    cols = ["x0", "D[D1][D1]", "A[C1.v][L1.i]"]
    run = lcsim.simulate(lcsim.load(path), t_end=1e-3, sensitivity=cols)
    out = subprocess.run([str(lcsim_binary), "simulate", str(path), "--json", "--t-end", "1e-3",
                          "--sensitivity", ",".join(cols)], capture_output=True, text=True,
                         check=True)
    cli = json.loads(out.stdout)["sensitivity"]
    assert cli["columns"] == run.sensitivity_columns
    final = np.array(cli["final"])
    np.testing.assert_array_equal(final[:, 3], run.dx_dp["D[D1][D1]"][-1])
    np.testing.assert_array_equal(final[:, 4], run.dx_dp["A[C1.v][L1.i]"][-1])
    assert not np.ma.is_masked(run.dx_dp["D[D1][D1]"])
    rect = lcsim.simulate(lcsim.load(robots.parent / "circuits" / "half_wave_rectifier.cir"),
                          t_end=1e-2, sensitivity=["x0"])
    assert rect.sensitivity_losses[0]["contact"] == "D1"
    with pytest.raises(lcsim.InputError, match="does not compute a general LCS"):
        lcsim.simulate(lcsim.load(path), method="euler", sensitivity=["D[D1][D1]"])


def test_input_parameters_same_numbers_as_the_cli(robots, lcsim_binary):
    """An input's own parameters (docs/sensitivities.md): the shaker table's frequency and
    phase, by the model file's keys and the input's name, the same numbers as the CLI; the
    first impact's dt1/dfrequency is the implicit function theorem's on the closed-form gap
    h - g t^2/2 - A sin(2 pi f t): -(2 pi t A cos a) / (g t + 2 pi f A cos a), a = 2 pi f t
    (1e-9 relative, as the C++ test); a name the input's kind has not is an input error."""
    path = robots / "shaker_table.yaml"
    cols = ["frequency[table]", "phase[table]"]
    run = lcsim.simulate(lcsim.load(path), t_end=1.5, sensitivity=cols)
    out = subprocess.run([str(lcsim_binary), "simulate", str(path), "--json", "--t-end", "1.5",
                          "--sensitivity", ",".join(cols)], capture_output=True, text=True,
                         check=True)
    cli = json.loads(out.stdout)["sensitivity"]
    assert cli["columns"] == run.sensitivity_columns == cols
    final = np.array(cli["final"])
    np.testing.assert_array_equal(final[:, 0], run.dx_dp["frequency[table]"][-1])
    np.testing.assert_array_equal(final[:, 1], run.dx_dp["phase[table]"][-1])
    assert not np.ma.is_masked(run.dx_dp["frequency[table]"])
    t, g, A, f = run.events[0].t, 9.81, 0.05, 5.0
    a = 2 * np.pi * f * t
    want = -(2 * np.pi * t * A * np.cos(a)) / (g * t + 2 * np.pi * f * A * np.cos(a))
    assert run.events[0].dt[0] == pytest.approx(want, rel=1e-9)
    with pytest.raises(lcsim.InputError, match="has no pwl_v"):
        lcsim.simulate(lcsim.load(path), sensitivity=["pwl_v[table][0]"])
