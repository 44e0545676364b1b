"""Exact overlap of two closed triangles by edge-triangle tests (seed S4, level 3).

What: ``triangles_intersect(a, b)`` answers whether two closed triangles in
3D share at least one point. Touching counts (a shared vertex, a vertex on an
edge or a face, coplanar triangles meeting along an edge), as in FCL. The
answer is exact for every finite float input: all decisions are signs of
orientation determinants (``refsim.collision.predicates``), computed with a
floating-point filter and an exact fallback.

Seed: S4, Test 3, "pairs of triangles ... are then tested for exact overlap
using edge-triangle intersection tests". The method here is that one: each
edge of one triangle is tested against the other triangle, both ways.

Background (cited, not copied): T. Moller, "A Fast Triangle-Triangle
Intersection Test", Journal of Graphics Tools 2(2), 1997 (the plane-rejection
step and the coplanar fallback to 2D tests in a projection); P. Guigue and
O. Devillers, "Fast and Robust Triangle-Triangle Overlap Test Using
Orientation Predicates", Journal of Graphics Tools 8(1), 2003 (decisions as
orientation signs only, so exact predicates make the whole test exact).
Guigue and Devillers is faster (it never tests all six edges); we keep the
seed's edge-triangle structure because it is the seed's and reads plainly.

Why edge-triangle tests both ways are complete
-----------------------------------------------
Let T1, T2 be closed non-degenerate triangles (positive area), with planes
P1, P2. Claim: T1 and T2 intersect if and only if some edge of T1 meets T2 or
some edge of T2 meets T1.

"If" is immediate: an edge is part of its triangle. "Only if": suppose
I = T1 n T2 is not empty. I is compact and convex (an intersection of two
compact convex sets), so it has an extreme point x (a point of I that is not
inside any segment lying in I). Suppose x were on no edge of T1 and no edge of
T2. Then x is in the relative interior of both triangles: some disc D1 around
x in P1 lies in T1 and some disc D2 around x in P2 lies in T2. The set
D1 n D2 contains a neighbourhood of x in P1 n P2, which is a line (planes
crossing) or the whole plane (coplanar triangles); either way it contains a
segment through x with x strictly inside. That segment lies in I, so x is not
extreme, a contradiction. Hence x lies on an edge of T1 or of T2, and that
edge meets the other triangle. (Parallel distinct planes give I empty.) The
argument uses positive area: the "edges" must be the triangle's relative
boundary, which is why degenerate triangles are handled separately.

Structure of the test
---------------------
1. Validate: finite coordinates (else ``StateError``); pick the predicate
   set (filtered, or exact-only when coordinates leave the filter's range).
2. Classify each triangle as the point set it is: a triangle (positive area),
   a segment (three collinear points, not all equal) or a point.
3. Triangle vs triangle: signs of each triangle's vertices against the other
   triangle's plane; plane rejection (Moller's first test); then the six
   edge-triangle tests.
4. Edge vs triangle: both endpoints strictly on one side -> miss; edge in the
   plane -> exact 2D test in a projection; otherwise the edge meets the plane
   in one point, inside the closed triangle iff the three orientations of the
   edge's line against the triangle's edges do not have mixed signs.
5. Lower-dimensional cases: segment vs triangle uses step 4; segment vs
   segment (and point cases, as segments with equal endpoints) is a
   coplanarity test then an exact 2D segment test.

Cost: O(1) per pair: at most 6 + 18 orient3d and a few dozen orient2d in the
coplanar case. Pure Python, so the interpreter's cost per pair dominates; use
``refsim.collision.triangle_batch`` for many pairs.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from refsim.collision.predicates import (
    EXACT,
    FILTERED,
    FLOAT,
    Predicates,
    in_filter_range,
)
from refsim.errors import StateError, as_numbers

Point = tuple[float, float, float]
Point2 = tuple[float, float]
Triangle = tuple[Point, Point, Point]


# --------------------------------------------------------------------------
# public entry points
# --------------------------------------------------------------------------

def triangles_intersect(a, b) -> bool:
    """Whether the closed triangles ``a`` and ``b`` share a point (exact).

    Parameters
    ----------
    a, b : array_like, shape (3, 3)
        One vertex per row. Degenerate triangles (collinear or repeated
        vertices) are answered as the segment or point they are.

    Returns
    -------
    bool
        True when the triangles intersect or touch.

    Raises
    ------
    StateError
        If a coordinate is not finite or a shape is wrong.
    """
    t1 = as_triangle(a, "a")
    t2 = as_triangle(b, "b")
    return intersect_point_sets(t1, t2, choose_predicates(t1[0] + t1[1] + t1[2]
                                                          + t2[0] + t2[1] + t2[2]))


def triangles_intersect_float(a, b) -> bool:
    """The same test with plain float signs (no filter, no exact fallback).

    This is what an unrobust 1997 implementation of the seed's test computes;
    refsim keeps it only to measure claim C4 (``refsim.studies.triangles``).
    Its answer can be wrong on near-degenerate input.
    """
    return intersect_point_sets(as_triangle(a, "a"), as_triangle(b, "b"), FLOAT)


def as_triangle(t, what: str = "triangle") -> Triangle:
    """Check a (3, 3) vertex array and return it as three tuples of floats."""
    array = as_numbers(what, t)
    if array.shape != (3, 3):
        raise StateError(f"{what}: expected shape (3, 3), got {array.shape}")
    if not np.isfinite(array).all():
        raise StateError(f"{what}: non-finite vertex coordinate")
    p, q, r = array.tolist()
    return tuple(p), tuple(q), tuple(r)


def intersect_point_sets(t1, t2, predicates: Predicates) -> bool:
    """Step 2 and dispatch: answer two vertex triples as the sets they span."""
    kind1, set1 = point_set(t1, predicates)
    kind2, set2 = point_set(t2, predicates)
    if kind1 == "triangle" and kind2 == "triangle":
        return _triangle_vs_triangle(set1, set2, predicates)
    if kind1 == "triangle":
        return segment_intersects_triangle(set2[0], set2[-1], set1, predicates)
    if kind2 == "triangle":
        return segment_intersects_triangle(set1[0], set1[-1], set2, predicates)
    # Segment or point vs segment or point: a point is a segment p == q.
    return segments_intersect(set1[0], set1[-1], set2[0], set2[-1], predicates)


def point_set(t, predicates: Predicates = FILTERED):
    """Classify three vertices as ``("triangle", (a, b, c))``,
    ``("segment", (p, q))`` or ``("point", (p,))``, exactly.

    Three points span positive area iff their normal (b - a) x (c - a) is not
    zero; its components are the orient2d of the three coordinate-plane
    projections. Collinear points span the segment between the
    lexicographically least and greatest of them: along a line, the
    lexicographic order of points is their order along the line.
    """
    a, b, c = t
    if any(normal_signs(a, b, c, predicates)):
        return "triangle", (a, b, c)
    lo, hi = min(t), max(t)
    if lo == hi:
        return "point", (lo,)
    return "segment", (lo, hi)


def normal_signs(a, b, c, predicates: Predicates = FILTERED) -> tuple[int, int, int]:
    """Signs of the components of (b - a) x (c - a), exactly.

    Component k is the orient2d of the projection that drops axis k, taken
    in cyclic order ((y, z), (z, x), (x, y)).
    """
    o2 = predicates.orient2d
    return (o2(_drop(a, 0), _drop(b, 0), _drop(c, 0)),
            o2(_drop(a, 1), _drop(b, 1), _drop(c, 1)),
            o2(_drop(a, 2), _drop(b, 2), _drop(c, 2)))


# --------------------------------------------------------------------------
# Step 3: triangle vs triangle
# --------------------------------------------------------------------------

def _triangle_vs_triangle(t1, t2, predicates: Predicates) -> bool:
    o3 = predicates.orient3d
    # Step 3a: which side of the other's plane each vertex lies on.
    sides1 = [o3(t2[0], t2[1], t2[2], p) for p in t1]
    sides2 = [o3(t1[0], t1[1], t1[2], p) for p in t2]

    # Step 3b, plane rejection (Moller 1997): all three vertices strictly on
    # one side of the other plane. Implied by the edge tests below (each
    # edge would be rejected); kept because it is cheap and common.
    if _strictly_one_side(sides1) or _strictly_one_side(sides2):
        return False

    # Step 3c: the seed's edge-triangle tests, edges of t1 against t2 and of
    # t2 against t1. Complete by the argument in the module docstring.
    for tri_edges, sides, other in ((t1, sides1, t2), (t2, sides2, t1)):
        for i in range(3):
            j = (i + 1) % 3
            if _edge_vs_triangle(tri_edges[i], tri_edges[j], sides[i], sides[j],
                                 other, predicates):
                return True
    return False


def _strictly_one_side(sides) -> bool:
    return sides[0] == sides[1] == sides[2] != 0


# --------------------------------------------------------------------------
# Step 4: segment (edge) vs triangle
# --------------------------------------------------------------------------

def segment_intersects_triangle(p, q, t, predicates: Predicates | None = None) -> bool:
    """Whether the closed segment pq meets the closed triangle t (exact).

    ``p == q`` (a point) is allowed. A degenerate ``t`` is answered as the
    segment or point it is. ``predicates=None`` checks the input and picks
    the filtered or the exact-only set (see :func:`choose_predicates`).
    """
    if predicates is None:
        p, q, t, predicates = _checked_points(p, q, *t)
    kind, s = point_set(t, predicates)
    if kind != "triangle":
        return segments_intersect(p, q, s[0], s[-1], predicates)
    o3 = predicates.orient3d
    sp = o3(s[0], s[1], s[2], p)
    sq = o3(s[0], s[1], s[2], q)
    return _edge_vs_triangle(p, q, sp, sq, s, predicates)


def _edge_vs_triangle(p, q, sp: int, sq: int, t, predicates: Predicates) -> bool:
    """Segment pq vs non-degenerate triangle t, given the sides of p and q."""
    # Case 4a, no crossing: both endpoints strictly on the same side.
    if sp == sq != 0:
        return False

    # Case 4b, coplanar: the segment lies in the triangle's plane. Exact 2D
    # test in a projection that drops an axis along which the exact normal
    # is non-zero (that projection is one-to-one on the plane).
    if sp == 0 and sq == 0:
        axis = projection_axis_of_triangle(t, predicates)
        a, b, c = (_drop(v, axis) for v in t)
        return segment_intersects_triangle_2d(_drop(p, axis), _drop(q, axis), a, b, c,
                                              predicates)

    # Case 4c, crossing: pq meets the plane in exactly one point X (an
    # endpoint when sp or sq is 0). X is in the closed triangle iff the line
    # pq passes on the same side of the three directed edges ab, bc, ca,
    # zeros allowed (Plucker side test written as orient3d). Not all three
    # can be zero: that would put the line in the triangle's plane.
    a, b, c = t
    o3 = predicates.orient3d
    return not _mixed_signs(o3(p, q, a, b), o3(p, q, b, c), o3(p, q, c, a))


def _mixed_signs(*signs: int) -> bool:
    return (1 in signs) and (-1 in signs)


# --------------------------------------------------------------------------
# Step 5: segment vs segment (points are segments with p == q)
# --------------------------------------------------------------------------

def segments_intersect(p, q, r, s, predicates: Predicates | None = None) -> bool:
    """Whether closed segments pq and rs in 3D share a point (exact).

    Either segment may be a point (equal endpoints). ``predicates=None``
    checks the input and picks the predicate set (:func:`choose_predicates`).
    """
    if predicates is None:
        p, q, (r, s), predicates = _checked_points(p, q, r, s)
    # Case 5a, skew: the four points are not coplanar, so the lines miss.
    if predicates.orient3d(p, q, r, s) != 0:
        return False
    # Case 5b, coplanar (or collinear): exact 2D test in a faithful projection.
    axis = projection_axis_of_points((p, q, r, s), predicates)
    return segments_intersect_2d(_drop(p, axis), _drop(q, axis), _drop(r, axis),
                                 _drop(s, axis), predicates)


def point_in_triangle(p, t, predicates: Predicates | None = None) -> bool:
    """Whether point p lies in the closed triangle t (any t, exact)."""
    return segment_intersects_triangle(p, p, t, predicates)


def choose_predicates(values) -> Predicates:
    """``FILTERED`` when every coordinate is in the filter's range, else
    ``EXACT`` (the filter's error bound assumes no underflow or overflow)."""
    return FILTERED if in_filter_range(values) else EXACT


def _checked_points(p, q, *rest):
    """Validate points (finite, 3 coordinates): (p, q, rest, predicates)."""
    try:
        array = np.asarray([p, q, *rest], dtype=np.float64)
    except ValueError:
        raise StateError("expected points with 3 coordinates each") from None
    if array.ndim != 2 or array.shape[1] != 3:
        raise StateError(f"expected points with 3 coordinates, got shape {array.shape}")
    if not np.isfinite(array).all():
        raise StateError("non-finite point coordinate")
    points = [tuple(row) for row in array.tolist()]
    return points[0], points[1], tuple(points[2:]), choose_predicates(array.ravel().tolist())


# --------------------------------------------------------------------------
# Projections
# --------------------------------------------------------------------------

def _drop(p, axis: int) -> Point2:
    """Project a 3D point by dropping ``axis``, keeping the cyclic order."""
    if axis == 0:
        return (p[1], p[2])
    if axis == 1:
        return (p[2], p[0])
    return (p[0], p[1])


def projection_axis_of_triangle(t: Triangle, predicates: Predicates = FILTERED) -> int:
    """An axis along which t's exact normal is non-zero (t non-degenerate).

    Of the admissible axes we drop the one with the largest float normal
    component: any admissible axis gives the exact answer, the largest one
    keeps the projected triangle fat, so the 2D filter rarely falls back.
    """
    signs = normal_signs(*t, predicates)
    candidates = [k for k in range(3) if signs[k] != 0]
    if not candidates:
        raise ValueError("projection_axis_of_triangle: triangle is degenerate")
    n = _float_normal(*t)
    return max(candidates, key=lambda k: abs(n[k]) if n[k] == n[k] else 0.0)


def projection_axis_of_points(points: Sequence[Point], predicates: Predicates = FILTERED) -> int:
    """An axis whose projection is one-to-one on the points' common plane.

    The points must be coplanar (exactly). If three of them are not
    collinear, their plane's normal gives the axis; if all are collinear, any
    axis not parallel to their line will do (drop the direction's smallest
    component); if all are equal, any axis.
    """
    m = len(points)
    for i in range(m):
        for j in range(i + 1, m):
            for k in range(j + 1, m):
                t = (points[i], points[j], points[k])
                if any(normal_signs(*t, predicates)):
                    return projection_axis_of_triangle(t, predicates)
    p0 = points[0]
    for p in points[1:]:
        if p != p0:
            d = [abs(p[k] - p0[k]) for k in range(3)]
            return min(range(3), key=lambda k: d[k])
    return 2


def _float_normal(a, b, c):
    u = [b[k] - a[k] for k in range(3)]
    v = [c[k] - a[k] for k in range(3)]
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


# --------------------------------------------------------------------------
# 2D tests (in a projection)
# --------------------------------------------------------------------------

def point_in_triangle_2d(p, a, b, c, predicates: Predicates = FILTERED) -> bool:
    """Point p in the closed non-degenerate 2D triangle abc (either winding)."""
    o2 = predicates.orient2d
    return not _mixed_signs(o2(a, b, p), o2(b, c, p), o2(c, a, p))


def segments_intersect_2d(p, q, r, s, predicates: Predicates = FILTERED) -> bool:
    """Closed 2D segments pq and rs share a point (either may be a point).

    Proper crossing: each segment's endpoints strictly on opposite sides of
    the other's line. Otherwise they meet iff an endpoint of one lies on the
    other: collinear with it (orientation 0) and inside its bounding box
    (exact float comparisons). This covers collinear overlap and points.
    """
    o2 = predicates.orient2d
    d1, d2 = o2(r, s, p), o2(r, s, q)
    d3, d4 = o2(p, q, r), o2(p, q, s)
    # Case: proper crossing.
    if d1 * d2 < 0 and d3 * d4 < 0:
        return True
    # Case: an endpoint of one segment lies on the other.
    return ((d1 == 0 and _in_box(p, r, s)) or (d2 == 0 and _in_box(q, r, s))
            or (d3 == 0 and _in_box(r, p, q)) or (d4 == 0 and _in_box(s, p, q)))


def _in_box(x, p, q) -> bool:
    """x within the axis-aligned box of p and q (x collinear with them)."""
    return (min(p[0], q[0]) <= x[0] <= max(p[0], q[0])
            and min(p[1], q[1]) <= x[1] <= max(p[1], q[1]))


def segment_intersects_triangle_2d(p, q, a, b, c, predicates: Predicates = FILTERED) -> bool:
    """Closed 2D segment pq (or point) vs closed non-degenerate triangle abc.

    The triangle is convex: if neither endpoint is inside and the segment
    meets it, the segment crosses its boundary, i.e. one of its edges.
    """
    if point_in_triangle_2d(p, a, b, c, predicates) or point_in_triangle_2d(q, a, b, c,
                                                                             predicates):
        return True
    return (segments_intersect_2d(p, q, a, b, predicates)
            or segments_intersect_2d(p, q, b, c, predicates)
            or segments_intersect_2d(p, q, c, a, predicates))
