"""The world cube test (seed S3): per-axis intervals, depths, correction, input checks."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from refsim.bounds.world_cube import world_cube_test
from refsim.errors import StateError


def test_box_inside_crosses_nothing():
    result = world_cube_test([-1.0, -1.0, -1.0], [1.0, 1.0, 1.0], half_size=5.0)
    assert not result.any
    assert result.below.tolist() == [-4.0, -4.0, -4.0]
    assert result.above.tolist() == [-4.0, -4.0, -4.0]
    assert result.correction.tolist() == [0.0, 0.0, 0.0]


def test_floor_crossing_is_reported_on_the_y_axis_only():
    # A body 0.25 below the floor y = -5 (gravity is -y).
    result = world_cube_test([0.0, -5.25, 1.0], [1.0, -4.25, 2.0], half_size=5.0)
    assert result.crossed.tolist() == [[False, False], [True, False], [False, False]]
    assert result.below[1] == 0.25
    assert result.correction.tolist() == [0.0, 0.25, 0.0]


def test_two_walls_on_different_axes():
    result = world_cube_test([4.5, -1.0, -6.0], [5.5, 1.0, -4.0], half_size=5.0)
    assert result.crossed.tolist() == [[False, True], [False, False], [True, False]]
    assert result.correction.tolist() == [-0.5, 0.0, 1.0]


def test_touching_a_wall_is_not_crossing_it():
    result = world_cube_test([-5.0, 0.0, 0.0], [-4.0, 5.0, 1.0], half_size=5.0)
    assert not result.any
    assert result.below[0] == 0.0 and result.above[1] == 0.0


def test_one_ulp_past_the_wall_is_crossing():
    hi = np.nextafter(5.0, np.inf)
    result = world_cube_test([0.0, 0.0, 0.0], [hi, 1.0, 1.0], half_size=5.0)
    assert result.crossed[0, 1] and result.above[0] == hi - 5.0


def test_box_wider_than_the_cube_is_centred_by_the_correction():
    # [-7, 6] in [-5, 5]: both walls crossed (by 2 and 1); centre -0.5 -> 0.
    result = world_cube_test([-7.0, 0.0, 0.0], [6.0, 1.0, 1.0], half_size=5.0)
    assert result.crossed[0].tolist() == [True, True]
    assert result.correction[0] == 0.5


def test_off_centre_cube():
    result = world_cube_test([9.0, 0.0, 0.0], [11.0, 1.0, 1.0], cube_lo=[0.0, -1.0, -1.0],
                             cube_hi=[10.0, 2.0, 2.0])
    assert result.crossed.tolist() == [[False, True], [False, False], [False, False]]
    assert result.above[0] == 1.0


def test_result_is_immutable():
    result = world_cube_test([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], half_size=5.0)
    with pytest.raises(ValueError):
        result.below[0] = 1.0


def test_public_name_is_exported():
    assert refsim.world_cube_test is world_cube_test


@pytest.mark.parametrize("kwargs", [
    dict(lo=[1.0, 0.0, 0.0], hi=[0.0, 1.0, 1.0], half_size=5.0),        # lo > hi
    dict(lo=[0.0, 0.0], hi=[1.0, 1.0], half_size=5.0),                  # shape
    dict(lo=[0.0, np.nan, 0.0], hi=[1.0, 1.0, 1.0], half_size=5.0),     # non-finite
    dict(lo=[0.0, 0.0, 0.0], hi=[1.0, 1.0, 1.0], half_size=0.0),        # empty cube
    dict(lo=[0.0, 0.0, 0.0], hi=[1.0, 1.0, 1.0]),                       # no cube
    dict(lo=[0.0, 0.0, 0.0], hi=[1.0, 1.0, 1.0], half_size=5.0,
         cube_lo=[-1.0, -1.0, -1.0], cube_hi=[1.0, 1.0, 1.0]),          # two cubes
    dict(lo=[0.0, 0.0, 0.0], hi=[1.0, 1.0, 1.0], cube_lo=[1.0, 0.0, 0.0],
         cube_hi=[1.0, 1.0, 1.0]),                                       # flat cube
])
def test_bad_input_raises_state_error(kwargs):
    with pytest.raises(StateError):
        world_cube_test(**kwargs)
