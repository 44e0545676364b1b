"""The scene keys that pose textbook problems (refsim.dynamics.loads), each
judged against its closed form on the corrected model:

- a block on an incline (a floor under a tilted gravity) slides with
  Coulomb's acceleration ``g (sin a - mu cos a)`` when ``tan a > mu`` and
  sticks otherwise (mu above 1 included): Kleppner & Kolenkow, *An
  Introduction to Mechanics*, 2nd ed., section 3.3;
- a constant torque spins a body up at ``tau / I`` and a constant force
  moves it by ``F t^2 / (2 m)`` (Newton's laws, no other load);
- a ball dropped on a fixed table rebounds to ``e^2`` of its drop height,
  ``e`` the pair's, not the world's; the table never moves;
- a missing wall lets a body through; the restitution threshold decides
  whether a slow impact bounces.

Tolerances come from the method's order, shown by halving h.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import refsim
from refsim.errors import SceneError
from refsim.models import shapes
from refsim.scenes.loader import scene_from_dict

CORRECTED = {"rotation": "impulse", "body_response": "impulse", "wall_response": "impulse"}


def incline(angle_deg: float, mu: float, h: float, duration: float = 1.0):
    """A 1 x 0.5 x 1 block resting on a floor-only world whose gravity is
    tilted by ``angle_deg`` about z: the block on an incline of that angle."""
    a = math.radians(angle_deg)
    return scene_from_dict({
        "world": {"gravity": 9.81, "gravity_direction": [math.sin(a), -math.cos(a), 0.0],
                  "walls": ["y-"], "mu": mu, "restitution": 0.0},
        "integration": {"solver": "euler", "step": h, "duration": duration},
        "dynamics": CORRECTED,
        "body": [{"shape": "box", "size": [1.0, 0.5, 1.0], "position": [-3.0, -4.75, 0.0]}]})


def travel(scene) -> float:
    tr = refsim.simulate(scene)
    return float(tr.position[-1, 0, 0] - tr.position[0, 0, 0])


@pytest.mark.parametrize("angle, mu", [(30.0, 0.3), (50.0, 1.0)])
def test_a_block_slides_down_an_incline_at_coulombs_acceleration(angle, mu):
    """Distance in 1 s from rest, ``g (sin a - mu cos a) / 2``: the error
    is first order (halves with h), and below 0.5 % at h = 2.5e-4 (measured
    2.0e-5 and 4.7e-3 relative). The steep block's error is the larger: its
    four floor contacts, solved one after the other, rock it sideways (about
    0.015 rad/s), 1.8e-2 relative at h = 1e-3."""
    a = math.radians(angle)
    exact = 9.81 * (math.sin(a) - mu * math.cos(a)) / 2.0
    errors = [abs(travel(incline(angle, mu, h)) - exact) for h in (5e-4, 2.5e-4)]
    assert errors[1] < 5e-3 * exact
    assert 1.6 < errors[0] / errors[1] < 2.4               # first order in h


@pytest.mark.parametrize("angle, mu", [(10.0, 0.3), (50.0, 1.5)])
def test_a_block_sticks_on_an_incline_below_its_friction_angle(angle, mu):
    """``tan a < mu`` (1.5 > tan 50 degrees = 1.19: mu above 1 means what
    Coulomb says): the block stays. It creeps by an amount of order h per
    second (the contact's sub-step rocking; measured 3.9 mm and 1.9 mm at
    h = 1e-3 and 5e-4 for 10 degrees): under 2.5 mm at h = 5e-4 and
    shrinking with h, where sliding would have moved it metres."""
    creep = [abs(travel(incline(angle, mu, h))) for h in (1e-3, 5e-4)]
    assert creep[1] < 2.5e-3
    assert creep[1] < 0.7 * creep[0]


def free_body(h: float):
    """A 1 x 0.6 x 0.3 box of 2 kg, no gravity, no walls, a torque of 0.5
    N m about z and a force of 1 N along x, from rest."""
    return scene_from_dict({
        "world": {"gravity": 0.0, "walls": []},
        "integration": {"solver": "rk4", "step": h, "duration": 1.0},
        "dynamics": CORRECTED,
        "body": [{"shape": "box", "size": [1.0, 0.6, 0.3], "mass": 2.0,
                  "torque": [0.0, 0.0, 0.5], "force": [1.0, 0.0, 0.0]}]})


def test_a_constant_torque_and_force_accelerate_a_free_body_by_newtons_laws():
    """After 1 s: ``w_z = tau t / I_z`` (I_z = m (a^2 + b^2) / 12; the
    angular impulses add exactly), turned by ``tau t^2 / (2 I_z)`` to the
    splitting's first order, and moved by ``F t^2 / (2 m)`` (RK4 is exact
    for a constant force)."""
    I_z = 2.0 * (1.0 + 0.36) / 12.0
    angle_errors = []
    for h in (1e-3, 5e-4):
        tr = refsim.simulate(free_body(h))
        w = tr.angular_velocity[-1, 0]
        assert w[2] == pytest.approx(0.5 / I_z, rel=1e-12)
        assert abs(w[0]) + abs(w[1]) < 1e-12
        R = tr.orientation[-1, 0]
        angle_errors.append(abs(math.atan2(R[1, 0], R[0, 0]) - 0.5 / I_z / 2.0))
        assert tr.position[-1, 0] == pytest.approx([0.25, 0.0, 0.0], abs=1e-12)
    assert angle_errors[1] < 1e-3
    assert 1.8 < angle_errors[0] / angle_errors[1] < 2.2


def ball_on_table(h: float, *, threshold: float | None = None, drop: float = 2.0,
                  duration: float = 1.6):
    world = {"restitution": 0.8, "friction": 0.0}
    if threshold is not None:
        world["restitution_threshold"] = threshold
    return scene_from_dict({
        "world": world,
        "integration": {"solver": "euler", "step": h, "duration": duration},
        "dynamics": CORRECTED,
        "body": [{"name": "table", "shape": "box", "size": [4.0, 1.0, 4.0],
                  "position": [0.0, -4.5, 0.0], "fixed": True},
                 {"name": "ball", "shape": "sphere", "radius": 0.25, "frequency": 6,
                  "position": [0.0, -4.0 + 0.25 + drop, 0.0]}],
        "pair": [{"bodies": ["table", "ball"], "restitution": 0.5}]})


def apexes(y: np.ndarray) -> list[float]:
    return [float(y[i]) for i in range(1, len(y) - 1) if y[i] >= y[i - 1] and y[i] > y[i + 1]]


def test_a_ball_rebounds_from_a_fixed_table_by_the_pairs_restitution():
    """The pair's e = 0.5 (the world's is 0.8): each apex is e^2 = 0.25 of
    the last height above the table, within 2 % at h = 5e-4 (a bounce is
    found up to one step late; measured 0.2510 and 0.2521, and 0.2504 at
    h = 2.5e-4). The fixed table does not move by one bit."""
    assert -shapes.geodesic_sphere(6, 0.25).vertices[:, 1].min() == 0.25   # rests at -3.75
    tr = refsim.simulate(ball_on_table(5e-4), every=1)
    assert not (tr.position[:, 0] - tr.position[0, 0]).any()
    assert not tr.velocity[:, 0].any() and not tr.angular_velocity[:, 0].any()
    rest = -3.75
    heights = [2.0] + [y - rest for y in apexes(tr.position[:, 1, 1])[1:]]
    assert len(heights) >= 3
    for before, after in zip(heights, heights[1:], strict=False):
        assert after / before == pytest.approx(0.25, rel=0.02)


def test_the_restitution_threshold_decides_whether_a_slow_impact_bounces():
    """A drop of 5 mm hits at sqrt(2 g 0.005) = 0.31 m/s: above the default
    threshold (0.05 m/s) it bounces (e = 0.5: up to 1.25 mm); with the
    threshold at 0.5 m/s it stays down."""
    for threshold, bounces in ((None, True), (0.5, False)):
        tr = refsim.simulate(ball_on_table(2.5e-4, threshold=threshold, drop=0.005,
                                           duration=0.1), every=1)
        y = tr.position[:, 1, 1] + 3.75
        after = y[np.flatnonzero(y < 1e-6)[0]:]             # from the impact on
        assert (after.max() > 1e-3) == bounces
        if bounces:
            # v' = e v: up to e^2 5 mm = 1.25 mm; measured 1.295 mm: the
            # impact found late (0.3139 m/s, not 0.3132) and explicit
            # Euler's apex (v' h / 2 = 2e-5 m high) are each about 1.6 %
            assert after.max() == pytest.approx(0.25 * 0.005, rel=0.05)


def test_a_body_leaves_through_a_missing_wall():
    """A floor-only world: a body thrown along x passes x = +H, and the
    floor still holds it (it rests at y = -H + 1/2)."""
    scene = scene_from_dict({
        "world": {"walls": ["y-"], "restitution": 0.0},
        "integration": {"solver": "euler", "step": 1e-3, "duration": 1.0},
        "dynamics": CORRECTED,
        "body": [{"shape": "box", "size": [1.0, 1.0, 1.0], "position": [4.0, -4.5, 0.0],
                  "velocity": [3.0, 0.0, 0.0]}]})
    tr = refsim.simulate(scene)
    assert tr.position[-1, 0, 0] == pytest.approx(7.0, abs=1e-9)
    assert tr.position[-1, 0, 1] == pytest.approx(-4.5, abs=1e-5)


def test_energy_in_a_tilted_field_is_conserved_in_frictionless_flight():
    """The field's potential (refsim.dynamics.loads.field_potential) makes
    the energy of a body thrown under tilted gravity constant: RK4 is exact
    for the uniform field, so to rounding."""
    scene = scene_from_dict({
        "world": {"gravity_direction": [1.0, -2.0, 0.5], "walls": []},
        "integration": {"solver": "rk4", "step": 1e-3, "duration": 0.5},
        "dynamics": CORRECTED,
        "body": [{"shape": "box", "size": [1.0, 0.6, 0.3], "velocity": [1.0, 3.0, -2.0],
                  "angular_velocity": [0.3, 1.0, 0.2]}]})
    sim = refsim.Simulation(scene)
    e0 = sim.energy().sum()
    sim.run(500)
    assert sim.energy().sum() == pytest.approx(e0, rel=1e-9)
    assert sim.energy_parts().potential.sum() != pytest.approx(
        refsim.Simulation(scene).energy_parts().potential.sum())   # it did fall


@pytest.mark.parametrize("dynamics, body, key", [
    ({"rotation": "seed"}, {"torque": [0.0, 0.0, 1.0]}, "body[0].torque"),
    ({"body_response": "seed"}, {"fixed": True}, "body[0].fixed"),
    ({"wall_response": "seed", "body_response": "seed"}, {"restitution": 0.5},
     "body[0].restitution"),
])
def test_a_key_the_chosen_model_cannot_honour_is_refused_by_name(dynamics, body, key):
    scene = scene_from_dict({"dynamics": dynamics,
                             "body": [dict({"shape": "box"}, **body)]})
    with pytest.raises(SceneError) as info:
        refsim.Simulation(scene)
    assert info.value.key == key


def test_the_compiled_loop_says_why_it_leaves_a_load_to_the_readable_step():
    sim = refsim.Simulation(free_body(1e-3), kernel="compiled")
    assert sim.loop == "a field other than gravity along -y (gravity_direction, force or fixed)"
