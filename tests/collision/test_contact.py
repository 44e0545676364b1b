"""The corners of two meshes' intersection region (refsim.collision.contact):
winding numbers, edge crossings, the points of two overlapping boxes, and
the contact polygon."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from refsim.collision.contact import (
    contact_points,
    contact_polygon,
    deepest_points,
    edge_crossings,
    exit_distances,
    intersection_points,
    winding_numbers,
)

CUBE = refsim.load_model("cube.ac")               # side 1, centred
IDENTITY = np.eye(3)


def _rows(points) -> set[tuple[float, ...]]:
    return {tuple(np.round(p, 12) + 0.0) for p in points}


def test_winding_numbers_inside_outside_and_on_the_surface():
    triangles = CUBE.vertices[CUBE.faces]
    points = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.5, 0.0, 0.0],
                       [0.5, 0.5, 0.0], [0.5, 0.5, 0.5], [0.5 + 1e-6, 0.0, 0.0]])
    # inside 1, outside 0, on a face 1/2, on an edge 1/4, at a corner 1/8;
    # the last is 1e-6 off a face, on the line of the edge between its two
    # triangles, where rounding is largest (module docstring)
    np.testing.assert_allclose(winding_numbers(points, triangles),
                               [1.0, 0.0, 0.5, 0.25, 0.125, 0.0], atol=1e-9)
    assert winding_numbers(np.empty((0, 3)), triangles).shape == (0,)


def test_an_edge_through_a_triangle_crosses_it_once_and_one_beside_it_not_at_all():
    triangle = np.array([[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]]])
    through = np.array([[[0.5, 0.5, -1.0], [0.5, 0.5, 1.0], [9.0, 9.0, 9.0]]])
    beside = np.array([[[3.0, 3.0, -1.0], [3.0, 3.0, 1.0], [9.0, 9.0, 9.0]]])
    # edge ab crosses at (0.5, 0.5, 0); bc and ca both end at (9, 9, 9), above
    np.testing.assert_allclose(edge_crossings(through, triangle), [[0.5, 0.5, 0.0]])
    assert edge_crossings(beside, triangle).shape == (0, 3)
    in_plane = np.array([[[0.1, 0.1, 0.0], [0.5, 0.1, 0.0], [0.1, 0.5, 0.0]]])
    assert edge_crossings(in_plane, triangle).shape == (0, 3)      # coplanar: none


def test_two_cubes_overlapping_by_a_slab_give_its_corners_and_boundary_points():
    """Cube B on top of cube A, shifted 0.3 along x and sunk 0.01 into it:
    the overlap is the box x in [-0.2, 0.5], y in [0.49, 0.5], z in
    [-0.5, 0.5]. Its eight corners are among the points, and every point
    lies on the box's boundary (the faces' diagonals cross the other
    cube's faces inside the box's faces too)."""
    pose_b = (IDENTITY, np.array([0.3, 0.99, 0.0]))
    points = intersection_points(CUBE, (IDENTITY, np.zeros(3)), CUBE, pose_b)
    lo, hi = np.array([-0.2, 0.49, -0.5]), np.array([0.5, 0.5, 0.5])
    corners = {(x, y, z) for x in (-0.2, 0.5) for y in (0.49, 0.5) for z in (-0.5, 0.5)}
    assert {tuple(np.round(c, 12)) for c in corners} <= _rows(points)
    assert np.all(points >= lo - 1e-12) and np.all(points <= hi + 1e-12)
    on_boundary = (np.isclose(points, lo, atol=1e-12) | np.isclose(points, hi, atol=1e-12))
    assert on_boundary.any(axis=1).all()
    # the contact polygon across the normal (y): the overlap's four corners
    polygon = contact_polygon(points, [0.0, 1.0, 0.0])
    assert {(round(p[0], 12) + 0.0, round(p[2], 12) + 0.0) for p in polygon} == {
        (-0.2, -0.5), (-0.2, 0.5), (0.5, -0.5), (0.5, 0.5)}


def test_meshes_apart_give_no_points():
    pose_b = (IDENTITY, np.array([0.3, 1.5, 0.0]))
    assert intersection_points(CUBE, (IDENTITY, np.zeros(3)), CUBE, pose_b).shape == (0, 3)


def test_the_contact_polygon_keeps_the_corners_of_the_projection():
    n = np.array([0.0, 1.0, 0.0])
    slab = np.array([[x, y, z] for x in (-0.2, 0.5) for y in (0.49, 0.5) for z in (-0.5, 0.5)]
                    + [[0.1, 0.495, 0.0]])                    # and a point inside
    corners = contact_polygon(slab, n)
    assert len(corners) == 4
    assert {(round(p[0], 12), round(p[2], 12)) for p in corners} == {
        (-0.2, -0.5), (-0.2, 0.5), (0.5, -0.5), (0.5, 0.5)}


@pytest.mark.parametrize("points, expected", [
    ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.5, 0.3, 0.0]], 2),   # a line
    ([[0.0, 0.0, 0.0]] * 5, 1),                                             # one point
    ([[0.0, 0.0, 0.0], [1.0, 0.0, 1.0]], 2),                                # two
])
def test_degenerate_polygons(points, expected):
    """Collinear points (the y offsets are along n) give the two ends; one
    point repeated gives itself."""
    assert len(contact_polygon(np.array(points), [0.0, 1.0, 0.0])) == expected


def test_exit_distances_along_a_direction():
    """From inside the unit cube, along +y: to the top face; from a point
    on the top face going up: 0; going down from it: the whole cube; from
    outside: no exit (inf)."""
    triangles = CUBE.vertices[CUBE.faces]
    points = np.array([[0.1, 0.2, 0.0], [0.1, 0.5, 0.3], [3.0, 0.0, 0.0]])
    np.testing.assert_allclose(exit_distances(points, [0.0, 1.0, 0.0], triangles),
                               [0.3, 0.0, np.inf])
    np.testing.assert_allclose(exit_distances(points[:2], [0.0, -1.0, 0.0], triangles),
                               [0.7, 1.0])


def test_the_deepest_points_of_a_cap_and_of_a_slab():
    """A cube corner pushed 0.1 into another cube's top face, its diagonal
    along the normal: the overlap is a tetrahedral cap, thick at the corner
    (chord 0.1) and thin at its rim on the face (chord 0): the corner alone
    is the contact. Two cubes overlapping in a slab keep all its corners."""
    from scipy.spatial.transform import Rotation

    # the corner (0.5, 0.5, 0.5) turned to point straight down
    turn = Rotation.align_vectors([[0.0, -1.0, 0.0]], [[1.0, 1.0, 1.0]])[0].as_matrix()
    tip = turn @ np.array([0.5, 0.5, 0.5])
    pose_a = (turn, np.array([0.0, 0.5 - 0.1, 0.0]) - tip)
    pose_b = (IDENTITY, np.zeros(3))
    n = np.array([0.0, 1.0, 0.0])
    points = contact_points(CUBE, pose_a, CUBE, pose_b, n)
    np.testing.assert_allclose(points, [[0.0, 0.4, 0.0]], atol=1e-12)
    slab_pose = (IDENTITY, np.array([0.3, 0.99, 0.0]))
    region = intersection_points(CUBE, slab_pose, CUBE, pose_b)
    tri = CUBE.vertices[CUBE.faces]
    kept = deepest_points(region, n, tri + slab_pose[1], tri)
    assert len(kept) == len(region)
