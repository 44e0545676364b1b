"""The one energy formula (refsim.dynamics.energy): its parts on a hand-worked
state, and the recorded trajectory's energy equal to the loop's own."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from refsim.dynamics.energy import mechanical_energy, trajectory_energy
from refsim.models.ac3d import write_ac3d
from refsim.scenes.loader import scene_from_dict

QUARTER_TURN_Z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


def test_the_parts_of_a_hand_worked_state():
    # m = 2 kg, I = diag(1, 2, 3), turned a quarter about z: the world's x
    # axis is the body's -y, so w = (1, 0, 0) spins about the body's y axis
    # (moment 2): w . I w / 2 = 1 J, where the unturned inertia would give 0.5.
    parts = mechanical_energy(mass=[2.0], inertia=[np.diag([1.0, 2.0, 3.0])], gravity=10.0,
                              floor=-5.0, center_of_mass=[[0.0, 1.0, 0.0]],
                              orientation=[QUARTER_TURN_Z], velocity=[[3.0, 4.0, 0.0]],
                              angular_velocity=[[1.0, 0.0, 0.0]])
    assert parts.kinetic.tolist() == [25.0]              # 2 * 25 / 2
    assert parts.rotational.tolist() == [1.0]
    assert parts.potential.tolist() == [120.0]           # 2 * 10 * (1 + 5)
    assert parts.total.tolist() == [146.0]


def test_leading_dimensions_are_frames():
    state = dict(mass=[1.0, 3.0], inertia=[np.eye(3), 2 * np.eye(3)], gravity=9.81,
                 floor=-5.0, center_of_mass=np.zeros((4, 2, 3)),
                 orientation=np.broadcast_to(np.eye(3), (4, 2, 3, 3)),
                 velocity=np.ones((4, 2, 3)), angular_velocity=np.ones((4, 2, 3)))
    parts = mechanical_energy(**state)
    assert parts.total.shape == (4, 2)
    np.testing.assert_array_equal(parts.kinetic, np.tile([1.5, 4.5], (4, 1)))
    np.testing.assert_array_equal(parts.rotational, np.tile([1.5, 3.0], (4, 1)))


@pytest.mark.parametrize("rotation", ["seed", "impulse"])
def test_a_recorded_run_has_the_loops_energy_in_every_frame(tmp_path, rotation):
    # A cube whose mesh origin is off its centre (both the vertex average of
    # "seed" and the solid's centre of mass of "impulse"): the recorded
    # position is the origin, not the simulated state, and the conversion
    # x = position + R c is exercised.
    cube = refsim.load_model("cube.ac")
    write_ac3d(refsim.Mesh(cube.vertices + [0.3, 0.2, -0.1], cube.faces),
               tmp_path / "offset.ac")
    scene = scene_from_dict({
        "integration": {"step": 1e-3, "duration": 0.2},
        "dynamics": {"rotation": rotation},
        "body": [{"model": "offset.ac", "position": [0.0, 1.0, 0.0],
                  "velocity": [1.0, 0.0, 0.5], "angular_velocity": [2.0, -1.0, 3.0]}]},
        tmp_path / "scene.toml")
    sim = refsim.Simulation(scene)
    np.testing.assert_allclose(sim.center, [[0.3, 0.2, -0.1]], rtol=1e-12)
    expected = []
    for _ in range(5):
        for _ in range(20):
            sim.step()
        sim.record()
        expected.append(sim.energy())
    parts = trajectory_energy(scene, sim.trajectory())
    # x - R c + R c returns x to a few ulps of the 1 m scale: the potential
    # (m g y ~ 60 J) moves by ~1e-14 relative, nothing else changes.
    np.testing.assert_allclose(parts.total, np.array(expected), rtol=1e-13, atol=0)
    assert (parts.rotational > 1.0).all()
