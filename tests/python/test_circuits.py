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
                            "(lcsim reads R, C, L, V, I, E, F, G, H, D, S and X)")


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


def test_buck_converter_loads_and_switches(robots):
    # circuits/buck_converter.cir: the switch S1 on at k T + 0.5 ns, off at
    # k T + 5.0005 us (T = 10 us), each a scheduled event (tests/circuit,
    # test_switches.cpp, checks the waveform against the closed form).
    model = lcsim.load(str(robots.parent / "circuits" / "buck_converter.cir"))
    run = lcsim.simulate(model, t_end=50e-6, dt_out=1e-6)
    switches = [e for e in run.events if e.type == "schedule" and "switch: S1" in e.note]
    assert len(switches) == 10
    for k, e in enumerate(switches):
        expected = (k // 2) * 10e-6 + (0.5e-9 if k % 2 == 0 else 5.0005e-6)
        assert abs(e.t - expected) < 1e-15  # one division: a few ulp (test_switches.cpp)
        assert e.note == "switch: S1 " + ("on" if k % 2 == 0 else "off")
    # The CSV's outputs follow the configuration: V(sw) is Vin - RON i while
    # S1 is on, 0 while D1 freewheels (1e-9 V: rounding of ~12 V).
    rows = run.to_csv().splitlines()
    header = rows[0].split(",")
    t_col, sw_col, i_col = header.index("t"), header.index("V(sw)"), header.index("L1.i")
    for line in rows[1:]:
        cells = line.split(",")
        t, vsw, i = float(cells[t_col]), float(cells[sw_col]), float(cells[i_col])
        phase = t % 10e-6
        if 1e-8 < phase < 5e-6:
            assert abs(vsw - (12.0 - 0.01 * i)) < 1e-9
        elif 5.1e-6 < phase < 9.9e-6:
            assert abs(vsw) < 1e-9
