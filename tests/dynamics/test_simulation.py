"""The simulation loop: stages, walls, rest, orthonormality, divergence, and
every bundled scene."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import refsim
from refsim.bundled import scenes_dir
from refsim.dynamics.simulate import MAX_FRAMES, default_every, simulate
from refsim.dynamics.simulation import Simulation
from refsim.errors import DivergenceError, StateError
from refsim.scenes.loader import scene_from_dict
from refsim.studies.dynamics import REST_SPEED, REST_SPIN

#: Exact rotations composed 10 000 times: rounding grows like sqrt(steps) ulps,
#: ~1e-14; 1e-10 leaves room and still catches any drift (the seed's Euler
#: step without re-orthonormalization is off by 1e-1 in such a run).
ORTHONORMAL_DRIFT_TOL = 1e-10


def _scene(bodies, **tables):
    data = {"world": {"half_size": 5.0}, "integration": {"step": 1e-3, "duration": 0.1},
            "collision": {"level": "none"}, "dynamics": {"rotation": "off",
                                                         "body_response": "off"}}
    for key, value in tables.items():
        data[key] = {**data.get(key, {}), **value}
    data["body"] = bodies
    return scene_from_dict(data)


CUBE = {"name": "cube", "model": "cube.ac", "position": [0.0, 0.0, 0.0]}


def test_public_names():
    assert refsim.simulate is simulate
    assert refsim.Simulation is Simulation
    assert refsim.Trajectory.__name__ == "Trajectory"


def test_one_body_has_no_body_body_stage_and_rotation_off_no_rotation_stage():
    sim = Simulation(_scene([CUBE], collision={"level": "exact"},
                            dynamics={"body_response": "seed"}))
    assert sim.stages == ("integrate", "check", "bounds", "walls")
    traj = simulate(_scene([CUBE]))
    assert "rotation" not in traj.stages and "broad-phase" not in traj.stages
    assert set(traj.stage_seconds) == set(traj.stages)


def test_two_bodies_at_level_aabb_have_broad_phase_but_no_narrow_phase():
    other = {**CUBE, "name": "other", "position": [2.0, 0.0, 0.0]}
    sim = Simulation(_scene([CUBE, other], collision={"level": "aabb"},
                            dynamics={"body_response": "seed", "rotation": "seed"}))
    assert sim.stages == ("integrate", "rotation", "check", "bounds", "walls", "broad-phase",
                          "body-response")


def test_free_fall_is_exact_with_rk4():
    traj = simulate(_scene([{**CUBE, "velocity": [1.0, 2.0, 0.0]}]), every=1)
    t = traj.t
    expected = np.stack([t, 2.0 * t - 0.5 * 9.81 * t * t, 0 * t], axis=1)
    assert np.allclose(traj.position[:, 0], expected, atol=1e-12)


def test_wall_hit_in_the_loop_pushes_back_exactly_and_records_an_event():
    # a cube whose bottom is 1 mm above the floor, falling at 2 m/s
    scene = _scene([{**CUBE, "position": [0.0, -4.499, 0.0], "velocity": [1.0, -2.0, 0.0]}],
                   world={"restitution": 0.5, "friction": 0.2})
    sim = Simulation(scene, wall_speed="seed")
    sim.step()
    assert sim.lo[0, 1] == pytest.approx(-5.0, abs=1e-15)      # back on the wall
    assert sim.position[0, 1] == pytest.approx(-4.5, abs=1e-15)
    v_deep = -2.0 - 9.81 * 1e-3
    assert sim.v[0, 1] == pytest.approx(-0.5 * v_deep, rel=1e-12)
    assert sim.v[0, 0] == pytest.approx(0.8, rel=1e-15)
    assert [(e.kind, e.body, e.other, e.step) for e in sim.events] == [
        ("wall", "cube", "y-", 1)]


def test_the_scenes_wall_speed_is_the_default_of_simulate_and_simulation():
    # the same first step as above: the scene's world.wall_speed = "seed"
    # chooses the seed's speed (-2 - g h, flipped), an explicit argument wins
    bodies = [{**CUBE, "position": [0.0, -4.499, 0.0], "velocity": [1.0, -2.0, 0.0]}]
    world = {"restitution": 0.5, "friction": 0.2}
    seed_scene = _scene(bodies, world={**world, "wall_speed": "seed"},
                        integration={"duration": 1e-3})
    v_seed = -0.5 * (-2.0 - 9.81 * 1e-3)
    assert Simulation(seed_scene).plan.wall_speed == "seed"
    assert simulate(seed_scene, every=1).velocity[-1, 0, 1] == pytest.approx(v_seed, rel=1e-12)
    corrected = simulate(seed_scene, every=1, wall_speed="wall").velocity[-1, 0, 1]
    assert corrected != pytest.approx(v_seed, rel=1e-6)
    with pytest.raises(refsim.OptionError, match="wall_speed must be one of"):
        Simulation(seed_scene, wall_speed="")


def test_equal_masses_exchange_velocities_in_the_loop():
    scene = refsim.load_scene(scenes_dir() / "head-on.toml")
    traj = simulate(scene, duration=2.5)
    assert np.allclose(traj.velocity[-1], [[-1.0, 0, 0], [1.5, 0, 0]])
    assert [e.kind for e in traj.events] == ["body"]


def test_spinning_cube_comes_to_rest_with_the_corrected_model():
    scene = refsim.load_scene(scenes_dir() / "spinning-cube.toml")
    scene = replace(scene, dynamics=replace(scene.dynamics, rotation="impulse"))
    traj = simulate(scene, duration=5.0, every=100)
    w = np.linalg.norm(traj.angular_velocity[-5:, 0], axis=1)
    v = np.linalg.norm(traj.velocity[-5:, 0], axis=1)
    print(f"last |w| {w.max():.3g} rad/s, |v| {v.max():.3g} m/s")
    assert w.max() < REST_SPIN and v.max() < REST_SPEED
    assert traj.position[-1, 0, 1] == pytest.approx(-4.5, abs=1e-4)   # flat on the floor


def test_seed_model_keeps_the_vertical_spin():
    scene = refsim.load_scene(scenes_dir() / "spinning-cube.toml")
    traj = simulate(scene, duration=5.0, every=100)
    # C12: the seed's contact torque is perpendicular to the floor's normal
    assert traj.angular_velocity[-1, 0, 1] == pytest.approx(5.0, rel=1e-12)


def test_orientation_stays_orthonormal_and_momentum_conserved_in_free_flight():
    beam = {"name": "beam", "model": "l-beam.ac", "angular_velocity": [3.0, 5.0, 1.0]}
    scene = _scene([beam], world={"gravity": 0.0, "half_size": 50.0},
                   integration={"duration": 10.0, "step": 1e-3},
                   dynamics={"rotation": "impulse"})
    sim = Simulation(scene)
    L0 = sim.R[0] @ sim.I_body[0] @ sim.R[0].T @ sim.w[0]
    worst = 0.0
    for _ in range(10):
        sim.run(1000)
        R = sim.R[0]
        worst = max(worst, np.abs(R.T @ R - np.eye(3)).max())
    L = sim.R[0] @ sim.I_body[0] @ sim.R[0].T @ sim.w[0]
    print(f"max |R^T R - I| = {worst:.3g} after {sim.steps} steps")
    assert worst < ORTHONORMAL_DRIFT_TOL
    assert np.allclose(L, L0, rtol=1e-12)                  # torque-free: L constant


def test_divergence_names_step_time_body_and_keeps_frames(tmp_path):
    # Euler with k h / m = 3: each step multiplies v by (1 - 3) = -2
    scene = _scene([CUBE, {**CUBE, "name": "fast", "position": [2.0, 0.0, 0.0],
                           "velocity": [1.0, 0.0, 0.0]}],
                   world={"gravity": 0.0, "drag": 3000.0, "restitution": 1.0},
                   integration={"solver": "euler", "duration": 1.0})
    with pytest.raises(DivergenceError) as info:
        simulate(scene, every=1)
    error = info.value
    assert error.body == "fast" and error.step > 5
    assert error.time == pytest.approx(error.step * 1e-3)
    assert "fast" in str(error) and f"step {error.step}" in str(error)
    partial = error.partial
    assert partial.n_frames == error.step                  # frames 0 .. step - 1
    assert np.isfinite(partial.velocity).all()
    loaded = refsim.Trajectory.load(partial.save(tmp_path / "partial.npz"))
    assert np.array_equal(loaded.velocity, partial.velocity)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")    # inf - inf on the way
def test_non_finite_state_raises_divergence():
    sim = Simulation(_scene([CUBE]))
    sim.v[0, 0] = np.inf
    with pytest.raises(DivergenceError, match="not finite") as info:
        sim.step()
    assert info.value.body == "cube" and info.value.step == 1


def test_default_stride_keeps_about_max_frames():
    assert default_every(5000) == 5
    traj = simulate(_scene([CUBE], integration={"duration": 2.5, "step": 1e-3}))
    assert traj.n_frames <= MAX_FRAMES + 2 and traj.t[-1] == pytest.approx(2.5)
    assert traj.settings["every"] == 3


def test_particle_only_scene_is_refused_clearly():
    data = {"particles": {"count": 10}}
    scene = scene_from_dict(data)
    with pytest.raises(StateError, match="no \\[\\[body\\]\\]"):
        Simulation(scene)


RIGID_SCENES = [p for p in sorted(scenes_dir().glob("*.toml")) if "[[body]]" in p.read_text()]


def test_the_bundled_rigid_scenes_are_found():
    assert len(RIGID_SCENES) >= 4          # bounce, head-on, mixed, spinning-cube, ...


@pytest.mark.parametrize("path", RIGID_SCENES, ids=lambda p: p.stem)
def test_every_bundled_rigid_scene_runs(path):
    scene = refsim.load_scene(path)
    assert scene.bodies
    traj = simulate(scene, duration=0.05)
    assert traj.n_frames >= 2
    for array in (traj.position, traj.velocity, traj.angular_velocity, traj.orientation):
        assert np.isfinite(array).all()
    assert traj.position.shape == (traj.n_frames, len(scene.bodies), 3)


@pytest.mark.parametrize("rotation", ["seed", "impulse"])
def test_box_paths_give_the_same_trajectory_bit_for_bit(rotation):
    # icosahedra (convex: the incremental tracker under "auto") bouncing and
    # colliding; the batched scan must reproduce the trackers' boxes exactly
    bodies = [{"name": f"b{i}", "model": "icosahedron.ac", "position": [1.9 * i - 2, 0, 0],
               "velocity": [2.0 - i, -3.0, 1.0], "angular_velocity": [1.0, 2.0, -1.0 + i]}
              for i in range(3)]
    scene = _scene(bodies, collision={"level": "aabb"},
                   dynamics={"rotation": rotation, "body_response": "impulse"},
                   integration={"duration": 1.0})
    a = simulate(scene, boxes="trackers", every=10)
    b = simulate(scene, boxes="batched", every=10)
    assert len(a.events) > 3
    assert np.array_equal(a.position, b.position) and np.array_equal(a.orientation,
                                                                     b.orientation)


def test_sphere_level_finds_the_contact_and_the_seed_exchanges():
    left = {"name": "left", "model": "icosahedron.ac", "position": [-1.0, 0.0, 0.0],
            "velocity": [1.0, 0.0, 0.0]}
    right = {**left, "name": "right", "position": [1.0, 0.0, 0.0], "velocity": [0.0, 0.0, 0.0]}
    scene = _scene([left, right], world={"gravity": 0.0},
                   collision={"level": "sphere"}, dynamics={"body_response": "seed"},
                   integration={"duration": 0.5})
    traj = simulate(scene)
    assert "narrow-phase" in traj.stages
    assert np.allclose(traj.velocity[-1], [[0.0, 0, 0], [1.0, 0, 0]])
    assert [(e.kind, e.body, e.other) for e in traj.events] == [("body", "left", "right")]


def test_a_state_that_overflows_within_a_step_is_a_divergence_of_that_body():
    # quadratic drag 1e50 (the most a scene allows) at 2000 m/s: RK4's stage
    # accelerations are -4e56, +4e156, then beyond float64 (inf) within the
    # first step; the check right after the motion names the body before any
    # box is computed
    fast = {"name": "fast", "model": "cube.ac", "velocity": [0.0, 0.0, 2000.0]}
    scene = _scene([fast, dict(CUBE, position=[2.0, 0.0, 0.0])],
                   world={"half_size": 3.0, "drag": 1e50, "drag_model": "quadratic"},
                   collision={"level": "aabb"}, dynamics={"body_response": "seed"})
    sim = Simulation(scene)
    with pytest.raises(DivergenceError) as info:
        sim.run(5)
    assert (info.value.step, info.value.body) == (1, "fast")
    assert info.value.time == pytest.approx(scene.integration.step)
    assert str(info.value).startswith("diverged at step 1, t = 0.001, body 'fast', ")


def test_the_largest_moments_come_from_the_jacobi_frames_not_lapack():
    """The divergence check's largest principal moment of each body is the
    fixed-order Jacobi solve's (rotation_impulse.principal_frame: the same
    bits on any OpenBLAS core), within rounding of LAPACK's eigvalsh; bodies
    with the same tensor share one solve's answer."""
    from refsim.dynamics.rotation_impulse import principal_frame

    scene = _scene([{**CUBE, "position": [0.0, 0.0, 0.0]},
                    {"name": "ball", "model": "sphere-2k.ac", "position": [3.0, 0.0, 0.0]},
                    {**CUBE, "name": "cube2", "position": [-3.0, 0.0, 0.0], "mass": 2.0}])
    sim = Simulation(scene)
    expected = [principal_frame(I)[1].max() for I in sim.I_body]
    assert sim.lambda_max.tolist() == expected
    np.testing.assert_allclose(sim.lambda_max, np.linalg.eigvalsh(sim.I_body)[:, -1],
                               rtol=1e-13)
    assert sim.lambda_max.flags.c_contiguous and sim.lambda_max[2] == 2 * sim.lambda_max[0]



def test_bodies_with_one_inertia_tensor_share_one_jacobi_solve(monkeypatch):
    from refsim.dynamics import simulation as module
    from refsim.dynamics.rotation_impulse import principal_frame
    from refsim.studies.bounce_scenes import cubes_scene

    calls = []

    def counted(I_body):
        calls.append(I_body.copy())
        return principal_frame(I_body)

    monkeypatch.setattr(module, "principal_frame", counted)
    cubes = Simulation(cubes_scene(10, "impulse"))
    assert len(calls) == 1                            # ten unit cubes, one tensor
    assert (cubes.moments == cubes.moments[0]).all() and (cubes.Q == cubes.Q[0]).all()
    Simulation(_scene([CUBE, {**CUBE, "name": "heavy", "position": [3.0, 0.0, 0.0],
                              "mass": 2.0}]))
    assert len(calls) == 3                            # two tensors, two solves
