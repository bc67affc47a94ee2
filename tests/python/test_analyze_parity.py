"""`lcsim analyze --json` and `lcsim.analyze` are one report (app::analysis_report):
on a matrix model, a scene, a friction model and an LCS model, in summary and in full,
the dict Python returns equals the JSON the command prints, field for field. Likewise
`lcsim impacts --json` and `lcsim.impacts` (app::impacts_at_state) at a state."""

import json
import subprocess

import numpy as np
import pytest

import lcsim

# One of each kind of model file of robots/: a matrix model with two contacts, a URDF
# scene (linear ranges), a model with friction, an LCS given by (A, B, C, D).
MODELS = ["two_carts_hook.yaml", "two_carts_hook_scene.yaml", "block_on_floor_friction.yaml",
          "triple_integrator.yaml"]


def cli_json(lcsim_binary, *args):
    r = subprocess.run([str(lcsim_binary), *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def assert_same_fields(cli, py):
    """Equal dicts, reported by the first field that differs. No tolerance: both are
    the same doubles, printed by nlohmann::json to round-trip and parsed by Python."""
    assert sorted(py) == sorted(cli)
    for key in cli:
        assert py[key] == cli[key], key


@pytest.mark.parametrize("name", MODELS)
@pytest.mark.parametrize("full", [False, True])
def test_analyze_is_the_cli_report(name, full, robots, lcsim_binary):
    path = robots / name
    cli = cli_json(lcsim_binary, "analyze", path, "--json", *(["--full"] if full else []))
    assert_same_fields(cli, lcsim.analyze(lcsim.load(path), full=full))


def test_the_report_has_the_cli_fields(robots):
    """What the CLI said and Python did not before: E_rank (was rank_E), the
    summary's left_out and not_judged, M's eigenvalues."""
    a = lcsim.analyze(lcsim.load(robots / "two_carts_hook.yaml"))
    assert a["E_rank"] == 2 and "rank_E" not in a
    assert a["full"] is False and a["left_out"] == [] and a["not_judged"] == []
    assert a["M_min_eigenvalue"] == a["M_max_eigenvalue"] == 1.0  # M = I (two unit carts)


def test_a_scene_threshold_is_the_cli_option(robots, lcsim_binary):
    path = robots / "two_carts_scene.yaml"
    cli = cli_json(lcsim_binary, "analyze", path, "--json", "--linearisation-threshold", "0.05")
    py = lcsim.analyze(lcsim.load(path), linearisation_threshold=0.05)
    assert py["linearisation_threshold"] == 0.05
    assert_same_fields(cli, py)


def test_a_bad_threshold_is_the_cli_error(robots, lcsim_binary):
    path = robots / "two_carts_scene.yaml"
    r = subprocess.run([str(lcsim_binary), "analyze", str(path), "--linearisation-threshold",
                        "-1"], capture_output=True, text=True)
    assert r.returncode == 2
    with pytest.raises(lcsim.InputError) as e:
        lcsim.analyze(lcsim.load(path), linearisation_threshold=-1.0)
    # The library names the field; the CLI prints it as its flag.
    assert str(e.value) == "linearisation_threshold must be a finite number > 0 (got -1)"
    assert r.stderr == "lcsim: error: --" + str(e.value).replace("_", "-") + "\n"


@pytest.mark.parametrize("name,x0", [("two_carts_hook.yaml", [0, 0, -1, 2]),
                                     ("block_on_floor_friction.yaml", None)])
def test_impacts_are_the_cli_rows(name, x0, robots, lcsim_binary):
    """Each law's row of `lcsim impacts --json` against lcsim.impacts' result: the same
    laws, and the same numbers to the last bit (one computation, printed to round-trip)."""
    path = robots / name
    args = ["impacts", path, "--json"] + (["--x0", ",".join(map(str, x0))] if x0 else [])
    cli = cli_json(lcsim_binary, *args)
    py = lcsim.impacts(lcsim.load(path), x0)
    assert sorted(py) == sorted(cli["rules"])
    n = len(cli["state_before"]) // 2
    for law, row in cli["rules"].items():
        r = py[law]
        assert r.ok == row["ok"] and r.admissible == row["admissible"], law
        assert r.message == row["message"], law
        assert np.array_equal(r.v_after, row["state_after"][n:]), law
        assert np.array_equal(r.impulse, row["impulse"]), law
        assert (r.energy_before, r.energy_after) == (row["energy_before"], row["energy_after"])
        assert r.worst_rate == row["worst_violation"], law


@pytest.mark.parametrize("name,flags,kwargs", [
    ("two_carts_hook.yaml", ["--x0", "-5,0,-1,2"], {"x0": [-5, 0, -1, 2]}),
    ("two_carts_hook.yaml", ["--restitution", "2,0"], {"restitution": [2.0, 0.0]}),
    ("block_on_floor_friction.yaml", ["--rules", "sequential"], {"rules": ["sequential"]}),
])
def test_impacts_errors_name_the_field_and_the_cli_its_flag(name, flags, kwargs, robots,
                                                             lcsim_binary):
    """The library's message names the field (x0, restitution, rules); the command
    prints the same message with the field's flag."""
    path = robots / name
    with pytest.raises(lcsim.InputError) as e:
        lcsim.impacts(lcsim.load(path), **kwargs)
    field = next(iter(kwargs))
    assert str(e.value).startswith(field)
    r = subprocess.run([str(lcsim_binary), "impacts", str(path), *flags], capture_output=True,
                       text=True)
    assert r.returncode == 2
    assert r.stderr == f"lcsim: error: --{e.value}\n"
