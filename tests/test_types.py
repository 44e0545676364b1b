"""Poses: checked once, at every public entry point."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.errors import StateError
from refsim.types import (
    ORTHONORMAL_TOL,
    as_pose,
    random_rotation,
    rotation_about_axis,
    transform_points,
)


def test_valid_pose_is_returned_as_float64():
    rotation, translation = as_pose(([[0, -1, 0], [1, 0, 0], [0, 0, 1]], [1, 2, 3]))
    assert rotation.dtype == translation.dtype == np.float64
    assert np.array_equal(translation, [1.0, 2.0, 3.0])


@pytest.mark.parametrize("pose, phrase", [
    ((np.eye(3),), "expected (rotation, translation)"),
    (5, "expected (rotation, translation)"),
    ((np.eye(2), np.zeros(3)), "shapes"),
    ((np.eye(3), np.zeros(4)), "shapes"),
    ((np.diag([1.0, np.nan, 1.0]), np.zeros(3)), "non-finite"),
    ((np.diag([1.0, np.inf, 1.0]), np.zeros(3)), "non-finite"),
    ((np.eye(3), np.array([0.0, np.nan, 0.0])), "non-finite"),
    ((np.eye(3), np.array([np.inf, 0.0, 0.0])), "non-finite"),
    ((2.0 * np.eye(3), np.zeros(3)), "orthonormal"),
    ((np.array([[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]), np.zeros(3)),
     "orthonormal"),
    ((np.full((3, 3), 1e200), np.zeros(3)), "orthonormal"),   # Gram overflows: finite input
])
def test_bad_poses_are_named(pose, phrase):
    with pytest.raises(StateError, match="pose_x") as info:
        as_pose(pose, what="pose_x")
    assert phrase in str(info.value)


def test_tolerance_admits_rounded_rotations():
    rotation = np.round(rotation_about_axis([1, 1, 0], 0.3), 8)   # 8 digits, as in a file
    assert np.abs(rotation.T @ rotation - np.eye(3)).max() < ORTHONORMAL_TOL
    as_pose((rotation, np.zeros(3)))


def test_rotations_are_proper_and_orthonormal():
    rng = np.random.default_rng(0)
    for _ in range(50):
        for r in (random_rotation(rng), rotation_about_axis(rng.normal(size=3), rng.normal())):
            np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-14)
            assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-14)
    quarter = rotation_about_axis([0, 0, 1], np.pi / 2)
    np.testing.assert_allclose(quarter @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    with pytest.raises(StateError, match="zero length"):
        rotation_about_axis([0, 0, 0], 1.0)


def test_transform_points():
    pose = (rotation_about_axis([0, 0, 1], np.pi / 2), np.array([1.0, 0.0, 0.0]))
    np.testing.assert_allclose(transform_points(np.array([[1.0, 0.0, 0.0]]), pose),
                               [[1.0, 1.0, 0.0]], atol=1e-15)
