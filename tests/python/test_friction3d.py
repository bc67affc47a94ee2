"""Three-dimensional friction (issue 27) from Python and from the CLI: `lcsim.impacts`
gives both tangential impulses and the cone facet of each contact, the same numbers as
`lcsim impacts --json`; a bad cone is one input-error line and exit 2."""

import json
import math
import subprocess

import numpy as np

import lcsim

MODEL = """name: p3
mechanical:
  M: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
  E: [[0, 0, 1]]
  constraints: [floor]
  friction:
    - {contact: floor, tangents: [[1, 0, 0], [0, 1, 0]], mu: 0.5%s}
initial: [0, 0, 0, %r, %r, -2]
"""


def test_impacts_give_both_impulses_and_the_facet(tmp_path, lcsim_binary):
    """v- tangential on the bisector of edges 0 and 1 (d = 4): it slides on, the impulse on
    the opposite face (edges 4 and 5), mu P_N cos(pi/8) = cos(pi/8) against the velocity."""
    a = math.pi / 8
    path = tmp_path / "p3.yaml"
    path.write_text(MODEL % ("", 3 * math.cos(a), 3 * math.sin(a)))
    r = subprocess.run([str(lcsim_binary), "impacts", str(path), "--json"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    cli = json.loads(r.stdout)["rules"]
    py = lcsim.impacts(lcsim.load(str(path)))
    for law in ("newton", "inelastic", "moreau-restitution"):
        res, row = py[law], cli[law]
        assert res.ok, res.message
        assert res.friction_mode == ["slip-face-4"] == [row["friction_mode"]["floor"]]
        assert res.friction_outcome == ["slip"]
        assert np.array_equal(res.friction_impulse, row["friction_impulse"])
        assert np.array_equal(res.friction_impulse2, row["friction_impulse2"])
        # The closed form, to rounding of a 12-unknown LCP on unit data.
        p = math.cos(a)
        assert abs(res.friction_impulse[0] + p * math.cos(a)) < 1e-12
        assert abs(res.friction_impulse2[0] + p * math.sin(a)) < 1e-12


def test_a_bad_cone_is_one_line_and_exit_2(tmp_path, lcsim_binary):
    path = tmp_path / "bad.yaml"
    path.write_text(MODEL % (", d: 0", 1.0, 0.0))
    r = subprocess.run([str(lcsim_binary), "impacts", str(path)], capture_output=True,
                       text=True)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1
    assert "mechanical.friction[0].d: must be a whole number >= 1" in r.stderr


def test_a_three_dimensional_contact_built_in_python():
    """`friction=[{..., "tangents": [t, t2], "d": 4}]` as the YAML entry: the same
    impact as the file's (the bisector case above), and a bad entry is InputError."""
    import pytest
    a = math.pi / 8
    model = lcsim.Model.mechanical(
        M=np.eye(3), E=np.array([[0.0, 0.0, 1.0]]), constraint_names=["floor"],
        friction=[{"contact": "floor", "tangents": [[1, 0, 0], [0, 1, 0]], "mu": 0.5,
                   "d": 4}])
    r = lcsim.impacts(model, [0, 0, 0, 3 * math.cos(a), 3 * math.sin(a), -2],
                      rules=["inelastic"])["inelastic"]
    assert r.friction_mode == ["slip-face-4"]
    assert abs(r.friction_impulse2[0] + math.cos(a) * math.sin(a)) < 1e-12
    with pytest.raises(lcsim.InputError) as e:
        lcsim.Model.mechanical(
            M=np.eye(3), E=np.array([[0.0, 0.0, 1.0]]),
            friction=[{"contact": 0, "tangents": [[1, 0, 0], [0, 1, 0.5]], "mu": 0.5}])
    assert "tangents[1] and the normal row E[0] are not orthogonal" in str(e.value)
    with pytest.raises(lcsim.InputError) as e:
        lcsim.Model.mechanical(
            M=np.eye(3), E=np.array([[0.0, 0.0, 1.0]]),
            friction=[{"contact": 0, "tangents": [[1, 0, 0], [0, 1, 0]], "mu": 0.5, "d": 0}])
    assert str(e.value) == "friction[0].d: must be >= 1 (got 0)"
