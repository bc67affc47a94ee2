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


def test_moreau_jean_outputs_the_second_tangent_and_the_facet(tmp_path, lcsim_binary):
    """A slide on the bisector of edges 0 and 1 (d = 4): u_t2 is the force along t2,
    mu g cos(pi/8) sin(pi/8) against the velocity (unit mass), the facet face 4 (code
    2*4 + 1 = 9), the same numbers and names as the CLI's CSV columns ut2_floor and
    fm_floor."""
    a = math.pi / 8
    path = tmp_path / "p3.yaml"
    path.write_text(MODEL.replace("M: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]",
                                  "M: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n  f: [0, 0, -9.81]")
                    % (", d: 4", math.cos(a), math.sin(a)))
    text = path.read_text().replace(", -2]", ", 0]")
    path.write_text(text)
    run = lcsim.simulate(lcsim.load(str(path)), method="moreau-jean", t_end=0.05, h=1e-3,
                         dt_out=0.01)
    assert run.ok, run.message
    assert run.u_t2.shape == (len(run.t), 1)
    assert run.friction_facets.shape == (len(run.t), 1)
    F = 0.5 * 9.81 * math.cos(a)
    # Rounding of the step's implicit solve: 1e-12 relative to the force.
    assert np.all(np.abs(run.u_t2[1:, 0] + F * math.sin(a)) < 1e-12 * F)
    assert np.all(run.friction_facets[1:, 0] == 9)
    names = run.friction_mode_names
    assert all(row == ["slip-face-4"] for row in names[1:])
    out = tmp_path / "p3.csv"
    r = subprocess.run([str(lcsim_binary), "simulate", str(path), "--method", "moreau-jean",
                        "--t-end", "0.05", "--h", "1e-3", "--dt-out", "0.01", "--out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    lines = out.read_text().splitlines()
    head = lines[0].split(",")
    i, j = head.index("ut2_floor"), head.index("fm_floor")
    assert j == i + 1 and head[i - 1] == "ut_floor"
    for k, line in enumerate(lines[2:], start=1):
        cells = line.split(",")
        assert float(cells[i]) == run.u_t2[k, 0]
        assert cells[j] == names[k][0]


def test_planar_runs_have_no_second_tangent(tmp_path):
    path = tmp_path / "p2.yaml"
    path.write_text(MODEL.replace("tangents: [[1, 0, 0], [0, 1, 0]]", "tangent: [1, 0, 0]")
                    % ("", 1.0, 0.0))
    run = lcsim.simulate(lcsim.load(str(path)), method="moreau-jean", t_end=0.01)
    assert run.ok, run.message
    assert run.u_t2.shape == (len(run.t), 0)
    assert run.friction_facets.shape == (len(run.t), 0)


def test_bad_3d_friction_is_one_line_and_exit_2_from_simulate(tmp_path, lcsim_binary):
    """mu < 0, d < 1, tangents not orthogonal to the normal, a friction entry on an
    unknown contact: each one line naming the entry and the value, exit 2."""
    cases = [
        ("mu: 0.5", "mu: -0.5", "mechanical.friction[0].mu: must be >= 0 (got -0.5)"),
        ("mu: 0.5", "mu: 0.5, d: 0", "mechanical.friction[0].d: must be a whole number >= 1"),
        ("tangents: [[1, 0, 0], [0, 1, 0]]", "tangents: [[1, 0, 0.5], [0, 1, 0]]",
         "tangents[0] and the normal row E[0] are not orthogonal"),
        ("contact: floor", "contact: roof",
         "mechanical.friction[0].contact: no constraint named 'roof'"),
    ]
    for old, new, want in cases:
        path = tmp_path / "bad.yaml"
        path.write_text((MODEL % ("", 1.0, 0.0)).replace(old, new))
        r = subprocess.run([str(lcsim_binary), "simulate", str(path), "--method", "moreau-jean",
                            "--t-end", "0.01"], capture_output=True, text=True)
        assert r.returncode == 2, (new, r.stderr)
        assert r.stderr.count("\n") == 1, r.stderr
        assert want in r.stderr, r.stderr


def test_an_event_reports_the_impacts_second_tangent_impulse():
    """The exact method's landing event carries the impact law's impulses along both
    tangents (Event.friction_impulse2 was empty on 3-D contacts, found on bullet3's
    r2d2): the point dropped 0.05 m while sliding at 3 m/s on the bisector pi/8 (d = 4)
    gets at its impact the law's impulses at the state before it, to 1e-12 (the same
    law on the same state; rounding of the event's state at ~1e-15)."""
    a = math.pi / 8
    model = lcsim.Model.mechanical(
        M=np.eye(3), E=np.array([[0.0, 0.0, 1.0]]), g=np.array([0.0]), f=[0, 0, -9.81],
        constraint_names=["floor"],
        friction=[{"contact": "floor", "tangents": [[1, 0, 0], [0, 1, 0]], "mu": 0.5,
                   "d": 4}])
    x0 = [0, 0, 0.05, 3 * math.cos(a), 3 * math.sin(a), 0]
    tr = lcsim.simulate(model, x0, t_end=0.2, method="event")
    assert tr.ok, tr.message
    hit = tr.events[0]
    assert hit.type == "impact"
    law = lcsim.impacts(model, hit.state_before, rules=["inelastic"])["inelastic"]
    assert len(hit.friction_impulse2) == 1
    assert abs(hit.friction_impulse2[0] - law.friction_impulse2[0]) < 1e-12
    assert abs(hit.friction_impulse[0] - law.friction_impulse[0]) < 1e-12
    assert abs(law.friction_impulse2[0]) > 0.1  # a real second-tangent impulse
