"""The state of a sphere run (soft and hard spheres) written between integrations: set, saved, read back bit for
bit, and integrated on from it (free flight over the expected distance; a resumed copy ends as the run held in
memory)."""

import numpy as np
import pytest

import rubblepile
from conftest import raw_files

# Two spheres far apart (no contact, no gravity): each flies freely, its spin constant.
FREE = """
[scene]
kind = "soft-spheres"
t_end = 2.0
seed = 1

[stepping]
dt = 1e-3

[material]
k_n = 1e5

[output]
every = 0.5
times = [0.0, 1.0, 2.0]

[[particle]]
radius = 0.5
density = 2000.0
position = [0.0, 0.0, 0.0]

[[particle]]
radius = 0.5
density = 2000.0
position = [10.0, 0.0, 0.0]
velocity = [0.0, 0.1, 0.0]
"""


# The same two spheres as hard spheres (elastic, no gravity).
HARD = """
[scene]
kind = "hard-spheres"
t_end = 2.0
seed = 0

[stepping]
dt = 1e-3

[material]
eps_n = 1.0
eps_t = 1.0

[output]
every = 0.5
times = [0.0, 1.0, 2.0]

[[particle]]
mass = 1.0
radius = 0.5
position = [0.0, 0.0, 0.0]

[[particle]]
mass = 1.0
radius = 0.5
position = [10.0, 0.0, 0.0]
velocity = [0.0, 0.1, 0.0]
"""


@pytest.mark.parametrize("scene", [FREE, HARD], ids=["soft-spheres", "hard-spheres"])
def test_sphere_state_set_saved_and_read_back(scene, tmp_path):
    sim = rubblepile.Simulation.from_scene(scene, tmp_path / "run")
    sim.integrate(1.0)
    assert sim.t == pytest.approx(1.0)
    t1 = sim.t
    pos = np.array([[0.25, -0.5, 1.0], [10.0, 3.0, -2.0]])
    vel = np.array([[0.5, -0.25, 0.125], [0.0, 0.0, -1.5]])
    spin = np.array([[0.0, 0.0, 2.0], [0.1, 0.2, 0.3]])
    sim.set_state(positions=pos, velocities=vel, angular_velocities=spin)
    now = sim.state()
    np.testing.assert_array_equal(now["positions"], pos)
    np.testing.assert_array_equal(now["velocities"], vel)
    np.testing.assert_array_equal(now["angular_velocities"], spin)
    sim.velocities = vel  # the property setter; the others keep their values
    np.testing.assert_array_equal(sim.positions, pos)
    sim.save(tmp_path / "saved")
    back = rubblepile.Simulation.from_run(tmp_path / "saved")
    assert back.t == t1
    again = back.state()
    for name in ["positions", "velocities", "angular_velocities", "masses", "radii"]:
        np.testing.assert_array_equal(again[name], sim.state()[name], err_msg=name)
    # Free flight from the state set: x(t_end) = x + v (t_end - t1), spins unchanged.
    sim.integrate()
    end = sim.state()
    np.testing.assert_allclose(end["positions"], pos + vel * (sim.t - t1), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(end["velocities"], vel)
    np.testing.assert_array_equal(end["angular_velocities"], spin)
    # The saved copy, resumed, ends bit for bit as the run held in memory.
    back.integrate()
    a, b = raw_files(tmp_path / "run"), raw_files(tmp_path / "saved")
    for name in a:
        if name.startswith("snapshots/"):
            assert a[name] == b[name], name
    sim.close()
    back.close()


def test_hard_state_predicts_collisions_again():
    # Two spheres sent at each other by the state set: they collide (the predictions were made from the new
    # state) and, elastic and equal, exchange their velocities.
    sim = rubblepile.Simulation.from_scene(HARD)
    sim.integrate(1.0)
    sim.set_state(positions=np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]]),
                  velocities=np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]))
    sim.integrate()
    np.testing.assert_allclose(sim.velocities, [[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], atol=1e-12)
    # they met at x = +-0.5 at t = 1.5 s and flew apart for the remaining 0.5 s
    np.testing.assert_allclose(sim.positions[:, 0], [0.5 - 0.5, 1.5 + 0.5], atol=1e-9)


def test_soft_state_sets_the_forces_again():
    # Two spheres pushed into contact by the state set: the first step after it repels them (the forces were
    # evaluated at the new positions, not kept from the old ones).
    sim = rubblepile.Simulation.from_scene(FREE)
    sim.integrate(1.0)
    sim.set_state(positions=np.array([[0.0, 0.0, 0.0], [0.99, 0.0, 0.0]]), velocities=np.zeros((2, 3)))
    sim.step()
    v = sim.velocities
    assert v[0, 0] < 0.0 < v[1, 0]
    np.testing.assert_allclose(v[0] * sim.masses[0] + v[1] * sim.masses[1], 0.0, atol=1e-12)


@pytest.mark.parametrize("scene", [FREE, HARD], ids=["soft-spheres", "hard-spheres"])
def test_sphere_state_writes_are_checked(scene):
    sim = rubblepile.Simulation.from_scene(scene)
    sim.step()
    with pytest.raises(rubblepile.SceneError, match=r"positions: expected shape \(2, 3\)"):
        sim.set_state(positions=np.zeros((3, 3)))
    with pytest.raises(rubblepile.SceneError, match="non-finite"):
        sim.set_state(velocities=np.full((2, 3), np.inf))
    with pytest.raises(rubblepile.SceneError, match="radii: not a writable"):
        sim.set_state(radii=np.ones((2, 1)))
