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
