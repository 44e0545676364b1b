"""The seed's wall response (S7) on constructed states."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.dynamics.walls import (
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
