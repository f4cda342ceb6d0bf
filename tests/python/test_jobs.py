"""Jobs as functions: impact (as `rubblepile impact`), analyze (as `rubblepile analyze`), read_run."""

import json

import numpy as np
import pytest

import rubblepile
from conftest import ROOT, run_cli, run_files

TARGET = ROOT / "targets" / "N30_T4.csv"


@pytest.fixture(scope="module")
def impacts(tmp_path_factory):
    """The same impact from the command line and from Python (the golden test's impact_n30)."""
    base = tmp_path_factory.mktemp("impact")
    cli, py = base / "cli", base / "py"
    r = run_cli("impact", "--target", str(TARGET), "--t-end-s", "300", "--every-s", "20", "--out", str(cli),
                "--no-progress")
    assert r.returncode == 0, r.stderr
    sim = rubblepile.impact(TARGET, py, t_end=300.0, every=20.0)
    errors = (sim.energy_error, sim.wall_seconds)
    assert sim.done and sim.t == 300.0
    sim.close()
    return cli, py, errors


def test_impact_writes_the_command_lines_files(impacts):
    cli, py, (energy_error, wall) = impacts
    a, b = run_files(cli), run_files(py)
    assert sorted(a) == sorted(b)
    for name in a:
        assert a[name] == b[name], name
    assert energy_error == json.loads((cli / "summary.json").read_text())["energy_error"]
    assert wall > 0


def test_analyze_is_the_command_lines(impacts, tmp_path):
    cli, py, _ = impacts
    r = run_cli("analyze", str(cli), "--at-s", "300")
    assert r.returncode == 0, r.stderr
    a = rubblepile.analyze(py, at=300.0)
    expected = json.loads((cli / "analysis" / "analysis.json").read_text())
    assert a["largest_remnant"] == expected["largest_remnant"]
    assert a["n_clumps"] == expected["n_clumps"]
    assert (py / "analysis" / "fragments.csv").read_text() == (cli / "analysis" / "fragments.csv").read_text()
    assert len(a["fragments"]["mass"]) > 0
    with pytest.raises(rubblepile.SceneError):
        rubblepile.analyze(py, at=300.0)  # already there, no force


def test_read_run(impacts):
    _, py, _ = impacts
    run = rubblepile.read_run(py)
    assert run["summary"]["status"] == "completed"
    ts = run["timeseries"]
    np.testing.assert_array_equal(ts["t"], np.arange(0.0, 301.0, 20.0))
    assert [k for k, _ in run["snapshots"]] == list(range(len(run["snapshots"])))
    snap = rubblepile.read_snapshot(run["snapshots"][-1][1])
    assert len(snap["x"]) == 31  # target + projectile


def test_impact_errors_name_the_argument(tmp_path):
    with pytest.raises(rubblepile.SceneError, match="angle"):
        rubblepile.impact(TARGET, tmp_path / "a", angle=200.0, t_end=300.0, run=False)
    with pytest.raises(rubblepile.SceneError, match="projectile"):
        rubblepile.impact(TARGET, tmp_path / "b", projectile="P9", run=False)
    with pytest.raises(rubblepile.SceneError, match="nope.csv"):
        rubblepile.impact(tmp_path / "nope.csv", tmp_path / "c", run=False)


def test_impact_aims_off_centre_as_the_command_line(tmp_path):
    sim = rubblepile.impact(TARGET, tmp_path / "b", impact_parameter_frac=0.7, aim_azimuth_deg=30.0, run=False)
    geometry = json.loads((tmp_path / "b" / "impact.json").read_text())["geometry"]
    assert abs(geometry["impact_parameter_m"] / geometry["target_radius_m"] - 0.7) < 1e-12, geometry
    assert geometry["aim_azimuth_deg"] == 30.0
    del sim
    with pytest.raises(rubblepile.SceneError, match="impact_angle_deg"):
        rubblepile.impact(TARGET, tmp_path / "c", impact_parameter_frac=0.5, impact_angle_deg=30.0, run=False)


def test_build_target_is_the_command_lines(tmp_path):
    r = run_cli("target", "build", "--fragments", "30", "--period-h", "4", "--out", str(tmp_path / "cli.csv"))
    assert r.returncode == 0, r.stderr
    report = rubblepile.build_target(30, 4.0, tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    assert report == json.loads((tmp_path / "cli.json").read_text())
    with pytest.raises(rubblepile.SceneError, match="exists"):
        rubblepile.build_target(30, 4.0, tmp_path / "py.csv")
    with pytest.raises(rubblepile.SceneError, match="rigidity"):
        rubblepile.build_target(30, 4.0, tmp_path / "x.csv", rigidity=2.0)


def test_build_aggregate_is_the_command_lines(tmp_path):
    # A small HCP ball (Zhang17's lattice model, carved; no packing recipe to run).
    args = ["--model", "hcp", "--shape", "sphere:60", "--radius-m", "6", "--lattice-orientation", "tilt:54.7"]
    r = run_cli("aggregate", "build", *args, "--out", str(tmp_path / "cli.csv"))
    assert r.returncode == 0, r.stderr
    report = rubblepile.build_aggregate("hcp", "sphere:60", tmp_path / "py.csv", radius=6.0,
                                        lattice_orientation="tilt:54.7")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    cli = json.loads((tmp_path / "cli.json").read_text())
    for side in (report, cli):
        side.pop("build_seconds")  # wall time
    assert report == cli
    assert report["n"] > 100
    with pytest.raises(rubblepile.SceneError, match="exists"):
        rubblepile.build_aggregate("hcp", "sphere:60", tmp_path / "py.csv", radius=6.0)
    with pytest.raises(rubblepile.SceneError, match="model"):
        rubblepile.build_aggregate("hex", "sphere:60", tmp_path / "x.csv", radius=6.0)
    with pytest.raises(rubblepile.SceneError, match="shake-periods"):
        rubblepile.build_aggregate("rcp", "sphere:60", tmp_path / "y.csv", radius=6.0, shake_periods=-1.0)


def test_flyby_is_the_command_lines(tmp_path):
    # The control flyby of tests/flyby.rs (planet mass 0, a rescaled and re-spun N30 pile, no control run).
    args = ["--target", str(TARGET), "--radius-m", "170", "--period-h", "30.5", "--q-m", "3.8e7",
            "--planet-mass-kg", "0", "--no-control"]
    r = run_cli("flyby", *args, "--out", str(tmp_path / "cli"))
    assert r.returncode == 0, r.stderr
    out = rubblepile.flyby(TARGET, tmp_path / "py", radius_m=170.0, period_hours=30.5, q_m=3.8e7,
                           planet_mass=0.0, control=False)
    assert out["analysis"] is not None
    a, b = run_files(tmp_path / "cli"), run_files(tmp_path / "py")
    assert sorted(a) == sorted(b)
    for name in a:
        assert a[name] == b[name], name
    # the lines but the run's wall time
    cli_lines = [l for l in r.stdout.splitlines() if not l.startswith("run: ")]
    assert [l for l in out["lines"] if not l.startswith("run: ")] == cli_lines
