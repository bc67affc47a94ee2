"""The command line and Python give bitwise-identical results on every shipped model:
`lcsim simulate MODEL --out f.csv --json` against Trajectory.to_csv/to_json of
lcsim.simulate with the same options. The texts are compared byte for byte, except the
JSON's wall_time_s (a clock reading). Horizons are cut to keep the suite quick."""

import json
import re
import subprocess

import pytest

import lcsim

# Every model file of robots/ (lcp_example.yaml is an LCP problem, not a model).
MODELS = ["ball.yaml", "triple_integrator.yaml", "two_carts.yaml", "two_carts_hook.yaml",
          "two_carts_scene.yaml", "two_carts_hook_scene.yaml", "double_pendulum_scene.yaml",
          "prismatic_chain_scene.yaml", "arm_gripper_scene.yaml", "kuka_iiwa_scene.yaml",
          "panda_gripper_scene.yaml", "nao_legs_scene.yaml",
          "block_on_floor_friction.yaml", "incline_friction.yaml", "mass_spring_friction.yaml",
          "spinning_disk_friction.yaml", "belt_friction.yaml",
          "box_drop_scene.yaml", "box_tip_scene.yaml", "box_slide_scene.yaml",
          "quadruped_drop_scene.yaml",
          "gripper_box_scene.yaml", "vision60_drop_scene.yaml", "shaker_table.yaml", "pwl_lift.yaml"]
HORIZON = 0.5  # s at most: 50 samples of dt_out, each model's events in that window


def test_every_model_is_listed(robots):
    shipped = {p.name for p in robots.glob("*.yaml")} - {"lcp_example.yaml"}
    assert shipped == set(MODELS)


def without_wall_time(text):
    return re.sub(r'\n *"wall_time_s": [^\n]*\n', "\n", text)


CASES = [(name, "default") for name in MODELS] + \
    [(name, "moreau-jean") for name in MODELS if "friction" in name]


@pytest.mark.parametrize("name,how", CASES)
def test_cli_and_python_agree(name, how, robots, lcsim_binary, tmp_path):
    path = robots / name
    model = lcsim.load(path)
    t_end = min(model.t_end or HORIZON, HORIZON)
    dt_out = t_end / 50
    # Friction models run twice, exact and Moreau-Jean: the tangential
    # multipliers' and friction modes' CSV columns are compared too.
    method = ["--method", "moreau-jean", "--h", "1e-3"] if how == "moreau-jean" else []
    kwargs = {"method": "moreau-jean", "h": 1e-3} if method else {}
    csv_path = tmp_path / "cli.csv"
    cli = subprocess.run([str(lcsim_binary), "simulate", str(path), "--t-end", repr(t_end),
                          "--dt-out", repr(dt_out), "--out", str(csv_path), "--json",
                          "--no-progress"] + method, capture_output=True, text=True)
    if cli.returncode == 2:  # refused: Python refuses it with the same message
        with pytest.raises(lcsim.InputError) as e:
            lcsim.simulate(model, t_end=t_end, dt_out=dt_out, **kwargs)
        assert str(e.value) in cli.stderr
        return
    run = lcsim.simulate(model, t_end=t_end, dt_out=dt_out, **kwargs)
    assert cli.returncode == (0 if run.ok else 3), cli.stderr
    assert without_wall_time(run.to_json()) == without_wall_time(cli.stdout)
    if run.ok:  # the CLI writes no CSV for a failed run
        assert run.to_csv() == csv_path.read_text()
        run.to_csv(tmp_path / "py.csv")
        assert (tmp_path / "py.csv").read_bytes() == csv_path.read_bytes()
    summary = json.loads(run.to_json())
    assert summary["status"] == run.status
    if "friction" in name:
        assert run.ok and "ut_" in run.to_csv().splitlines()[0], run.message
        assert "fm_" in run.to_csv().splitlines()[0]
    assert len(summary["events"]) == len(run.events)


def test_long_scene_run_reports_the_same_linearisation_check(robots, lcsim_binary, tmp_path):
    """Past 2 x 200 samples both thin the visited states the same way
    (scene::LinearisationStates) before the scene's linearisation check: 1001 samples."""
    path = robots / "two_carts_scene.yaml"
    cli = subprocess.run([str(lcsim_binary), "simulate", str(path), "--t-end", "1",
                          "--dt-out", "0.001", "--out", str(tmp_path / "cli.csv"), "--json",
                          "--no-progress"], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    run = lcsim.simulate(lcsim.load(path), t_end=1.0, dt_out=0.001)
    assert len(run.t) > 1000
    assert without_wall_time(run.to_json()) == without_wall_time(cli.stdout)
