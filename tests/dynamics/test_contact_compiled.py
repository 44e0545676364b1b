"""The corrected body response on the compiled kernel against the readable
one, bit for bit: the contact geometry twin
(refsim.dynamics._numba_contact) on seeded poses, and whole trajectories of
cubes that collide and come to rest on each other (exact level, impulse
responses), where the compiled kernel runs its compiled narrow phase,
contact points and geometry in the steps the loop hands back."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from refsim.dynamics.body_response import contact_geometry
from refsim.dynamics.simulation import Simulation
from refsim.scenes.loader import scene_from_dict

pytest.importorskip("numba")

CUBE = refsim.load_model("cube.ac")


def _rotation(rng) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.random(random_state=int(rng.integers(2**31))).as_matrix()


def _geometry(world_a, world_b, c_a, c_b, R_a, R_b, kernel):
    try:
        g = contact_geometry(world_a, world_b, c_a, c_b, R_a, R_b, kernel=kernel)
    except ValueError as exc:
        return str(exc)
    return (g.n.tobytes(), np.float64(g.depth).tobytes(), g.point.tobytes(),
            np.float64(g.extent).tobytes())


def test_compiled_contact_geometry_is_the_readable_one():
    rng = np.random.default_rng(11)
    depths = []
    for _ in range(200):
        R_a, R_b = _rotation(rng), _rotation(rng)
        c_a, c_b = rng.uniform(-1.0, 1.0, 3), rng.uniform(-1.0, 1.0, 3)
        world_a = (R_a @ CUBE.vertices.T).T + c_a
        world_b = (R_b @ CUBE.vertices.T).T + c_b
        readable = _geometry(world_a, world_b, c_a, c_b, R_a, R_b, "readable")
        assert _geometry(world_a, world_b, c_a, c_b, R_a, R_b, "compiled") == readable
        depths.append(contact_geometry(world_a, world_b, c_a, c_b, R_a, R_b).depth)
    assert min(depths) < 0.0 < max(depths)        # separated and overlapping poses both
    # no candidate axis: the same error from both
    zero, origin = np.zeros((3, 3)), np.zeros(3)
    readable = _geometry(CUBE.vertices, CUBE.vertices, origin, origin, zero, zero, "readable")
    assert readable.startswith("contact_geometry: every candidate axis")
    assert _geometry(CUBE.vertices, CUBE.vertices, origin, origin, zero, zero,
                     "compiled") == readable


def _scene(bodies, seed: int):
    """Cubes at the exact level with the corrected responses; ``bodies``
    (position) rows, seeded random velocities up to 2 m/s."""
    rng = np.random.default_rng(seed)
    return scene_from_dict({
        "world": {"half_size": 3.0, "gravity": 9.81, "restitution": 0.5, "friction": 0.1,
                  "mu": 0.4},
        "integration": {"solver": "euler", "step": 1e-3, "duration": 5.0},
        "collision": {"level": "exact"},
        "dynamics": {"rotation": "impulse", "body_response": "impulse",
                     "wall_response": "impulse"},
        "body": [{"name": f"c{i}", "model": "cube.ac", "position": list(p),
                  "velocity": [float(x) for x in rng.uniform(-2.0, 2.0, 3)]}
                 for i, p in enumerate(bodies)]})


#: A column of four cubes over the floor, falling onto each other (deep and
#: grazing contacts, then resting ones), and six cubes thrown in a small world.
SCENES = {
    "column": ([[0.1 * i, -2.4 + 1.05 * i, 0.07 * i] for i in range(4)], 7, 400),
    "thrown": ([[x, y, 0.0] for x in (-1.2, 0.0, 1.2) for y in (-2.0, 0.5)], 8, 700),
}


@pytest.mark.parametrize("name", sorted(SCENES))
def test_body_contacts_on_the_compiled_kernel_bit_for_bit(name):
    bodies, seed, steps = SCENES[name]
    scene = _scene(bodies, seed)
    readable = Simulation(scene, kernel="readable")
    compiled = Simulation(scene, kernel="compiled")
    for sim in (readable, compiled):
        sim.record()
        sim.run(steps, every=5)
    a, b = readable.trajectory(), compiled.trajectory()
    for field in ("t", "position", "velocity", "angular_velocity", "orientation"):
        assert getattr(a, field).tobytes() == getattr(b, field).tobytes(), field
    assert a.events == b.events
    assert sum(e.kind == "body" for e in a.events) >= 3        # the bodies met
    # the loop took every step, the body stage of some of them (with the
    # compiled contact stages) between two of its calls
    assert compiled.loop_steps == steps and 0 < compiled.loop_body_steps < steps
