"""The error contract of the public API: a user's mistake raises a RefsimError
that is also the ValueError or TypeError Python code expects, with a message
naming the argument; nothing else escapes (DESIGN.md, Errors)."""

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
])
def test_bad_arguments_raise_refsim_errors_naming_them(call, error, phrase):
    with pytest.raises(error) as info:
        call()
    assert phrase in str(info.value)
