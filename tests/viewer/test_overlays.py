"""What the viewer draws besides the bodies (refsim.viewer.overlays), the
chunked runs behind its controls (refsim.viewer.runs) and the pose
conversion (refsim.viewer.server.wxyz)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import refsim
from refsim.studies.dynamics import c11_scene
from refsim.viewer import overlays
from refsim.viewer.runs import Cancelled, run_bodies, run_particles
from refsim.viewer.server import wxyz

#: Quaternion round trips in float64: a few units in the last place.
ROUND_TRIP_TOL = 1e-14

#: The wall impulse is read from frames a few steps apart, where gravity's
#: share is removed but the frames' spacing blurs the bounce a little:
#: within 2% of the analytic m (1 + e) v.
IMPULSE_RTOL = 0.02


def _short(name: str, duration: float):
    scene = refsim.load_scene(name)
    return replace(scene, integration=replace(scene.integration, duration=duration))


@pytest.fixture(scope="module")
def bounce():
    scene = _short("bounce.toml", 1.5)
    return scene, refsim.simulate(scene, every=5)


@pytest.fixture(scope="module")
def spin():
    scene = _short("spinning-cube.toml", 1.5)
    return scene, refsim.simulate(scene)


def test_box_edges_are_the_twelve_edges_of_the_box():
    edges = overlays.box_edges(np.array([0.0, 0.0, 0.0]), np.array([1.0, 2.0, 3.0]))
    assert edges.shape == (12, 2, 3)
    lengths = np.sort(np.linalg.norm(edges[:, 1] - edges[:, 0], axis=1))
    assert lengths.tolist() == [1.0] * 4 + [2.0] * 4 + [3.0] * 4
    # each edge changes exactly one coordinate
    assert ((edges[:, 1] != edges[:, 0]).sum(axis=1) == 1).all()


def test_cube_edges_span_the_world_cube_moved_by_the_offset():
    edges = overlays.cube_edges(5.0, (10.0, 0.0, 0.0))
    points = edges.reshape(-1, 3)
    assert points.min(axis=0).tolist() == [5.0, -5.0, -5.0]
    assert points.max(axis=0).tolist() == [15.0, 5.0, 5.0]


def test_body_boxes_are_the_linear_scan_of_the_recorded_poses(spin):
    scene, traj = spin
    meshes = overlays.body_meshes(scene)
    boxes = overlays.body_boxes(meshes, traj)
    assert boxes.shape == (traj.n_frames, 1, 2, 3)
    for f in (0, traj.n_frames // 2, traj.n_frames - 1):
        lo, hi = refsim.aabb_linear(meshes[0], (traj.orientation[f, 0], traj.position[f, 0]))
        assert np.array_equal(boxes[f, 0, 0], lo) and np.array_equal(boxes[f, 0, 1], hi)


def test_energy_is_the_simulations_own(spin):
    scene, traj = spin
    energy = overlays.energy_per_frame(scene, traj)
    # frame 0 is the scene's initial state: Simulation.energy, to the bit
    assert energy.total[0] == refsim.Simulation(scene).energy().sum()
    assert np.allclose(energy.kinetic + energy.potential + energy.rotational, energy.total,
                       rtol=1e-12, atol=1e-12)
    assert (energy.kinetic >= -1e-12).all() and (energy.rotational >= -1e-12).all()
    # the seed's rotation model: the cube starts with w = (2, 5, 1) rad/s
    I = 1.0 / 6.0                                      # unit cube of 1 kg: m a^2 / 6
    assert energy.rotational[0] == pytest.approx(0.5 * I * (4 + 25 + 1), rel=1e-9)


def test_wall_hit_of_a_dropped_sphere(bounce):
    scene, traj = bounce
    meshes = overlays.body_meshes(scene)
    hits = overlays.wall_hits(meshes, traj, [1.0], scene.world.gravity, scene.world.half_size)
    first = hits[0]
    assert first.wall == "y-" and first.body == 0
    assert first.normal.tolist() == [0.0, 1.0, 0.0]
    assert first.point[1] == -scene.world.half_size
    assert traj.t[first.frame - 1] < first.time <= traj.t[first.frame]
    # the drop: from the sphere's lowest point to the floor
    radius = -meshes[0].vertices[:, 1].min()
    v = np.sqrt(2 * scene.world.gravity * (2.0 - radius + scene.world.half_size))
    e = scene.world.restitution
    assert first.impulse[1] == pytest.approx((1 + e) * v, rel=IMPULSE_RTOL)
    assert abs(first.impulse[0]) < 1e-9 and abs(first.impulse[2]) < 1e-9


def test_contacting_triangles_of_interpenetrating_bodies():
    scene = c11_scene("stack", "seed", duration=2.0)
    traj = refsim.simulate(scene, every=10)
    meshes = overlays.body_meshes(scene)

    def pose(f):
        return [(traj.orientation[f, b], traj.position[f, b]) for b in (0, 1)]

    sunk = [f for f in range(traj.n_frames)
            if refsim.bodies_collide(meshes[0], pose(f)[0], meshes[1], pose(f)[1])]
    assert len(sunk) > 10                                  # C11: the top body sinks in
    f = sunk[len(sunk) // 2]
    found = overlays.contacting_triangles(meshes, traj, f)
    assert [(f.a, f.b) for f in found] == [(0, 1)]
    expected = refsim.intersecting_pairs(meshes[0], pose(f)[0], meshes[1], pose(f)[1])
    assert np.array_equal(found[0].pairs, expected) and len(expected)
    # at the start they are apart: no pairs
    assert overlays.contacting_triangles(meshes, traj, 0) == []


def test_overlapping_bodies_counts_touching_boxes():
    boxes = np.array([[[0, 0, 0], [1, 1, 1]], [[1, 0, 0], [2, 1, 1]], [[3, 3, 3], [4, 4, 4]]],
                     dtype=float)
    assert overlays.overlapping_bodies(boxes) == [(0, 1)]


def test_scene_with_replaces_the_options():
    scene = refsim.load_scene("spinning-cube.toml")
    changed = overlays.scene_with(scene, solver="midpoint", step=0.002, level="aabb",
                                  aabb="linear", rotation="impulse", body_response="seed")
    assert changed.integration.solver == "midpoint" and changed.integration.step == 0.002
    assert changed.collision.level == "aabb" and changed.collision.aabb == "linear"
    assert (changed.dynamics.rotation, changed.dynamics.body_response) == ("impulse", "seed")
    assert changed.bodies == scene.bodies and changed.world == scene.world


@pytest.mark.parametrize("options, message", [
    ({"solver": "leapfrog"}, "solver must be one of"),
    ({"rotation": "exact"}, "rotation must be one of"),
    ({"step": -0.1}, "integration.step: must be > 0"),
    ({"step": 0.0007}, "integration.step"),                # 6 s is not whole steps of it
    ({"gravity": 1.0}, "unknown option 'gravity'"),
])
def test_scene_with_refuses_bad_options(options, message):
    scene = refsim.load_scene("spinning-cube.toml")
    with pytest.raises(refsim.RefsimError, match=message):
        overlays.scene_with(scene, **options)


def test_particle_scene_follows_the_solver_and_step():
    scene = refsim.load_scene("particles.toml")
    changed = overlays.scene_with(scene, solver="rk4", step=0.001)
    assert (changed.particles.solver, changed.particles.step) == ("rk4", 0.001)


def test_chunked_run_is_simulate_bit_for_bit():
    scene = _short("spinning-cube.toml", 0.75)
    fractions = []
    traj = run_bodies(scene, every=7, progress=fractions.append)
    expected = refsim.simulate(scene, every=7)
    for name in ("t", "position", "velocity", "angular_velocity", "orientation"):
        assert np.array_equal(getattr(traj, name), getattr(expected, name)), name
    assert traj.events == expected.events
    assert traj.settings["every"] == 7
    assert fractions == sorted(fractions) and fractions[-1] == 1.0 and len(fractions) > 1


def test_a_cancelled_run_stops():
    calls = []
    with pytest.raises(Cancelled):
        run_bodies(_short("spinning-cube.toml", 0.75), progress=calls.append,
                   cancelled=lambda: len(calls) >= 1)
    assert len(calls) == 1


def test_particle_run_keeps_first_and_last_frames():
    scene = refsim.load_scene("particles.toml")
    scene = replace(scene, integration=replace(scene.integration, duration=0.1),
                    particles=replace(scene.particles, count=50))
    run = run_particles(scene, every=15)
    assert run.t[0] == 0.0 and run.t[-1] == pytest.approx(0.1)
    assert run.position.shape == (len(run.t), 50, 3)
    x0, _ = scene.particles.initial_state()
    assert np.array_equal(run.position[0], x0.astype(np.float32))


def test_quaternions_of_rotations():
    rng = np.random.default_rng(1997)
    rotations = Rotation.random(200, random_state=rng)
    # include the branches where x, y or z is the largest component
    extra = Rotation.from_rotvec([[np.pi, 0, 0], [0, np.pi, 0], [0, 0, np.pi],
                                  [0, 0, 0], [3.0, 0.1, -0.2]])
    matrices = np.concatenate([rotations.as_matrix(), extra.as_matrix()])
    q = wxyz(matrices)
    back = Rotation.from_quat(np.column_stack([q[:, 1:], q[:, 0]])).as_matrix()
    assert np.abs(back - matrices).max() < ROUND_TRIP_TOL * 10
    assert np.abs(np.linalg.norm(q, axis=1) - 1.0).max() < ROUND_TRIP_TOL * 10


@pytest.mark.parametrize("direction", [(0.45, 0.5, 1.0), (0.12, 0.3, 1.0)])
def test_a_panned_camera_shows_the_box_off_centre_away_from_the_panel(direction):
    """pan > 0 (the live viewer's panel on the right) moves the camera and its
    target along the screen's right: the box appears left of centre, by the
    same view as without the pan; pan < 0 (a replay's panel on the left) the
    other way."""
    from types import SimpleNamespace

    from refsim.viewer import draw

    def placed(pan):
        camera = SimpleNamespace()
        draw.place_camera(camera, 4.0, 4.0, direction=direction, pan=pan)
        return np.array(camera.position), np.array(camera.look_at)

    position, target = placed(0.0)
    assert np.array_equal(target, np.zeros(3))
    forward = -position / np.linalg.norm(position)
    right = np.cross(forward, (0.0, 1.0, 0.0))
    right /= np.linalg.norm(right)
    for pan in (draw.PANEL_PAN, -draw.PANEL_PAN):
        moved_position, moved_target = placed(pan)
        shift = moved_target - target
        assert np.allclose(moved_position - position, shift)      # the same view, moved
        assert np.allclose(shift, (shift @ right) * right)        # along the screen's right
        assert np.sign(shift @ right) == np.sign(pan)             # the box the other way
