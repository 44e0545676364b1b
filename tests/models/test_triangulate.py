"""Ear clipping of single polygons (refsim.models.triangulate, seed S1)."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.errors import ModelError
from refsim.models.mesh import Mesh
from refsim.models.triangulate import ear_clip, newell_normal
from refsim.types import rotation_about_axis

#: Areas are sums of a handful of products of coordinates of size <= 10:
#: rounding is a few ulps of 100, so 1e-12 absolute is ample and still far
#: below any area error a wrong triangulation would make (>= 1e-2 here).
AREA_ATOL = 1e-12


def _square():
    return np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)


def _l_shape():
    return np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [1, 1, 0], [1, 2, 0], [0, 2, 0]], float)


def _star(points=5, outer=2.0, inner=0.7):
    t = np.pi / 2 + np.arange(2 * points) * np.pi / points
    r = np.where(np.arange(2 * points) % 2 == 0, outer, inner)
    return np.c_[r * np.cos(t), r * np.sin(t), np.zeros(2 * points)]


def _comb():
    """A comb: three teeth pointing up, four reflex corners (12 vertices)."""
    xy = [(0, 0), (5, 0), (5, 3), (4, 3), (4, 1), (3, 1), (3, 3), (2, 3), (2, 1), (1, 1),
          (1, 3), (0, 3)]
    return np.array([(x, y, 0.0) for x, y in xy])


def _collinear_square():
    """A 2x2 square with the midpoint of every side as an extra corner."""
    xy = [(0, 0), (1, 0), (2, 0), (2, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
    return np.array([(x, y, 0.0) for x, y in xy])


POLYGONS = {
    "convex quad": (_square, 1.0),
    "L shape": (_l_shape, 3.0),
    "star": (_star, None),  # area computed by the shoelace formula below
    "comb": (_comb, 11.0),  # 5 x 3 minus two 1 x 2 notches
    "collinear corners": (_collinear_square, 4.0),
}


def _shoelace(p2):
    x, y = p2[:, 0], p2[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def _triangle_normals(p, tri):
    v = p[tri]
    return np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])


def _inside(point, polygon2):
    """Crossing-number point-in-polygon test (strict interior, 2-D)."""
    x, y = point
    inside = False
    for (x0, y0), (x1, y1) in zip(polygon2, np.roll(polygon2, -1, axis=0), strict=True):
        if (y0 > y) != (y1 > y):
            xc = x0 + (y - y0) * (x1 - x0) / (y1 - y0)
            if xc > x:
                inside = not inside
    return inside


def _check(p, tri):
    """The laws every triangulation of a simple polygon obeys."""
    k = len(p)
    n = newell_normal(p)
    assert tri.shape == (k - 2, 3)
    assert tri.dtype == np.int64
    # every corner of the polygon is used, only corners are used
    assert set(tri.ravel().tolist()) == set(range(k))
    normals = _triangle_normals(p, tri)
    # every triangle has the polygon's orientation, and positive area
    assert (normals @ n > 0).all()
    # the areas sum to the polygon's area
    areas = 0.5 * np.linalg.norm(normals, axis=1)
    assert areas.sum() == pytest.approx(0.5 * np.linalg.norm(n), abs=AREA_ATOL)
    # each triangle lies inside the polygon: its centroid is an interior point
    # (with the orientations and the area sum, this rules out overlaps)
    axis = int(np.argmax(np.abs(n)))
    keep = [a for a in range(3) if a != axis]
    poly2 = p[:, keep]
    for t in tri:
        assert _inside(p[t].mean(axis=0)[keep], poly2)
    return areas


@pytest.mark.parametrize("name", sorted(POLYGONS))
def test_polygon_laws_both_windings(name):
    make, _ = POLYGONS[name]
    p = make()
    for polygon in (p, p[::-1].copy()):
        tri = ear_clip(polygon)
        _check(polygon, tri)


@pytest.mark.parametrize("name", ["L shape", "star", "comb", "collinear corners"])
def test_area_matches_shoelace(name):
    make, area = POLYGONS[name]
    p = make()
    expected = _shoelace(p[:, :2])
    assert expected > 0.0
    if area is not None:
        assert expected == pytest.approx(area)
    tri = ear_clip(p)
    assert 0.5 * np.linalg.norm(_triangle_normals(p, tri), axis=1).sum() == pytest.approx(
        expected, abs=AREA_ATOL)


def test_convex_quad_is_the_fan_from_corner_zero():
    assert ear_clip(_square()).tolist() == [[0, 1, 2], [0, 2, 3]]
    assert ear_clip(_square()[::-1].copy()).tolist() == [[0, 1, 2], [0, 2, 3]]


def test_reversed_winding_reverses_triangle_normals():
    p = _l_shape()
    up = _triangle_normals(p, ear_clip(p))
    q = p[::-1].copy()
    down = _triangle_normals(q, ear_clip(q))
    assert (up[:, 2] > 0).all() and (down[:, 2] < 0).all()
    assert np.abs(up).sum() == pytest.approx(np.abs(down).sum())


def test_l_shape_never_cuts_across_the_notch():
    # The reflex corner (1, 1) is index 3: no triangle may join corners 2 and 4
    # (their segment runs outside the L).
    tri = ear_clip(_l_shape())
    for t in tri.tolist():
        assert not {2, 4} <= set(t)


def test_star_has_eight_triangles_each_with_a_tip():
    p = _star()
    tri = ear_clip(p)
    assert tri.shape == (8, 3)
    tips = set(range(0, 10, 2))
    # every outer tip is a convex corner that only an ear can cover
    assert tips <= set(tri.ravel().tolist())
    _check(p, tri)


def test_collinear_corners_give_no_zero_area_triangle():
    p = _collinear_square()
    areas = _check(p, ear_clip(p))
    assert (areas > 0.0).all()
    # three collinear corners in a row, twice
    q = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0], [3, 1, 0], [0, 1, 0]], float)
    areas = _check(q, ear_clip(q))
    assert (areas > 0.0).all()


def test_tilted_polygon_far_from_origin():
    # The same L, rotated out of every coordinate plane and moved far away:
    # same triangles (ear clipping only sees the projected order).
    r = rotation_about_axis([1.0, 2.0, 3.0], 0.7)
    p = _l_shape() @ r.T + np.array([1e3, -2e3, 5e2])
    tri = ear_clip(p)
    assert tri.tolist() == ear_clip(_l_shape()).tolist()
    n = newell_normal(p)
    assert (_triangle_normals(p, tri) @ n > 0).all()
    assert 0.5 * np.linalg.norm(n) == pytest.approx(3.0, rel=1e-12)


def test_polygon_in_each_coordinate_plane():
    p = _l_shape()
    for perm in ([0, 1, 2], [2, 0, 1], [1, 2, 0]):
        q = p[:, perm]
        _check(q, ear_clip(q))


def test_triangle_is_returned_as_is():
    p = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    assert ear_clip(p).tolist() == [[0, 1, 2]]


def test_repeated_point_polygon_is_triangulated():
    # A square with a notch (1, 2)-(1, 1)-(0, 2) and a zero-width spike up to
    # (1, 1.5): the point (1, 1) is visited twice. Points that coincide with
    # an ear's corner do not block it. Area 4 - 0.5.
    xy = [(0, 0), (2, 0), (2, 2), (1, 2), (1, 1), (1, 1.5), (1, 1), (0, 2)]
    p = np.array([(x, y, 0.0) for x, y in xy])
    tri = ear_clip(p)
    assert tri.shape == (6, 3)
    normals = _triangle_normals(p, tri)
    assert (normals[:, 2] >= 0).all()
    assert 0.5 * np.linalg.norm(normals, axis=1).sum() == pytest.approx(3.5)
    assert _shoelace(p[:, :2]) == pytest.approx(3.5)


def test_degenerate_polygon_is_a_fan_of_zero_area_triangles():
    # Documented choice: no plane -> the fan (0, i, i+1), areas exactly zero,
    # reported by Mesh.degenerate_faces rather than an error.
    line = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0], [1.5, 0, 0]], float)
    tri = ear_clip(line)
    assert tri.tolist() == [[0, 1, 2], [0, 2, 3], [0, 3, 4]]
    assert (_triangle_normals(line, tri) == 0.0).all()
    mesh = Mesh(line, tri)
    assert mesh.degenerate_faces.tolist() == [0, 1, 2]
    point = np.zeros((4, 3))
    assert ear_clip(point).tolist() == [[0, 1, 2], [0, 2, 3]]


@pytest.mark.parametrize("bad", [np.zeros((2, 3)), np.zeros((4, 2)), np.zeros(3),
                                 np.array([[0, 0, 0], [1, 0, 0], [np.nan, 1, 0], [0, 1, 0]])])
def test_bad_input_raises_model_error(bad):
    with pytest.raises(ModelError):
        ear_clip(bad)


@pytest.mark.parametrize("scale", [1e300, 8.5e307, 1e-300, 2e-323])
def test_extreme_scales_give_the_same_triangles(scale):
    # Coordinates are scaled by a power of two before any product, so neither
    # overflow (1e300 ** 2) nor underflow (1e-300 ** 2) reaches the tests.
    p = _l_shape()
    assert ear_clip(p * scale).tolist() == ear_clip(p).tolist()
