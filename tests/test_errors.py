"""The error contract of the public API: a user's mistake raises a RefsimError
that is also the ValueError or TypeError Python code expects, with a message
naming the argument; nothing else escapes (docs/design.md, Errors)."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from refsim.errors import (
    ArgumentTypeError,
    OptionError,
    RefsimError,
    StateError,
    check_count,
    check_option,
)
from refsim.limits import MAX_PARTICLES, MAX_STEPS

CUBE = refsim.load_model("cube.ac")
POSE = (np.eye(3), np.zeros(3))


def test_the_hierarchy_is_also_pythons():
    assert issubclass(refsim.ModelError, ValueError)
    assert issubclass(refsim.SceneError, ValueError)
    assert issubclass(refsim.StateError, ValueError)
    assert issubclass(refsim.OptionError, ValueError)
    assert issubclass(refsim.ArgumentTypeError, TypeError)
    assert issubclass(refsim.OutputError, OSError)
    for cls in (refsim.ModelError, refsim.SceneError, refsim.StateError, refsim.OptionError,
                refsim.ArgumentTypeError, refsim.OutputError, refsim.DivergenceError):
        assert issubclass(cls, RefsimError)


def test_check_option_names_the_option_and_the_choices():
    assert check_option("level", "aabb", ("aabb", "exact")) == "aabb"
    with pytest.raises(OptionError) as info:
        check_option("level", "obb", ("aabb", "exact"))
    assert str(info.value) == "level must be one of 'aabb', 'exact', got 'obb'"
    with pytest.raises(OptionError):
        check_option("level", ["aabb"], ("aabb",))       # unhashable: still an OptionError


@pytest.mark.parametrize("value, error", [(-1, StateError), (2.5, ArgumentTypeError),
                                          (True, ArgumentTypeError), (None, ArgumentTypeError),
                                          ("3", ArgumentTypeError)])
def test_check_count_refuses_what_is_not_a_count(value, error):
    with pytest.raises(error, match="steps must be"):
        check_count("steps", value)
    assert check_count("steps", np.int64(3)) == 3


@pytest.mark.parametrize("call, error, phrase", [
    (lambda: refsim.bodies_collide(CUBE, POSE, CUBE, POSE, level="obb"), OptionError,
     "level must be one of"),
    (lambda: refsim.intersecting_pairs(CUBE, POSE, CUBE, POSE, method="fast"), OptionError,
     "method must be one of"),
    (lambda: refsim.intersecting_pairs(CUBE, POSE, CUBE, POSE, kernel="cuda"), OptionError,
     "kernel must be one of"),
    (lambda: refsim.aabb_linear(CUBE, POSE, kernel="cuda"), OptionError, "kernel"),
    (lambda: refsim.IncrementalAABB(CUBE, kernel="cuda"), OptionError, "kernel"),
    (lambda: refsim.make_aabb_tracker(CUBE, "fast"), OptionError, "aabb mode"),
    (lambda: refsim.bodies_collide(None, POSE, CUBE, POSE), ArgumentTypeError,
     "mesh_a must be a refsim.Mesh, got NoneType"),
    (lambda: refsim.intersecting_pairs(CUBE, POSE, "cube", POSE), ArgumentTypeError,
     "mesh_b must be a refsim.Mesh, got str"),
    (lambda: refsim.aabb_linear(None, POSE), ArgumentTypeError, "mesh must be"),
    (lambda: refsim.IncrementalAABB(None), ArgumentTypeError, "mesh must be"),
    (lambda: refsim.load_scene(None), ArgumentTypeError, "path must be a file path"),
    (lambda: refsim.load_model(3), ArgumentTypeError, "path must be a file path"),
    (lambda: refsim.Simulation(None), ArgumentTypeError, "scene must be a refsim.Scene"),
    (lambda: refsim.integrate(lambda t, y: -y, [1.0], 0.0, 1.0, 5e-324), StateError,
     f"exceeds the limit of {MAX_STEPS:.0e}"),
    (lambda: refsim.integrate(lambda t, y: -y, [1.0], 0.0, 1e9, 1.0), StateError,
     "exceeds the limit"),
    (lambda: refsim.integrate(lambda t, y: -y, np.ones(10**6), 0.0, 1e3, 1e-3), StateError,
     "GiB"),
    (lambda: refsim.integrate(lambda t, y: -y, [1.0], 0.0, 1.0, 0.1, method="rk5"),
     OptionError, "unknown solver"),
    (lambda: refsim.ParticleConfig(count=10**10), refsim.SceneError,
     f"must be in [1, {MAX_PARTICLES}]"),
    (lambda: refsim.ParticleSystem(refsim.ParticleConfig(count=10)).run(-5), StateError,
     "steps must be at least 0"),
    (lambda: refsim.ParticleSystem(refsim.ParticleConfig(count=10)).run(2.5),
     ArgumentTypeError, "steps must be an integer"),
    (lambda: refsim.ParticleSystem(refsim.ParticleConfig(count=10)).run(MAX_STEPS + 1),
     StateError, f"steps must be at least 0 and at most {MAX_STEPS}"),
    (lambda: refsim.Simulation(refsim.load_scene("bounce.toml")).run(10**9), StateError,
     f"n_steps must be at least 0 and at most {MAX_STEPS}"),
    (lambda: refsim.integrate(None, [1.0], 0.0, 1.0, 0.1), ArgumentTypeError,
     "f must be callable, got NoneType"),
    (lambda: refsim.integrate(lambda t, y: -y, "abc", 0.0, 1.0, 0.1), ArgumentTypeError,
     "y0 must be an array of real numbers, got str"),
    (lambda: refsim.integrate(lambda t, y: -y, [1.0], None, 1.0, 0.1), ArgumentTypeError,
     "t0 must be a real number, got NoneType"),
    (lambda: refsim.integrate(lambda t, y: -y, [1.0], 0.0, 1.0, "0.1"), ArgumentTypeError,
     "h must be a real number, got str"),
    (lambda: refsim.SOLVERS["rk4"].step(42, 0.0, np.ones(1), 0.1), ArgumentTypeError,
     "f must be callable, got int"),
    (lambda: refsim.SOLVERS["rk4"].step(lambda t, y: -y, 0.0, None, 0.1), ArgumentTypeError,
     "y must be an array of numbers, got NoneType"),
    (lambda: refsim.SOLVERS["rk4"].step(lambda t, y: -y, 0.0, np.ones((2, 2)), 0.1),
     StateError, "y must be a vector (d,), got shape (2, 2)"),
    (lambda: refsim.SOLVERS["euler"].step(lambda t, y: -y, True, np.ones(1), 0.1),
     ArgumentTypeError, "t must be a real number, got bool"),
    (lambda: refsim.triangles_intersect("abc", np.eye(3)), ArgumentTypeError,
     "a must be an array of real numbers, got str"),
    (lambda: refsim.triangles_intersect(np.eye(3), np.eye(3) * 1j), ArgumentTypeError,
     "b must be an array of real numbers, got ndarray"),
    (lambda: refsim.triangles_intersect(np.eye(3), [[0, 0], [1, 0, 0], [0, 1, 0]]),
     ArgumentTypeError, "b must be an array of real numbers, got list"),
    # found by the second fuzz campaign: a derivative of the wrong kind or
    # shape (the shape used to broadcast into a (7,) "answer")
    (lambda: refsim.SOLVERS["rk4"].step(lambda t, y: None, 0.0, np.ones(1), 0.1),
     ArgumentTypeError, "f(t, y) must be an array of numbers, got NoneType"),
    (lambda: refsim.SOLVERS["backwards-euler"].step(lambda t, y: "x", 0.0, np.ones(2), 0.1),
     ArgumentTypeError, "f(t, y) must be an array of numbers, got str"),
    (lambda: refsim.SOLVERS["rk4"].step(lambda t, y: np.zeros(7), 0.0, np.ones(1), 0.1),
     StateError, "f(t, y) must return the state's shape (1,), got shape (7,)"),
    (lambda: refsim.load_scene("bounce.toml\x00"), refsim.SceneError,
     "bounce.toml\x00: a file name cannot contain a NUL byte"),
    (lambda: refsim.load_model("cu\x00be.ac"), refsim.ModelError, "cannot contain a NUL byte"),
    (lambda: refsim.simulate(refsim.load_scene("bounce.toml"), duration="0.1"),
     ArgumentTypeError, "duration must be a real number, got str '0.1'"),
    (lambda: refsim.aabb_linear(CUBE, (np.eye(3), ["0", 0, 0]), kernel="readable"),
     ArgumentTypeError, "pose translation must be an array of real numbers, got list"),
    (lambda: refsim.bodies_collide(CUBE, POSE, CUBE, (np.eye(3).astype(str), np.zeros(3))),
     ArgumentTypeError, "pose_b rotation must be an array of real numbers, got ndarray"),
    (lambda: refsim.ParticleSystem(refsim.ParticleConfig(count=10), positions="abc",
                                   velocities="abc"),
     ArgumentTypeError, "positions must be an array of real numbers, got str"),
])
def test_bad_arguments_raise_refsim_errors_naming_them(call, error, phrase):
    with pytest.raises(error) as info:
        call()
    assert phrase in str(info.value)


def test_a_step_takes_any_sequence_of_numbers_for_the_state():
    # The checks convert; they do not narrow what a correct call may pass.
    from_list = refsim.SOLVERS["rk4"].step(lambda t, y: -y, 0, [1.0], 0.5)
    from_array = refsim.SOLVERS["rk4"].step(lambda t, y: -y, 0.0, np.array([1.0]), 0.5)
    assert from_list.tolist() == from_array.tolist()
    assert from_array[0] == pytest.approx(1 - 0.5 + 0.5**2 / 2 - 0.5**3 / 6 + 0.5**4 / 24,
                                          rel=1e-15)
