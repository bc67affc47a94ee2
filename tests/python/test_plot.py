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


def test_circuit_waveforms_are_labelled_by_what_they_are(robots, lcsim_binary, tmp_path):
    """A circuit's CSV (its states by name, the diode's pair, then V(node) and I(element))
    draws voltage and current panels, from Python and from the files the CLI writes."""
    netlist = robots.parent / "circuits" / "half_wave_rlc.cir"
    run = lcsim.simulate(lcsim.load(netlist), dt_out=1e-4)
    header = run.to_csv().splitlines()[0].split(",")
    layout = lcsim.plot.split_columns(header)
    named = lambda cols: [header[j] for j in cols]
    assert layout.kind == "lcs"
    assert named(layout.pos) == ["C1.v", "L1.i", "1"]
    assert named(layout.force) == ["u_D1"] and named(layout.gap) == ["y_D1"]
    assert [(label, named(cols)) for label, cols in layout.outputs] == [
        ("voltage (V)", ["V(a)", "V(m)"]),
        ("current (A)", ["I(C1)", "I(L1)", "I(D1)", "I(R1)"])]
    lcsim.plot.trajectory(run, tmp_path / "py.png", gaps=True)
    assert_png(tmp_path / "py.png")
    cli = subprocess.run([str(lcsim_binary), "simulate", str(netlist), "--dt-out", "1e-4",
                          "--out", str(tmp_path / "c.csv"), "--json"],
                         capture_output=True, text=True)
    assert cli.returncode == 0, cli.stderr
    (tmp_path / "c.json").write_text(cli.stdout)
    assert lcsim.plot.main(["trajectory", str(tmp_path / "c.csv"), "--events",
                            str(tmp_path / "c.json"), "-o", str(tmp_path / "cli.png")]) == 0
    assert_png(tmp_path / "cli.png")


def test_friction_columns_are_drawn_and_modes_kept_as_words(robots, tmp_path):
    """A frictional model's CSV has ut_ (numbers) and fm_ (words such as 'slip+')
    after the pairs: the tangential force gets a panel, the modes are not parsed as
    numbers."""
    run = lcsim.simulate(lcsim.load(robots / "block_on_floor_friction.yaml"))
    run.to_csv(tmp_path / "f.csv")
    header, layout, data, _ = lcsim.plot.read_trajectory(tmp_path / "f.csv")
    assert [header[j] for j in layout.friction] == ["ut_floor"]
    assert [header[j] for j in layout.text] == ["fm_floor"]
    assert "slip+" in data["fm_floor"]
    lcsim.plot.trajectory(tmp_path / "f.csv", tmp_path / "f.png")
    assert_png(tmp_path / "f.png")


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


def test_work_precision_draws_the_gradient_beside_the_state(robots, lcsim_binary, tmp_path):
    # A sweep asked for sensitivities: each scheme row's error_gradient (its
    # dx(T)/dx0 against the exact one; the two carts before their impact, where
    # both converge) is drawn in a second panel, from Python and from the CLI.
    model = lcsim.load(robots / "two_carts.yaml")
    sweep = lcsim.sweep(model, ["event", "euler"], [1e-2, 1e-3], t_end=0.9, repeat=1,
                        sensitivity=["x0"])
    grads = [r["error_gradient"] for r in sweep["rows"] if r["method"] == "euler"]
    assert len(grads) == 2 and 0 < grads[1] < grads[0]  # first order: it falls with h
    assert lcsim.plot.work_precision(sweep, tmp_path / "py.png") == ["error_max",
                                                                      "error_gradient"]
    assert_png(tmp_path / "py.png")
    cli = subprocess.run([str(lcsim_binary), "sweep", str(robots / "two_carts.yaml"),
                          "--methods", "event,euler", "--h", "1e-2", "--repeat", "1",
                          "--t-end", "0.9", "--sensitivity", "x0",
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
