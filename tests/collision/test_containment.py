"""refsim's one point-in-mesh test (refsim.collision.containment), used by
the body-level study's classifier and by the conformance kit's."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.collision.containment import contains_point, winding_number
from refsim.models.mesh import Mesh
from refsim.studies.levels import bundled_mesh
from refsim.types import rotation_about_axis

IDENTITY = (np.eye(3), np.zeros(3))


def test_cube():
    cube = bundled_mesh("cube")
    assert contains_point(cube, IDENTITY, [0.1, -0.2, 0.3]) is True
    assert contains_point(cube, IDENTITY, [0.6, 0.0, 0.0]) is False


def test_non_convex_torus():
    torus = bundled_mesh("torus")
    assert contains_point(torus, IDENTITY, [1.0, 0.0, 0.0]) is True     # in the tube
    assert contains_point(torus, IDENTITY, [0.0, 0.0, 0.0]) is False    # in the hole


def test_pose_moves_the_mesh_not_the_point():
    cube = bundled_mesh("cube")
    pose = (rotation_about_axis(np.array([1.0, 2.0, 3.0]), 0.7), np.array([5.0, 0.0, 0.0]))
    assert contains_point(cube, pose, [5.1, 0.1, -0.1]) is True
    assert contains_point(cube, pose, [0.0, 0.0, 0.0]) is False


def test_orientation_does_not_matter():
    cube = bundled_mesh("cube")
    flipped = Mesh(cube.vertices, cube.faces[:, ::-1].copy())
    assert winding_number(cube, IDENTITY, [0.0, 0.0, 0.0]) == pytest.approx(
        -winding_number(flipped, IDENTITY, [0.0, 0.0, 0.0]))
    assert contains_point(flipped, IDENTITY, [0.0, 0.0, 0.0]) is True


@pytest.mark.parametrize("point", [[0.0, 0.0, 0.0], [0.25, 0.25, 0.25], [-0.4, 0.4, 0.0]])
def test_a_ray_through_an_edge_or_a_vertex_is_no_matter(point):
    # points on the cube's diagonals and face diagonals: a parity-of-crossings
    # test with an axis or diagonal ray would meet edges and vertices here
    assert abs(winding_number(bundled_mesh("cube"), IDENTITY, point)) == pytest.approx(
        1.0, abs=1e-12)
