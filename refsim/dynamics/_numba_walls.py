"""The wall stage of the compiled simulation loop
(:mod:`refsim.dynamics._numba_kernels`): the seed's spin change at a wall
and the corrected wall impulses, each the compiled twin of a readable
function it names, in that function's operations and order (bit for bit;
tests/dynamics/test_compiled_loop.py checks whole trajectories).

- :func:`wall_spin_seed`: S9's spin change at a crossed wall;
- :func:`wall_impulse_response`: the corrected response at a crossed wall (the
  vertices past it, the push-back, the speed at the wall, the contact
  solve compiled from its readable source, a bounce carried on from its
  instant);
- :func:`wall_speed`, :func:`world_inertia`: the small pieces the loop's
  own stages share with these (:func:`origin` is theirs alone).

Seed sections: S7, S9 and their correction (D1, D6).

Cost: O(vertices of the body) per crossed wall for the seed's spin change;
for the corrected one O(leaves + the vertices of the leaves near the wall)
to find the vertices past it, plus the contact solve.

This module imports numba at import time; import it only when the compiled
kernels are chosen.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from refsim.dynamics.impulse import contact_sum_python, solve_contacts_python
from refsim.dynamics.rotation_impulse import WALL_DEEPEST_FRACTION
from refsim.dynamics.walls import bounce_advance, crossing_time, deepest_speed

#: :func:`refsim.kernels.sources_digest` of the refsim modules this one imports:
#: an edit there must change this line, so that numba renews its cache of
#: this module (tests/test_kernels.py checks it).
SOURCES_DIGEST = "8ad5793c7a079de3"

#: The contact solve of the corrected wall response, compiled from the
#: readable source (:func:`refsim.dynamics.impulse.solve_contacts_python`,
#: as :func:`~refsim.dynamics.impulse.solve_contacts_compiled` compiles it).
_solve_contacts = numba.njit(cache=True, nogil=True)(solve_contacts_python)
_contact_sum = numba.njit(cache=True, nogil=True)(contact_sum_python)
_deepest_speed = numba.njit(cache=True, nogil=True)(deepest_speed)
_crossing_time = numba.njit(cache=True, nogil=True)(crossing_time)
_bounce_advance = numba.njit(cache=True, nogil=True)(bounce_advance)


@numba.njit(cache=True, nogil=True)
def wall_spin_seed(b, corr, vertices_t, first, end, x, center, v, w, R, lo, hi,
                   restitution, friction):
    """Mirrors :meth:`refsim.dynamics.simulation.Simulation._wall_spin_seed`
    (the world vertices under :meth:`~refsim.dynamics.simulation.Simulation.pose`,
    origin ``x - R c`` summed left to right, also for c = 0): for each
    crossed wall, the contact vertex
    (:func:`refsim.dynamics.rotation_seed.contact_vertex_seed`: the first
    deepest world vertex) and w += Pi x I
    (:func:`refsim.dynamics.rotation_seed.contact_spin_seed`).

    ``np.dot(Vi, N)`` there sums from 0.0 (BLAS, or numpy's own loop), with
    N a signed unit axis: every product is exact, so the sum is the one
    nonzero product in any order, written here ``((0 + p0) + p1) + p2``.
    """
    o0, o1, o2 = origin(b, x, R, center)
    for k in range(3):
        if corr[k] == 0.0:
            continue
        low = corr[k] > 0.0
        o_k = o0 if k == 0 else (o1 if k == 1 else o2)
        # The deepest vertex: the first whose world coordinate r_k + origin_k
        # is least (greatest). The box's lo_k (hi_k) is that least value, from
        # the same r_k and origin (rounding is monotone: min(r) + o is the
        # least r + o; the origins differ at most in the sign of a zero, which
        # == ignores), so the scan stops at the first vertex that reaches it.
        target = lo[b, k] if low else hi[b, k]
        index = -1
        for q in range(first, end):
            r = ((R[b, k, 0] * vertices_t[0, q] + R[b, k, 1] * vertices_t[1, q])
                 + R[b, k, 2] * vertices_t[2, q]) + o_k
            if r == target:
                index = q
                break
        if index < 0:                # not reached (cannot happen): argmin / argmax
            best = 0.0
            for q in range(first, end):
                r = ((R[b, k, 0] * vertices_t[0, q] + R[b, k, 1] * vertices_t[1, q])
                     + R[b, k, 2] * vertices_t[2, q]) + o_k
                if index < 0 or (r < best if low else r > best):
                    best = r
                    index = q
        P0 = (((R[b, 0, 0] * vertices_t[0, index] + R[b, 0, 1] * vertices_t[1, index])
               + R[b, 0, 2] * vertices_t[2, index]) + o0) - x[b, 0]
        P1 = (((R[b, 1, 0] * vertices_t[0, index] + R[b, 1, 1] * vertices_t[1, index])
               + R[b, 1, 2] * vertices_t[2, index]) + o1) - x[b, 1]
        P2 = (((R[b, 2, 0] * vertices_t[0, index] + R[b, 2, 1] * vertices_t[1, index])
               + R[b, 2, 2] * vertices_t[2, index]) + o2) - x[b, 2]
        N0 = N1 = N2 = 0.0
        sign = 1.0 if low else -1.0
        if k == 0:
            N0 = sign
        elif k == 1:
            N1 = sign
        else:
            N2 = sign
        w0, w1, w2 = w[b, 0], w[b, 1], w[b, 2]
        # Vi = (w x Pi) + Vel
        V0 = (w1 * P2 - w2 * P1) + v[b, 0]
        V1 = (w2 * P0 - w0 * P2) + v[b, 1]
        V2 = (w0 * P1 - w1 * P0) + v[b, 2]
        dot = ((0.0 + V0 * N0) + V1 * N1) + V2 * N2
        minus = -dot
        # normal = -(Vi . N) N; I = normal kRestitution; T = Pi x I
        I0 = (minus * N0) * restitution
        I1 = (minus * N1) * restitution
        I2 = (minus * N2) * restitution
        w[b, 0] = w0 + (P1 * I2 - P2 * I1)
        w[b, 1] = w1 + (P2 * I0 - P0 * I2)
        w[b, 2] = w2 + (P0 * I1 - P1 * I0)


@numba.njit(cache=True, nogil=True)
def origin(b, x, R, center):
    """Body b's mesh origin ``x - R c`` as :meth:`Simulation.pose
    <refsim.dynamics.simulation.Simulation.pose>` computes it (``R c``
    summed left to right, also for c = 0)."""
    o0 = x[b, 0] - ((R[b, 0, 0] * center[b, 0] + R[b, 0, 1] * center[b, 1])
                    + R[b, 0, 2] * center[b, 2])
    o1 = x[b, 1] - ((R[b, 1, 0] * center[b, 0] + R[b, 1, 1] * center[b, 1])
                    + R[b, 1, 2] * center[b, 2])
    o2 = x[b, 2] - ((R[b, 2, 0] * center[b, 0] + R[b, 2, 1] * center[b, 1])
                    + R[b, 2, 2] * center[b, 2])
    return o0, o1, o2


@numba.njit(cache=True, nogil=True)
def wall_speed(v_k, a_k, correction_k):
    """Mirrors :func:`refsim.dynamics.walls.wall_speed`."""
    squared = v_k * v_k + 2.0 * a_k * correction_k
    if 0.0 > squared:
        squared = 0.0
    return np.copysign(np.sqrt(squared), v_k)


@numba.njit(cache=True, nogil=True)
def world_inertia(Rb, I_body, out):
    """Mirrors :func:`refsim.dynamics.rotation_impulse.world_inertia` for one
    body: ``(R I) R^T`` into out (3, 3), each sum left to right."""
    T = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            T[i, j] = (Rb[i, 0] * I_body[0, j] + Rb[i, 1] * I_body[1, j]) \
                + Rb[i, 2] * I_body[2, j]
    for i in range(3):
        for j in range(3):
            out[i, j] = (T[i, 0] * Rb[j, 0] + T[i, 1] * Rb[j, 1]) + T[i, 2] * Rb[j, 2]


#: Relative slack of :func:`vertices_past_wall`'s test (far above the
#: rounding it covers, about 1e-15 relative).
CULL_SLACK = 1e-9


@numba.njit(cache=True, nogil=True)
def vertices_past_wall(b, k, low, wall, o_k, R, vertices_t, leaf_order, leaf_start,
                       leaf_spheres, first_leaf, past):
    """The columns q of ``vertices_t`` (body b's vertices) whose world
    coordinate ``W_q = ((R_k0 X_q + R_k1 Y_q) + R_k2 Z_q) + o_k`` is past the
    wall (``W_q < wall`` for a low wall, ``> wall`` for a high one), in
    increasing order, into ``past``; returns how many. The same list as
    testing every vertex (as :func:`refsim.dynamics.rotation_impulse.wall_contacts`
    does), without looking at the leaves that cannot hold one.

    Why a leaf can be passed over. With ``a = R[b, k]`` and a leaf's sphere
    ``(c, rho)`` (:func:`refsim.dynamics.compiled_loop.vertex_leaves`), every
    vertex v of the leaf has ``|a . (v - c)| <= |a| rho``, so
    ``a . v + o_k`` lies within ``|a| rho`` of ``s = a . c + o_k``. The
    computed ``W_q`` and ``s`` differ from these exact values by a few
    rounding errors, each below ``4 u (|a| (|c| + rho) + |o_k|)`` (u =
    2^-53; ``|c| + rho`` bounds ``|v|``); the slack ``CULL_SLACK (|a| (|c| +
    rho) + |o_k| + |wall|)`` covers them and the rounding of the test itself
    many times over. So when ``s - (|a| rho + slack) > wall`` every
    computed ``W_q`` of the leaf is above the wall (below it for a high
    wall, mirrored), and no vertex of the leaf is past it. A non-finite
    value makes the test false, and the leaf is tested vertex by vertex.
    """
    a0, a1, a2 = R[b, k, 0], R[b, k, 1], R[b, k, 2]
    norm = math.sqrt((a0 * a0 + a1 * a1) + a2 * a2)
    count = np.int64(0)         # typed int64 at once: a literal 0 compiles _sort_ascending twice
    for leaf in range(first_leaf[b], first_leaf[b + 1]):
        s = ((a0 * leaf_spheres[leaf, 0] + a1 * leaf_spheres[leaf, 1])
             + a2 * leaf_spheres[leaf, 2]) + o_k
        reach = norm * leaf_spheres[leaf, 3] \
            + CULL_SLACK * ((norm * leaf_spheres[leaf, 4] + abs(o_k)) + abs(wall))
        if (s - reach > wall) if low else (s + reach < wall):
            continue
        for p in range(leaf_start[leaf], leaf_start[leaf + 1]):
            q = leaf_order[p]
            W_k = ((a0 * vertices_t[0, q] + a1 * vertices_t[1, q]) + a2 * vertices_t[2, q]) \
                + o_k
            if W_k < wall if low else W_k > wall:
                past[count] = q
                count += 1
    _sort_ascending(past, count)
    return count


@numba.njit(cache=True, nogil=True)
def _sort_ascending(a, n):
    """``a[:n]`` (vertex indices) in increasing order, in place: a heapsort,
    O(n log n) with no scratch. Written out rather than numpy's sort, whose
    compiled quicksort costs about a second of an empty cache's compile."""
    for root in range(n // 2 - 1, -1, -1):
        _sift_down(a, root, n)
    for end in range(n - 1, 0, -1):
        a[0], a[end] = a[end], a[0]
        _sift_down(a, np.int64(0), end)      # not a literal 0: one compiled version


@numba.njit(cache=True, nogil=True)
def _sift_down(a, root, n):
    """The heap of ``a[:n]`` (largest at the top) restored below ``root``."""
    while True:
        child = 2 * root + 1
        if child >= n:
            return
        if child + 1 < n and a[child + 1] > a[child]:
            child += 1
        if a[root] >= a[child]:
            return
        a[root], a[child] = a[child], a[root]
        root = child


@numba.njit(cache=True, nogil=True)
def deepest_contacts(b, k, low, wall, o_k, R, vertices_t, past, count):
    """Mirrors the depth filter of
    :func:`refsim.dynamics.rotation_impulse.wall_contacts`: of the ``count``
    vertices in ``past`` (past the wall, in increasing order), those at
    least WALL_DEEPEST_FRACTION of the deepest one's depth past it, kept in order
    at the front of ``past``; returns how many."""
    a0, a1, a2 = R[b, k, 0], R[b, k, 1], R[b, k, 2]
    deepest = 0.0
    for i in range(count):
        q = past[i]
        W_k = ((a0 * vertices_t[0, q] + a1 * vertices_t[1, q]) + a2 * vertices_t[2, q]) + o_k
        depth = wall - W_k if low else W_k - wall
        if i == 0 or depth > deepest:
            deepest = depth
    kept = 0
    for i in range(count):
        q = past[i]
        W_k = ((a0 * vertices_t[0, q] + a1 * vertices_t[1, q]) + a2 * vertices_t[2, q]) + o_k
        depth = wall - W_k if low else W_k - wall
        if depth >= WALL_DEEPEST_FRACTION * deepest:
            past[kept] = q
            kept += 1
    return kept


@numba.njit(cache=True, nogil=True)
def offsets(b, x, R, vertices_t, o, past, count, r_a):
    """``r_a[:count]``: body b's vertices ``past[:count]`` in world
    coordinates (as :func:`refsim.types.transform_points` computes them,
    about the mesh origin ``o``) less the centroid ``x[b]``."""
    for i in range(count):
        q = past[i]
        for j in range(3):
            r_a[i, j] = (((R[b, j, 0] * vertices_t[0, q] + R[b, j, 1] * vertices_t[1, q])
                          + R[b, j, 2] * vertices_t[2, q]) + o[j]) - x[b, j]


@numba.njit(cache=True, nogil=True)
def wall_impulse_response(b, corr, vertices_t, leaf_order, leaf_start, leaf_spheres,
                          first_leaf, x, center, v, w, R, lo, hi, h, half_size, gravity,
                          restitution, friction, threshold, iterations, inv_mass, I_inv, past,
                          r_a, P, n, v_contact, turn, impulse_now, keep, wall_r, wall_at,
                          kept):
    """Mirrors :meth:`refsim.dynamics.simulation.Simulation._wall_impulse` for
    body b, in place: for each crossed wall, the vertices past it (found by
    :func:`vertices_past_wall`, world coordinates as
    :func:`refsim.types.transform_points` computes them; for an impact the
    deepest of them, :func:`refsim.dynamics.rotation_impulse.wall_contacts`),
    the push-back, the speed at the wall (D6), the contact solve
    (:func:`refsim.dynamics.impulse.wall_impulses`, the wall static: B's
    arrays None) and its impulses into ``impulse_now[b, wall]``
    (:func:`refsim.dynamics.impulse.contact_sum_python`), then a bounce
    carried on from its instant (:func:`refsim.dynamics.walls.deepest_speed`,
    :func:`~refsim.dynamics.walls.crossing_time`,
    :func:`~refsim.dynamics.walls.bounce_advance`, compiled from the same
    source), the box ``lo``, ``hi`` moving with the body. ``I_inv`` is the
    body's world inverse inertia; ``v_contact`` (3,) and ``turn`` (3, 3)
    scratch. With ``keep``, each wall's vertices past it (offsets from the
    centroid before the push-back, what the readable stage keeps in
    ``Simulation._wall_contacts``) go to rows ``kept`` on of ``wall_r``,
    their start and count to ``wall_at[b, wall]``; returns the rows of
    ``wall_r`` used so far."""
    for k in range(3):
        if corr[k] == 0.0:
            continue
        low = corr[k] > 0.0
        wall = -half_size if low else half_size
        o = origin(b, x, R, center)
        count = vertices_past_wall(b, k, low, wall, o[k], R, vertices_t, leaf_order,
                                   leaf_start, leaf_spheres, first_leaf, past)
        # D6: the speed at the wall, only for a real bounce
        bounce = v[b, k] * corr[k] < -threshold * abs(corr[k])
        # every vertex past the wall holds a body at rest; an impact (its
        # deepest contact moving into the wall faster than the threshold)
        # began at the deepest ones
        offsets(b, x, R, vertices_t, o, past, count, r_a)
        if keep:
            side = 2 * k + (0 if low else 1)
            wall_at[b, side, 0] = kept
            wall_at[b, side, 1] = count
            for i in range(count):
                for j in range(3):
                    wall_r[kept + i, j] = r_a[i, j]
            kept += count
        u = _deepest_speed(r_a, count, k, low, v[b], w[b]) if count else 0.0
        if bounce or (u < -threshold if low else u > threshold):
            count = deepest_contacts(b, k, low, wall, o[k], R, vertices_t, past, count)
            offsets(b, x, R, vertices_t, o, past, count, r_a)
        a_k = -gravity if k == 1 else 0.0
        tau = _crossing_time(u, a_k, corr[k], low, h) if bounce else 0.0
        x[b, k] += corr[k]
        if bounce:
            v[b, k] = wall_speed(v[b, k], a_k, corr[k])
        if count == 0:
            continue
        for j in range(3):
            n[j] = 0.0
            v_contact[j] = v[b, j]
        w0, w1, w2 = w[b, 0], w[b, 1], w[b, 2]
        n[k] = 1.0 if low else -1.0
        _solve_contacts(r_a[:count], None, n, inv_mass, I_inv, v[b], w[b], 0.0, None, None,
                        None, restitution, friction, threshold, iterations, P[:count])
        _contact_sum(P[:count], n, r_a[:count], x[b], impulse_now[b, 2 * k + (0 if low else 1)])
        if tau > 0.0:
            _bounce_advance(x[b], v[b], v_contact, R[b], w[b], w[b, 0] - w0, w[b, 1] - w1,
                            w[b, 2] - w2, turn, lo[b], hi[b], k, low, a_k, tau)
    return kept
