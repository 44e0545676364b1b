"""The pybullet oracle runs the scene it is given: mass properties, poses,
no hidden damping, and a bounce close to Newton's restitution law."""

from __future__ import annotations

import numpy as np
import pytest
from refsim.oracles.pybullet_adapter import PybulletOracle, mass_properties

from refsim.dynamics import analytic
from refsim.scenes.loader import scene_from_dict
from refsim.studies.bounce_scenes import (
    DROP_HEIGHT,
    GRAVITY,
    SPHERE,
    apex_ratio,
    drop_scene,
    duration_for,
    read_bounces,
    touch_height,
)

pytestmark = pytest.mark.oracle

#: pybullet stores mass properties in double precision; what comes back from
#: getDynamicsInfo is what was passed, up to the rounding of the diagonal
#: through Bullet's btVector3 (float64 here) and trimesh's eigen-solve.
MASS_RTOL = 1e-12
INERTIA_RTOL = 1e-9

#: Poses go through a quaternion (scipy) and back: a few ulps of rotation
#: entries, amplified by the lever arm of the centre of mass (< 1 m).
POSE_ATOL = 1e-12

#: Bounces tested, as in the bounce study.
K = 3


def pybullet_apex_tolerance(e: float, step: float, h0: float = DROP_HEIGHT) -> float:
    """Relative tolerance on pybullet's mean apex ratio over K bounces.

    Bullet finds a contact only after the body has overlapped the wall (with
    ``contactProcessingThreshold=0``) and applies the restitution to the
    velocity it has there, up to one step deeper than the touching point, so
    bounce k may return up to ``delta_k = v_k h`` more height than the ideal
    (split impulse removes the overlap without adding energy). Relative to the
    apex ``h_k = e^(2k) h0``, with ``v_k = e^k v0``, that is
    ``v0 h / (e^k h0)``, largest at the last bounce (k = K - 1 before it).
    Symplectic Euler's O(h) shift of the flight's energy is of the same size
    and sign-free; twice the larger lag bounds both.
    """
    v0 = analytic.impact_speed(h0, GRAVITY)
    return 2.0 * v0 * step / (e ** (K - 1) * h0)


@pytest.fixture
def pybullet(oracle):
    engine = oracle(PybulletOracle)
    yield engine
    engine.close()


def _scene(model: str, *, position=(0.0, 0.0, 0.0), orientation=None, scale=1.0, mass=1.0,
           velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0), gravity=9.81,
           duration=0.1, step=1e-3):
    body = {"model": model, "position": list(position), "velocity": list(velocity),
            "angular_velocity": list(angular_velocity), "mass": mass, "scale": scale}
    if orientation is not None:
        body["orientation"] = [list(map(float, row)) for row in orientation]
    return scene_from_dict({"world": {"gravity": gravity},
                            "integration": {"step": step, "duration": duration},
                            "body": [body]})


def _rotation(axis, angle) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(np.asarray(axis, float) / np.linalg.norm(axis) * angle).as_matrix()


@pytest.mark.parametrize("model,scale,mass", [("sphere-2k.ac", 1.0, 1.0), ("cube.ac", 2.0, 3.0),
                                               ("l-beam.ac", 0.5, 2.0)])
def test_mass_and_inertia_passed_are_trimesh_s(pybullet, model, scale, mass):
    trimesh = pytest.importorskip("trimesh")
    scene = _scene(model, scale=scale, mass=mass)
    pybullet.load(scene)
    info = pybullet.dynamics_info(0)
    mesh = scene.mesh(scene.bodies[0])
    solid = trimesh.Trimesh(mesh.vertices * scale, mesh.faces, process=False)
    solid.density = mass / solid.volume
    expected = np.sort(np.linalg.eigvalsh(solid.moment_inertia))
    assert info["mass"] == pytest.approx(mass, rel=MASS_RTOL)
    np.testing.assert_allclose(np.sort(info["inertia"]), expected, rtol=INERTIA_RTOL)
    # Not pybullet's default, the inertia of the bounding box:
    lo, hi = (mesh.vertices * scale).min(0), (mesh.vertices * scale).max(0)
    d = hi - lo
    box = mass / 12.0 * np.array([d[1] ** 2 + d[2] ** 2, d[0] ** 2 + d[2] ** 2,
                                  d[0] ** 2 + d[1] ** 2])
    if model != "cube.ac":                          # for a cube the two coincide
        assert np.abs(np.sort(info["inertia"]) - np.sort(box)).max() > 1e-3 * box.max()


def test_mass_properties_of_a_unit_cube_are_exact():
    pytest.importorskip("trimesh")
    from refsim.bundled import models_dir
    from refsim.models.loading import load_model

    mesh = load_model(models_dir() / "cube.ac")
    props = mass_properties(mesh.vertices, mesh.faces, mass=6.0, scale=2.0)
    # Side 2, mass 6: I = m s^2 / 6 = 4 about every axis.
    np.testing.assert_allclose(props.inertia, [4.0, 4.0, 4.0], rtol=1e-12)
    np.testing.assert_allclose(props.center, 0.0, atol=1e-15)
    assert np.linalg.det(props.axes) == pytest.approx(1.0)


def test_pose_and_velocity_of_an_offset_body_round_trip(pybullet):
    """The L-beam's centre of mass is off its origin and its principal axes
    are not the mesh axes: the state read back is the scene's."""
    r = _rotation((1.0, 2.0, 3.0), 0.7)
    x = np.array([0.3, -0.2, 1.1])
    v = np.array([0.5, 1.0, -0.25])
    w = np.array([0.2, -0.4, 0.9])
    scene = _scene("l-beam.ac", position=x, orientation=r, velocity=v, angular_velocity=w)
    pybullet.load(scene)
    x1, v1, w1, r1 = pybullet.state()
    np.testing.assert_allclose(x1[0], x, atol=POSE_ATOL)
    np.testing.assert_allclose(r1[0], r, atol=POSE_ATOL)
    np.testing.assert_allclose(w1[0], w, atol=POSE_ATOL)
    np.testing.assert_allclose(v1[0], v, atol=POSE_ATOL)


def test_no_hidden_damping_in_free_flight(pybullet):
    """pybullet's default damping (0.04) would slow this body by 4% a second;
    the oracle sets it to 0, so with no gravity the velocity stays exact."""
    scene = _scene("sphere-2k.ac", velocity=(1.0, 0.0, 0.5), angular_velocity=(0.0, 2.0, 0.0),
                   gravity=0.0, duration=1.0)
    trajectory = pybullet.simulate(scene)
    np.testing.assert_allclose(trajectory.velocity[-1, 0], [1.0, 0.0, 0.5], atol=1e-12)
    np.testing.assert_allclose(trajectory.angular_velocity[-1, 0], [0.0, 2.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(trajectory.position[-1, 0], [1.0, 0.0, 0.5], atol=1e-9)


def test_free_fall_is_symplectic_euler(pybullet):
    """Bullet steps v += h g, then x += h v: after n steps from rest,
    y = -g h^2 n (n + 1) / 2."""
    h, n = 1e-3, 200
    scene = _scene("sphere-2k.ac", duration=n * h, step=h)
    trajectory = pybullet.simulate(scene)
    assert trajectory.velocity[-1, 0, 1] == pytest.approx(-9.81 * h * n, rel=1e-12)
    assert trajectory.position[-1, 0, 1] == pytest.approx(-9.81 * h * h * n * (n + 1) / 2,
                                                          rel=1e-9)


@pytest.mark.parametrize("e", [0.5, 0.8, 0.9])
def test_pybullet_apex_ratio_is_close_to_e_squared(pybullet, e):
    step = 1e-3
    scene = drop_scene(SPHERE, e, step=step, duration=duration_for(e, K))
    trajectory = pybullet.simulate(scene)
    bounces = read_bounces(trajectory.t, trajectory.position[:, 0, 1],
                           trajectory.velocity[:, 0, 1], touch_height(scene))
    ratio = apex_ratio(bounces.apex_heights, K)
    tolerance = pybullet_apex_tolerance(e, step)
    print(f"pybullet e={e}: apex ratio {ratio:.6f}, e^2 {e * e:.6f}, "
          f"relative error {abs(ratio - e * e) / (e * e):.2e} (tolerance {tolerance:.2e})")
    assert abs(ratio - e * e) / (e * e) <= tolerance
    # The sphere lands on its pole: a single contact point, no spin.
    assert np.abs(trajectory.angular_velocity).max() < 1e-6


def test_restitution_and_friction_multiply_to_the_scene_s(pybullet):
    """Walls and bodies carry the square roots of the scene's values:
    Bullet's products are the scene's e and mu at a wall and between two
    bodies. (getDynamicsInfo of a maximal-coordinates body does not report
    restitution, so the bounces are the check: above, and the head-on
    collision below.)"""
    scene = drop_scene(SPHERE, 0.8, friction=0.3)
    pybullet.load(scene)
    assert pybullet.dynamics_info(0)["lateral_friction"] == pytest.approx(0.3 ** 0.5)
    for wall in pybullet.walls:
        info = pybullet.p.getDynamicsInfo(wall, -1, physicsClientId=pybullet.client)
        assert info[1] == pytest.approx(0.3 ** 0.5)


@pytest.mark.parametrize("e", [0.5, 0.8])
def test_two_bodies_meet_with_the_scene_s_restitution(pybullet, e):
    """Two equal spheres (radius 1) 1 m apart, closing at 1 m/s each, no
    gravity, centre to centre: after the impact each leaves at e m/s
    (Newton's law, equal masses). With 1 on the walls and e on the bodies
    Bullet would give e^2. Tolerance 1e-3 m/s: the contact is found up to a
    step late, at up to h * 2 m/s of overlap, which split impulse removes
    without changing the velocities; the faceted spheres meet vertex to
    vertex, nearly centrally. (Two cubes meeting face to face leave at
    0.38 m/s for e = 0.5 and 0.70 for e = 0.8, and turn: Bullet solves the
    four corner contacts one after another.) Their contact is no wall's:
    no wall event (the walls are more than 2 m away throughout)."""
    scene = scene_from_dict({
        "world": {"half_size": 5.0, "gravity": 0.0, "restitution": e, "friction": 0.0},
        "integration": {"step": 1e-3, "duration": 1.0},
        "body": [{"name": "a", "model": SPHERE, "position": [-1.5, 0.0, 0.0],
                  "velocity": [1.0, 0.0, 0.0]},
                 {"name": "b", "model": SPHERE, "position": [1.5, 0.0, 0.0],
                  "velocity": [-1.0, 0.0, 0.0]}]})
    trajectory = pybullet.simulate(scene)
    v = np.asarray(trajectory.velocity)
    np.testing.assert_allclose(v[-1, 0], [-e, 0.0, 0.0], atol=1e-3)
    np.testing.assert_allclose(v[-1, 1], [e, 0.0, 0.0], atol=1e-3)
    assert trajectory.events == []


def test_walls_hold_the_body_inside_the_cube(pybullet):
    """A fast body thrown at a corner stays inside [-L, L]^3: its centre
    keeps at least the cube's inradius (0.5) from every wall, up to the
    overlap of one step before a contact is solved (|v| h < 1.5 cm here)."""
    scene = _scene("cube.ac", velocity=(9.0, 7.0, -8.0), duration=2.0)
    trajectory = pybullet.simulate(scene)
    overlap = np.linalg.norm([9.0, 7.0 + 9.81 * 2.0, 8.0]) * scene.integration.step
    assert np.abs(trajectory.position).max() <= scene.world.half_size - 0.5 + overlap
    assert {e.other for e in trajectory.events} >= {"x+", "y-", "z-"}


def test_close_is_idempotent(oracle):
    engine = oracle(PybulletOracle)
    with engine:
        assert engine.client is not None
    assert engine.client is None
    engine.close()


@pytest.mark.parametrize("model", ["l-beam.ac", "torus.ac", "star.ac"])
def test_mass_properties_agree_with_refsim_s_own_integrals(model):
    """trimesh's integrals (what pybullet is given) against refsim's
    tetrahedron sums (refsim.dynamics.mass_properties): two independent
    computations of the same uniform solid."""
    pytest.importorskip("trimesh")
    from refsim.bundled import models_dir
    from refsim.dynamics.mass_properties import mass_properties as refsim_mass_properties
    from refsim.models.loading import load_model

    mesh = load_model(models_dir() / model)
    theirs = mass_properties(mesh.vertices, mesh.faces, mass=2.0, scale=1.5)
    ours = refsim_mass_properties(mesh.vertices * 1.5, mesh.faces, 2.0)
    np.testing.assert_allclose(theirs.center, ours.center, atol=1e-12)
    np.testing.assert_allclose(theirs.inertia, np.linalg.eigvalsh(ours.inertia), rtol=1e-10)
    # The principal axes diagonalise refsim's tensor too.
    np.testing.assert_allclose(theirs.axes.T @ ours.inertia @ theirs.axes,
                               np.diag(theirs.inertia), atol=1e-10 * theirs.inertia.max())


def test_drag_is_an_external_force_in_bullet_s_euler_step(pybullet):
    """Linear drag F = -k v, applied before each step, enters Bullet's
    velocity update v += h F / m: v_n = v_0 (1 - k h / m)^n exactly."""
    k, m, h, n = 0.5, 2.0, 1e-3, 500
    scene = scene_from_dict({"world": {"gravity": 0.0, "drag": k},
                             "integration": {"step": h, "duration": n * h},
                             "body": [{"model": "sphere-2k.ac", "mass": m,
                                       "velocity": [2.0, 0.0, -1.0]}]})
    trajectory = pybullet.simulate(scene)
    factor = (1.0 - k * h / m) ** n
    np.testing.assert_allclose(trajectory.velocity[-1, 0], [2.0 * factor, 0.0, -factor],
                               rtol=1e-9, atol=1e-12)


#: A fresh interpreter that loads pybullet through the adapter and writes a
#: line of its own to each stream, before and after.
LOAD_PYBULLET = """
import sys
print("out before", flush=True)
print("err before", file=sys.stderr, flush=True)
from refsim.oracles.pybullet_adapter import PybulletOracle
with PybulletOracle() as oracle:
    oracle.p.getAPIVersion()
print("out after", flush=True)
print("err after", file=sys.stderr, flush=True)
"""


def test_loading_pybullet_prints_no_banner(oracle):
    import subprocess
    import sys

    oracle(PybulletOracle).close()          # skips with the reason where pybullet is missing
    result = subprocess.run([sys.executable, "-c", LOAD_PYBULLET], capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout == "out before\nout after\n"
    assert result.stderr == "err before\nerr after\n"


def test_what_else_a_loading_engine_prints_still_reaches_its_stream(capfd):
    import os

    from refsim.oracles import c_banner_dropped

    with c_banner_dropped("engine build time:"):
        os.write(1, b"engine build time: today\nkept on stdout\n")
        os.write(2, b"engine build time: today\nkept on stderr\n")
    captured = capfd.readouterr()
    assert captured.out == "kept on stdout\n"
    assert captured.err == "kept on stderr\n"
