"""Scenes of several bodies (issue 26 part A) load in Python unchanged and run:
the gripper closing on the box and the Vision 60 quadruped dropped onto its toes,
their first impacts at the closed-form times (docs/contacts.md)."""

import math

import lcsim


def first_impact(run):
    return next(e for e in run.events if max(abs(p) for p in e.impulse) > 0.0)


def test_gripper_scene_loads_and_closes_at_the_closed_form_time(robots):
    model = lcsim.load(robots / "gripper_box_scene.yaml")
    run = lcsim.simulate(model)
    assert run.ok, run.message
    # Each finger q(t) = 0.05 + 0.1 cos(20 t) meets the box's face at q = 0.11:
    # a root found to rounding (1e-12 s).
    assert abs(first_impact(run).t - math.acos(0.6) / 20.0) <= 1e-12
    assert abs(run.final_state[4] - 0.05) <= 1e-12  # the box is still on the floor


def test_vision60_scene_loads_and_lands_at_sqrt_2h_over_g(robots):
    model = lcsim.load(robots / "vision60_drop_scene.yaml")
    run = lcsim.simulate(model)
    assert run.ok, run.message
    assert abs(first_impact(run).t - math.sqrt(2 * 0.03 / 9.81)) <= 1e-12
    assert max(abs(v) for v in run.final_state[18:]) <= 1e-8  # settled (as the C++ test)
