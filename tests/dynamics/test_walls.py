"""The seed's wall response (S7) on constructed states, and the corrected
response's time of impact within the step."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.dynamics.simulation import Simulation
from refsim.dynamics.walls import (
    bounce_advance,
    crossing_time,
    deepest_speed,
    wall_name,
    wall_response_points_inplace,
    wall_response_seed,
    wall_speed,
)

E, FRICTION, G = 0.8, 0.25, 9.81


def test_floor_crossing_leaves_with_e_v_up_and_lateral_scaled_seed_speed():
    x = np.array([0.1, -4.02, 0.3])
    v = np.array([1.0, -6.0, -2.0])
    correction = np.array([0.0, 0.02, 0.0])          # the box is 2 cm below the floor
    x1, v1 = wall_response_seed(x, v, correction, E, FRICTION, G, speed="seed")
    assert x1[1] == x[1] + 0.02                       # pushed back by exactly the crossing
    assert x1[0] == x[0] and x1[2] == x[2]            # along that axis only
    assert v1[1] == E * 6.0                           # flipped, damped by e
    assert v1[0] == (1.0 - FRICTION) * 1.0            # kFriction = 1 - friction
    assert v1[2] == (1.0 - FRICTION) * -2.0


def test_speed_at_the_wall_pays_for_the_push_back():
    v_deep, delta = -6.0, 0.02
    x1, v1 = wall_response_seed(np.zeros(3), np.array([0.0, v_deep, 0.0]),
                                np.array([0.0, delta, 0.0]), E, 0.0, G, speed="wall")
    v_wall = np.sqrt(v_deep ** 2 - 2.0 * G * delta)   # energy from the wall down to the deep point
    assert v1[1] == pytest.approx(E * v_wall, rel=1e-15)
    # The energy after the bounce, at the wall, is e^2 times the energy at the wall:
    # potential gained by the push-back is not created.
    before = 0.5 * v_deep ** 2 + G * (-delta)
    after = 0.5 * v1[1] ** 2
    assert after == pytest.approx(E ** 2 * before, rel=1e-14)


def test_speed_at_the_wall_is_zero_in_resting_contact():
    # a body found deeper than its speed could carry it from the wall: resting
    assert wall_speed(-0.001, -G, 0.01) == 0.0
    assert wall_speed(3.0, 0.0, -0.5) == 3.0          # no gravity along x: unchanged


def test_ceiling_and_side_walls_flip_with_their_sign():
    x1, v1 = wall_response_seed(np.zeros(3), np.array([2.0, 1.0, 0.0]),
                                np.array([-0.01, -0.02, 0.0]), 1.0, 0.0, 0.0, speed="seed")
    assert np.array_equal(x1, [-0.01, -0.02, 0.0])
    assert np.array_equal(v1, [-2.0, -1.0, 0.0])
    assert wall_name(0, -0.01) == "x+" and wall_name(1, 0.02) == "y-"


def test_unknown_speed_option_raises():
    with pytest.raises(ValueError):
        wall_response_seed(np.zeros(3), np.zeros(3), np.zeros(3), E, 0.0, G, speed="x")


def test_inplace_response_needs_its_scratch_for_the_speed_at_the_wall():
    # Found by the type checker: without the scratch array, speed="wall"
    # failed with "unsupported operand type(s) for +: 'NoneType' and 'float'".
    x, v = np.array([[1.5, 0.0, 0.0]]), np.array([[1.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="needs the \\(N,\\) float scratch"):
        wall_response_points_inplace(x, v, 1.0, 0.7, 0.2, np.empty(1, dtype=bool),
                                     speed="wall", scratch=None)
    # the seed's speed needs no scratch
    n = wall_response_points_inplace(x, v, 1.0, 0.5, 0.2, np.empty(1, dtype=bool),
                                     speed="seed", scratch=None)
    assert n == 1 and x[0, 0] == 1.0 and v[0, 0] == -0.5


def test_crossing_time_of_a_fall_under_gravity():
    # a point fell from the floor (y = 0) at 3 m/s for tau = 0.6 ms under g:
    # it is 3 tau + g tau^2 / 2 deep, moving at 3 + g tau
    tau, h = 6e-4, 1e-3
    depth = 3.0 * tau + 0.5 * G * tau * tau
    assert crossing_time(-(3.0 + G * tau), -G, depth, True, h) == pytest.approx(tau, rel=1e-12)
    # a contact moving out of the wall has not just crossed it; a shallow
    # crossing at a crawl is clamped to the step
    assert crossing_time(3.0, -G, depth, True, h) == 0.0
    assert crossing_time(-1e-3, 0.0, 1e-4, True, h) == h
    # the ceiling: the normal is -e_k, a crossing moves up
    assert crossing_time(2.0, 0.0, -1e-3, False, h) == pytest.approx(5e-4, rel=1e-12)


def test_the_deepest_contact_and_its_normal_speed():
    # the contact lowest along y crosses a low wall first; its speed along y
    # is v_y + (w x r)_y = v_y + w_z r_x - w_x r_z
    r_a = np.array([[0.3, -0.2, 0.0], [-0.75, -0.5, 0.1], [0.5, -0.5, 0.0]])
    v, w = np.array([1.0, -2.0, 0.0]), np.array([0.5, 0.0, 4.0])
    assert deepest_speed(r_a, 3, 1, True, v, w) == -2.0 + 4.0 * -0.75 - 0.5 * 0.1
    assert deepest_speed(r_a, 3, 1, False, v, w) == -2.0 + 4.0 * 0.3      # the highest
    assert deepest_speed(r_a, 1, 1, True, v, w) == -2.0 + 4.0 * 0.3       # only the first


def test_bounce_advance_carries_the_rebound_from_the_instant_of_impact():
    # at the floor, 2 m/s up after the impulse, 0.4 ms before the step's end;
    # the impulse also changed the lateral velocity by -0.5 m/s and the spin
    # by 3 rad/s about z
    tau = 4e-4
    x, v = np.array([1.0, -5.0, 0.0]), np.array([0.5, 2.0, 0.0])
    R, w = np.eye(3), np.array([0.0, 1.0, 3.0])
    lo, hi = x - 0.5, x + 0.5
    bounce_advance(x, v, np.array([1.0, -2.1, 0.0]), R, w, 0.0, 0.0, 3.0, np.empty((3, 3)),
                   lo, hi, 1, True, -G, tau)
    assert x[1] == pytest.approx(-5.0 + 2.0 * tau - 0.5 * G * tau * tau, rel=1e-15)
    assert v[1] == pytest.approx(2.0 - G * tau, rel=1e-15)
    assert x[0] == pytest.approx(1.0 - 0.5 * tau, rel=1e-15)
    assert v[0] == 0.5 and x[2] == 0.0
    assert np.array_equal(hi - lo, np.ones(3)) and lo[1] == x[1] - 0.5
    # turned by 3 tau about z, the spin with it (its z part stays)
    a = 3.0 * tau
    turn = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0, 0, 1.0]])
    assert np.allclose(R, turn, rtol=0.0, atol=1e-15)
    assert np.allclose(w, turn @ [0.0, 1.0, 3.0], rtol=0.0, atol=1e-15)
    # an impact that leaves the body on the floor (e = 0): nothing moves
    x, v, R = np.array([0.0, -5.0, 0.0]), np.array([0.0, 0.0, 0.0]), np.eye(3)
    bounce_advance(x, v, np.array([0.0, -2.0, 0.0]), R, np.zeros(3), 1.0, 0.0, 0.0,
                   np.empty((3, 3)), x.copy(), x.copy(), 1, True, -G, tau)
    assert x[1] == -5.0 and v[1] == 0.0 and np.array_equal(R, np.eye(3))


@pytest.mark.parametrize("kernel", ["readable", "compiled"])
def test_bounces_happen_at_their_closed_form_times(kernel):
    """A cube dropped face down from 2 m with e = 0.8 (RK4, h = 1e-3): the
    k-th bounce at t_1 = sqrt(2 H / g), t_(k+1) = t_k + 2 e^k g t_1 / g
    (Kleppner & Kolenkow, 2nd ed., section 1.7: free fall), read by
    extrapolating the arc after each bounce back to the floor. RK4 is exact
    for constant gravity and the impact acts at the instant of the crossing,
    so only rounding remains: 1e-9 s, a millionth of a step. (Restarting
    from the wall at the step's end made each bounce up to a step late:
    0.45, 0.77 and 1.42 steps by the third.)"""
    import math

    from refsim.scenes.loader import scene_from_dict

    H, e = 2.0, 0.8
    scene = scene_from_dict({
        "world": {"restitution": e, "friction": 0.0},
        "integration": {"solver": "rk4", "step": 1e-3, "duration": 3.2},
        "dynamics": {"rotation": "impulse", "body_response": "impulse",
                     "wall_response": "impulse"},
        "body": [{"model": "cube.ac", "position": [0.0, -4.5 + H, 0.0]}]})
    sim = Simulation(scene, kernel=kernel)
    sim.record()
    sim.run(scene.integration.n_steps)
    tr = sim.trajectory()
    t, y, vy = tr.t, tr.position[:, 0, 1] + 4.5, tr.velocity[:, 0, 1]
    up = np.flatnonzero((vy[:-1] < 0.0) & (vy[1:] > 0.0)) + 1   # first frame after each
    assert len(up) >= 3
    t1 = math.sqrt(2.0 * H / G)
    expected = [t1 + sum(2.0 * e ** j * t1 for j in range(1, k + 1)) for k in range(3)]
    for k, i in enumerate(up[:3]):
        # y(t_i - s) = y_i - vy_i s - g s^2 / 2 = 0: the arc's root before t_i
        s = (-vy[i] + math.sqrt(vy[i] ** 2 + 2.0 * G * y[i])) / G
        assert t[i] - s == pytest.approx(expected[k], abs=1e-9)
