"""The Drake engine (refsim.oracles.drake_adapter): free fall in closed form,
a ball at rest at the stiffness's depth, the centre-of-mass velocity
convention, the dissipation measured on Drake's own impact and a refused
scene key. The kit's verdict on Drake (every check passes or fails as
refsim/conformance/expected/drake.txt declares) is held in
tests/conformance/test_matrix.py, whose shared run includes Drake."""

from __future__ import annotations

import math

import numpy as np
import pytest
from refsim.oracles.drake_adapter import (
    DrakeSettings,
    contact_parameters,
    drake_dv,
    drake_restitution,
    engine,
)

from refsim.conformance import cases_rigid as R
from refsim.conformance.checks_contact import REST_PENETRATION_STEPS
from refsim.errors import OptionError
from refsim.scenes.loader import scene_from_dict

pytestmark = pytest.mark.oracle

G = 9.81
H = 1e-3
#: sphere-2k's lowest vertex is this far below its origin (its radius).
SPHERE_RADIUS = 1.0


def _sphere_scene(y: float, duration: float, e: float = 0.5):
    return scene_from_dict({
        "world": {"half_size": 5.0, "gravity": G, "restitution": e, "friction": 0.5},
        "integration": {"step": H, "duration": duration},
        "body": [{"model": "sphere-2k.ac", "position": [0.0, y, 0.0]}]})


def test_a_dropped_ball_falls_freely_before_contact():
    """Drake's discrete step is symplectic Euler in free flight: after k
    steps ``v = -g k h`` and ``y = y0 - g h^2 k (k + 1) / 2`` (the closed form
    of the scheme), within ``g h t / 2`` of the parabola; 0.3 s from 4 m
    above the floor, no contact."""
    trajectory = engine().simulate(_sphere_scene(0.0, 0.3))
    t = np.asarray(trajectory.t)
    k = np.rint(t / H)
    y = np.asarray(trajectory.position)[:, 0, 1]
    v = np.asarray(trajectory.velocity)[:, 0, 1]
    np.testing.assert_allclose(v, -G * k * H, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(y, -G * H ** 2 * k * (k + 1) / 2, rtol=0.0, atol=1e-12)
    assert np.abs(y + G * t ** 2 / 2).max() <= G * H * t[-1] / 2 + 1e-12
    np.testing.assert_allclose(np.asarray(trajectory.position)[:, 0, [0, 2]], 0.0, atol=1e-15)
    assert trajectory.events == []


def test_a_ball_rests_on_the_floor_at_the_stiffness_depth():
    """Set down touching the floor, the sphere settles where its weight meets
    the contact's stiffness, ``m g / k`` = 6.4e-5 m (k from 8 contact steps
    at h = 1e-3), within 1 % from 0.25 s on, inside the kit's 10 g h^2 =
    9.8e-5 m; set down, it first overshoots (measured 9.9e-5 m), less than
    an undamped spring released at its free length would (``2 m g / k``)."""
    scene = _sphere_scene(-5.0 + SPHERE_RADIUS, 0.5)
    depth = G / contact_parameters(scene).stiffness
    assert depth == pytest.approx(G * (8 * H) ** 2 / math.pi ** 2, rel=1e-12)
    trajectory = engine().simulate(scene)
    sunk = -5.0 + SPHERE_RADIUS - np.asarray(trajectory.position)[:, 0, 1]
    settled = sunk[np.asarray(trajectory.t) >= 0.25]
    np.testing.assert_allclose(settled, depth, rtol=0.01)
    assert settled.max() < REST_PENETRATION_STEPS * G * H ** 2
    assert sunk.max() < 2.0 * depth
    assert abs(np.asarray(trajectory.velocity)[-1, 0, 1]) < 1e-6
    assert [e.other for e in trajectory.events] == ["y-"]


def test_the_velocity_is_the_centre_of_mass_s():
    """The l-beam (centre of mass 0.22 m off its origin) spinning at 5 rad/s
    without gravity: the first frame reads back the scene's state exactly
    (the origin's velocity converted both ways), and the centre of mass
    keeps to its straight line within Drake's first-order step (measured
    3.9e-4 m in 0.2 s), where the origin swings by more than 5 cm."""
    scene = scene_from_dict({
        "world": {"half_size": 5.0, "gravity": 0.0},
        "integration": {"step": H, "duration": 0.2},
        "body": [{"model": "l-beam.ac", "velocity": [0.3, 0.0, 0.0],
                  "angular_velocity": [0.0, 0.0, 5.0]}]})
    _, center, _ = R._body("l-beam.ac")
    trajectory = engine().simulate(scene)
    np.testing.assert_allclose(trajectory.velocity[0, 0], [0.3, 0.0, 0.0], atol=1e-15)
    np.testing.assert_allclose(trajectory.angular_velocity[0, 0], [0.0, 0.0, 5.0], atol=1e-15)
    R_t = np.asarray(trajectory.orientation)[:, 0]
    com = np.asarray(trajectory.position)[:, 0] + R_t @ center
    line = com[0] + np.outer(np.asarray(trajectory.t), [0.3, 0.0, 0.0])
    assert np.abs(com - line).max() < 1e-3
    origin = np.asarray(trajectory.position)[:, 0]
    assert np.abs(origin - line).max() > 0.05


def test_the_wall_test_reads_the_poses_the_state_reads():
    """The test for wall contacts after each step reads the positions alone:
    the same origins and rotations as the recorded state, bit for bit, for
    each of two bodies (one turning, one resting on the floor), and only
    the resting one touches a wall (the floor, y-)."""
    scene = scene_from_dict({
        "world": {"half_size": 5.0, "gravity": G},
        "integration": {"step": H, "duration": 0.1},
        "body": [{"model": "l-beam.ac", "position": [1.5, 0.0, 0.0],
                  "angular_velocity": [0.0, 2.0, 5.0]},
                 {"model": "sphere-2k.ac", "position": [-2.0, -5.0 + SPHERE_RADIUS, 0.0]}]})
    drake = engine()
    drake.load(scene)
    for _ in range(50):
        drake.step()
    x, _, _, r = drake.state()
    origins, rotations = drake._poses()
    assert np.array_equal(np.array(origins), x) and np.array_equal(np.array(rotations), r)
    assert not np.array_equal(r[0], np.eye(3))
    assert drake._wall_contacts(origins, rotations) == {(1, 2)}     # body 1, wall 2: y-


def test_the_dissipation_meets_e_on_drakes_own_impact():
    """The measured ``d v0`` gives restitution e = 0.5 on the probe impact
    (to the bisection's width); above the discrete step's own restitution
    at d = 0 (0.584 at 8 contact steps) none is needed, and a slower impact
    of the same ``d`` bounces higher (the Hunt-Crossley law)."""
    steps = DrakeSettings().contact_steps
    dv = drake_dv(0.5, steps)
    assert drake_restitution(dv, steps) == pytest.approx(0.5, abs=1e-3)
    assert drake_restitution(0.0, steps) == pytest.approx(0.584, abs=1e-3)
    assert drake_dv(0.8, steps) == 0.0
    assert drake_restitution(dv / 4, steps) > 0.5


def test_linear_drag_is_applied_at_the_centre_of_mass_each_step():
    """Drag ``F = -k v`` from the step's start velocity: after n steps
    ``v = (1 - k h / m)^n v0`` (explicit in the drag, as the other oracles),
    within ``k^2 h t / 2`` of ``exp(-k t / m)``; the body does not turn."""
    k = 0.5
    scene = scene_from_dict({
        "world": {"half_size": 50.0, "gravity": 0.0, "drag": k},
        "integration": {"step": H, "duration": 1.0},
        "body": [{"model": "sphere-2k.ac", "velocity": [1.0, 0.0, 0.0]}]})
    trajectory = engine().simulate(scene)
    v = np.asarray(trajectory.velocity)[:, 0, 0]
    n = np.rint(np.asarray(trajectory.t) / H)
    np.testing.assert_allclose(v, (1.0 - k * H) ** n, rtol=1e-12)
    assert abs(v[-1] - math.exp(-k)) < k ** 2 * H / 2
    np.testing.assert_allclose(np.asarray(trajectory.angular_velocity), 0.0, atol=1e-15)


def test_a_scene_with_particles_is_refused_naming_the_key_and_the_engine():
    scene = scene_from_dict({"particles": {"count": 4},
                             "body": [{"model": "cube.ac"}]})
    with pytest.raises(OptionError, match=r"^scene key particles: engine drake "):
        engine().simulate(scene)
    with pytest.raises(OptionError, match=r"^engine drake: approximation must be one of "
                                          r"lagged, similar, got 'sap'$"):
        engine(approximation="sap").simulate(_sphere_scene(0.0, 0.01))


def test_a_missing_drake_names_its_own_extra(monkeypatch):
    """Drake is an extra of its own: a missing pydrake says ``refsim[drake]``,
    and ``conform --all`` names both extras when both are wanted."""
    import sys

    from refsim.oracles import OracleUnavailable, install_hint

    monkeypatch.setitem(sys.modules, "pydrake", None)          # import pydrake -> ImportError
    with pytest.raises(OracleUnavailable, match=r"pip install 'refsim\[drake\]'"):
        engine()
    assert install_hint(["mujoco", "drake"]) == "pip install 'refsim[oracles,drake]'"
    assert install_hint(["pybullet"]) == "pip install 'refsim[oracles]'"

