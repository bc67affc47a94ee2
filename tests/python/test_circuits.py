"""SPICE netlists from Python (issue 29): lcsim.load reads a .cir like any model; an
initial state lists the circuit's states only (the sources' exosystem is the model's);
a bad netlist raises InputError with the library's one line."""

import math

import pytest

import lcsim


def test_rectifier_turns_off_where_the_closed_form_says(robots):
    model = lcsim.load(str(robots.parent / "circuits" / "half_wave_rectifier.cir"))
    run = lcsim.simulate(model, dt_out=1e-3)
    w, rc = 100 * math.pi, 0.1
    t_off = (math.pi - math.atan(w * rc)) / w  # C v' + v / R = 0 for v = 10 sin(w t)
    # 1e-12 s: the exact method finds the root to a few ulp (tests/circuit).
    assert abs(run.events[0].t - t_off) < 1e-12


def test_initial_state_lists_the_circuit_states_only(robots):
    model = lcsim.load(str(robots.parent / "circuits" / "half_wave_rectifier.cir"))
    run = lcsim.simulate(model, x0=[5.0], t_end=1e-4)
    # The state (C1.v, 1, V1.sin, V1.cos): the exosystem starts from the source.
    assert len(run.final_state) == 4
    assert run.final_state[1] == 1.0


def test_bad_netlist_raises_input_error(tmp_path):
    bad = tmp_path / "bad.cir"
    bad.write_text("title\nV1 a 0 1\nR1 a 0 1k\nQ1 a 0 b npn\n")
    with pytest.raises(lcsim.InputError) as e:
        lcsim.load(str(bad))
    assert str(e.value) == (f"{bad}:4: Q1: unknown element type 'Q' "
                            "(lcsim reads R, C, L, V, I, E, F, G, H, D and X)")


def test_pwl_source_breakpoints_are_scheduled_events(tmp_path):
    # A PWL into an RC (tau = 1 ms): a ramp of 1000 V/s to 1 V at 1 ms, held.
    net = tmp_path / "pwl.cir"
    net.write_text("PWL into an RC\nV1 in 0 PWL(0 0 1m 1 2m 1)\nR1 in out 1k\n"
                   "C1 out 0 1u\n.tran 10u 2m uic\n")
    model = lcsim.load(str(net))
    run = lcsim.simulate(model, dt_out=1e-4)
    scheduled = [e for e in run.events if e.type == "schedule"]
    assert [e.t for e in scheduled] == [1e-3]
    assert scheduled[0].note == "breakpoint of input 'V1'"
    # v(t) = a (t - tau + tau e^(-t/tau)) under the ramp: e^-1 at 1 ms; the
    # state (C1.v, 1, V1.p, V1.r). 1e-12 V: the rounding of a few matrix
    # exponentials (tests/circuit/test_sources.cpp).
    assert abs(scheduled[0].state_after[0] - math.exp(-1.0)) < 1e-12
    assert len(run.final_state) == 4
