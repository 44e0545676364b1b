"""Compiled kernels of body-body collision (seed S4), for the optional extra
``fast``: the certified triangle-pair filter (:mod:`refsim.collision.triangle_numba`)
and the hierarchy's refit and traversal (:mod:`refsim.collision.bvh`).

Line for line the same steps as the readable kernels, as plain loops over
arrays. The functions are defined at module level on purpose: numba's on-disk
cache (``cache=True``) keys a function by its source and its globals, and a
kernel built inside a factory function closes over other dispatchers, which
pickle differently in every process, so the cache never hit and every process
recompiled. At module level the cache hits and the compile is paid once per
machine (measured in :mod:`refsim.studies.levels`).

Arithmetic: numba compiles without fast-math, so each operation is rounded
once, as in Python and in elementwise numpy; the tests compare the kernels
bit for bit with the readable ones.

This module imports numba at import time; import it only when the compiled
kernel is chosen.
"""

from __future__ import annotations

import numba
import numpy as np

from refsim.collision._numba_exact import triangles_intersect_exact
from refsim.collision.predicates import FILTER_MAX_ABS, FILTER_MIN_ABS
from refsim.rounding import O2D_ERRBOUND_A, O3D_ERRBOUND_A

#: :func:`refsim.kernels.sources_digest` of the refsim modules this one imports:
#: an edit there must change this line, so that numba renews its cache of
#: this module (tests/test_kernels.py checks it).
SOURCES_DIGEST = "93f8352e1cf32731"

# -- the certified triangle-pair filter (triangle_numba's steps 1-4) -------------------
#
# Points are 3-tuples and triangles 3-tuples of points. Tuples are passed by
# value; an array passed to a compiled helper, or a row sliced from one
# (``t[0]``), is a reference-counted object, and doing that a dozen times per
# pair made the first version of this filter several times slower
# (docs/decisions/triangle-filter-arguments.md).


@numba.njit(cache=True)
def o3d(a, b, c, d):
    """(sign, certain) of orient3d(a, b, c, d) under Shewchuk's static filter."""
    adx, ady, adz = a[0] - d[0], a[1] - d[1], a[2] - d[2]
    bdx, bdy, bdz = b[0] - d[0], b[1] - d[1], b[2] - d[2]
    cdx, cdy, cdz = c[0] - d[0], c[1] - d[1], c[2] - d[2]
    bdxcdy = bdx * cdy
    cdxbdy = cdx * bdy
    cdxady = cdx * ady
    adxcdy = adx * cdy
    adxbdy = adx * bdy
    bdxady = bdx * ady
    det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady)
    permanent = ((abs(bdxcdy) + abs(cdxbdy)) * abs(adz)
                 + (abs(cdxady) + abs(adxcdy)) * abs(bdz)
                 + (abs(adxbdy) + abs(bdxady)) * abs(cdz))
    if abs(det) > O3D_ERRBOUND_A * permanent:
        return (1 if det > 0 else -1), True
    return 0, False

@numba.njit(cache=True)
def o2d_certain(a0, a1, b0, b1, c0, c1):
    detleft = (a0 - c0) * (b1 - c1)
    detright = (a1 - c1) * (b0 - c0)
    det = detleft - detright
    return abs(det) > O2D_ERRBOUND_A * (abs(detleft) + abs(detright))

@numba.njit(cache=True)
def filter_applies(t):
    """Step 1 for one triangle: coordinates in the filter's range and the
    triangle certainly non-degenerate."""
    for v in range(3):
        for k in range(3):
            m = abs(t[v][k])
            if m != 0.0 and not (FILTER_MIN_ABS <= m <= FILTER_MAX_ABS):
                return False
    p, q, r = t
    for i, j in ((1, 2), (2, 0), (0, 1)):
        if o2d_certain(p[i], p[j], q[i], q[j], r[i], r[j]):
            return True
    return False

@numba.njit(cache=True)
def sides(plane, t):
    """(signs, certain) of t's vertices against the plane of triangle ``plane``."""
    s0, c0 = o3d(plane[0], plane[1], plane[2], t[0])
    s1, c1 = o3d(plane[0], plane[1], plane[2], t[1])
    s2, c2 = o3d(plane[0], plane[1], plane[2], t[2])
    return (s0, s1, s2), (c0, c1, c2)

@numba.njit(cache=True)
def certainly_one_side(s, c):
    return c[0] and c[1] and c[2] and s[0] == s[1] and s[1] == s[2]

@numba.njit(cache=True)
def edges_vs_triangle(e, t, s, c):
    """(any certain hit, all three edges certainly miss) for the edges of e
    against triangle t; s, c are the sides of e's vertices to t's plane."""
    all_miss = True
    for i in range(3):
        j = (i + 1) % 3
        if c[i] and c[j]:
            if s[i] == s[j]:
                continue                                    # case 4a: miss
            g1, k1 = o3d(e[i], e[j], t[0], t[1])
            g2, k2 = o3d(e[i], e[j], t[1], t[2])
            g3, k3 = o3d(e[i], e[j], t[2], t[0])
            pos = g1 > 0 or g2 > 0 or g3 > 0
            neg = g1 < 0 or g2 < 0 or g3 < 0
            if pos and neg:
                continue                                    # case 4c: miss
            if k1 and k2 and k3:
                return True, False                          # case 4c: hit
        all_miss = False
    return False, all_miss

@numba.njit(cache=True)
def certify_filtered(a, b):
    """Steps 2-4 for triangles that passed step 1: (answer, certain)."""
    sa, ca = sides(b, a)
    if certainly_one_side(sa, ca):
        return False, True                  # (the numpy kernel computes both sides first)
    sb, cb = sides(a, b)
    if certainly_one_side(sb, cb):
        return False, True
    hit, miss_a = edges_vs_triangle(a, b, sa, ca)
    if hit:
        return True, True
    hit, miss_b = edges_vs_triangle(b, a, sb, cb)
    if hit:
        return True, True
    return False, miss_a and miss_b

@numba.njit(cache=True)
def certify_pair(a, b):
    """(answer, certain) for one pair of triangles (tuples of three points)."""
    if not (filter_applies(a) and filter_applies(b)):
        return False, False
    return certify_filtered(a, b)

@numba.njit(cache=True)
def certified(A, B):
    """Mirrors :func:`refsim.collision.triangle_batch.triangles_intersect_batch`'s float filter.

    ``certify_pair`` for every pair of two (k, 3, 3) arrays."""
    k = A.shape[0]
    answer = np.zeros(k, dtype=np.bool_)
    certain = np.zeros(k, dtype=np.bool_)
    for n in range(k):
        a = ((A[n, 0, 0], A[n, 0, 1], A[n, 0, 2]), (A[n, 1, 0], A[n, 1, 1], A[n, 1, 2]),
             (A[n, 2, 0], A[n, 2, 1], A[n, 2, 2]))
        b = ((B[n, 0, 0], B[n, 0, 1], B[n, 0, 2]), (B[n, 1, 0], B[n, 1, 1], B[n, 1, 2]),
             (B[n, 2, 0], B[n, 2, 1], B[n, 2, 2]))
        answer[n], certain[n] = certify_pair(a, b)
    return answer, certain

@numba.njit(cache=True)
def certified_indexed(world_a, faces_a, world_b, faces_b, pairs):
    """``certified`` for pairs of face indices into two meshes."""
    k = pairs.shape[0]
    answer = np.zeros(k, dtype=np.bool_)
    certain = np.zeros(k, dtype=np.bool_)
    for n in range(k):
        p, q, r = faces_a[pairs[n, 0], 0], faces_a[pairs[n, 0], 1], faces_a[pairs[n, 0], 2]
        a = ((world_a[p, 0], world_a[p, 1], world_a[p, 2]),
             (world_a[q, 0], world_a[q, 1], world_a[q, 2]),
             (world_a[r, 0], world_a[r, 1], world_a[r, 2]))
        p, q, r = faces_b[pairs[n, 1], 0], faces_b[pairs[n, 1], 1], faces_b[pairs[n, 1], 2]
        b = ((world_b[p, 0], world_b[p, 1], world_b[p, 2]),
             (world_b[q, 0], world_b[q, 1], world_b[q, 2]),
             (world_b[r, 0], world_b[r, 1], world_b[r, 2]))
        answer[n], certain[n] = certify_pair(a, b)
    return answer, certain


# -- the hierarchy: transform, triangle boxes, refit; traversal (bvh) ----------------


@numba.njit(cache=True)
def prepare(vertices, faces, rotation, translation, left, right, start, count, order):
    """Mirrors :func:`refsim.collision.boxes.world_vertices`,
    :func:`refsim.collision.boxes.triangle_boxes` and :func:`refsim.collision.bvh.refit`."""
    n = vertices.shape[0]
    world = np.empty((n, 3))
    for i in range(n):
        x, y, z = vertices[i, 0], vertices[i, 1], vertices[i, 2]
        for k in range(3):
            world[i, k] = ((rotation[k, 0] * x + rotation[k, 1] * y)
                           + rotation[k, 2] * z) + translation[k]
    m = faces.shape[0]
    tri_lo = np.empty((m, 3))
    tri_hi = np.empty((m, 3))
    for t in range(m):
        for k in range(3):
            a = world[faces[t, 0], k]
            b = world[faces[t, 1], k]
            c = world[faces[t, 2], k]
            tri_lo[t, k] = min(a, min(b, c))
            tri_hi[t, k] = max(a, max(b, c))
    nodes = left.shape[0]
    lo = np.empty((nodes, 3))
    hi = np.empty((nodes, 3))
    for node in range(nodes - 1, -1, -1):                 # children before parents
        if left[node] < 0:
            for k in range(3):
                lo[node, k] = np.inf
                hi[node, k] = -np.inf
            for s in range(start[node], start[node] + count[node]):
                t = order[s]
                for k in range(3):
                    lo[node, k] = min(lo[node, k], tri_lo[t, k])
                    hi[node, k] = max(hi[node, k], tri_hi[t, k])
        else:
            a, b = left[node], right[node]
            for k in range(3):
                lo[node, k] = min(lo[a, k], lo[b, k])
                hi[node, k] = max(hi[a, k], hi[b, k])
    return world, lo, hi, tri_lo, tri_hi

@numba.njit(cache=True)
def traverse(left_a, right_a, start_a, count_a, order_a, lo_a, hi_a, tlo_a, thi_a,
             left_b, right_b, start_b, count_b, order_b, lo_b, hi_b, tlo_b, thi_b,
             first_only):
    """Mirrors :func:`refsim.collision.bvh._pairs_python`.

    The triangle-box pairs (i, j) whose world boxes overlap (seed test 2),
    by simultaneous descent of the refit trees; at most one with ``first_only``."""
    out = np.empty((64, 2), dtype=np.int64)
    found = 0
    stack = np.empty((64, 2), dtype=np.int64)
    stack[0, 0] = 0
    stack[0, 1] = 0
    top = 1
    while top > 0:
        top -= 1
        a = stack[top, 0]
        b = stack[top, 1]
        if (lo_a[a, 0] > hi_b[b, 0] or lo_b[b, 0] > hi_a[a, 0]
                or lo_a[a, 1] > hi_b[b, 1] or lo_b[b, 1] > hi_a[a, 1]
                or lo_a[a, 2] > hi_b[b, 2] or lo_b[b, 2] > hi_a[a, 2]):
            continue                                        # node boxes apart
        leaf_a = left_a[a] < 0
        leaf_b = left_b[b] < 0
        if leaf_a and leaf_b:
            for s in range(start_a[a], start_a[a] + count_a[a]):
                i = order_a[s]
                for r in range(start_b[b], start_b[b] + count_b[b]):
                    j = order_b[r]
                    if (tlo_a[i, 0] > thi_b[j, 0] or tlo_b[j, 0] > thi_a[i, 0]
                            or tlo_a[i, 1] > thi_b[j, 1] or tlo_b[j, 1] > thi_a[i, 1]
                            or tlo_a[i, 2] > thi_b[j, 2] or tlo_b[j, 2] > thi_a[i, 2]):
                        continue                            # triangle boxes apart
                    if found == out.shape[0]:
                        out = grow(out, found)
                    out[found, 0] = i
                    out[found, 1] = j
                    found += 1
                    if first_only:
                        return out[:found]
            continue
        if top + 2 > stack.shape[0]:
            stack = grow(stack, top)
        size_a = (hi_a[a, 0] - lo_a[a, 0]) + (hi_a[a, 1] - lo_a[a, 1]) \
            + (hi_a[a, 2] - lo_a[a, 2])
        size_b = (hi_b[b, 0] - lo_b[b, 0]) + (hi_b[b, 1] - lo_b[b, 1]) \
            + (hi_b[b, 2] - lo_b[b, 2])
        if leaf_b or (not leaf_a and size_a >= size_b):     # open the bigger node
            stack[top, 0], stack[top, 1] = right_a[a], b
            stack[top + 1, 0], stack[top + 1, 1] = left_a[a], b
        else:
            stack[top, 0], stack[top, 1] = a, right_b[b]
            stack[top + 1, 0], stack[top + 1, 1] = a, left_b[b]
        top += 2
    return out[:found]

@numba.njit("(intp[:, ::1], intp)", cache=True)
def grow(rows, used):
    """``rows`` (k, 2) copied into an array twice as long (amortized O(1) appends)."""
    bigger = np.empty((2 * rows.shape[0], 2), dtype=np.int64)
    for i in range(used):                     # element by element: an array assignment
        bigger[i, 0] = rows[i, 0]             # compiles numba's shape-error text
        bigger[i, 1] = rows[i, 1]
    return bigger


# -- the exact level in the first body's frame (bvh_exact) ---------------------------
#
# The same steps as bvh_exact's readable traversal. The separating-axis node
# test, the preparation of a leaf (once for body a, once for body b) and the
# loops over a leaf pair are written out in the main loop: a helper taking a
# dozen arrays made the whole query measurably slower on the separated
# benchmarks (docs/decisions/triangle-filter-arguments.md).
#
# A mesh's constant arrays come packed in two (bvh_exact.pack_frame_tree, built
# once per mesh): numba unboxes every array argument at every call, and a
# query that passed each array on its own spent about a third of its fixed
# cost doing so (docs/decisions/query-fixed-cost.md).
#
# Caveat: the boolean mode calls the exact stage of _numba_exact, and numba's
# cache keys a kernel by its own source file only: after an edit to
# _numba_exact.py alone, clear __pycache__ (or touch this file) so that the
# cached exact_query is compiled again.

#: Query modes of ``exact_query``.
ALL_HITS, FIRST_HIT, CANDIDATES = 0, 1, 2

#: Answers of ``exact_collide``: no pair intersects, one does, some pairs are
#: left to the readable exact kernel, pose a / pose b is not valid.
APART, HIT, UNDECIDED, BAD_POSE_A, BAD_POSE_B = 0, 1, 2, 3, 4

#: Columns of a hierarchy's ``links`` (bvh_exact.FrameTree); its ``boxes``
#: hold a node's centre in columns 0-2, half-extents in 3-5 and axes in 6-14.
LEFT, RIGHT, START, COUNT = 0, 1, 2, 3

#: Leading entries of the packed arrays: (reach, axes deviation) of the
#: floats, (vertices, faces, nodes) of the integers.
FLOAT_HEADER, INT_HEADER = 2, 3


@numba.njit(cache=True, inline="always")
def carve(block, at, rows, columns):
    """``(view, end)``: ``block[at:end]`` as a (rows, columns) array, ``end =
    at + rows columns``."""
    end = at + rows * columns
    return block[at:end].reshape((rows, columns)), end

@numba.njit(cache=True)
def unpack(floats, ints):
    """The arrays of :func:`refsim.collision.bvh_exact.pack_frame_tree` as
    views: ``(vertices, faces, links, order, boxes, reach, axes_deviation)``."""
    n_vertices, n_faces, n_nodes = ints[0], ints[1], ints[2]
    faces, at = carve(ints, INT_HEADER, n_faces, 3)
    links, at = carve(ints, at, n_nodes, 4)
    order = ints[at:at + n_faces]
    vertices, at = carve(floats, FLOAT_HEADER, n_vertices, 3)
    boxes, _ = carve(floats, at, n_nodes, 15)
    return vertices, faces, links, order, boxes, floats[0], floats[1]

@numba.njit(cache=True)
def pose_deviation(rotation, translation, tol):
    """max |R^T R - I| of a valid pose, or -1.0 if the pose is not valid (a
    non-finite value, an entry of R above 1 + tol, or R^T R further than tol
    from I: the conditions of refsim.types.as_pose), or of the wrong shape."""
    if rotation.shape[0] != 3 or rotation.shape[1] != 3 or translation.shape[0] != 3:
        return -1.0
    for k in range(3):
        if not abs(translation[k]) < np.inf:
            return -1.0
        for j in range(3):
            if not abs(rotation[k, j]) <= 1.0 + tol:
                return -1.0
    deviation = 0.0
    for i in range(3):
        for j in range(3):
            gram = (rotation[0, i] * rotation[0, j] + rotation[1, i] * rotation[1, j]
                    + rotation[2, i] * rotation[2, j])
            deviation = max(deviation, abs(gram - (1.0 if i == j else 0.0)))
    return deviation if deviation <= tol else -1.0


@numba.njit(cache=True, inline="always")
def place(boxes_b, M, u, node, placed):
    """Node b's box in body a's frame, kept for the rest of the query:
    ``placed[node]`` = (M cb + u, then M Ab row by row), as
    bvh_exact.place computes it (the part of a node pair's frame that
    depends on node b alone)."""
    for i in range(3):
        placed[node, i] = (M[i, 0] * boxes_b[node, 0] + M[i, 1] * boxes_b[node, 1]
                           + M[i, 2] * boxes_b[node, 2] + u[i])
        for j in range(3):
            placed[node, 3 + 3 * i + j] = (M[i, 0] * boxes_b[node, 6 + j]
                                           + M[i, 1] * boxes_b[node, 9 + j]
                                           + M[i, 2] * boxes_b[node, 12 + j])

@numba.njit(cache=True, inline="always")
def squared_distance(x, i, y, j):
    """|x[i, :3] - y[j, :3]|^2."""
    return ((x[i, 0] - y[j, 0]) ** 2 + (x[i, 1] - y[j, 1]) ** 2
            + (x[i, 2] - y[j, 2]) ** 2)

@numba.njit(cache=True, inline="always")
def frame_row(A, i, d, P):
    """``T[i]`` and row i of ``R`` (bvh_exact.node_pair_frame): ``T = A^T d``,
    ``R = A^T P`` for A and P given by rows."""
    t = A[0][i] * d[0] + A[1][i] * d[1] + A[2][i] * d[2]
    r = (A[0][i] * P[0][0] + A[1][i] * P[1][0] + A[2][i] * P[2][0],
         A[0][i] * P[0][1] + A[1][i] * P[1][1] + A[2][i] * P[2][1],
         A[0][i] * P[0][2] + A[1][i] * P[1][2] + A[2][i] * P[2][2])
    return t, r

@numba.njit(cache=True, inline="always")
def node_boxes_apart(c, h, A, p, P, g, margin):
    """:func:`refsim.collision.bvh_exact.boxes_apart` of two node boxes, with
    their frame (:func:`refsim.collision.bvh_exact.node_pair_frame`), on
    tuples: node a's box has centre c, half-extents h and axes the columns
    of A (given by rows); node b's, in a's body frame, centre p = M cb + u,
    axes the columns of P = M Ab and half-extents g. The same formulas in
    the same order; each row of R is computed when its face normal of a is
    tested, and the test stops at the first separating axis. Tuples, not
    arrays: values in registers, nothing reference-counted
    (docs/decisions/triangle-filter-arguments.md)."""
    d = (p[0] - c[0], p[1] - c[1], p[2] - c[2])
    t0, r0 = frame_row(A, 0, d, P)                          # a's face normals
    q0 = (abs(r0[0]), abs(r0[1]), abs(r0[2]))
    if abs(t0) > h[0] + g[0] * q0[0] + g[1] * q0[1] + g[2] * q0[2] + margin:
        return True
    t1, r1 = frame_row(A, 1, d, P)
    q1 = (abs(r1[0]), abs(r1[1]), abs(r1[2]))
    if abs(t1) > h[1] + g[0] * q1[0] + g[1] * q1[1] + g[2] * q1[2] + margin:
        return True
    t2, r2 = frame_row(A, 2, d, P)
    q2 = (abs(r2[0]), abs(r2[1]), abs(r2[2]))
    if abs(t2) > h[2] + g[0] * q2[0] + g[1] * q2[1] + g[2] * q2[2] + margin:
        return True
    # b's face normals (M Ab)_j: projection T . R[:, j], radius h . |R[:, j]| + g[j]
    if abs(t0 * r0[0] + t1 * r1[0] + t2 * r2[0]) > (h[0] * q0[0] + h[1] * q1[0]
                                                    + h[2] * q2[0] + g[0]) + margin:
        return True
    if abs(t0 * r0[1] + t1 * r1[1] + t2 * r2[1]) > (h[0] * q0[1] + h[1] * q1[1]
                                                    + h[2] * q2[1] + g[1]) + margin:
        return True
    if abs(t0 * r0[2] + t1 * r1[2] + t2 * r2[2]) > (h[0] * q0[2] + h[1] * q1[2]
                                                    + h[2] * q2[2] + g[2]) + margin:
        return True
    # the nine edge-edge axes e_i x (M Ab)_j, i by i: (i1, i2) = (i+1, i+2) mod 3
    return (edge_axes_apart(t2, r1, t1, r2, h[1], q2, h[2], q1, q0, g, margin)      # i = 0
            or edge_axes_apart(t0, r2, t2, r0, h[2], q0, h[0], q2, q1, g, margin)   # i = 1
            or edge_axes_apart(t1, r0, t0, r1, h[0], q1, h[1], q0, q2, g, margin))  # i = 2

@numba.njit(cache=True, inline="always")
def edge_axes_apart(t_i2, r_i1, t_i1, r_i2, h_i1, q_i2, h_i2, q_i1, q_i, g, margin):
    """The three edge-edge axes of one i in :func:`refsim.collision.bvh_exact.boxes_apart`,
    j = 0, 1, 2 written out (a loop over tuple indices computed mod 3 was
    about twice as slow): projection ``T[i2] R[i1, j] - T[i1] R[i2, j]``,
    radius ``h[i1] |R[i2, j]| + h[i2] |R[i1, j]| + g[j1] |R[i, j2]| + g[j2] |R[i, j1]|``."""
    if abs(t_i2 * r_i1[0] - t_i1 * r_i2[0]) > (h_i1 * q_i2[0] + h_i2 * q_i1[0]
                                               + g[1] * q_i[2] + g[2] * q_i[1]) + margin:
        return True
    if abs(t_i2 * r_i1[1] - t_i1 * r_i2[1]) > (h_i1 * q_i2[1] + h_i2 * q_i1[1]
                                               + g[2] * q_i[0] + g[0] * q_i[2]) + margin:
        return True
    return abs(t_i2 * r_i1[2] - t_i1 * r_i2[2]) > (h_i1 * q_i2[2] + h_i2 * q_i1[2]
                                                   + g[0] * q_i[1] + g[1] * q_i[0]) + margin

@numba.njit(cache=True)
def exact_query(floats_a, ints_a, rotation_a, translation_a,
                floats_b, ints_b, rotation_b, translation_b,
                mode, tol, margin_rounding, margin_per_deviation):
    """Mirrors :func:`refsim.collision.bvh_exact.descend` with the filter of :func:`certified`.

    Returns ``(status, found, uncertain)``. Each mesh comes as the two arrays
    of :func:`refsim.collision.bvh_exact.pack_frame_tree`.

    status: 0, or 1 / 2 when pose a / b is not valid (nothing else computed).
    found: the pairs certified to intersect (ALL_HITS; at most one for
    FIRST_HIT), or every candidate pair (CANDIDATES: node boxes not separated,
    triangle boxes overlap; nothing certified).
    uncertain: the candidate pairs the float filter could not decide; with
    FIRST_HIT, only those the compiled exact stage could not decide either.

    FIRST_HIT answers each pair the filter leaves open with the compiled exact
    stage on the spot (:func:`refsim.collision._numba_exact.triangles_intersect_exact`),
    so it stops at the first intersecting pair whichever decides it, and
    descends into the nearer child first (centre to centre), where a hit is
    likelier. The other modes descend as the readable traversal does.
    """
    deviation_a = pose_deviation(rotation_a, translation_a, tol)
    deviation_b = pose_deviation(rotation_b, translation_b, tol)
    if deviation_a < 0.0 or deviation_b < 0.0:
        none = np.empty((0, 2), dtype=np.int64)
        return (1 if deviation_a < 0.0 else 2), none, none
    vertices_a, faces_a, links_a, order_a, boxes_a, reach_a, axes_deviation_a = \
        unpack(floats_a, ints_a)
    vertices_b, faces_b, links_b, order_b, boxes_b, reach_b, axes_deviation_b = \
        unpack(floats_b, ints_b)
    n_vertices_a, n_faces_a, n_nodes_a = vertices_a.shape[0], faces_a.shape[0], links_a.shape[0]
    n_vertices_b, n_faces_b, n_nodes_b = vertices_b.shape[0], faces_b.shape[0], links_b.shape[0]

    # Per-query state, filled lazily: node b's box in a's frame (``place``),
    # then leaf by leaf. Carved out of one float and one flag array: a
    # separate allocation for each costs more than a query far apart.
    scratch = np.empty(12 + 12 * n_nodes_b + 3 * (n_vertices_a + n_vertices_b)
                       + 6 * (n_faces_a + n_faces_b + n_nodes_a + n_nodes_b))
    M, at = carve(scratch, 0, 3, 3)
    u = scratch[9:12]
    placed_b, at = carve(scratch, 12, n_nodes_b, 12)
    world_a, at = carve(scratch, at, n_vertices_a, 3)
    world_b, at = carve(scratch, at, n_vertices_b, 3)
    tri_box_a, at = carve(scratch, at, n_faces_a, 6)
    tri_box_b, at = carve(scratch, at, n_faces_b, 6)
    leaf_box_a, at = carve(scratch, at, n_nodes_a, 6)
    leaf_box_b, at = carve(scratch, at, n_nodes_b, 6)
    flags = np.zeros(n_vertices_a + n_vertices_b + n_faces_a + n_faces_b + n_nodes_a
                     + 2 * n_nodes_b, dtype=np.bool_)
    vertex_done_a = flags[0:n_vertices_a]
    at = n_vertices_a
    vertex_done_b = flags[at:at + n_vertices_b]
    at += n_vertices_b
    tri_ok_a = flags[at:at + n_faces_a]
    at += n_faces_a
    tri_ok_b = flags[at:at + n_faces_b]
    at += n_faces_b
    leaf_done_a = flags[at:at + n_nodes_a]
    at += n_nodes_a
    leaf_done_b = flags[at:at + n_nodes_b]
    at += n_nodes_b
    placed_done_b = flags[at:at + n_nodes_b]

    # Body b in a's frame: x_a = M x_b + u, M = Ra^T Rb, u = Ra^T (tb - ta).
    for i in range(3):
        for j in range(3):
            M[i, j] = (rotation_a[0, i] * rotation_b[0, j] + rotation_a[1, i] * rotation_b[1, j]
                       + rotation_a[2, i] * rotation_b[2, j])
        u[i] = (rotation_a[0, i] * (translation_b[0] - translation_a[0])
                + rotation_a[1, i] * (translation_b[1] - translation_a[1])
                + rotation_a[2, i] * (translation_b[2] - translation_a[2]))
    scale = reach_a + reach_b
    for k in range(3):
        scale = max(scale, reach_a + reach_b + abs(translation_a[k]) + abs(translation_b[k]))
    deviation = max(max(deviation_a, deviation_b), max(axes_deviation_a, axes_deviation_b))
    margin = (margin_rounding + margin_per_deviation * deviation) * scale

    found = np.empty((64, 2), dtype=np.int64)
    n_found = 0
    uncertain = np.empty((64, 2), dtype=np.int64)
    n_uncertain = 0
    stack = np.empty((256, 2), dtype=np.int64)
    stack[0, 0] = 0
    stack[0, 1] = 0
    top = 1
    place(boxes_b, M, u, 0, placed_b)                   # every pushed node b is placed
    while top > 0:
        top -= 1
        a = stack[top, 0]
        b = stack[top, 1]

        # The separating-axis test of node a's box and node b's
        # (bvh_exact.node_pair_frame, bvh_exact.boxes_apart), on values
        # loaded once: a node's axes are the columns of the 3x3 matrix in
        # boxes[node, 6:15], row by row; placed_b[b] holds M cb + u and M Ab.
        if node_boxes_apart(
                (boxes_a[a, 0], boxes_a[a, 1], boxes_a[a, 2]),
                (boxes_a[a, 3], boxes_a[a, 4], boxes_a[a, 5]),
                ((boxes_a[a, 6], boxes_a[a, 7], boxes_a[a, 8]),
                 (boxes_a[a, 9], boxes_a[a, 10], boxes_a[a, 11]),
                 (boxes_a[a, 12], boxes_a[a, 13], boxes_a[a, 14])),
                (placed_b[b, 0], placed_b[b, 1], placed_b[b, 2]),
                ((placed_b[b, 3], placed_b[b, 4], placed_b[b, 5]),
                 (placed_b[b, 6], placed_b[b, 7], placed_b[b, 8]),
                 (placed_b[b, 9], placed_b[b, 10], placed_b[b, 11])),
                (boxes_b[b, 3], boxes_b[b, 4], boxes_b[b, 5]), margin):
            continue

        leaf_a = links_a[a, LEFT] < 0
        leaf_b = links_b[b, LEFT] < 0
        if leaf_a and leaf_b:
            # A pair of leaves: world boxes, then the triangle pairs.
            if not leaf_done_a[a]:
                # prepare leaf a: world vertices (each once per query, with
                # refsim's one transform arithmetic), triangle boxes (lo xyz,
                # hi xyz), step 1 of the filter per triangle, the leaf's box
                for k in range(3):
                    leaf_box_a[a, k] = np.inf
                    leaf_box_a[a, 3 + k] = -np.inf
                for s in range(links_a[a, START], links_a[a, START] + links_a[a, COUNT]):
                    f = order_a[s]
                    for c in range(3):
                        v = faces_a[f, c]
                        if not vertex_done_a[v]:
                            x, y, z = vertices_a[v, 0], vertices_a[v, 1], vertices_a[v, 2]
                            for k in range(3):
                                world_a[v, k] = ((rotation_a[k, 0] * x + rotation_a[k, 1] * y)
                                                + rotation_a[k, 2] * z) + translation_a[k]
                            vertex_done_a[v] = True
                    p, q, r = faces_a[f, 0], faces_a[f, 1], faces_a[f, 2]
                    for k in range(3):
                        lo = min(world_a[p, k], min(world_a[q, k], world_a[r, k]))
                        hi = max(world_a[p, k], max(world_a[q, k], world_a[r, k]))
                        tri_box_a[f, k] = lo
                        tri_box_a[f, 3 + k] = hi
                        leaf_box_a[a, k] = min(leaf_box_a[a, k], lo)
                        leaf_box_a[a, 3 + k] = max(leaf_box_a[a, 3 + k], hi)
                    tri_ok_a[f] = filter_applies(
                        ((world_a[p, 0], world_a[p, 1], world_a[p, 2]),
                         (world_a[q, 0], world_a[q, 1], world_a[q, 2]),
                         (world_a[r, 0], world_a[r, 1], world_a[r, 2])))
                leaf_done_a[a] = True
            if not leaf_done_b[b]:
                # prepare leaf b: world vertices (each once per query, with
                # refsim's one transform arithmetic), triangle boxes (lo xyz,
                # hi xyz), step 1 of the filter per triangle, the leaf's box
                for k in range(3):
                    leaf_box_b[b, k] = np.inf
                    leaf_box_b[b, 3 + k] = -np.inf
                for s in range(links_b[b, START], links_b[b, START] + links_b[b, COUNT]):
                    f = order_b[s]
                    for c in range(3):
                        v = faces_b[f, c]
                        if not vertex_done_b[v]:
                            x, y, z = vertices_b[v, 0], vertices_b[v, 1], vertices_b[v, 2]
                            for k in range(3):
                                world_b[v, k] = ((rotation_b[k, 0] * x + rotation_b[k, 1] * y)
                                                + rotation_b[k, 2] * z) + translation_b[k]
                            vertex_done_b[v] = True
                    p, q, r = faces_b[f, 0], faces_b[f, 1], faces_b[f, 2]
                    for k in range(3):
                        lo = min(world_b[p, k], min(world_b[q, k], world_b[r, k]))
                        hi = max(world_b[p, k], max(world_b[q, k], world_b[r, k]))
                        tri_box_b[f, k] = lo
                        tri_box_b[f, 3 + k] = hi
                        leaf_box_b[b, k] = min(leaf_box_b[b, k], lo)
                        leaf_box_b[b, 3 + k] = max(leaf_box_b[b, 3 + k], hi)
                    tri_ok_b[f] = filter_applies(
                        ((world_b[p, 0], world_b[p, 1], world_b[p, 2]),
                         (world_b[q, 0], world_b[q, 1], world_b[q, 2]),
                         (world_b[r, 0], world_b[r, 1], world_b[r, 2])))
                leaf_done_b[b] = True
            if (leaf_box_a[a, 0] > leaf_box_b[b, 3] or leaf_box_b[b, 0] > leaf_box_a[a, 3]
                    or leaf_box_a[a, 1] > leaf_box_b[b, 4] or leaf_box_b[b, 1] > leaf_box_a[a, 4]
                    or leaf_box_a[a, 2] > leaf_box_b[b, 5] or leaf_box_b[b, 2] > leaf_box_a[a, 5]):
                continue
            for s in range(links_a[a, START], links_a[a, START] + links_a[a, COUNT]):
                i = order_a[s]
                for r in range(links_b[b, START], links_b[b, START] + links_b[b, COUNT]):
                    j = order_b[r]
                    if (tri_box_a[i, 0] > tri_box_b[j, 3]
                            or tri_box_b[j, 0] > tri_box_a[i, 3]
                            or tri_box_a[i, 1] > tri_box_b[j, 4]
                            or tri_box_b[j, 1] > tri_box_a[i, 4]
                            or tri_box_a[i, 2] > tri_box_b[j, 5]
                            or tri_box_b[j, 2] > tri_box_a[i, 5]):
                        continue                            # triangle boxes apart
                    if mode == CANDIDATES:
                        answer, certain = True, True
                    else:
                        p0, p1, p2 = faces_a[i, 0], faces_a[i, 1], faces_a[i, 2]
                        q0, q1, q2 = faces_b[j, 0], faces_b[j, 1], faces_b[j, 2]
                        tri_a = ((world_a[p0, 0], world_a[p0, 1], world_a[p0, 2]),
                                 (world_a[p1, 0], world_a[p1, 1], world_a[p1, 2]),
                                 (world_a[p2, 0], world_a[p2, 1], world_a[p2, 2]))
                        tri_b = ((world_b[q0, 0], world_b[q0, 1], world_b[q0, 2]),
                                 (world_b[q1, 0], world_b[q1, 1], world_b[q1, 2]),
                                 (world_b[q2, 0], world_b[q2, 1], world_b[q2, 2]))
                        if tri_ok_a[i] and tri_ok_b[j]:
                            answer, certain = certify_filtered(tri_a, tri_b)
                        else:
                            answer, certain = False, False
                        if not certain and mode == FIRST_HIT:
                            answer, certain = triangles_intersect_exact(tri_a, tri_b)
                    if certain:
                        if answer:
                            if n_found == found.shape[0]:
                                found = grow(found, n_found)
                            found[n_found, 0] = i
                            found[n_found, 1] = j
                            n_found += 1
                            if mode == FIRST_HIT:
                                return 0, found[:n_found], uncertain[:n_uncertain]
                    else:
                        if n_uncertain == uncertain.shape[0]:
                            uncertain = grow(uncertain, n_uncertain)
                        uncertain[n_uncertain, 0] = i
                        uncertain[n_uncertain, 1] = j
                        n_uncertain += 1
            continue
        if top + 2 > stack.shape[0]:
            stack = grow(stack, top)
        if leaf_b or (not leaf_a and (boxes_a[a, 3] + boxes_a[a, 4] + boxes_a[a, 5]
                                      >= boxes_b[b, 3] + boxes_b[b, 4] + boxes_b[b, 5])):
            near, far = links_a[a, LEFT], links_a[a, RIGHT]     # open the bigger node
            if mode == FIRST_HIT and (squared_distance(boxes_a, far, placed_b, b)
                                      < squared_distance(boxes_a, near, placed_b, b)):
                near, far = far, near
            stack[top, 0] = far
            stack[top, 1] = b
            stack[top + 1, 0] = near
            stack[top + 1, 1] = b
        else:
            near, far = links_b[b, LEFT], links_b[b, RIGHT]
            if not placed_done_b[near]:                   # (the two children together)
                place(boxes_b, M, u, near, placed_b)
                place(boxes_b, M, u, far, placed_b)
                placed_done_b[near] = True
            if mode == FIRST_HIT and (squared_distance(boxes_a, a, placed_b, far)
                                      < squared_distance(boxes_a, a, placed_b, near)):
                near, far = far, near
            stack[top, 0] = a
            stack[top, 1] = far
            stack[top + 1, 0] = a
            stack[top + 1, 1] = near
        top += 2
    return 0, found[:n_found], uncertain[:n_uncertain]


#: The one signature ``exact_collide`` is compiled for: packed mesh arrays,
#: float64 C-contiguous poses. The caller compiles it (or loads it from
#: numba's cache) for this signature alone and then turns compiling off
#: (bvh_exact's ``_compiled``), so that numba refuses any other argument
#: types with a TypeError instead of compiling for them, and the caller need
#: not check a pose's layout before the call (bvh_exact.collide_compiled). It is
#: not compiled as this module is imported: importing the module must stay
#: cheap, so that whether numba's cache holds its kernels can be asked
#: without compiling them (refsim.kernels.Tier).
EXACT_COLLIDE_SIGNATURE = numba.int64(
    numba.float64[::1], numba.int64[::1], numba.float64[:, ::1], numba.float64[::1],
    numba.float64[::1], numba.int64[::1], numba.float64[:, ::1], numba.float64[::1],
    numba.float64, numba.float64, numba.float64)


@numba.njit(cache=True)
def exact_collide(floats_a, ints_a, rotation_a, translation_a,
                  floats_b, ints_b, rotation_b, translation_b,
                  tol, margin_rounding, margin_per_deviation):
    """Mirrors :func:`refsim.collision.bvh_exact.descend` as :func:`exact_query`
    does, in mode FIRST_HIT, answered as one code (APART, HIT, UNDECIDED,
    BAD_POSE_A, BAD_POSE_B): returning a number instead of two arrays
    spares the caller numba's boxing of the arrays."""
    # the mode as an int64, not the literal a global constant is typed as:
    # exact_query then reuses the machine code of its calls from Python
    # instead of compiling a second specialization for the literal
    status, found, uncertain = exact_query(
        floats_a, ints_a, rotation_a, translation_a, floats_b, ints_b, rotation_b,
        translation_b, np.int64(FIRST_HIT), tol, margin_rounding, margin_per_deviation)
    if status:
        return BAD_POSE_A if status == 1 else BAD_POSE_B
    if found.shape[0]:
        return HIT
    return UNDECIDED if uncertain.shape[0] else APART
