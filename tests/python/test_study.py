"""lcsim.study returns the table `lcsim study` writes: the same bytes, whatever the
number of threads; bad study files raise InputError with the library's line."""

import subprocess

import pytest

import lcsim

STUDY = """name: py_parity
model: {model}
seed: 11
axes:
  - count: 6
    x0.x1: {{uniform: [0.0, 0.5]}}
    v0.x1: {{normal: [0.0, 0.5]}}
  - method: [event, moreau-jean]
    h: [1e-3, 1e-2]
t_end: 1
"""


@pytest.fixture
def study_file(tmp_path, robots):
    f = tmp_path / "parity.yaml"
    f.write_text(STUDY.format(model=robots / "two_carts.yaml"))
    return f


def test_python_table_is_the_cli_table(study_file, tmp_path, lcsim_binary):
    out = tmp_path / "cli.csv"
    cli = subprocess.run([str(lcsim_binary), "study", str(study_file), "--out", str(out),
                          "--jobs", "1"], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    serial = lcsim.study(study_file, jobs=1)
    threads = lcsim.study(study_file, jobs=2)
    # Bitwise: the table holds no wall time, and rows are in run order.
    assert serial.text == out.read_text() == threads.text
    assert serial.total == 12 and serial.computed == 12 and serial.failed == 0
    assert len(serial.rows) == 12
    assert [r["method"] for r in serial.rows[:2]] == ["event", "moreau-jean"]


def test_resume_computes_nothing_twice(study_file, tmp_path):
    out = tmp_path / "kept.csv"
    first = lcsim.study(study_file, out=out, jobs=1)
    again = lcsim.study(study_file, out=out, resume=True, jobs=1)
    assert again.text == first.text and again.resumed == 12 and again.computed == 0
    with pytest.raises(lcsim.InputError, match="journal"):
        lcsim.study(study_file, out=out, jobs=1)  # an existing journal without resume


def test_bad_study_file_raises_input_error(tmp_path, robots):
    f = tmp_path / "bad.yaml"
    f.write_text(f"model: {robots / 'two_carts.yaml'}\naxes:\n  - x0.nope: [1, 2]\n")
    with pytest.raises(lcsim.InputError, match="nope"):
        lcsim.study(f)
