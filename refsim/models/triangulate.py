"""Triangulation of one planar polygon by ear clipping (seed S1).

AC3D surfaces are polygons with any number of corners; the simulation works
on triangles. :func:`ear_clip` cuts a simple planar polygon with ``k``
corners into ``k - 2`` triangles whose corners are the polygon's own.

Method (Eberly, "Triangulation by Ear Clipping", Geometric Tools, 2002;
O'Rourke, *Computational Geometry in C*, 2nd ed., sec. 1.6):

1. Plane. The polygon's normal is Newell's normal, the sum over edges of
   ``p_i x p_{i+1}`` (taken about the centroid for conditioning); its length
   is twice the polygon's area and its direction follows the polygon's
   winding (right-hand rule).
   The corners are first scaled by a power of two (exact) so that the
   largest coordinate is near 1: no product overflows or underflows.
2. Projection. Drop the coordinate along which the normal is largest; the
   other two, taken in cyclic order and swapped when that normal component is
   negative, give 2-D points in which the polygon runs counter-clockwise.
   Dropping a coordinate is exact: no rounding enters the projection.
3. Ears. Corner ``i`` with neighbours ``a`` and ``b`` is an *ear* when it is
   strictly convex (``cross(p_i - p_a, p_b - p_i) > 0``) and no other corner
   of the remaining polygon lies in the closed triangle ``(a, i, b)``, apart
   from points that coincide with one of its three corners (these arise when
   a polygon visits the same point twice). Clip an ear: emit ``(a, i, b)``,
   unlink ``i``, and re-examine only ``a`` and ``b``. Start at corner 1 and
   continue after each clipped ear, so that a convex polygon comes out as the
   fan ``(0, 1, 2), (0, 2, 3), ...``.

Each triangle lists its corners in the polygon's order, so it has the
polygon's orientation (its normal points the same way as Newell's).

Collinear consecutive corners are never ears themselves (not strictly
convex); they become corners of the neighbouring ears' triangles, so no
zero-area triangle is emitted for them.

Degenerate polygons (a documented choice, not an error): when Newell's
normal is no larger than the rounding error of its own sum
(``DEGENERATE_RTOL``), the polygon has no usable plane; all corners are
collinear or coincident. Such a polygon is returned as the fan
``(0, i, i + 1)`` of ``k - 2`` zero-area triangles; :class:`Mesh` then lists
them in ``degenerate_faces``. The same fallback finishes a polygon in which
rounding (or self-intersection, which is outside the method's contract)
leaves no ear: the most convex remaining corner is clipped, so the function
always returns ``k - 2`` triangles and never fails on finite input.

Two implementations of step 3, one result. :func:`ear_clip_reference` is
the specification: it tests each candidate ear against every other corner
and walks the ring to the next ear, O(k^2) for ``k`` corners, which AC3D
files with polygons of thousands of corners make minutes.
:func:`ear_clip_indexed` clips the same ears in the same order, asking the
same ear test only of the corners that can block an ear (Eberly's
reflex-corner observation, made exact for closed triangles, repeated points
and touching edges), found through a k-d tree, and taking the next ear from
a queue; :mod:`refsim.models.ear_index` gives the argument and the cost,
O(k log k) for typical polygons. It returns the reference's triangles bit
for bit on simple polygons and on polygons that touch themselves without
crossing (collinear runs, repeated corners, spikes, bridges to holes;
tests/models/test_ear_index.py, properties/models/test_ear_index_properties.py).
On self-intersecting input, and on the pinched polygons the reference itself
turns self-intersecting, the two may clip differently, both within the
contract above (:mod:`refsim.models.ear_index`, DEVIATION).
:func:`ear_clip` uses the reference below ``INDEX_MIN_CORNERS`` corners and
the compiled indexed clipping from there on.
"""

from __future__ import annotations

import numpy as np

from refsim.errors import ModelError
from refsim.models.ear_index import clip_indexed

#: A polygon is degenerate (no plane) when the length of Newell's normal is at
#: most this many times the sum of the lengths of its terms
#: ``|q_i| |q_{i+1}|``. The rounding error of the sum is bounded by about
#: ``k`` unit roundoffs of that sum; 64 eps covers polygons of a few dozen
#: corners with margin and is still far below any polygon drawn on purpose.
DEGENERATE_RTOL = 64 * np.finfo(np.float64).eps

#: :func:`ear_clip` runs the reference below this many corners: there its
#: O(k^2) costs at most a few hundred microseconds, no more than setting up
#: the index, and a model of quads and other small polygons never loads numba.
INDEX_MIN_CORNERS = 16


def newell_normal(points: np.ndarray) -> np.ndarray:
    """Newell's normal (3,) of a closed polygon ``points`` (k, 3).

    Twice the vector area: its length is twice the polygon's area for a
    planar polygon, and it points by the right-hand rule of the corner order.
    Computed about the centroid, which leaves the exact value unchanged and
    reduces rounding for polygons far from the origin.
    """
    q = points - points.mean(axis=0)
    return np.cross(q, np.roll(q, -1, axis=0)).sum(axis=0)


def ear_clip(points) -> np.ndarray:
    """Triangulate one planar polygon by ear clipping.

    The triangles of :func:`ear_clip_reference`, bit for bit, for every
    simple polygon and every polygon that touches itself without crossing
    (module docstring): below ``INDEX_MIN_CORNERS`` corners by the reference
    itself, from there on by :func:`ear_clip_indexed` (compiled).

    Parameters
    ----------
    points : array_like, shape (k, 3)
        The polygon's corners in order (either winding), ``k >= 3``, finite.

    Returns
    -------
    ndarray of int64, shape (k - 2, 3)
        Corner indices of each triangle, in the polygon's winding.

    Raises
    ------
    ModelError
        When ``points`` is not a (k, 3) array with ``k >= 3`` of finite values.
    """
    p = _checked(points)
    if len(p) < INDEX_MIN_CORNERS:
        return ear_clip_reference(p)
    return ear_clip_indexed(p)


def ear_clip_reference(points) -> np.ndarray:
    """The specification: steps 1 to 3 of the module docstring as written,
    each ear test against every other corner, each next ear found by walking
    the ring. O(k^2); the tests compare :func:`ear_clip_indexed` with it.
    Same parameters, result and errors as :func:`ear_clip`."""
    p = _checked(points)
    k = len(p)
    if k == 3:
        return np.array([[0, 1, 2]], dtype=np.int64)
    plane = project_polygon(p)
    if plane is None:
        return _fan(k)
    xs, ys = plane
    return _clip_by_walking(xs.tolist(), ys.tolist())


def ear_clip_indexed(points, *, kernel: str | None = None, work=None) -> np.ndarray:
    """:func:`ear_clip_reference`'s triangles by the indexed clipping of
    :mod:`refsim.models.ear_index`: O(k log k) for typical polygons.

    ``kernel`` (:mod:`refsim.kernels`): "compiled" runs numba's build of that
    module's source, "readable" the source as Python.
    ``work``, if given, is an int64 array (4,) that receives the counters of
    :func:`refsim.models.ear_index.clip_ears` (zeros for the fan and the
    triangle, which clip nothing). Same parameters, result and errors as
    :func:`ear_clip`.
    """
    p = _checked(points)
    k = len(p)
    if k == 3:
        return np.array([[0, 1, 2]], dtype=np.int64)
    plane = project_polygon(p)
    if plane is None:
        return _fan(k)
    return clip_indexed(*plane, kernel=kernel, work=work)


def project_polygon(p: np.ndarray):
    """Steps 1 and 2: the 2-D corners ``(xs, ys)``, two float64 arrays (k,) in
    which the polygon runs counter-clockwise, every coordinate in (-1, 1);
    or None when the polygon has no plane (degenerate). ``p`` is a checked
    (k, 3) float64 array."""
    # Scale by a power of two so that the largest coordinate is in [0.5, 1):
    # exact (orientation signs cannot change), and the products below can
    # neither overflow (coordinates near 1e308) nor underflow (near 1e-308).
    largest = float(np.abs(p).max())
    if largest > 0.0:
        p = np.ldexp(p, -np.frexp(largest)[1])

    # Step 1: the plane, from Newell's normal.
    n = newell_normal(p)
    q = p - p.mean(axis=0)
    scale = float((np.linalg.norm(q, axis=1) * np.linalg.norm(np.roll(q, -1, axis=0),
                                                               axis=1)).sum())
    if not np.linalg.norm(n) > DEGENERATE_RTOL * scale:
        return None

    # Step 2: project by dropping the dominant axis; orient counter-clockwise.
    a = int(np.argmax(np.abs(n)))
    u, v = (a + 1) % 3, (a + 2) % 3
    if n[a] < 0.0:
        u, v = v, u
    return np.ascontiguousarray(p[:, u]), np.ascontiguousarray(p[:, v])


def _checked(points) -> np.ndarray:
    """``points`` as a (k, 3) float64 array, or ModelError."""
    p = np.asarray(points, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 3:
        raise ModelError(f"a polygon needs shape (k, 3) with k >= 3, got {p.shape}")
    if not np.isfinite(p).all():
        raise ModelError("a polygon corner has a non-finite coordinate")
    return p


def _clip_by_walking(xs: list, ys: list) -> np.ndarray:
    """Step 3 as the specification states it, on the projected corners."""
    k = len(xs)
    prev = [(i - 1) % k for i in range(k)]
    nxt = [(i + 1) % k for i in range(k)]
    ear = [_is_ear(i, prev, nxt, xs, ys) for i in range(k)]
    triangles = []
    remaining = k
    i = 1
    while remaining > 3:
        start, found = i, False
        while True:
            if ear[i]:
                found = True
                break
            i = nxt[i]
            if i == start:
                break
        if not found:
            i = _most_convex(start, prev, nxt, xs, ys)  # fallback, see module docstring
        a_, b_ = prev[i], nxt[i]
        triangles.append((a_, i, b_))
        nxt[a_], prev[b_] = b_, a_
        remaining -= 1
        ear[a_] = _is_ear(a_, prev, nxt, xs, ys)
        ear[b_] = _is_ear(b_, prev, nxt, xs, ys)
        i = b_
    triangles.append((prev[i], i, nxt[i]))
    return np.array(triangles, dtype=np.int64)


def _fan(k: int) -> np.ndarray:
    """The fan ``(0, i, i + 1)`` for ``i = 1 .. k - 2``."""
    i = np.arange(1, k - 1, dtype=np.int64)
    return np.stack([np.zeros_like(i), i, i + 1], axis=1)


def _cross(xs, ys, a: int, b: int, c: int) -> float:
    """Twice the signed area of the 2-D triangle (a, b, c); > 0 when CCW."""
    return (xs[b] - xs[a]) * (ys[c] - ys[a]) - (ys[b] - ys[a]) * (xs[c] - xs[a])


def _is_ear(i: int, prev, nxt, xs, ys) -> bool:
    """Whether corner ``i`` of the current ring is an ear (Eberly, sec. 2)."""
    a, b = prev[i], nxt[i]
    if not _cross(xs, ys, a, i, b) > 0.0:
        return False  # reflex or collinear: clipping it would fold the polygon
    corners = ((xs[a], ys[a]), (xs[i], ys[i]), (xs[b], ys[b]))
    j = nxt[b]
    while j != a:
        point = (xs[j], ys[j])
        if point not in corners and _in_closed_triangle(xs, ys, a, i, b, j):
            return False
        j = nxt[j]
    return True


def _in_closed_triangle(xs, ys, a: int, b: int, c: int, j: int) -> bool:
    """Whether point ``j`` lies in the closed CCW triangle (a, b, c)."""
    return (_cross(xs, ys, a, b, j) >= 0.0 and _cross(xs, ys, b, c, j) >= 0.0
            and _cross(xs, ys, c, a, j) >= 0.0)


def _most_convex(start: int, prev, nxt, xs, ys) -> int:
    """The corner of the ring with the largest turn; the first one on ties."""
    best, best_turn = start, _cross(xs, ys, prev[start], start, nxt[start])
    j = nxt[start]
    while j != start:
        turn = _cross(xs, ys, prev[j], j, nxt[j])
        if turn > best_turn:
            best, best_turn = j, turn
        j = nxt[j]
    return best
