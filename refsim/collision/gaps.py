"""How far a wrong geometric answer is from being right, in metres.

When an engine's answer on two triangles differs from the exact one, the
conformance kit and the studies measure the **gap** of the pair
(:func:`refsim.collision.disagreement.classify_triangle_pair`): the distance between the closed
triangles when they are apart, minus the penetration depth when they cross
(the shortest translation that separates them), 0 when they touch. A
mesh-pair or collide answer is measured by the gaps of the face pairs it
gets wrong. The class then compares that length (the scene's unit, metres)
with two allowances:

- the **rounding bound** ``ROUNDING_ULPS u s`` (:func:`rounding_bound`),
  ``s`` the largest coordinate magnitude of the six vertices, ``u = 2^-53``.
  The gap is 1-Lipschitz in the vertices (moving every vertex by at most
  ``d`` moves each triangle by at most ``d`` in the Hausdorff distance, so
  the distance, and the depth, of the pair change by at most ``2 d``): an
  engine whose answer is exact for its input moved by ``d`` per vertex,
  rounding's backward error, errs only on pairs with ``|gap| <= 2 d``;
- the engine's declared ``distance_tolerance``
  (:func:`refsim.engines.declarations`).

``|gap|`` within either is "tolerance", beyond both "bug". An exact zero
(touching, coplanar) keeps its own class, decided by exact predicates.

The depth is the smallest overlap of the two triangles' projections on the
candidate separating axes (each triangle's normal and the nine cross
products of an edge of one with an edge of the other): for two convex
polytopes those axes include every facet normal of the Minkowski
difference, where the smallest overlap is attained (the separating axis
theorem; C. Ericson, *Real-Time Collision Detection*, Morgan Kaufmann
2005, 5.2.1). The distance is the smallest of the six vertex-triangle and
nine edge-edge distances (Ericson 5.1.5, closest point on a triangle;
5.1.9, closest points of two segments). Both are evaluated in float64: their
own rounding, some ``u s``, is far below the bound they are compared with.

Cost: O(1) per triangle pair (about 60 closest-point evaluations); a mesh
case, O(pairs it gets wrong), and for a false "collide" a box test of every
face pair (numpy) before the triangles within reach.
"""

from __future__ import annotations

import math

import numpy as np

#: The rounding allowance, in units of ``u s`` (module docstring): a backward
#: error of 2^13 ulps of the largest coordinate per vertex, doubled. A float
#: engine's plane equations, projections and clipping lose a few thousand
#: ulps at most on well-scaled input (the allowance the orientation-margin
#: classification gave, 1e-12 relative, now as a length); a gap beyond it is
#: not explained by rounding.
ROUNDING_ULPS = 2.0 ** 14

UNIT_ROUNDOFF = 2.0 ** -53


def rounding_bound(*triangles) -> float:
    """``ROUNDING_ULPS u s`` metres, ``s`` the largest coordinate magnitude
    of the given (3, 3) triangles (module docstring)."""
    s = max(float(np.abs(np.asarray(t, dtype=np.float64)).max()) for t in triangles)
    return ROUNDING_ULPS * UNIT_ROUNDOFF * s


def _sub(p, q):
    return (p[0] - q[0], p[1] - q[1], p[2] - q[2])


def _dot(p, q) -> float:
    return p[0] * q[0] + p[1] * q[1] + p[2] * q[2]


def _cross(p, q):
    return (p[1] * q[2] - p[2] * q[1], p[2] * q[0] - p[0] * q[2], p[0] * q[1] - p[1] * q[0])


def _along(p, d, t):
    return (p[0] + t * d[0], p[1] + t * d[1], p[2] + t * d[2])


def _closest_on_triangle(p, a, b, c):
    """The point of triangle abc closest to p (Ericson 5.1.5, by Voronoi regions)."""
    ab, ac, ap = _sub(b, a), _sub(c, a), _sub(p, a)
    d1, d2 = _dot(ab, ap), _dot(ac, ap)
    if d1 <= 0.0 and d2 <= 0.0:
        return a
    bp = _sub(p, b)
    d3, d4 = _dot(ab, bp), _dot(ac, bp)
    if d3 >= 0.0 and d4 <= d3:
        return b
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        return _along(a, ab, d1 / (d1 - d3))
    cp = _sub(p, c)
    d5, d6 = _dot(ab, cp), _dot(ac, cp)
    if d6 >= 0.0 and d5 <= d6:
        return c
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        return _along(a, ac, d2 / (d2 - d6))
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        return _along(b, _sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)))
    denominator = va + vb + vc
    v, w = vb / denominator, vc / denominator
    return (a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w,
            a[2] + ab[2] * v + ac[2] * w)


def _clamp(x: float) -> float:
    return min(1.0, max(0.0, x))


def _segments_distance(p1, q1, p2, q2) -> float:
    """The distance between segments p1q1 and p2q2 (Ericson 5.1.9)."""
    d1, d2, r = _sub(q1, p1), _sub(q2, p2), _sub(p1, p2)
    a, e, f = _dot(d1, d1), _dot(d2, d2), _dot(d2, r)
    if a == 0.0 and e == 0.0:
        s = t = 0.0
    elif a == 0.0:
        s, t = 0.0, _clamp(f / e)
    else:
        c = _dot(d1, r)
        if e == 0.0:
            s, t = _clamp(-c / a), 0.0
        else:
            b = _dot(d1, d2)
            denominator = a * e - b * b
            s = _clamp((b * f - c * e) / denominator) if denominator != 0.0 else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                s, t = _clamp(-c / a), 0.0
            elif t > 1.0:
                s, t = _clamp((b - c) / a), 1.0
    return math.dist(_along(p1, d1, s), _along(p2, d2, t))


def triangle_distance(a, b) -> float:
    """The distance between the closed triangles ``a``, ``b`` ((3, 3) rows);
    0 where they meet only if rounding lands there (use it for pairs known
    to be apart)."""
    ta = [tuple(map(float, p)) for p in np.asarray(a, dtype=np.float64)]
    tb = [tuple(map(float, p)) for p in np.asarray(b, dtype=np.float64)]
    best = math.inf
    for p in ta:
        best = min(best, math.dist(p, _closest_on_triangle(p, *tb)))
    for p in tb:
        best = min(best, math.dist(p, _closest_on_triangle(p, *ta)))
    for i in range(3):
        for j in range(3):
            best = min(best, _segments_distance(ta[i], ta[(i + 1) % 3],
                                                tb[j], tb[(j + 1) % 3]))
    return best


def penetration_depth(a, b) -> float:
    """The smallest overlap of the projections of crossing triangles ``a``,
    ``b`` on the candidate axes (module docstring): the shortest
    translation that separates them."""
    ta = [tuple(map(float, p)) for p in np.asarray(a, dtype=np.float64)]
    tb = [tuple(map(float, p)) for p in np.asarray(b, dtype=np.float64)]
    edges_a = [_sub(ta[(i + 1) % 3], ta[i]) for i in range(3)]
    edges_b = [_sub(tb[(i + 1) % 3], tb[i]) for i in range(3)]
    axes = [_cross(edges_a[0], edges_a[1]), _cross(edges_b[0], edges_b[1])]
    axes += [_cross(e, f) for e in edges_a for f in edges_b]
    best = math.inf
    for axis in axes:
        length = math.sqrt(_dot(axis, axis))
        if length == 0.0:
            continue
        pa = [_dot(p, axis) / length for p in ta]
        pb = [_dot(p, axis) / length for p in tb]
        best = min(best, max(0.0, min(max(pa) - min(pb), max(pb) - min(pa))))
    return 0.0 if best == math.inf else best


def signed_gap(a, b, intersect: bool) -> float:
    """The gap of the module docstring: the distance when ``intersect`` (the
    exact answer) is false, minus the penetration depth when it is true."""
    return -penetration_depth(a, b) if intersect else triangle_distance(a, b)


def face_box_distances(world_a, faces_a, world_b, faces_b) -> np.ndarray:
    """(m_a, m_b) distances between the boxes of every face of A and every
    face of B (world vertices (n, 3), faces (m, 3)): a lower bound of each
    face pair's distance."""
    ta, tb = world_a[faces_a], world_b[faces_b]
    lo_a, hi_a = ta.min(axis=1), ta.max(axis=1)
    lo_b, hi_b = tb.min(axis=1), tb.max(axis=1)
    apart = np.maximum(lo_b[None, :, :] - hi_a[:, None, :], lo_a[:, None, :] - hi_b[None, :, :])
    apart = np.maximum(apart, 0.0)
    return np.sqrt((apart * apart).sum(axis=2))
