"""An independent exact triangle-triangle test: the separating axis theorem in
rational arithmetic. It is a ground truth for checking refsim's edge-triangle
test (seed S4, level 3) and for classifying oracle disagreements, not a fast
path.

What: two closed, non-degenerate triangles are disjoint exactly when some
plane strictly separates them, and then one with a normal among

- the two triangle normals n_A, n_B,
- the nine cross products e_i x f_j of an edge of each,
- the six in-plane edge normals n_A x e_i and n_B x f_j (the "side faces" of
  a flat polygon, needed when the triangles are coplanar)

does (the separating axis theorem for convex polytopes, with a triangle as a
flat polytope: S. Gottschalk, M. C. Lin, D. Manocha, "OBBTree", SIGGRAPH
1996, sec. 4; C. Ericson, *Real-Time Collision Detection*, 2005, sec. 5.2.1).
On each axis the projections are compared strictly, so touching sets (a
shared point) are never separated: closed semantics, like refsim's test.

Every float coordinate is an exact rational whose denominator is a power
of two (``float.as_integer_ratio``); the six points are scaled by their
common denominator into Python integers (a positive scale: every
comparison of projections keeps its sign), so every projection and
comparison is exact integer arithmetic: no tolerance anywhere, and no
fraction reduced on the way. It is a different algorithm from refsim's
edge-triangle test, so agreement between the two is evidence for both.

Cost: 17 axes x 6 dot products of integers of a few hundred bits per pair,
with no gcd (``fractions.Fraction`` reduces at every operation; the figures
as first measured: docs/decisions/library-cost-figures.md).
"""

from __future__ import annotations


def _sub(p, q):
    return (p[0] - q[0], p[1] - q[1], p[2] - q[2])


def _cross(u, v):
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def _dot(u, v):
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


def _integer_points(a, b) -> tuple[list, list]:
    """The vertices of ``a`` and ``b`` as integer triples, all scaled by one
    power of two ``D`` (the largest denominator of their coordinates as
    exact rationals): ``x = n / d`` becomes ``n (D / d)``, exactly."""
    ratios = [[[float(x).as_integer_ratio() for x in p] for p in t] for t in (a, b)]
    D = max(d for t in ratios for p in t for _, d in p)
    A, B = ([tuple(n * (D // d) for n, d in p) for p in t] for t in ratios)
    return A, B


def triangles_intersect_sat(a, b) -> bool | None:
    """Whether closed triangles ``a`` and ``b`` (3, 3) intersect, exactly.

    Returns None when either triangle is degenerate (zero area: its normal
    vanishes and the axis set above is no longer complete).
    """
    A, B = _integer_points(a, b)
    edges_a = [_sub(A[(i + 1) % 3], A[i]) for i in range(3)]
    edges_b = [_sub(B[(i + 1) % 3], B[i]) for i in range(3)]
    n_a, n_b = _cross(edges_a[0], edges_a[1]), _cross(edges_b[0], edges_b[1])
    if not any(n_a) or not any(n_b):
        return None
    axes = [n_a, n_b]
    axes += [_cross(e, f) for e in edges_a for f in edges_b]
    axes += [_cross(n_a, e) for e in edges_a] + [_cross(n_b, f) for f in edges_b]
    for w in axes:
        if not any(w):
            continue                      # parallel edges: no axis here
        pa = [_dot(w, p) for p in A]
        pb = [_dot(w, p) for p in B]
        if max(pa) < min(pb) or max(pb) < min(pa):
            return False                  # a strictly separating plane
    return True
