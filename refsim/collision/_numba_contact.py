"""The contact points of two meshes (:func:`refsim.collision.contact.contact_points`
after its triangle pairs), compiled with numba: one call per contact instead
of a few dozen numpy calls.

What: :func:`contact_region_numba` takes the two meshes' world vertices and
faces, the intersecting triangle pairs (rows sorted, as
:func:`refsim.collision.bodies.intersecting_pairs` gives them) and the
normal, and returns the points :func:`refsim.collision.contact.contact_points`
returns: the region's points (edge crossings, then A's vertices within B,
then B's within A), their thickest part (:func:`refsim.collision.contact.deepest_points`)
and the corners of its polygon (:func:`refsim.collision.contact.contact_polygon`).

Each helper is written in the readable function's operations and order:
every product and sum rounded once, left to right, as the readable
``_dot`` and ``_cross`` are; the winding number's ``atan2`` is the C
library's, as the readable one calls it (``math.atan2``), summed triangle
by triangle; numba compiles without fast-math. So the two kernels keep the
same points, bit for bit (tests/collision/test_contact_compiled.py).

Division by zero gives inf or nan as numpy's does (``error_model="numpy"``):
a ray along a face's plane (``det`` rounded to zero) misses it either way.

Cost: as the readable functions; O(pairs + k m) for k vertices of one mesh
in the other's box against its m triangles, with no per-call array
allocation beyond the result's.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from refsim.collision._numba_kernels import (
    APART,
    BAD_POSE_A,
    BAD_POSE_B,
    FIRST_HIT,
    HIT,
    UNDECIDED,
    exact_query,
)
from refsim.collision.contact import CROSSING_SLACK, DEEPEST_FRACTION, ON_SURFACE

#: :func:`refsim.kernels.sources_digest` of the refsim modules this one imports:
#: an edit there must change this line, so that numba renews its cache of
#: this module (tests/test_kernels.py checks it).
SOURCES_DIGEST = "d5c99dfb81b6e2f1"



@numba.njit(cache=True, nogil=True, error_model="numpy")
def _dot(a0, a1, a2, b0, b1, b2):
    return a0 * b0 + a1 * b1 + a2 * b2


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _edge_crossings(edge_world, edge_faces, tri_world, tri_faces, pairs, edge_col, tri_col,
                    out, k):
    """Mirrors refsim.collision.contact.edge_crossings: the edges of the
    ``edge_col`` triangle of each pair crossing the ``tri_col`` one, appended
    to ``out`` from row ``k``; returns the new count."""
    for p in range(pairs.shape[0]):
        ft = tri_faces[pairs[p, tri_col]]
        fe = edge_faces[pairs[p, edge_col]]
        a0, a1, a2 = tri_world[ft[0], 0], tri_world[ft[0], 1], tri_world[ft[0], 2]
        b0, b1, b2 = tri_world[ft[1], 0], tri_world[ft[1], 1], tri_world[ft[1], 2]
        c0, c1, c2 = tri_world[ft[2], 0], tri_world[ft[2], 1], tri_world[ft[2], 2]
        n0, n1, n2 = _cross(b0 - a0, b1 - a1, b2 - a2, c0 - a0, c1 - a1, c2 - a2)
        scale = CROSSING_SLACK * _dot(n0, n1, n2, n0, n1, n2)
        for e in range(3):
            ip, iq = fe[e], fe[(e + 1) % 3]
            p0, p1, p2 = edge_world[ip, 0], edge_world[ip, 1], edge_world[ip, 2]
            q0, q1, q2 = edge_world[iq, 0], edge_world[iq, 1], edge_world[iq, 2]
            dp = _dot(n0, n1, n2, p0 - a0, p1 - a1, p2 - a2)
            dq = _dot(n0, n1, n2, q0 - a0, q1 - a1, q2 - a2)
            if not (((dp <= 0.0 and dq >= 0.0) or (dp >= 0.0 and dq <= 0.0)) and dp != dq):
                continue
            s = dp / (dp - dq)
            x0, x1, x2 = p0 + s * (q0 - p0), p1 + s * (q1 - p1), p2 + s * (q2 - p2)
            inside = True
            for side in range(3):
                if side == 0:
                    u0, u1, u2, v0, v1, v2 = a0, a1, a2, b0, b1, b2
                elif side == 1:
                    u0, u1, u2, v0, v1, v2 = b0, b1, b2, c0, c1, c2
                else:
                    u0, u1, u2, v0, v1, v2 = c0, c1, c2, a0, a1, a2
                w0, w1, w2 = _cross(v0 - u0, v1 - u1, v2 - u2, x0 - u0, x1 - u1, x2 - u2)
                if not (_dot(n0, n1, n2, w0, w1, w2) >= -scale):
                    inside = False
            if inside:
                out[k, 0], out[k, 1], out[k, 2] = x0, x1, x2
                k += 1
    return k


@numba.njit(cache=True, nogil=True, error_model="numpy")
def winding_number_numba(x0, x1, x2, world, faces):
    """Mirrors refsim.collision.contact.winding_numbers for one point
    ``(x0, x1, x2)`` about the closed mesh ``world[faces]``: the signed
    solid angles (van Oosterom and Strackee) summed in face order."""
    total = 0.0
    for j in range(faces.shape[0]):
        f = faces[j]
        a0, a1, a2 = world[f[0], 0] - x0, world[f[0], 1] - x1, world[f[0], 2] - x2
        b0, b1, b2 = world[f[1], 0] - x0, world[f[1], 1] - x1, world[f[1], 2] - x2
        c0, c1, c2 = world[f[2], 0] - x0, world[f[2], 1] - x1, world[f[2], 2] - x2
        la = math.sqrt(_dot(a0, a1, a2, a0, a1, a2))
        lb = math.sqrt(_dot(b0, b1, b2, b0, b1, b2))
        lc = math.sqrt(_dot(c0, c1, c2, c0, c1, c2))
        bc0, bc1, bc2 = _cross(b0, b1, b2, c0, c1, c2)
        numerator = _dot(a0, a1, a2, bc0, bc1, bc2)
        denominator = (la * lb * lc + _dot(a0, a1, a2, b0, b1, b2) * lc
                       + _dot(b0, b1, b2, c0, c1, c2) * la + _dot(c0, c1, c2, a0, a1, a2) * lb)
        angle = math.atan2(numerator, denominator)
        total = angle if j == 0 else total + angle
    return 2.0 * total / (4.0 * math.pi)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _vertices_within(world, other, other_faces, out, k):
    """Mirrors refsim.collision.contact._vertices_within: ``world``'s vertices
    in ``other``'s box whose winding number about it exceeds ON_SURFACE,
    appended to ``out`` in index order."""
    lo0 = hi0 = other[0, 0]
    lo1 = hi1 = other[0, 1]
    lo2 = hi2 = other[0, 2]
    for i in range(1, other.shape[0]):
        lo0, hi0 = min(lo0, other[i, 0]), max(hi0, other[i, 0])
        lo1, hi1 = min(lo1, other[i, 1]), max(hi1, other[i, 1])
        lo2, hi2 = min(lo2, other[i, 2]), max(hi2, other[i, 2])
    for i in range(world.shape[0]):
        x0, x1, x2 = world[i, 0], world[i, 1], world[i, 2]
        if not (lo0 <= x0 <= hi0 and lo1 <= x1 <= hi1 and lo2 <= x2 <= hi2):
            continue
        if winding_number_numba(x0, x1, x2, other, other_faces) > ON_SURFACE:
            out[k, 0], out[k, 1], out[k, 2] = x0, x1, x2
            k += 1
    return k


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _exit_distance(x0, x1, x2, d0, d1, d2, world, faces):
    """Mirrors refsim.collision.contact.exit_distances for one point: the
    nearest crossing, along the unit ``d``, of a face facing along ``d``
    (Moeller and Trumbore), inf when there is none."""
    best = np.inf
    for j in range(faces.shape[0]):
        f = faces[j]
        a0, a1, a2 = world[f[0], 0], world[f[0], 1], world[f[0], 2]
        e10, e11, e12 = world[f[1], 0] - a0, world[f[1], 1] - a1, world[f[1], 2] - a2
        e20, e21, e22 = world[f[2], 0] - a0, world[f[2], 1] - a1, world[f[2], 2] - a2
        g0, g1, g2 = _cross(e10, e11, e12, e20, e21, e22)
        if not (_dot(g0, g1, g2, d0, d1, d2) > 0.0):
            continue                                   # not facing along d
        pv0, pv1, pv2 = _cross(d0, d1, d2, e20, e21, e22)
        det = _dot(e10, e11, e12, pv0, pv1, pv2)
        t0, t1, t2 = x0 - a0, x1 - a1, x2 - a2
        u = _dot(t0, t1, t2, pv0, pv1, pv2) / det
        q0, q1, q2 = _cross(t0, t1, t2, e10, e11, e12)
        v = _dot(q0, q1, q2, d0, d1, d2) / det
        t = _dot(q0, q1, q2, e20, e21, e22) / det
        hit = u >= -CROSSING_SLACK and v >= -CROSSING_SLACK and u + v <= 1.0 + CROSSING_SLACK
        if hit and t >= -CROSSING_SLACK * math.sqrt(_dot(e10, e11, e12, e10, e11, e12)):
            t = t if t >= 0.0 else 0.0              # np.maximum(t, 0.0)
            if t < best:
                best = t
    return best


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _deepest(points, k, d0, d1, d2, world_a, faces_a, world_b, faces_b):
    """Mirrors refsim.collision.contact.deepest_points over ``points[:k]``:
    a mask of the points kept."""
    keep = np.ones(k, dtype=np.bool_)
    if k <= 1:
        return keep
    chord = np.empty(k)
    largest = -np.inf
    any_finite = False
    for i in range(k):
        x0, x1, x2 = points[i, 0], points[i, 1], points[i, 2]
        up = min(_exit_distance(x0, x1, x2, d0, d1, d2, world_a, faces_a),
                 _exit_distance(x0, x1, x2, d0, d1, d2, world_b, faces_b))
        down = min(_exit_distance(x0, x1, x2, -d0, -d1, -d2, world_a, faces_a),
                   _exit_distance(x0, x1, x2, -d0, -d1, -d2, world_b, faces_b))
        chord[i] = up + down
        if np.isfinite(chord[i]):
            any_finite = True
            if chord[i] > largest:
                largest = chord[i]
    if not any_finite:
        return keep
    for i in range(k):
        keep[i] = np.isfinite(chord[i]) and chord[i] >= DEEPEST_FRACTION * largest
    return keep


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _turn(u, v, o, a, b):
    return (u[a] - u[o]) * (v[b] - v[o]) - (v[a] - v[o]) * (u[b] - u[o])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _chain(u, v, order, tol, span, kept):
    """Andrew's chain over ``order`` into ``kept``; returns its length."""
    m = 0
    for i in order:
        while m >= 2 and _turn(u, v, kept[m - 2], kept[m - 1], i) <= tol:
            m -= 1
        if m and abs(u[i] - u[kept[m - 1]]) + abs(v[i] - v[kept[m - 1]]) <= 1e-12 * span:
            continue                                   # the same point again
        kept[m] = i
        m += 1
    return m


@numba.njit(cache=True, nogil=True, error_model="numpy")
def contact_polygon_numba(points, n0, n1, n2):
    """Mirrors refsim.collision.contact.contact_polygon: the corners of the
    convex hull of ``points``' projection across ``n``, in the hull's order
    (the same stable order by (u, v) as numpy's lexsort)."""
    k = points.shape[0]
    if k <= 2:
        return points.copy()
    h0, h1, h2 = 0.0, 0.0, 0.0
    least = 0
    for j in range(1, 3):                              # np.argmin(np.abs(n)): the first least
        if abs((n0, n1, n2)[j]) < abs((n0, n1, n2)[least]):
            least = j
    if least == 0:
        h0 = 1.0
    elif least == 1:
        h1 = 1.0
    else:
        h2 = 1.0
    s0, s1, s2 = _cross(n0, n1, n2, h0, h1, h2)
    length = math.sqrt(_dot(s0, s1, s2, s0, s1, s2))
    s0, s1, s2 = s0 / length, s1 / length, s2 / length
    r0, r1, r2 = _cross(n0, n1, n2, s0, s1, s2)
    u = np.empty(k)
    v = np.empty(k)
    for i in range(k):
        u[i] = _dot(points[i, 0], points[i, 1], points[i, 2], s0, s1, s2)
        v[i] = _dot(points[i, 0], points[i, 1], points[i, 2], r0, r1, r2)
    span = max(u.max() - u.min(), v.max() - v.min())
    tol = 1e-12 * span * span
    order = np.arange(k)
    for i in range(1, k):                              # stable insertion sort by (u, v)
        j = i
        while j > 0 and (u[order[j - 1]] > u[order[j]]
                         or (u[order[j - 1]] == u[order[j]] and v[order[j - 1]] > v[order[j]])):
            order[j - 1], order[j] = order[j], order[j - 1]
            j -= 1
    lower = np.empty(k, dtype=np.int64)
    upper = np.empty(k, dtype=np.int64)
    m_lower = _chain(u, v, order, tol, span, lower)
    m_upper = _chain(u, v, order[::-1], tol, span, upper)
    count = max(m_lower - 1, 0) + max(m_upper - 1, 0)
    if count == 0:                                     # every point the same
        out = np.empty((1, 3))
        out[0] = points[order[0]]
        return out
    out = np.empty((count, 3))
    c = 0
    for i in range(m_lower - 1):
        out[c] = points[lower[i]]
        c += 1
    for i in range(m_upper - 1):
        out[c] = points[upper[i]]
        c += 1
    return out


@numba.njit(cache=True, nogil=True, error_model="numpy")
def contact_region_numba(world_a, faces_a, world_b, faces_b, pairs, n):
    """Mirrors refsim.collision.contact.contact_points from its triangle
    pairs on: the region's points (crossings of A's edges, of B's edges,
    A's vertices within B, B's within A), then deepest_points and
    contact_polygon; (0, 3) when there are none."""
    cap = 6 * pairs.shape[0] + world_a.shape[0] + world_b.shape[0]
    points = np.empty((cap, 3))
    k = _edge_crossings(world_a, faces_a, world_b, faces_b, pairs, 0, 1, points, 0)
    k = _edge_crossings(world_b, faces_b, world_a, faces_a, pairs, 1, 0, points, k)
    k = _vertices_within(world_a, world_b, faces_b, points, k)
    k = _vertices_within(world_b, world_a, faces_a, points, k)
    if k == 0:
        return np.empty((0, 3))
    keep = _deepest(points, k, n[0], n[1], n[2], world_a, faces_a, world_b, faces_b)
    kept = 0
    for i in range(k):
        if keep[i]:
            points[kept] = points[i]
            kept += 1
    return contact_polygon_numba(points[:kept], n[0], n[1], n[2])


@numba.njit(cache=True, nogil=True, error_model="numpy")
def collide_pairs_numba(floats, float_start, ints, int_start, mesh_of, rotation, origin, pairs,
                        tol, margin_rounding, margin_per_deviation, codes):
    """The exact level's answer for each body pair of ``pairs`` (P, 2), as
    :func:`refsim.collision._numba_kernels.exact_collide` gives it for one
    pair (APART, HIT, UNDECIDED, BAD_POSE_A, BAD_POSE_B), into ``codes``
    (P,): the same query, one call for a step's pairs instead of one per
    pair. Mesh m's packed arrays (:func:`refsim.collision.bvh_exact.pack_frame_tree`)
    are ``floats[float_start[m]:float_start[m + 1]]`` and likewise ``ints``;
    body i has mesh ``mesh_of[i]`` and pose ``(rotation[i], origin[i])``."""
    for p in range(pairs.shape[0]):
        a, b = pairs[p, 0], pairs[p, 1]
        ma, mb = mesh_of[a], mesh_of[b]
        status, found, uncertain = exact_query(
            floats[float_start[ma]:float_start[ma + 1]], ints[int_start[ma]:int_start[ma + 1]],
            rotation[a], origin[a],
            floats[float_start[mb]:float_start[mb + 1]], ints[int_start[mb]:int_start[mb + 1]],
            rotation[b], origin[b], FIRST_HIT, tol, margin_rounding, margin_per_deviation)
        if status:
            codes[p] = BAD_POSE_A if status == 1 else BAD_POSE_B
        elif found.shape[0]:
            codes[p] = HIT
        else:
            codes[p] = UNDECIDED if uncertain.shape[0] else APART
