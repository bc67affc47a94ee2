"""lcsim.plot draws from the Python results and from the files the command line
writes, and the command line's --plot runs the same module. A figure counts as drawn
when the file is a PNG image of the size matplotlib gives the figure."""

import subprocess

import matplotlib.image
import pytest

import lcsim
import lcsim.plot

PNG = b"\x89PNG\r\n\x1a\n"


def assert_png(path):
    assert path.read_bytes()[:8] == PNG
    h, w = matplotlib.image.imread(path).shape[:2]
    assert h > 100 and w > 100


def test_trajectory_from_python_and_from_cli_files(robots, lcsim_binary, tmp_path):
    model = lcsim.load(robots / "two_carts.yaml")
    run = lcsim.simulate(model, dt_out=0.05)
    lcsim.plot.trajectory(run, tmp_path / "py.png", title="two carts")
    assert_png(tmp_path / "py.png")
    run.to_csv(tmp_path / "t.csv")
    run.to_json(tmp_path / "t.json")
    lcsim.plot.trajectory(tmp_path / "t.csv", tmp_path / "files.png", events=tmp_path / "t.json")
    assert_png(tmp_path / "files.png")


def test_impact_map_python_and_cli(robots, lcsim_binary, tmp_path):
    model = lcsim.load(robots / "two_carts_hook.yaml")
    grid = lcsim.impact_map(model, v1=(-1, 1), v2=(-1, 1), n=5)
    cli = subprocess.run([str(lcsim_binary), "impacts", str(robots / "two_carts_hook.yaml"),
                          "--map", "-1:1:5,-1:1:5", "--plot", str(tmp_path / "cli.png")],
                         capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    assert grid == cli.stdout  # the same app::impact_map_csv text
    assert_png(tmp_path / "cli.png")
    lcsim.plot.impact_map(grid, tmp_path / "py.png")
    assert_png(tmp_path / "py.png")


def test_work_precision_python_and_cli(robots, lcsim_binary, tmp_path):
    model = lcsim.load(robots / "two_carts.yaml")
    sweep = lcsim.sweep(model, ["event", "moreau-jean"], [1e-2], repeat=1)
    assert [r["method"] for r in sweep["rows"]] == ["event", "moreau-jean"]
    lcsim.plot.work_precision(sweep, tmp_path / "py.png")
    assert_png(tmp_path / "py.png")
    cli = subprocess.run([str(lcsim_binary), "sweep", str(robots / "two_carts.yaml"),
                          "--methods", "event,moreau-jean", "--h", "1e-2", "--repeat", "1",
                          "--plot", str(tmp_path / "cli.png")], capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    assert_png(tmp_path / "cli.png")


def test_bad_file_is_one_line_and_exit_1(tmp_path):
    (tmp_path / "bad.csv").write_text("a,b\n1,2\n")
    assert lcsim.plot.main(["trajectory", str(tmp_path / "bad.csv"), "-o",
                            str(tmp_path / "x.png")]) == 1
    assert not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("kind", ["trajectory", "impact-map", "work-precision", "chain"])
def test_every_figure_has_a_subcommand(kind):
    with pytest.raises(SystemExit) as e:
        lcsim.plot.main([kind, "--help"])
    assert e.value.code == 0
