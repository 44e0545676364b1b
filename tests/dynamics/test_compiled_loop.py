"""The compiled loop against the readable step: whole trajectories, bit for
bit, over seeded scenes with wall bounces and body contacts, for each
rotation model ("off", "seed", and "impulse" with its wall impulses), and
the hand-backs."""

from __future__ import annotations

import functools
import os
import signal
import threading
from dataclasses import replace

import numpy as np
import pytest

from refsim.bundled import scenes_dir
from refsim.dynamics.compiled_loop import loop_support
from refsim.dynamics.simulation import Simulation
from refsim.errors import DivergenceError
from refsim.scenes.loader import load_scene, scene_from_dict
from refsim.studies.bounce_scenes import cubes_scene

pytest.importorskip("numba")


def _pair(scene, n_steps: int, every: int, **options):
    """The same scene run by the readable step and by the compiled loop."""
    readable = Simulation(scene, kernel="readable", **options)
    compiled = Simulation(scene, kernel="compiled", **options)
    for sim in (readable, compiled):
        sim.record()
        sim.run(n_steps, every=every)
    return readable, compiled


def _assert_same(readable: Simulation, compiled: Simulation) -> None:
    a, b = readable.trajectory(), compiled.trajectory()
    for name in ("t", "position", "velocity", "angular_velocity", "orientation"):
        left, right = getattr(a, name), getattr(b, name)
        assert left.shape == right.shape
        assert left.tobytes() == right.tobytes(), name        # bit for bit, signs of zero too
    assert a.events == b.events
    for name in ("x", "v", "w", "R", "lo", "hi"):
        assert getattr(readable, name).tobytes() == getattr(compiled, name).tobytes(), name
    assert (readable.steps, readable.t) == (compiled.steps, compiled.t)


@pytest.mark.parametrize("rotation", ["off", "seed", "impulse"])
@pytest.mark.parametrize(("count", "seed", "solver"), [
    (1, 1, "rk4"), (3, 2, "midpoint"), (10, 3, "backwards-euler"), (40, 4, "rk4")])
def test_cubes_bounce_and_collide_bit_for_bit(count, seed, solver, rotation):
    # cubes at up to 3 m/s in a 10 m cube: every one reaches a wall within
    # 2500 steps; the 40 collide with each other (level "aabb", the seed's exchange)
    scene = cubes_scene(count, rotation, seed=seed, solver=solver)
    readable, compiled = _pair(scene, 2500, every=7)
    assert compiled.loop is None and compiled.loop_steps > 2000
    _assert_same(readable, compiled)
    kinds = {e.kind for e in compiled.events}
    assert "wall" in kinds
    if count == 40:
        assert "body" in kinds
    spins = np.abs(compiled.trajectory().angular_velocity).max()
    if rotation == "seed" or (rotation == "impulse" and count > 1):
        assert spins > 0.1       # the walls' (and, for 40, each other's) torques turned them
    elif rotation == "impulse":
        # a lone axis-aligned cube meets every wall face-flat: with Coulomb
        # friction over the whole impact the pure translation is the answer
        # (the friction's moment is balanced by a larger normal impulse at the
        # leading corners, possible for mu <= 1), so it does not turn; what is
        # left is the contact solve's residual after its sweeps
        assert spins < 1e-5


def test_quadratic_drag_euler_and_the_seeds_wall_speed_bit_for_bit():
    scene = cubes_scene(5, "seed", seed=5, solver="euler")
    scene = replace(scene, world=replace(scene.world, drag=0.3, drag_model="quadratic"))
    readable, compiled = _pair(scene, 2000, every=1, wall_speed="seed")
    assert compiled.loop_steps == 2000
    _assert_same(readable, compiled)
    assert any(e.kind == "wall" for e in compiled.events)


@pytest.mark.parametrize("rotation", ["off", "seed"])
def test_sphere_off_centre_bit_for_bit(rotation):
    # the 2000-triangle sphere's vertex average is ~1e-16 off its origin: the
    # mesh origin is x - R c, in the loop as in the readable step
    scene = scene_from_dict({
        "world": {"half_size": 2.0, "restitution": 0.9, "friction": 0.2},
        "integration": {"step": 1e-3, "duration": 1.0},
        "collision": {"level": "none"}, "dynamics": {"rotation": rotation},
        "body": [{"name": "ball", "model": "sphere-2k.ac", "position": [0.3, 0.5, -0.2],
                  "velocity": [4.0, -2.0, 3.0], "angular_velocity": [1.0, 2.0, -3.0]}]})
    readable, compiled = _pair(scene, 1500, every=50)
    assert compiled.loop is None and compiled.loop_steps == 1500
    assert not compiled.centred
    assert compiled._loop is not None and compiled._loop.tracked.tolist() == [0]  # the walk
    _assert_same(readable, compiled)
    assert len({e.other for e in compiled.events}) >= 3          # several walls
    if rotation == "seed":
        assert not np.array_equal(compiled.R[0], np.eye(3))


def test_spinning_cube_scene_bit_for_bit():
    scene = load_scene(scenes_dir() / "spinning-cube.toml")
    assert scene.dynamics.rotation == "seed"
    readable, compiled = _pair(scene, 3000, every=10)
    assert compiled.loop_steps == 3000
    _assert_same(readable, compiled)


def test_exact_level_hands_contact_steps_back_bit_for_bit():
    # the corrected response: the loop takes every step, and runs the body
    # stage of each step whose boxes overlap between two of its calls
    readable, compiled = _pair(_two_cubes_at_level_exact(), 1500, every=3)
    assert compiled.loop_steps == 1500 and 0 < compiled.loop_body_steps < 1500
    _assert_same(readable, compiled)
    assert any(e.kind == "body" for e in compiled.events)


def test_divergence_is_raised_by_the_readable_step_at_the_same_step():
    scene = cubes_scene(2, "off", seed=6, solver="euler")
    scene = replace(scene, world=replace(scene.world, drag=3000.0, gravity=0.0))
    errors = []
    for kernel in ("readable", "compiled"):
        sim = Simulation(scene, kernel=kernel)
        with pytest.raises(DivergenceError) as info:
            sim.run(200, every=1)
        errors.append(info.value)
    assert errors[0].step == errors[1].step > 5
    assert errors[0].body == errors[1].body
    assert errors[0].partial.velocity.tobytes() == errors[1].partial.velocity.tobytes()


def test_advance_then_step_then_advance_keeps_events_in_order():
    scene = cubes_scene(10, "seed", seed=7)
    readable = Simulation(scene, kernel="readable")
    compiled = Simulation(scene, kernel="compiled")
    for _ in range(3):
        readable.run(700)
        compiled.advance(700)
        readable.step()
        compiled.step()                           # the readable stages, after the loop
    assert compiled.loop_steps == 2100
    assert readable.events == compiled.events and len(compiled.events) > 5
    assert compiled.x.tobytes() == readable.x.tobytes()
    assert compiled.w.tobytes() == readable.w.tobytes()


def _two_cubes_at_level_exact():
    # two cubes meeting head-on at level "exact": the loop hands back the
    # steps whose boxes overlap
    return scene_from_dict({
        "world": {"half_size": 5.0, "gravity": 0.0},
        "integration": {"step": 1e-3, "duration": 1.0},
        "collision": {"level": "exact"},
        "dynamics": {"rotation": "off", "body_response": "impulse"},
        "body": [{"name": "a", "model": "cube.ac", "position": [-2.0, 0.0, 0.0],
                  "velocity": [3.0, 0.0, 0.0]},
                 {"name": "b", "model": "cube.ac", "position": [2.0, 0.1, 0.0],
                  "velocity": [-3.0, 0.0, 0.0]}]})


@pytest.mark.parametrize("case", ["1 cube", "10 cubes", "sphere-2k", "40 cubes seed",
                                  "exact level"])
def test_one_step_per_call_is_one_call_and_the_readable_step_bit_for_bit(case):
    # Simulation.advance's fast path (one kernel call, no signal hold) against
    # one advance of all the steps and against the readable step: the same
    # state, counts and events, with wall and body events and hand-backs
    from refsim.studies.bounce_scenes import bench_scene

    if case == "exact level":
        scene, n = _two_cubes_at_level_exact(), 1000
    elif case == "40 cubes seed":
        scene, n = cubes_scene(40, "seed", seed=4), 600
    else:
        scene, n = bench_scene(case, "impulse")[0], 2500
    whole = Simulation(scene, kernel="compiled")
    whole.advance(n)
    calls = Simulation(scene, kernel="compiled")
    for _ in range(n):
        calls.advance(1)
    readable = Simulation(scene, kernel="readable")
    readable.advance(n)
    for sim in (calls, whole):
        for name in ("x", "v", "w", "R"):
            assert getattr(sim, name).tobytes() == getattr(readable, name).tobytes(), name
        assert (sim.steps, sim.t) == (readable.steps, readable.t) == (n, n * scene.integration.step)
        assert sim.events == readable.events
    assert calls.loop_steps == whole.loop_steps > 0
    assert readable.events                    # wall contacts at least
    if case == "exact level":
        assert calls.loop_steps == n and any(e.kind == "body" for e in calls.events)
        assert calls.loop_body_steps == whole.loop_body_steps > 0


def test_event_rows_left_by_an_interrupted_call_are_added_once():
    # What a signal between the kernel's return and the bookkeeping leaves:
    # the kernel has counted the steps and its event rows are pending. They
    # become events when the list is read, and a second reading after a cut
    # between the list's growth and the counters' reset adds nothing twice.
    from refsim.dynamics import loop_layout as slot

    scene = cubes_scene(10, "impulse", seed=3)
    reference = Simulation(scene, kernel="compiled")
    reference.advance(2500)
    sim = Simulation(scene, kernel="compiled")
    loop = sim._loop
    kernel, floats, ints, flags = loop._call
    counters = loop.counters
    for done in range(500, 2501, 500):         # the kernel alone, nothing noted
        kernel(500, floats, ints, flags)
        assert counters[slot.C_LEFT] == 0 and sim.steps == done   # counted by the kernel
    assert counters[slot.C_PENDING] > 1 and sim._events == []
    before = counters.copy()
    sim._events.extend(reference.events[:2])   # as if cut after part of a note
    counters[...] = before
    assert sim.events == reference.events      # the rest added, none twice
    counters[...] = before                     # cut after the extend, before the reset
    assert sim.events == reference.events and counters[slot.C_PENDING] == 0
    for name in ("x", "v", "w", "R"):
        assert getattr(sim, name).tobytes() == getattr(reference, name).tobytes(), name
    sim.advance(300)
    reference.advance(300)
    assert sim.events == reference.events and sim.t == reference.t


def test_what_the_loop_does_not_run_says_why():
    assert "readable" in Simulation(cubes_scene(1), kernel="readable").loop
    assert Simulation(cubes_scene(1, "impulse"), kernel="compiled").loop is None
    sphere = cubes_scene(2)
    sphere = replace(sphere, collision=replace(sphere.collision, level="sphere"))
    assert "sphere" in loop_support(Simulation(sphere, kernel="compiled"))


@pytest.mark.parametrize("name", ["bounce", "head-on", "mixed", "spinning-cube"])
def test_bundled_scenes_bit_for_bit(name):
    # mixed.toml: a sphere, a torus (not convex: the linear scan) and an
    # l-beam at level "triangle-aabb" (hand-back), with the seed's rotation:
    # a step handed back after a wall contact changed w must restore w too;
    # head-on.toml: two icosahedra meeting at level "exact"
    scene = load_scene(scenes_dir() / f"{name}.toml")
    readable, compiled = _pair(scene, 1200, every=5)
    assert compiled.loop is None and compiled.loop_steps > 0
    _assert_same(readable, compiled)
    assert len(compiled.events) >= 1


@pytest.mark.parametrize("rotation", ["off", "seed"])
def test_cubes_at_level_exact_hand_back_bit_for_bit(rotation):
    # the 40 cubes' contacts, found exactly: every step with overlapping
    # boxes runs its body stage between two calls of the loop, walls and
    # spin included
    scene = cubes_scene(40, rotation, seed=9)
    scene = replace(scene, collision=replace(scene.collision, level="exact"))
    readable, compiled = _pair(scene, 800, every=9)
    assert compiled.loop is None and compiled.loop_steps == 800
    assert 0 < compiled.loop_body_steps < 800
    _assert_same(readable, compiled)
    assert {e.kind for e in compiled.events} == {"wall", "body"}


def test_box_trackers_in_the_loop_bit_for_bit():
    # boxes="trackers": each cube's incremental walk, in the loop as in the step
    scene = cubes_scene(10, "seed", seed=10)
    readable, compiled = _pair(scene, 2500, every=11, boxes="trackers")
    assert compiled._loop is not None and (compiled._loop.tracked >= 0).all()
    _assert_same(readable, compiled)
    assert any(e.kind == "wall" for e in compiled.events)


@pytest.mark.parametrize("response", ["seed", "impulse"])
@pytest.mark.parametrize("case", ["chase", "slow", "stack", "glancing"])
def test_claim_c11_scenes_bit_for_bit(case, response):
    # the report's C11 scenes at level "exact": contacts that end while the
    # loop runs and begin again (the stack's bounces) are new events each time
    from refsim.studies.dynamics import c11_scene

    # as the report runs them; a step of the impulse stack in contact is a
    # readable body-contact step on both kernels, and its first second holds
    # the bounces this test needs
    seconds = 1.0 if (case, response) == ("stack", "impulse") else 2.0
    scene = c11_scene(case, response, duration=seconds, step=1e-3)
    readable, compiled = _pair(scene, round(seconds / 1e-3), every=1)
    assert compiled.loop is None and compiled.loop_steps == round(seconds / 1e-3)
    assert compiled.loop_body_steps > 0        # the body stage between two calls
    _assert_same(readable, compiled)
    assert any(e.kind == "body" for e in compiled.events)
    if case == "stack":
        assert sum(e.kind == "body" for e in compiled.events) >= 2


def test_ctrl_c_during_the_loop_leaves_the_simulation_consistent():
    # SIGINT from another thread while the main thread is inside the
    # compiled loop: the interrupt comes out of run(), and the steps, time
    # and events account for exactly the state reached (a handler that
    # raised between the kernel's return and its bookkeeping left the state
    # up to a chunk of steps ahead of them)
    scene = cubes_scene(10, "seed", seed=3, solver="rk4")
    sim = Simulation(scene, kernel="compiled")
    sim.run(10)                                   # compiled and loaded: not timed below
    timer = threading.Timer(0.3, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            sim.run(5_000_000)
    finally:
        timer.cancel()
    assert 10 < sim.steps < 5_000_000 and sim.t == sim.steps * sim.h
    again = Simulation(scene, kernel="compiled")
    again.run(sim.steps)
    for name in ("x", "v", "w", "R"):
        assert getattr(sim, name).tobytes() == getattr(again, name).tobytes(), name
    assert sim.events == again.events
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler   # restored


# the interrupt Hypothesis's gc callback drops (see the test) is reported as
# unraisable; it is expected here
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_ctrl_c_during_one_step_calls_leaves_the_simulation_consistent():
    # the same with advance(1) in a Python loop, the fast path without the
    # signal hold: wherever the interrupt lands, the kernel has counted the
    # steps it took and its event rows, and they show in steps, t and events
    scene = cubes_scene(10, "seed", seed=3, solver="rk4")
    sim = Simulation(scene, kernel="compiled")
    sim.advance(1)
    _interrupt_one_step_calls(sim, 0.3)
    assert 10 < sim.steps and sim.t == sim.steps * sim.h
    again = Simulation(scene, kernel="compiled")
    again.run(sim.steps)
    for name in ("x", "v", "w", "R"):
        assert getattr(sim, name).tobytes() == getattr(again, name).tobytes(), name
    assert sim.events == again.events and sim.events
    assert sim.loop_steps == sim.steps


# -- the corrected rotation model ("impulse") and its wall impulses -------------------------

def _one_body_scene(model: str, *, solver: str = "rk4", world: dict | None = None,
                    dynamics: dict | None = None, **body):
    return scene_from_dict({
        "world": {"half_size": 2.0, "restitution": 0.7, "friction": 0.3, **(world or {})},
        "integration": {"solver": solver, "step": 1e-3, "duration": 10.0},
        "collision": {"level": "none"},
        "dynamics": {"rotation": "impulse", **(dynamics or {})},
        "body": [{"name": "body", "model": model, **body}]})


@pytest.mark.parametrize("model", ["long-box.ac", "l-beam.ac"])
def test_impulse_free_flight_of_an_unequal_body_bit_for_bit(model):
    # torque-free tumbling of a body with three different principal moments
    # (the l-beam's centre of mass is off its mesh origin): w changes every
    # step, and no wall is reached
    scene = _one_body_scene(model, world={"gravity": 0.0, "half_size": 50.0},
                            angular_velocity=[3.0, 5.0, 1.0], velocity=[0.5, 0.0, 0.0])
    readable, compiled = _pair(scene, 3000, every=13)
    assert compiled.loop is None and compiled.loop_steps == 3000
    _assert_same(readable, compiled)
    assert not compiled.events
    w = compiled.trajectory().angular_velocity[:, 0]
    assert np.abs(w - w[0]).max() > 0.5                  # not a steady spin


@pytest.mark.parametrize("solver", ["euler", "averaged-euler", "backwards-euler", "midpoint",
                                    "rk4"])
def test_impulse_wall_bounces_each_solver_bit_for_bit(solver):
    # a spinning long box thrown at the walls, then tumbling on the floor:
    # one to four vertices past a wall in a step (rk4: 348 steps with one,
    # 1727 with two, 18 with three, 37 with four)
    scene = _one_body_scene("long-box.ac", solver=solver, position=[0.0, 0.5, 0.0],
                            velocity=[3.0, -2.0, 1.5], angular_velocity=[2.0, -4.0, 6.0])
    readable, compiled = _pair(scene, 1500, every=17)
    assert compiled.loop is None and compiled.loop_steps == 1500
    _assert_same(readable, compiled)
    assert len({e.other for e in compiled.events}) >= 3            # several walls


def test_impulse_cube_landing_flat_then_resting_bit_for_bit():
    # four corners past the floor at once, then resting contact: the
    # restitution threshold and the speed at the wall (D6) in every step
    scene = _one_body_scene("cube.ac", world={"restitution": 0.5},
                            position=[0.0, -1.0, 0.0], velocity=[0.4, 0.0, 0.0])
    readable, compiled = _pair(scene, 1500, every=97)     # at rest from about step 1100
    assert compiled.loop is None and compiled.loop_steps == 1500
    _assert_same(readable, compiled)
    assert np.abs(compiled.v).max() < 1e-6 and np.abs(compiled.w).max() < 1e-6   # at rest
    assert compiled.lo[0, 1] == -2.0                     # on the floor, pushed back exactly


@pytest.mark.parametrize("boxes", ["trackers", "batched"])
def test_impulse_incremental_and_linear_boxes_bit_for_bit(boxes):
    # "trackers": each cube's incremental walk; "batched": the linear scan
    scene = cubes_scene(10, "impulse", seed=11)
    readable, compiled = _pair(scene, 2500, every=11, boxes=boxes)
    tracked = compiled._loop.tracked if compiled._loop is not None else None
    assert tracked is not None and ((tracked >= 0).all() if boxes == "trackers"
                                    else (tracked < 0).all())
    _assert_same(readable, compiled)
    assert any(e.kind == "wall" for e in compiled.events)


def test_impulse_sphere_off_centre_with_its_walk_bit_for_bit():
    scene = scene_from_dict({
        "world": {"half_size": 2.0, "restitution": 0.9, "friction": 0.2},
        "integration": {"step": 1e-3, "duration": 1.0},
        "collision": {"level": "none"}, "dynamics": {"rotation": "impulse"},
        "body": [{"name": "ball", "model": "sphere-2k.ac", "position": [0.3, 0.5, -0.2],
                  "velocity": [4.0, -2.0, 3.0], "angular_velocity": [1.0, 2.0, -3.0]}]})
    readable, compiled = _pair(scene, 1500, every=50)
    assert compiled._loop is not None and compiled._loop.tracked.tolist() == [0]
    assert compiled.loop_steps == 1500
    _assert_same(readable, compiled)
    assert len({e.other for e in compiled.events}) >= 3


@pytest.mark.parametrize(("rotation", "wall_response"), [
    ("impulse", "seed"), ("off", "impulse"), ("seed", "impulse")])
def test_each_rotation_with_each_wall_response_bit_for_bit(rotation, wall_response):
    scene = cubes_scene(3, rotation, seed=12, solver="midpoint")
    scene = replace(scene, dynamics=replace(scene.dynamics, wall_response=wall_response))
    readable, compiled = _pair(scene, 2500, every=7)
    assert compiled.loop is None and compiled.loop_steps == 2500
    assert compiled.plan.wall_response == wall_response
    _assert_same(readable, compiled)
    assert any(e.kind == "wall" for e in compiled.events)


@pytest.mark.parametrize("level", ["aabb", "exact"])
def test_impulse_body_contacts_are_handed_back_bit_for_bit(level):
    # the corrected body response is the readable step's: each step with
    # overlapping boxes runs its body stage between two calls of the loop,
    # walls and the exact rotation included
    scene = cubes_scene(40, "impulse", seed=13)
    scene = replace(scene, collision=replace(scene.collision, level=level),
                    dynamics=replace(scene.dynamics, body_response="impulse"))
    readable, compiled = _pair(scene, 800, every=9)
    assert compiled.loop is None and compiled.loop_steps == 800
    assert 0 < compiled.loop_body_steps < 800
    _assert_same(readable, compiled)
    assert {e.kind for e in compiled.events} == {"wall", "body"}


# -- the wall stage's leaves (vertex_leaves, _vertices_past_wall) -----------------------------


def _model_vertices(model: str) -> np.ndarray:
    from refsim.bundled import models_dir
    from refsim.models.loading import load_model

    return load_model(models_dir() / model).vertices


def test_vertex_leaves_partition_the_mesh_into_small_groups_inside_their_spheres():
    from refsim.dynamics.compiled_loop import LEAF_VERTICES, vertex_leaves

    for model in ("sphere-2k.ac", "cube.ac", "l-beam.ac"):
        vertices = _model_vertices(model)
        order, start, spheres = vertex_leaves(vertices)
        assert sorted(order.tolist()) == list(range(len(vertices)))      # each vertex once
        sizes = np.diff(start)
        assert start[0] == 0 and start[-1] == len(vertices)
        assert sizes.min() >= 1 and sizes.max() <= LEAF_VERTICES
        for leaf, sphere in enumerate(spheres):
            points = vertices[order[start[leaf]:start[leaf + 1]]]
            distance = np.linalg.norm(points - sphere[:3], axis=1)
            assert distance.max() <= sphere[3] * (1 + 1e-12)
            assert np.linalg.norm(points, axis=1).max() <= sphere[4] * (1 + 1e-12)
        again = vertex_leaves(vertices)                                   # deterministic
        assert all(np.array_equal(a, b) for a, b in zip(again, (order, start, spheres),
                                                        strict=True))
    order, start, spheres = vertex_leaves(_model_vertices("sphere-2k.ac"))
    assert len(spheres) == 64 and spheres[:, 3].max() < 0.35    # local groups (radius 1)


def _past_by_testing_every_vertex(a, X, o_k, wall, low):
    W = ((a[0] * X[0] + a[1] * X[1]) + a[2] * X[2]) + o_k     # numpy rounds each op once
    return np.flatnonzero(W < wall if low else W > wall)


def test_the_vertices_past_a_wall_are_those_of_testing_every_vertex():
    # the leaves are only passed over when no vertex can be past: the list is
    # the full scan's, in the same order, also for walls through a vertex
    from refsim.dynamics import _numba_walls as kernels
    from refsim.dynamics.compiled_loop import vertex_leaves
    from refsim.types import random_rotation

    rng = np.random.default_rng(314)
    checked = hits = 0
    for model in ("sphere-2k.ac", "l-beam.ac", "cube.ac"):
        vertices = _model_vertices(model)
        X = np.ascontiguousarray(vertices.T)
        order, start, spheres = vertex_leaves(vertices)
        first_leaf = np.array([0, len(spheres)], np.int64)
        past = np.empty(len(vertices), np.int64)
        for trial in range(300):
            R = random_rotation(rng)[None]
            k = trial % 3
            low = trial % 2 == 0
            wall = float(rng.choice([-2.0, 2.0, -1e3, 7.5]))
            a = R[0, k]
            r = ((a[0] * X[0] + a[1] * X[1]) + a[2] * X[2])
            # a wall through a vertex (to rounding), or at a random depth
            target = r[rng.integers(len(r))] if trial % 4 else rng.uniform(r.min(), r.max())
            for o_k in (wall - target, np.nextafter(wall - target, np.inf),
                        np.nextafter(wall - target, -np.inf)):
                expected = _past_by_testing_every_vertex(a, X, o_k, wall, low)
                count = kernels.vertices_past_wall(0, k, low, wall, o_k, R, X, order, start,
                                                   spheres, first_leaf, past)
                assert past[:count].tolist() == expected.tolist()
                checked += 1
                hits += count > 0
    assert checked == 2700 and hits > 1000


def _rotation_with_row(u: np.ndarray, k: int, rng) -> np.ndarray:
    """A rotation whose row k is the unit vector u."""
    t = rng.normal(size=3)
    t -= (t @ u) * u
    t /= np.linalg.norm(t)
    R = np.empty((3, 3))
    R[k], R[(k + 1) % 3], R[(k + 2) % 3] = u, t, np.cross(u, t)
    if np.linalg.det(R) < 0:
        R[(k + 1) % 3] *= -1.0
    return R


def test_a_wall_touching_a_leafs_sphere_finds_the_vertices_past_it():
    # where the slack matters: each leaf's farthest vertex from its centre
    # lies on its sphere, so with the rotation's row k pointing from it to
    # the centre (away from it, for a high wall) and the wall through it
    # (and one float either side), the leaf's sphere touches the wall up to
    # rounding. Walls near 0 make that rounding large against the wall's
    # spacing of floats: with CULL_SLACK = 0 this test fails (some leaves
    # are passed over with a vertex past the wall).
    from refsim.dynamics import _numba_walls as kernels
    from refsim.dynamics.compiled_loop import vertex_leaves

    rng = np.random.default_rng(1)
    checked = 0
    for model in ("sphere-2k.ac", "torus.ac"):
        vertices = _model_vertices(model)
        X = np.ascontiguousarray(vertices.T)
        order, start, spheres = vertex_leaves(vertices)
        first_leaf = np.array([0, len(spheres)], np.int64)
        past = np.empty(len(vertices), np.int64)
        for leaf in range(len(spheres)):
            members = order[start[leaf]:start[leaf + 1]]
            centre = spheres[leaf, :3]
            far = members[np.argmax(np.linalg.norm(vertices[members] - centre, axis=1))]
            d = (vertices[far] - centre) / np.linalg.norm(vertices[far] - centre)
            for k, low, size in ((leaf % 3, True, 0.01), ((leaf + 1) % 3, False, 0.01),
                                 ((leaf + 2) % 3, True, 2.0)):
                R = _rotation_with_row(-d if low else d, k, rng)[None]
                assert abs(np.linalg.det(R[0]) - 1.0) < 1e-12
                wall = -size if low else size
                a = R[0, k]
                through = wall - ((a[0] * X[0, far] + a[1] * X[1, far]) + a[2] * X[2, far])
                for o_k in (through, np.nextafter(through, np.inf),
                            np.nextafter(through, -np.inf)):
                    expected = _past_by_testing_every_vertex(a, X, o_k, wall, low)
                    count = kernels.vertices_past_wall(0, k, low, wall, o_k, R, X, order,
                                                       start, spheres, first_leaf, past)
                    assert past[:count].tolist() == expected.tolist()
                    checked += 1
    assert checked == 3 * 3 * (64 + 64)


def test_several_bodies_with_several_leaves_each_bit_for_bit():
    # the leaves' layout across bodies: two spheres sharing a mesh, cubes,
    # a torus, each with its own slice of leaves and vertex columns
    bodies = [("sphere-2k.ac", [-1.0, 0.0, 0.0], [3.0, -2.0, 1.0]),
              ("cube.ac", [1.5, 1.5, 1.5], [-2.0, 1.0, 3.0]),
              ("sphere-2k.ac", [1.5, -1.2, -1.0], [1.0, 4.0, -2.0]),
              ("torus.ac", [-1.5, 1.5, -1.5], [2.0, -3.0, -1.0]),
              ("cube.ac", [1.6, 1.6, -1.6], [0.5, 0.5, 4.0])]
    scene = scene_from_dict({
        "world": {"half_size": 3.0, "restitution": 0.8, "friction": 0.3},
        "integration": {"step": 1e-3, "duration": 2.0},
        "collision": {"level": "none"}, "dynamics": {"rotation": "impulse"},
        "body": [{"name": f"b{i}", "model": model, "position": x, "velocity": v,
                  "angular_velocity": [1.0, -2.0, 0.5]}
                 for i, (model, x, v) in enumerate(bodies)]})
    readable, compiled = _pair(scene, 1200, every=40)
    loop = compiled._loop
    assert loop is not None and compiled.loop_steps == 1200
    leaves = np.diff(loop.first_leaf)
    assert leaves.tolist() == [64, 1, 64, 64, 1]
    for b in range(len(bodies)):                     # each body's indices in its own columns
        first, end = loop.first_leaf[b], loop.first_leaf[b + 1]
        columns = loop.leaf_order[loop.leaf_start[first]:loop.leaf_start[end]]
        assert sorted(columns.tolist()) == list(range(loop.first_vertex[b],
                                                      loop.first_vertex[b + 1]))
    _assert_same(readable, compiled)
    assert len({e.body for e in compiled.events if e.kind == "wall"}) == len(bodies)


def test_impulse_sphere_rolling_on_the_floor_bit_for_bit(monkeypatch):
    # the benchmark's settled sphere: rolling on the floor, a few of its 1002
    # vertices past it in almost every step (the leaves passed over, the
    # contact solve with a static wall), from the same state on both kernels
    from refsim.dynamics import impulse
    from refsim.studies.bounce_scenes import SETTLE_STEPS, sphere_scene

    scene = sphere_scene("impulse")
    compiled = Simulation(scene, kernel="compiled")
    compiled.advance(SETTLE_STEPS["sphere"])
    start = compiled.snapshot()
    compiled.events.clear()                   # the settling's; the readable one has none
    readable = Simulation(scene, kernel="readable")
    readable.restore(start)
    contacts = []
    solve = impulse.solve_contacts

    def counted(r_a, *args, **options):
        contacts.append(len(r_a))
        return solve(r_a, *args, **options)

    monkeypatch.setattr(impulse, "solve_contacts", counted)
    for sim in (readable, compiled):
        sim.record()
        sim.run(400, every=7)
    _assert_same(readable, compiled)
    assert compiled.loop_steps == SETTLE_STEPS["sphere"] + 400
    # touching in most steps (a facet's edge it rolls over bumps it off the
    # floor now and then: 320 of the 400 steps touch), at its lowest vertex
    # or two: at rest every vertex past the floor holds it, and the impacts
    # act at the deepest of them only (rotation_impulse.wall_contacts), never
    # at the ring of vertices a deeper landing leaves past the floor
    assert len(contacts) >= 300 and max(contacts) <= 2
    assert np.abs(compiled.w).max() > 0.05                        # rolling, not at rest


# -- body-contact steps in the loop (the body stage between two of its calls) -----------------

def _contact_scene(count: int, solver: str):
    """The body-contact benchmark's cubes (tests/benchmarks/test_bench_dynamics.py
    ``contact_scene``): exact level, every response "impulse", mu 0.3."""
    from refsim.studies.bounce_scenes import bench_scene

    scene = bench_scene(f"{count} cubes", "impulse")[0]
    return replace(
        scene, world=replace(scene.world, mu=0.3),
        integration=replace(scene.integration, solver=solver),
        collision=replace(scene.collision, level="exact"),
        dynamics=replace(scene.dynamics, rotation="impulse", body_response="impulse",
                         wall_response="impulse"))


#: Steps before the compared ones: the benchmark's "in flight" (the cubes
#: meet in the air) and "settled" (the ten rest on the floor, apart under
#: Euler; most of the forty rest on each other).
_CONTACT_STATES = {"in flight": 500, "settled": 3000}


@functools.cache
def _contact_state(count: int, state: str) -> dict:
    """The cubes' (x, v, w, R) after the steps of ``state``, taken by the
    compiled loop under Euler whatever the compared solver: the state is a
    start, not a result, and rk4 takes four stages a step to reach it."""
    lead = Simulation(_contact_scene(count, "euler"), kernel="compiled")
    lead.advance(_CONTACT_STATES[state])
    return {name: getattr(lead, name).copy() for name in ("x", "v", "w", "R")}


@pytest.mark.parametrize("solver", ["euler", "rk4"])
@pytest.mark.parametrize("state", sorted(_CONTACT_STATES))
@pytest.mark.parametrize("count", [10, 40])
def test_body_contact_steps_in_the_loop_bit_for_bit(count, state, solver):
    # From the same state (reached by the compiled loop under Euler, written
    # into both), the readable step and the loop take the same steps: the
    # loop takes every one, and runs the body stage of those with
    # overlapping boxes between two of its calls.
    scene = _contact_scene(count, solver)
    start = _contact_state(count, state)
    readable = Simulation(scene, kernel="readable")
    compiled = Simulation(scene, kernel="compiled")
    for sim in (readable, compiled):
        for name in ("x", "v", "w", "R"):
            getattr(sim, name)[...] = start[name]
        sim.record()
        sim.run(120, every=3)
    _assert_same(readable, compiled)
    assert compiled.loop_steps == 120
    if (count, state) == (10, "settled"):
        # resting apart on the floor: no body stage, the loop alone
        assert compiled.loop_body_steps == 0
    elif state == "settled":                     # resting contacts: nearly every step
        assert compiled.loop_body_steps >= 100
        assert any(e.kind == "body" for e in compiled.events)
    else:
        assert compiled.loop_body_steps > 0
        assert any(e.kind == "body" for e in compiled.events)


def test_body_contact_steps_one_call_each_bit_for_bit():
    # advance(1) per step (the fast path): the body stage runs inside the call
    scene = _contact_scene(10, "euler")
    calls = Simulation(scene, kernel="compiled")
    whole = Simulation(scene, kernel="compiled")
    readable = Simulation(scene, kernel="readable")
    for _ in range(700):
        calls.advance(1)
    whole.advance(700)
    readable.advance(700)
    for sim in (calls, whole):
        for name in ("x", "v", "w", "R", "lo", "hi"):
            assert getattr(sim, name).tobytes() == getattr(readable, name).tobytes(), name
        assert sim.events == readable.events and sim.steps == 700
        assert sim.loop_steps == 700
    assert calls.loop_body_steps == whole.loop_body_steps > 0


def test_divergence_after_body_contact_steps_is_raised_at_the_same_step():
    # cubes meeting in the air, then a drag that makes Euler unstable
    # (|1 - h k / m| = 2): the loop's body-stage steps come first, then the
    # readable step raises at the same step as on the readable kernel
    scene = _contact_scene(10, "euler")
    lead = Simulation(scene, kernel="compiled")
    lead.advance(500)
    unstable = replace(scene, world=replace(scene.world, drag=3000.0))
    errors, body_steps = [], []
    for kernel in ("readable", "compiled"):
        sim = Simulation(unstable, kernel=kernel)
        for name in ("x", "v", "w", "R"):
            getattr(sim, name)[...] = getattr(lead, name)
        with pytest.raises(DivergenceError) as info:
            sim.run(2000, every=1)
        errors.append(info.value)
        body_steps.append(sim.loop_body_steps)
    assert errors[0].step == errors[1].step > 5
    assert errors[0].body == errors[1].body
    assert errors[0].partial.velocity.tobytes() == errors[1].partial.velocity.tobytes()
    assert body_steps[0] == 0 < body_steps[1]


# the interrupt Hypothesis's gc callback drops is reported as unraisable (as above)
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_ctrl_c_during_body_contact_steps_leaves_the_simulation_consistent():
    # advance(1) calls on a stack of cubes in contact, each step a body stage
    # in Python after the kernel stopped inside the step: an interrupt before
    # the step is committed puts the state back to the step's start, so
    # steps, t, contacts and events account for the state wherever it lands
    from refsim.studies.dynamics import c11_scene

    scene = c11_scene("stack", "impulse", duration=1000.0, step=1e-3)
    sim = Simulation(scene, kernel="compiled")
    sim.advance(1000)                           # in contact from about step 670 on
    start, body_steps = sim.snapshot(), sim.loop_body_steps
    _interrupt_one_step_calls(sim, 0.05)
    assert sim.steps > start["steps"] and sim.t == sim.steps * sim.h
    assert sim.loop_body_steps - body_steps == sim.steps - start["steps"]   # each one
    again = Simulation(scene, kernel="compiled")
    again.advance(sim.steps)
    for name in ("x", "v", "w", "R"):
        assert getattr(sim, name).tobytes() == getattr(again, name).tobytes(), name
    assert sim.events == again.events and sim.events
    sim.advance(50)                             # and it goes on as if not interrupted
    again.advance(50)
    for name in ("x", "v", "w", "R"):
        assert getattr(sim, name).tobytes() == getattr(again, name).tobytes(), name
    assert sim.events == again.events


def test_an_exception_in_the_body_stage_puts_the_step_back():
    # an interrupt raised inside the body stage (here from the body
    # response, deterministically): the step is not committed, the state is
    # the step's start, and the next call takes the step from there
    from refsim.studies.dynamics import c11_scene

    scene = c11_scene("stack", "impulse", duration=10.0, step=1e-3)
    sim = Simulation(scene, kernel="compiled")
    reference = Simulation(scene, kernel="compiled")
    sim.advance(1000)
    reference.advance(1000)
    before = {name: getattr(sim, name).copy() for name in ("x", "v", "w", "R")}
    events, body_steps = list(sim.events), sim.loop_body_steps
    respond = sim._body_response

    def interrupted(pairs, touching):
        respond(pairs, touching)               # the state moved, then the interrupt
        raise KeyboardInterrupt

    sim._body_response = interrupted
    with pytest.raises(KeyboardInterrupt):
        sim.advance(5)
    del sim._body_response
    assert sim.steps == 1000 and sim.loop_body_steps == body_steps
    for name, value in before.items():
        assert getattr(sim, name).tobytes() == value.tobytes(), name
    assert sim.events == events
    sim.advance(200)
    reference.advance(200)
    for name in ("x", "v", "w", "R"):
        assert getattr(sim, name).tobytes() == getattr(reference, name).tobytes(), name
    assert sim.events == reference.events and sim.loop_body_steps == reference.loop_body_steps


def test_the_loops_sort_of_vertex_indices_is_numpys():
    """_sort_ascending (the wall stage's vertices past a wall, in increasing
    order) sorts ``a[:n]`` and leaves the rest, for lengths 0 to 300."""
    from refsim.dynamics import _numba_walls

    rng = np.random.default_rng(7)
    for _ in range(300):
        n = int(rng.integers(0, 301))
        a = rng.permutation(5000)[:n + 3].astype(np.int64)
        expected = a.copy()
        expected[:n] = np.sort(expected[:n])
        _numba_walls._sort_ascending(a, n)
        assert np.array_equal(a, expected), n


def _interrupt_one_step_calls(sim: Simulation, period: float) -> None:
    """SIGINT every ``period`` seconds while ``sim`` takes one step per call,
    until the call in progress raises KeyboardInterrupt. Ctrl-C raises it in
    whatever Python code runs when it is handled, and one raised inside a
    garbage-collector callback (Hypothesis registers one) is reported and
    dropped, not propagated: so the signal is sent until one arrives."""
    caught = []

    def interrupt(signum, frame):
        if not caught:
            raise KeyboardInterrupt

    previous = signal.signal(signal.SIGINT, interrupt)
    stop = threading.Event()

    def send():
        while not stop.wait(period):
            os.kill(os.getpid(), signal.SIGINT)

    sender = threading.Thread(target=send, daemon=True)
    sender.start()
    try:
        for _ in range(5_000_000):             # bounded: never fills memory
            sim.advance(1)
    except KeyboardInterrupt:
        caught.append(True)
    finally:
        stop.set()
        sender.join()
        signal.signal(signal.SIGINT, previous)
    assert caught, "no interrupt reached the loop"
