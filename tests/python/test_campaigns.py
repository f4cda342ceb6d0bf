"""Jobs as functions, continued: campaign (as `rubblepile campaign`), spinup (a spin-up run, as `rubblepile run`)
and critical_search (as `rubblepile spinup critical`): the same files as the command line, and returned values that
are what the command line wrote."""

import json
import pathlib

import numpy as np
import pytest

import rubblepile
from conftest import ROOT, run_cli, run_files
from rubblepile.runs import _read_csv

TARGET = ROOT / "targets" / "N30_T4.csv"
GOLDEN_SPINUP = ROOT / "tests" / "golden" / "spinup_ball"

# Two runs of a small, slow projectile grazing the 30-fragment target, for a few tens of simulated seconds.
CAMPAIGN = """
[campaign]
out = "out"
targets = ["{target}"]
projectiles = ["S1"]
angles = [0.0, 90.0]
seeds = [7]
parallel = 2

[impact]
t_end = 20.0
contact_time = 5.0
every = 5.0

[[projectile]]
id = "S1"
radius_km = 1.0
speed_km_s = 0.02
"""


def same_run_files(a: pathlib.Path, b: pathlib.Path, replace=()):
    """The run files under `a` and `b` (machine columns and manifests aside) are the same, with each `(x, y)` of
    `replace` (paths that name the directories themselves) read as the same text."""
    fa, fb = run_files(a), run_files(b)
    assert sorted(fa) == sorted(fb)
    for name in fa:
        ta, tb = fa[name], fb[name]
        if name.endswith("checkpoint.json"):
            # its record of the files' lengths counts the wall-clock columns' digits
            drop = ('"bytes": ', '_bytes": ')
            ta, tb = ("".join(l for l in t.splitlines(True) if not any(d in l for d in drop)) for t in (ta, tb))
        for x, y in replace:
            ta, tb = ta.replace(x, "OUT"), tb.replace(y, "OUT")
        assert ta == tb, name


def test_campaign_is_the_command_lines(tmp_path):
    file = tmp_path / "campaign.toml"
    file.write_text(CAMPAIGN.format(target=TARGET))
    cli, py = tmp_path / "cli", tmp_path / "py"
    r = run_cli("campaign", str(file), "--out", str(cli), "--no-progress")
    assert r.returncode == 0, r.stderr
    result = rubblepile.campaign(file, py)
    assert result["problem"] is None and result["out"] == str(py)
    assert result["line"].startswith("campaign: 2 runs: 2 completed (0 skipped, 0 resumed), 0 failed")
    same_run_files(cli, py)
    runs = result["runs"]
    assert list(runs["run"]) == ["N30_T4_S1_z0_s7", "N30_T4_S1_z90_s7"]
    assert runs["completed"].all() and list(runs["action"]) == ["started", "started"]
    # The values returned are those the command line wrote (its wall-clock times aside: those are this call's own).
    written = _read_csv(cli / "campaign.csv")
    own = _read_csv(py / "campaign.csv")
    for name, column in written.items():
        expected = own[name] if name == "wall_seconds" else column
        got = runs[name]
        if expected.dtype == object:
            assert list(got) == list(expected), name
        else:
            np.testing.assert_array_equal(got.astype(float), expected, err_msg=name)
    for k, d in enumerate(runs["dir"]):
        summary = json.loads((pathlib.Path(d) / "summary.json").read_text())
        assert runs["energy_error"][k] == summary["energy_error"]
        assert summary["status"] == "completed"
    # A second call skips both completed runs.
    again = rubblepile.campaign(file, py)
    assert list(again["runs"]["action"]) == ["skipped", "skipped"]
    np.testing.assert_array_equal(again["runs"]["energy_error"], runs["energy_error"])
    with pytest.raises(rubblepile.SceneError, match="angles"):
        bad = tmp_path / "bad.toml"
        bad.write_text(CAMPAIGN.format(target=TARGET).replace("[0.0, 90.0]", "[0.0, 200.0]"))
        rubblepile.campaign(bad, tmp_path / "bad")


def ball(dir: pathlib.Path) -> None:
    """`ball.csv` of the golden spin-up case (the ~90-sphere HCP ball at rest) in `dir`: its snapshot at t = 0 with
    the velocities and spins the spin-up gave it set to zero."""
    lines = (GOLDEN_SPINUP / "expected" / "snapshots" / "0.csv").read_text().splitlines()
    out = [lines[0]]
    for line in lines[1:]:
        c = line.split(",")
        out.append(",".join(c[:7] + ["0"] * 6))
    (dir / "ball.csv").write_text("\n".join(out) + "\n")


def test_spinup_is_the_command_lines(tmp_path):
    ball(tmp_path)
    scene = tmp_path / "scene.toml"
    scene.write_text((GOLDEN_SPINUP / "scene.toml").read_text())
    cli, py = tmp_path / "cli", tmp_path / "py"
    r = run_cli("run", str(scene), "--out", str(cli), "--no-progress")
    assert r.returncode == 0, r.stderr
    result = rubblepile.spinup(scene, py)
    result["simulation"].close()
    assert result["dir"] == str(py) and result["summary"]["status"] == "completed"
    same_run_files(cli, py)
    # The returned rows are spinup.csv's, and the golden case's.
    s = result["spinup"]
    for name, column in _read_csv(cli / "spinup.csv").items():
        np.testing.assert_array_equal(s[name], column, err_msg=name)
    assert (py / "spinup.csv").read_bytes() == (GOLDEN_SPINUP / "expected" / "spinup.csv").read_bytes()
    assert s["t"][-1] == 1200.0 and abs(s["period_h"][-1] - 6.0) < 1e-6
    with pytest.raises(rubblepile.SceneError, match="spinup"):
        rubblepile.spinup(ROOT / "targets" / "examples" / "soft_spheres.toml")


def test_critical_search_is_the_command_lines(tmp_path):
    # The scene of tests/spinup_run.rs's search: the ball spun from 8 h to 5 h by t = 2000 s, held to 2400 s; two
    # holds branched off the path at 5.9 and 6 h, each 600 s long.
    ball(tmp_path)
    text = (GOLDEN_SPINUP / "scene.toml").read_text()
    for a, b in (("t_end = 1200.0", "t_end = 2400.0"), ("every = 60.0", "every = 120.0"),
                 ("times = [0.0, 600.0, 1200.0]", "times = [0.0, 1200.0, 2400.0]"), ("T_final = 6.0", "T_final = 5.0"),
                 ("t_start = 300.0", "t_start = 600.0"), ("t_inter = 600.0", "t_inter = 1200.0"),
                 ("t_final = 1000.0", "t_final = 2000.0")):
        assert a in text
        text = text.replace(a, b)
    scene = tmp_path / "s.toml"
    scene.write_text(text)
    cli, py = tmp_path / "cli", tmp_path / "py"
    args = ["--from-h", "5.9", "--to-h", "6.0", "--step-h", "0.1", "--branch", "--hold-s", "600", "--all-holds"]
    r = run_cli("spinup", "critical", "--scene", str(scene), *args, "--out", str(cli))
    assert r.returncode == 0, r.stderr
    result = rubblepile.critical_search(scene, py, from_hours=5.9, to_hours=6.0, step_hours=0.1, branch=True,
                                        hold=600.0, all_holds=True)
    same_run_files(cli, py, replace=[(str(cli), str(py))])
    assert (py / "critical.csv").read_bytes() == (cli / "critical.csv").read_bytes()
    assert [l.replace(str(py), "OUT") for l in result["lines"]] == \
        [l.replace(str(cli), "OUT") for l in r.stdout.splitlines()]
    # The verdicts returned are those the command line wrote.
    written = json.loads((cli / "critical.json").read_text())
    assert result["criterion"] == "paper"
    assert result["t_c3_hours"] == written["t_c3_hours"]
    assert result["friction_angle_deg"] == written["friction_angle_deg"]
    for key, name in (("paper", "paper"), ("paper_tolerance", "paper-tolerance"), ("ours", "ours")):
        for field in ("t_c3_hours", "friction_angle_deg", "set_aside_hours"):
            assert result["by_criterion"][name][field] == written[key][field], (name, field)
    holds = result["holds"]
    np.testing.assert_array_equal(holds["t_final_h"], [5.9, 6.0])
    for name, column in _read_csv(cli / "critical.csv").items():
        if column.dtype == object:
            assert list(holds[name]) == list(column), name
        else:
            np.testing.assert_array_equal(holds[name], column, err_msg=name)
    assert len(result["runs"]) == 2
    assert [h["t_final_hours"] for h in result["runs"]] == [5.9, 6.0]
    with pytest.raises(rubblepile.SceneError, match="critical.json exists"):
        rubblepile.critical_search(scene, py, from_hours=5.9, to_hours=6.0, step_hours=0.1, branch=True, hold=600.0)
    with pytest.raises(rubblepile.SceneError, match="criterion"):
        rubblepile.critical_search(scene, tmp_path / "x", from_hours=5.9, to_hours=6.0, criterion="nope")
