"""The linear scan (seed S2): known boxes, kernels, input checks, arithmetic."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from refsim.bounds.aabb_linear import (
    LinearAABB,
    aabb_linear,
    rotated_coordinate,
    rotated_coordinates,
    transform_vertices,
)
from refsim.errors import RefsimError, StateError
from refsim.models import shapes
from refsim.types import random_rotation, rotation_about_axis, transform_points


def test_identity_pose_gives_the_body_box():
    mesh = shapes.box((1.0, 2.0, 3.0))
    lo, hi = aabb_linear(mesh, (np.eye(3), np.zeros(3)))
    assert lo.tolist() == [-0.5, -1.0, -1.5]
    assert hi.tolist() == [0.5, 1.0, 1.5]


def test_translation_moves_the_box():
    mesh = shapes.box((1.0, 2.0, 3.0))
    lo, hi = aabb_linear(mesh, (np.eye(3), np.array([1.0, -2.0, 0.25])))
    assert lo.tolist() == [0.5, -3.0, -1.25]
    assert hi.tolist() == [1.5, -1.0, 1.75]


def test_quarter_turn_swaps_extents():
    # Exact quarter turn about z (x -> y, y -> -x): the 1 x 2 x 3 box becomes 2 x 1 x 3.
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    lo, hi = aabb_linear(shapes.box((1.0, 2.0, 3.0)), (quarter, np.zeros(3)))
    assert lo.tolist() == [-1.0, -0.5, -1.5]
    assert hi.tolist() == [1.0, 0.5, 1.5]


def test_rotated_sphere_box_lies_just_inside_the_unit_cube():
    mesh = shapes.geodesic_sphere(10)
    lo, hi = aabb_linear(mesh, (rotation_about_axis([1.0, 2.0, 3.0], 0.7), np.zeros(3)))
    assert (hi <= 1.0).all() and (lo >= -1.0).all()
    # 1002 vertices on the unit sphere: the box reaches within 1% of it.
    assert (hi > 0.99).all() and (lo < -0.99).all()


def test_numba_kernel_equals_numpy_bitwise():
    rng = np.random.default_rng(5)
    for mesh in (shapes.geodesic_sphere(7), shapes.torus(), shapes.l_beam()):
        for _ in range(20):
            pose = (random_rotation(rng), rng.uniform(-3.0, 3.0, 3))
            a = aabb_linear(mesh, pose)
            b = aabb_linear(mesh, pose, kernel="compiled")
            assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


@pytest.mark.parametrize("kernel", ["readable", "compiled"])
def test_linear_tracker_matches_function_and_counts_all_vertices(kernel):
    mesh = shapes.geodesic_sphere(5)
    tracker = LinearAABB(mesh, kernel=kernel)
    pose = (rotation_about_axis([0.0, 1.0, 1.0], 0.3), np.array([0.5, 0.0, -1.0]))
    lo, hi = tracker.update(pose)
    expected = aabb_linear(mesh, pose)
    assert np.array_equal(lo, expected[0]) and np.array_equal(hi, expected[1])
    assert (tracker.visits, tracker.evaluations) == (mesh.n_vertices, 3 * mesh.n_vertices)


def test_public_name_is_exported():
    assert refsim.aabb_linear is aabb_linear


def test_unknown_kernel_raises():
    with pytest.raises(RefsimError, match="kernel"):
        aabb_linear(shapes.box(), (np.eye(3), np.zeros(3)), kernel="fortran")
    with pytest.raises(RefsimError, match="kernel"):
        LinearAABB(shapes.box(), kernel="fortran")


@pytest.mark.parametrize("pose", [
    (np.eye(3) * 2.0, np.zeros(3)),             # a scale, not a rotation
    (np.eye(3), np.array([0.0, np.nan, 0.0])),  # non-finite
    (np.eye(2), np.zeros(3)),                   # wrong shape
])
def test_bad_pose_raises_state_error(pose):
    with pytest.raises(StateError):
        aabb_linear(shapes.box(), pose)


def test_scalar_and_vectorized_coordinates_are_the_same_bits():
    rng = np.random.default_rng(11)
    vertices = rng.standard_normal((500, 3)) * [1.0, 30.0, 1e-3]
    rotation = random_rotation(rng)
    many = rotated_coordinates(rotation, vertices.T)
    one_by_one = np.array([[rotated_coordinate(rotation, v, k) for v in vertices]
                           for k in range(3)])
    assert np.array_equal(many, one_by_one)
    translation = rng.standard_normal(3)
    world = transform_vertices(vertices, (rotation, translation))
    assert np.array_equal(world, one_by_one.T + translation)


def test_matmul_may_differ_in_the_last_bit_which_is_why_it_is_not_used():
    # refsim.types.transform_points uses `points @ R.T + t` (BLAS). Measure how
    # often it differs from the boxes' arithmetic, and by how much: a few ulps
    # at most, but not zero in general, so a box from it could not be compared
    # bit for bit with the tracker's.
    rng = np.random.default_rng(12)
    vertices = rng.standard_normal((2000, 3))
    rotation, translation = random_rotation(rng), rng.standard_normal(3)
    ours = transform_vertices(vertices, (rotation, translation))
    blas = transform_points(vertices, (rotation, translation))
    difference = np.abs(ours - blas)
    ulp = np.spacing(np.abs(ours) + np.abs(translation))
    assert (difference <= 4.0 * ulp).all()  # the same value up to rounding
    print(f"matmul differs from the elementwise arithmetic in "
          f"{np.count_nonzero(difference)} of {difference.size} coordinates")
