"""The Python front against the command line: the same scene gives the same run directory, for every engine; state
arrays; errors; an interrupted integration resumes."""

import _thread
import pathlib
import re
import signal
import threading
import tomllib

import numpy as np
import pytest

import rubblepile
from conftest import EXAMPLES, ROOT, raw_files, run_cli, run_files, summary

SCENES = {
    "ellipsoids": EXAMPLES / "two_ellipsoids.toml",
    "soft-spheres": EXAMPLES / "soft_spheres.toml",
    "hard-spheres": EXAMPLES / "hard_spheres.toml",
}


def test_version_is_the_crates():
    cargo = (ROOT / "Cargo.toml").read_text()
    version = re.search(r'^version = "([^"]+)"', cargo, re.M).group(1)
    assert rubblepile.__version__ == version


@pytest.mark.parametrize("kind", list(SCENES))
def test_same_files_as_the_command_line(kind, tmp_path):
    scene = SCENES[kind]
    cli_dir, py_dir = tmp_path / "cli", tmp_path / "py"
    r = run_cli("run", str(scene), "--out", str(cli_dir), "--no-progress")
    assert r.returncode == 0, r.stderr
    sim = rubblepile.Simulation.from_scene(scene, py_dir)
    assert sim.kind == kind
    t = sim.integrate()
    # (the fixed-step engines end on their last whole step, within one step of t_end)
    assert sim.done and t == sim.t and abs(t - sim.t_end) < 1e-3
    errors = (sim.energy_error, sim.momentum_error, sim.angular_momentum_error)
    assert sim.summary() == summary(py_dir) and sim.wall_seconds == summary(py_dir)["wall_seconds"]
    sim.close()
    assert sim.energy_error == errors[0]  # still readable after close
    cli, py = run_files(cli_dir), run_files(py_dir)
    assert sorted(cli) == sorted(py)
    for name in cli:
        assert cli[name] == py[name], name
    # Beyond the scrubbed columns, every snapshot and the scene copy are byte for byte the same.
    cli_raw, py_raw = raw_files(cli_dir), raw_files(py_dir)
    for name in cli_raw:
        if name.startswith("snapshots/") or name == "scene.toml":
            assert cli_raw[name] == py_raw[name], name
    # The summary's numbers as the CLI prints them.
    s = summary(cli_dir)
    assert errors[0] == s["energy_error"]
    assert errors[1] == s.get("linear_momentum_error", s.get("momentum_error"))
    assert errors[2] == s.get("angular_momentum_error")


def test_steps_on_the_output_grid_and_reads_state():
    sim = rubblepile.Simulation.from_scene(SCENES["ellipsoids"])
    times = sim.sample_times
    assert times[0] == 0.0 and times[-1] == sim.t_end
    assert sim.step() == times[0]
    assert sim.step() == times[1]
    assert sim.integrate(20.0) == 20.0
    st = sim.state()
    n = 2
    assert st["positions"].shape == (n, 3) and st["velocities"].shape == (n, 3)
    assert st["quaternions"].shape == (n, 4) and st["semi_axes"].shape == (n, 3)
    np.testing.assert_allclose(np.linalg.norm(st["quaternions"], axis=1), 1.0, rtol=1e-9)
    assert list(st["ids"]) == [0, 1]
    assert st["masses"][0] == 30000.0
    assert st["semi_axes"][0].tolist() == [3.0, 2.0, 1.5]
    s = sim.summary()
    assert s["status"] == "running"
    assert abs(sim.energy_error) < 1e-6
    with pytest.raises(AttributeError):
        sim.radii
    with pytest.raises(ValueError, match="t_end"):
        sim.integrate(1e9)


def test_sphere_state_has_radii():
    sim = rubblepile.Simulation.from_scene(SCENES["hard-spheres"])
    sim.integrate(0.5)
    st = sim.state()
    assert st["radii"].tolist() == [0.05]
    assert "quaternions" not in st
    assert sim.angular_momentum_error is None or np.isfinite(sim.angular_momentum_error)


def test_scene_as_dict_and_text_give_the_files_of_the_path(tmp_path):
    path = SCENES["hard-spheres"]
    table = tomllib.loads(path.read_text())
    runs = {}
    for name, scene in [("path", path), ("dict", table), ("text", path.read_text())]:
        sim = rubblepile.Simulation.from_scene(scene, tmp_path / name)
        sim.integrate()
        sim.close()
        runs[name] = run_files(tmp_path / name)
    for name in ["timeseries.csv", "snapshots/0.csv", "snapshots/2.csv"]:
        assert runs["path"][name] == runs["dict"][name] == runs["text"][name], name


def test_errors_name_the_field_and_are_the_command_lines(tmp_path):
    text = SCENES["ellipsoids"].read_text().replace("t_end = 60.0", "t_end = -1.0")
    bad = tmp_path / "bad.toml"
    bad.write_text(text)
    with pytest.raises(rubblepile.SceneError) as e:
        rubblepile.Simulation.from_scene(bad, tmp_path / "out")
    assert "t_end" in str(e.value)
    r = run_cli("run", str(bad), "--out", str(tmp_path / "cli"), "--no-progress")
    assert r.returncode == 2
    assert str(e.value) in r.stderr
    assert isinstance(e.value, rubblepile.RubblepileError)
    # an existing, non-empty output directory
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x").write_text("x")
    with pytest.raises(rubblepile.SceneError, match="not empty"):
        rubblepile.Simulation.from_scene(SCENES["ellipsoids"], tmp_path / "full")
    # nothing to resume
    with pytest.raises(rubblepile.SceneError, match="nothing to resume"):
        rubblepile.Simulation.from_run(tmp_path / "full")
    # a closed simulation
    sim = rubblepile.Simulation.from_scene(SCENES["ellipsoids"])
    sim.close()
    with pytest.raises(rubblepile.SceneError, match="closed"):
        sim.step()


def test_a_budget_too_small_is_refused_as_the_command_line_does(tmp_path):
    with pytest.raises(rubblepile.SceneError) as e:
        rubblepile.Simulation.from_scene(SCENES["soft-spheres"], tmp_path / "run", max_steps=20000)
    assert "max_steps" in str(e.value)
    r = run_cli("run", str(SCENES["soft-spheres"]), "--out", str(tmp_path / "cli"), "--max-steps", "20000",
                "--no-progress")
    assert r.returncode == 2 and str(e.value) in r.stderr


def test_save_then_resume_from_the_command_line(tmp_path):
    scene = SCENES["ellipsoids"]
    r = run_cli("run", str(scene), "--out", str(tmp_path / "cli"), "--no-progress")
    assert r.returncode == 0, r.stderr
    sim = rubblepile.Simulation.from_scene(scene)
    sim.integrate(20.0)
    sim.save(tmp_path / "saved")
    sim.close()
    assert (tmp_path / "saved" / "checkpoint.json").is_file()
    r = run_cli("resume", str(tmp_path / "saved"), "--no-progress")
    assert r.returncode == 0, r.stderr
    cli, saved = run_files(tmp_path / "cli"), run_files(tmp_path / "saved")
    saved.pop("checkpoint.json")
    assert sorted(cli) == sorted(saved)
    for name in cli:
        assert cli[name] == saved[name], name


def test_ctrl_c_leaves_a_checkpoint_that_resumes(tmp_path):
    # The soft-sphere example run for 300 s (about 4e6 steps, a few seconds): long enough to be interrupted.
    scene = SCENES["soft-spheres"].read_text().replace("t_end = 10.0 ", "t_end = 300.0 ")
    assert "t_end = 300.0" in scene
    whole = tmp_path / "whole"
    sim = rubblepile.Simulation.from_scene(scene, whole)
    sim.integrate()
    sim.close()
    part = tmp_path / "part"
    sim = rubblepile.Simulation.from_scene(scene, part)
    # A process started in the background by a non-interactive shell inherits SIGINT ignored, and Python then
    # leaves it ignored, so `interrupt_main` would do nothing: Ctrl-C's Python handler is installed for this test.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        timer = threading.Timer(0.3, _thread.interrupt_main)
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            sim.integrate()
        timer.join()
    finally:
        signal.signal(signal.SIGINT, previous)
    t_stop = sim.t
    assert 0.0 < t_stop < sim.t_end
    sim.close()
    assert (part / "checkpoint.json").is_file()
    sim = rubblepile.Simulation.from_run(part)
    assert sim.t == t_stop
    sim.integrate()
    sim.close()
    a, b = run_files(whole), run_files(part)
    b.pop("checkpoint.json")
    assert sorted(a) == sorted(b)
    for name in a:
        if name != "summary.json":
            assert a[name] == b[name], name


def test_state_set_saved_and_read_back(tmp_path):
    sim = rubblepile.Simulation.from_scene(SCENES["ellipsoids"])
    sim.integrate(20.0)
    st = sim.state()
    pos = st["positions"] + np.array([[0.0, 0.0, 0.0], [1.0, 0.25, -0.5]])
    vel = st["velocities"] * 0.5
    q = np.array([[0.0, 0.0, 0.0, 1.0], [0.0, 0.6, 0.0, 0.8]])
    w = np.array([[0.0, 0.0, 0.01], [0.02, 0.0, 0.0]])
    sim.set_state(positions=pos, velocities=vel, quaternions=q, angular_velocities=w)
    now = sim.state()
    np.testing.assert_array_equal(now["positions"], pos)
    np.testing.assert_allclose(now["velocities"], vel, rtol=1e-15, atol=0)
    np.testing.assert_allclose(now["quaternions"], q, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(now["angular_velocities"], w, rtol=1e-12, atol=1e-15)
    sim.positions = pos  # the property setters
    np.testing.assert_array_equal(sim.positions, pos)
    now = sim.state()
    sim.save(tmp_path / "saved")
    sim.close()
    back = rubblepile.Simulation.from_run(tmp_path / "saved")
    assert back.t == 20.0
    again = back.state()
    for name in ["positions", "velocities", "quaternions", "angular_velocities", "masses", "semi_axes"]:
        np.testing.assert_array_equal(again[name], now[name], err_msg=name)
    back.integrate()  # continues from the changed state
    assert back.done
    back.close()
    # The CLI reads the directory the saved run finished.
    r = run_cli("check", str(tmp_path / "saved"))
    assert r.returncode == 0, r.stdout + r.stderr


def test_state_writes_are_checked():
    sim = rubblepile.Simulation.from_scene(SCENES["ellipsoids"])
    sim.step()
    with pytest.raises(rubblepile.SceneError, match=r"positions: expected shape \(2, 3\)"):
        sim.set_state(positions=np.zeros((3, 3)))
    with pytest.raises(rubblepile.SceneError, match="non-finite"):
        sim.set_state(velocities=np.full((2, 3), np.nan))
    with pytest.raises(rubblepile.SceneError, match="masses: not a writable"):
        sim.set_state(masses=np.ones((2, 1)))
    spheres = rubblepile.Simulation.from_scene(SCENES["hard-spheres"])
    spheres.step()
    with pytest.raises(rubblepile.SceneError, match="quaternions: not a writable"):
        spheres.set_state(quaternions=np.zeros((1, 4)))


def test_a_spent_budget_stops_with_a_checkpoint(tmp_path):
    scene = SCENES["soft-spheres"].read_text().replace("t_end = 10.0 ", "t_end = 300.0 ")
    sim = rubblepile.Simulation.from_scene(scene, tmp_path / "run", max_wall_seconds=0.3)
    with pytest.raises(rubblepile.RunStopped, match="max_wall_seconds") as e:
        sim.integrate()
    assert 0.0 < e.value.t < 300.0
    with pytest.raises(rubblepile.SceneError, match="has ended"):
        sim.step()
    sim.close()
    assert (tmp_path / "run" / "checkpoint.json").is_file()
    sim = rubblepile.Simulation.from_run(tmp_path / "run")
    assert sim.t == e.value.t
    sim.close()
