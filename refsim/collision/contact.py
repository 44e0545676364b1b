"""Where two meshes touch: points of the boundary of their intersection region.

A contact between two bodies acts over a region, not at a point: a cube
resting across the edge of another is held up along the whole strip where
the two overlap, and a ball that strikes a rod near its end pushes the rod
there, not at its middle. The corrected body response
(:mod:`refsim.dynamics.body_response`) solves its impulses over the points
this module returns, as the wall response does over the vertices past a
wall.

What: for two closed triangle meshes at their poses, points of the
boundary of the region where their solids overlap, its corners (the
vertices of the intersection of two polyhedra) among them. They are of
three kinds:

1. where an edge of one mesh crosses a triangle of the other
   (:func:`edge_crossings`, over the triangle pairs that
   :func:`refsim.collision.bodies.intersecting_pairs` finds at the exact
   level);
2. vertices of A inside B, or on B's surface;
3. vertices of B inside A, or on A's surface.

Inside is decided by the winding number (:func:`winding_numbers`): the sum
of the signed solid angles of the other mesh's triangles seen from the
point, over 4 pi (A. van Oosterom, J. Strackee, "The Solid Angle of a Plane
Triangle", IEEE Trans. Biomed. Eng. 30(2), 1983). It is 1 inside a closed
mesh, 0 outside, and the fraction of the full solid angle that the solid
fills at a point of its surface (1/2 on a face, 1/8 at a cube's corner); a
point counts when its winding number exceeds :data:`ON_SURFACE`, so points
where the surfaces only touch are contact points too.

:func:`contact_points` gives the contact's points: the corners, across the
normal, of the region's thickest part (:func:`deepest_points`: where the
region is at least half as thick along the normal as at its thickest,
which is where the contact began within the step).

For two boxes overlapping by a thin slab (a box resting on another, offset),
these are the eight corners of the slab, and the points where the
diagonals of the boxes' triangulated faces cross the other box's faces
(on the slab's faces). :func:`contact_polygon` keeps the corners of their
projection across the contact normal: the four corners of the rectangle
where the boxes overlap. An empty result means the two surfaces neither
cross nor touch and neither holds a vertex of the other (at a coarse
collision level, boxes or spheres can overlap while the meshes do not).

The points are in a fixed order (crossings in the order of the sorted
triangle pairs, A's edges before B's; then A's vertices, then B's, by
index), so that a contact solve that visits them one after another gives
the same bits every run. Each is computed by element-wise float arithmetic
(no BLAS); the winding number is compared with a threshold only.

Cost: O(pairs) for the crossings after the exact level's query, and O(k m)
for the k vertices of one mesh inside the other's box against its m
triangles.
"""

from __future__ import annotations

import math

import numpy as np

from refsim.collision.bodies import intersecting_pairs
from refsim.collision.boxes import world_vertices
from refsim.kernels import CONTACT_REGION

#: A point whose winding number exceeds this is inside the mesh or on its
#: surface. Outside, the winding number is 0 up to rounding: about 1e-15,
#: except for a point close to the line of one of the mesh's edges, where the
#: two triangles' solid angles cancel and the rounding grows as
#: ``1.7e-17 / d`` for a point at distance ``d`` (measured on the unit
#: cube: 1.7e-8 at d = 1e-9, 4e-11 at 1e-6), so a point within about 1e-8 of
#: an edge counts as touching it. On the surface the winding number is the
#: fraction of the full solid angle the solid fills there, more than 1e-3
#: at every corner of the bundled models (a cube's is 1/8).
ON_SURFACE = 1e-9

#: A crossing point counts as inside its triangle down to this (relative)
#: negative barycentric weight: the pair is known to intersect (exact
#: predicates), and the float point can land a rounding outside an edge.
CROSSING_SLACK = 1e-9


def _dot(a, b):
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _cross(a, b):
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


#: Points per block of the point-by-triangle arrays (:func:`winding_numbers`,
#: :func:`exit_distances`): a block holds at most this many point-triangle
#: pairs, so memory stays bounded (tens of MB) for meshes of any size.
PAIRS_PER_BLOCK = 200_000


def _blocks(points: np.ndarray, triangles: int):
    """Slices of ``points`` holding at most PAIRS_PER_BLOCK point-triangle pairs."""
    step = max(1, PAIRS_PER_BLOCK // max(triangles, 1))
    return [slice(i, i + step) for i in range(0, len(points), step)]


#: ``math.atan2`` element by element: the C library's, which the compiled
#: twin (:mod:`refsim.collision._numba_contact`) calls too.
_atan2 = np.frompyfunc(math.atan2, 2, 1)


def winding_numbers(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(k,) winding numbers of ``points`` (k, 3) about the closed surface of
    ``triangles`` (m, 3, 3): 1 inside, 0 outside (module docstring)."""
    points = np.asarray(points, dtype=np.float64)
    if not len(points) or not len(triangles):
        return np.zeros(len(points))             # no surface: outside
    if len(points) * len(triangles) > PAIRS_PER_BLOCK:
        return np.concatenate([winding_numbers(points[s], triangles)
                               for s in _blocks(points, len(triangles))])
    t = triangles[None, :, :, :] - points[:, None, None, :]          # (k, m, 3, 3)
    a, b, c = t[..., 0, :], t[..., 1, :], t[..., 2, :]
    la, lb, lc = (np.sqrt(_dot(x, x)) for x in (a, b, c))
    numerator = _dot(a, _cross(b, c))
    denominator = la * lb * lc + _dot(a, b) * lc + _dot(b, c) * la + _dot(c, a) * lb
    # the C library's atan2 (numpy's own loops differ from it in the last bit
    # on some processors) and the angles summed triangle by triangle
    # (cumsum: one order everywhere), as the compiled twin does
    angles = _atan2(numerator, denominator).astype(np.float64)
    return 2.0 * np.cumsum(angles, axis=1)[:, -1] / (4.0 * np.pi)


def edge_crossings(edge_triangles: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Where the edges of ``edge_triangles`` (p, 3, 3) cross the paired
    ``triangles`` (p, 3, 3): the points (q, 3), pair by pair, edges in the
    order ab, bc, ca. An edge crosses when its ends lie strictly on
    opposite sides of the triangle's plane, or one end lies on it, and the
    point where it meets the plane is in the triangle (closed). An edge in
    the plane of the triangle gives nothing (coplanar pairs touch along
    other edges, or at vertices counted as on the surface)."""
    a, b, c = (triangles[:, None, k] for k in range(3))            # (p, 1, 3) each
    normal = _cross(b - a, c - a)                                    # (p, 1, 3)
    scale = CROSSING_SLACK * _dot(normal, normal)                    # (p, 1)
    p = edge_triangles                                               # edges ab, bc, ca
    q = edge_triangles[:, [1, 2, 0]]
    dp, dq = _dot(normal, p - a), _dot(normal, q - a)                # (p, 3)
    crossing = ((dp <= 0.0) & (dq >= 0.0) | (dp >= 0.0) & (dq <= 0.0)) & (dp != dq)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(crossing, dp / (dp - dq), 0.0)
    x = p + s[..., None] * (q - p)                                   # (p, 3, 3)
    inside = crossing
    for u, v in ((a, b), (b, c), (c, a)):
        inside = inside & (_dot(normal, _cross(v - u, x - u)) >= -scale)
    return x[inside]                                                 # pair by pair, in edge order


def intersection_points(mesh_a, pose_a, mesh_b, pose_b, kernel: str | None = None
                        ) -> np.ndarray:
    """(k, 3) world points of the boundary of the region where the solids of
    ``mesh_a`` and ``mesh_b`` at their poses overlap or touch, its corners
    among them (module docstring); empty when their surfaces neither cross nor touch and
    neither holds a vertex of the other."""
    return _region(mesh_a, pose_a, mesh_b, pose_b, kernel)[0]


def _region(mesh_a, pose_a, mesh_b, pose_b, kernel):
    """:func:`intersection_points`, and the two meshes' world triangles."""
    world_a, world_b = world_vertices(mesh_a, pose_a), world_vertices(mesh_b, pose_b)
    tri_a, tri_b = world_a[mesh_a.faces], world_b[mesh_b.faces]
    pairs = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, level="exact", kernel=kernel)
    parts = []
    if len(pairs):                                  # rows sorted
        parts += [edge_crossings(tri_a[pairs[:, 0]], tri_b[pairs[:, 1]]),
                  edge_crossings(tri_b[pairs[:, 1]], tri_a[pairs[:, 0]])]
    parts += [_vertices_within(world_a, world_b, tri_b), _vertices_within(world_b, world_a, tri_a)]
    return np.concatenate(parts), tri_a, tri_b


#: A point of the intersection region counts as a contact when the region
#: is at least this fraction as thick there (along the normal) as where it is
#: thickest (:func:`deepest_points`).
DEEPEST_FRACTION = 0.5


def exit_distances(points: np.ndarray, direction, triangles: np.ndarray) -> np.ndarray:
    """(k,) how far each of ``points`` (inside the closed mesh ``triangles``
    (m, 3, 3), wound counter-clockwise seen from outside, or on it) goes
    along the unit ``direction`` before it leaves the solid: the nearest
    crossing of a triangle facing along ``direction`` (0 for a point on
    such a triangle; inf when the ray meets none; a point outside gets the
    far side's distance, or inf).
    Moeller and Trumbore's ray-triangle test ("Fast, minimum storage
    ray-triangle intersection", J. Graphics Tools 2(1), 1997), element-wise;
    barycentric weights down to -:data:`CROSSING_SLACK`."""
    d = np.asarray(direction, dtype=np.float64)
    if len(points) * len(triangles) > PAIRS_PER_BLOCK:
        return np.concatenate([exit_distances(points[s], d, triangles)
                               for s in _blocks(points, len(triangles))])
    a, b, c = triangles[:, 0], triangles[:, 1], triangles[:, 2]
    e1, e2 = b - a, c - a
    leaving = _dot(_cross(e1, e2), d) > 0.0                       # (m,) faces along d
    e1, e2, a = e1[leaving], e2[leaving], a[leaving]
    pvec = _cross(d, e2)                                          # (m', 3)
    det = _dot(e1, pvec)
    tvec = points[:, None, :] - a[None, :, :]                     # (k, m', 3)
    u = _dot(tvec, pvec) / det
    qvec = _cross(tvec, e1)
    v = _dot(qvec, d) / det
    t = _dot(qvec, e2) / det
    hit = (u >= -CROSSING_SLACK) & (v >= -CROSSING_SLACK) & (u + v <= 1.0 + CROSSING_SLACK)
    t = np.where(hit & (t >= -CROSSING_SLACK * np.sqrt(_dot(e1, e1))), np.maximum(t, 0.0),
                 np.inf)
    return t.min(axis=1) if t.shape[1] else np.full(len(points), np.inf)


def deepest_points(points: np.ndarray, n, triangles_a: np.ndarray,
                   triangles_b: np.ndarray) -> np.ndarray:
    """The ``points`` of an intersection region (``n`` from B into A) where
    the region is at least :data:`DEEPEST_FRACTION` as thick along ``n`` as
    where it is thickest: its chord through each point, from where it
    leaves A or B going down to where it leaves A or B going up.

    A contact found after the bodies overlapped (by up to a step's approach)
    is a region whose thickness tells when each part of it began to touch:
    the thickest part first. A faceted ball found a millimetre into a rod's
    face overlaps it in a cap, thick at the ball's lowest vertex and thin
    where the cap's rim crosses the face; impulses stopping the approach at
    the rim's points, which the face's triangulation places unevenly, turn
    a frictionless ball; at the thick part they act on its centre line
    (docs/decisions/body-contact.md). Two faces resting on each other
    overlap in a slab of even thickness: every corner stays."""
    n = np.asarray(n, dtype=np.float64)
    if len(points) <= 1:
        return points
    up = np.minimum(exit_distances(points, n, triangles_a), exit_distances(points, n, triangles_b))
    down = np.minimum(exit_distances(points, -n, triangles_a),
                      exit_distances(points, -n, triangles_b))
    chord = up + down
    finite = np.isfinite(chord)
    if not finite.any():
        return points
    return points[finite & (chord >= DEEPEST_FRACTION * chord[finite].max())]


def contact_polygon(points: np.ndarray, n) -> np.ndarray:
    """The ``points`` (k, 3) that are the corners of the convex hull of their
    projection on the plane across the unit normal ``n``, in the hull's
    order (counter-clockwise about ``n``, from the point least along the
    first in-plane axis): the corners of the contact's polygon.

    A contact solve needs no more: impulses at the corners of a polygon can
    press at any point inside it. The points of an intersection region come
    in pairs a depth apart along ``n`` (the top and bottom of the slab where
    two faces overlap) and with points on its faces between the corners
    (two cubes offset on each other: 50 points, 4 corners); the solve over
    the corners costs less and leaves the same motion
    (docs/decisions/body-contact.md). The in-plane component of a lever
    arm is all a normal impulse's torque depends on, so which point of a
    pair is kept does not matter for the normal impulse; a friction
    impulse's torque differs by the slab's depth times it.

    Points closer than 1e-12 of the set's span in the plane count as one;
    collinear points give the two ends; one point gives itself. Andrew's
    monotone chain (A. M. Andrew, "Another efficient algorithm for convex
    hulls in two dimensions", Inf. Proc. Letters 9(5), 1979)."""
    points = np.asarray(points, dtype=np.float64)
    if len(points) <= 2:
        return points
    n = np.asarray(n, dtype=np.float64)
    helper = np.zeros(3)
    helper[int(np.argmin(np.abs(n)))] = 1.0            # the axis least along n
    t1 = _cross(n, helper)
    t1 = t1 / np.sqrt(_dot(t1, t1))
    t2 = _cross(n, t1)
    u, v = _dot(points, t1), _dot(points, t2)
    span = max(float(u.max() - u.min()), float(v.max() - v.min()))
    tol = 1e-12 * span * span
    order = np.lexsort((v, u)).tolist()

    def turn(o: int, a: int, b: int) -> float:
        return float((u[a] - u[o]) * (v[b] - v[o]) - (v[a] - v[o]) * (u[b] - u[o]))

    def chain(indices: list[int]) -> list[int]:
        kept: list[int] = []
        for i in indices:
            while len(kept) >= 2 and turn(kept[-2], kept[-1], i) <= tol:
                kept.pop()
            if kept and abs(u[i] - u[kept[-1]]) + abs(v[i] - v[kept[-1]]) <= 1e-12 * span:
                continue                                   # the same point again
            kept.append(i)
        return kept

    lower, upper = chain(order), chain(order[::-1])
    hull = lower[:-1] + upper[:-1]
    if not hull:                                         # every point the same
        hull = [order[0]]
    return points[hull]


def contact_points(mesh_a, pose_a, mesh_b, pose_b, n, kernel: str | None = None
                   ) -> np.ndarray:
    """Where a contact's impulses act, ``n`` the normal from B into A: the
    corners (:func:`contact_polygon`) of the thickest part
    (:func:`deepest_points`) of the meshes' intersection region
    (:func:`intersection_points`); empty when the meshes do not meet.

    ``kernel`` (:mod:`refsim.kernels`) chooses the pair
    :data:`refsim.kernels.CONTACT_REGION`: "compiled" runs the steps after
    the triangle pairs as one compiled call, the same points bit for bit.
    Either side passes ``kernel`` on as given to the exact query that finds
    the triangle pairs, so that with the default (None) the query's own
    tier chooses its kernel (the readable one while numba's cache lacks
    it)."""
    return CONTACT_REGION(kernel)(mesh_a, pose_a, mesh_b, pose_b, n, kernel)


def contact_region_readable(mesh_a, pose_a, mesh_b, pose_b, n, kernel: str | None = None
                            ) -> np.ndarray:
    """:func:`contact_points` on the readable kernel (the pairs' query on
    ``kernel``)."""
    points, tri_a, tri_b = _region(mesh_a, pose_a, mesh_b, pose_b, kernel)
    if not len(points):
        return points
    return contact_polygon(deepest_points(points, n, tri_a, tri_b), n)


def contact_region_compiled(mesh_a, pose_a, mesh_b, pose_b, n, kernel: str | None = None
                            ) -> np.ndarray:
    """:func:`contact_points` with the steps after the triangle pairs as one
    compiled call (:func:`refsim.collision._numba_contact.contact_region_numba`;
    the pairs' query on ``kernel``)."""
    from refsim.collision._numba_contact import contact_region_numba

    world_a, world_b = world_vertices(mesh_a, pose_a), world_vertices(mesh_b, pose_b)
    pairs = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, level="exact", kernel=kernel)
    return contact_region_numba(world_a, mesh_a.faces, world_b, mesh_b.faces, pairs,
                                np.asarray(n, dtype=np.float64))


def _vertices_within(vertices: np.ndarray, other: np.ndarray, triangles: np.ndarray
                     ) -> np.ndarray:
    """The ``vertices`` inside the closed mesh ``triangles`` (of vertices
    ``other``) or on its surface, in index order; only those in its box are
    tested."""
    in_box = np.all((vertices >= other.min(axis=0)) & (vertices <= other.max(axis=0)), axis=1)
    candidates = vertices[in_box]
    return candidates[winding_numbers(candidates, triangles) > ON_SURFACE]
