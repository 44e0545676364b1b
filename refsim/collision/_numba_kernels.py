"""Compiled kernels of body-body collision (seed S4), for the optional extra
``fast``: the certified triangle-pair filter (:mod:`refsim.collision.triangle_numba`)
and the hierarchy's refit and traversal (:mod:`refsim.collision.bvh`).

Line for line the same steps as the readable kernels, as plain loops over
arrays. The functions are defined at module level on purpose: numba's on-disk
cache (``cache=True``) keys a function by its source and its globals, and a
kernel built inside a factory function closes over other dispatchers, which
pickle differently in every process, so the cache never hit and every process
recompiled (6-10 s). At module level the cache hits and the compile is paid
once per machine (measured in :mod:`refsim.collision.measure_levels`).

Arithmetic: numba compiles without fast-math, so each operation is rounded
once, as in Python and in elementwise numpy; the tests compare the kernels
bit for bit with the readable ones.

This module imports numba at import time; import it only when the compiled
kernel is chosen.
"""

from __future__ import annotations

import numba
import numpy as np

from refsim.collision.predicates import (
    FILTER_MAX_ABS,
    FILTER_MIN_ABS,
    O2D_ERRBOUND_A,
    O3D_ERRBOUND_A,
)

# -- the certified triangle-pair filter (triangle_numba's steps 1-4) -------------------


@numba.njit(cache=True)
def o3d(a, b, c, d):
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
def in_range(t):
    for v in range(3):
        for k in range(3):
            m = abs(t[v, k])
            if m != 0.0 and not (FILTER_MIN_ABS <= m <= FILTER_MAX_ABS):
                return False
    return True

@numba.njit(cache=True)
def nondegenerate(t):
    p, q, r = t[0], t[1], t[2]
    for i, j in ((1, 2), (2, 0), (0, 1)):
        if o2d_certain(p[i], p[j], q[i], q[j], r[i], r[j]):
            return True
    return False

@numba.njit(cache=True)
def edges_vs_triangle(e, t, s, c):
    """(any certain hit, all three edges certainly miss)."""
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
def certify_pair(a, b):
    """(answer, certain) for one pair of (3, 3) triangles."""
    # step 1
    if not (in_range(a) and in_range(b) and nondegenerate(a) and nondegenerate(b)):
        return False, False
    # step 2
    sa = np.empty(3, dtype=np.int64)
    ca = np.empty(3, dtype=np.bool_)
    sb = np.empty(3, dtype=np.int64)
    cb = np.empty(3, dtype=np.bool_)
    for v in range(3):
        sa[v], ca[v] = o3d(b[0], b[1], b[2], a[v])
        sb[v], cb[v] = o3d(a[0], a[1], a[2], b[v])
    one_side_a = ca[0] and ca[1] and ca[2] and sa[0] == sa[1] and sa[1] == sa[2]
    one_side_b = cb[0] and cb[1] and cb[2] and sb[0] == sb[1] and sb[1] == sb[2]
    if one_side_a or one_side_b:
        return False, True
    # steps 3 and 4
    hit, miss_a = edges_vs_triangle(a, b, sa, ca)
    if hit:
        return True, True
    hit, miss_b = edges_vs_triangle(b, a, sb, cb)
    if hit:
        return True, True
    return False, miss_a and miss_b

@numba.njit(cache=True)
def certified(A, B):
    k = A.shape[0]
    answer = np.zeros(k, dtype=np.bool_)
    certain = np.zeros(k, dtype=np.bool_)
    for n in range(k):
        answer[n], certain[n] = certify_pair(A[n], B[n])
    return answer, certain

@numba.njit(cache=True)
def certified_indexed(world_a, faces_a, world_b, faces_b, pairs):
    """``certified`` for pairs of face indices into two meshes."""
    k = pairs.shape[0]
    answer = np.zeros(k, dtype=np.bool_)
    certain = np.zeros(k, dtype=np.bool_)
    ta = np.empty((3, 3))
    tb = np.empty((3, 3))
    for n in range(k):
        for v in range(3):
            for c in range(3):
                ta[v, c] = world_a[faces_a[pairs[n, 0], v], c]
                tb[v, c] = world_b[faces_b[pairs[n, 1], v], c]
        answer[n], certain[n] = certify_pair(ta, tb)
    return answer, certain


# -- the hierarchy: transform, triangle boxes, refit; traversal (bvh) ----------------


@numba.njit(cache=True)
def prepare(vertices, faces, rotation, translation, left, right, start, count, order):
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
def apart(lo1, hi1, i, lo2, hi2, j):
    for k in range(3):
        if lo1[i, k] > hi2[j, k] or lo2[j, k] > hi1[i, k]:
            return True
    return False

@numba.njit(cache=True)
def push(stack, top, a, b):
    if top == stack.shape[0]:
        bigger = np.empty((2 * top, 2), dtype=np.int64)
        bigger[:top] = stack[:top]
        stack = bigger
    stack[top, 0] = a
    stack[top, 1] = b
    return stack, top + 1

@numba.njit(cache=True)
def traverse(left_a, right_a, start_a, count_a, order_a, lo_a, hi_a, tlo_a, thi_a,
             world_a, faces_a,
             left_b, right_b, start_b, count_b, order_b, lo_b, hi_b, tlo_b, thi_b,
             world_b, faces_b, mode):
    """Returns (pairs, hit): the triangle-box pairs found (modes 0, 1), or
    the pairs the exact filter could not certify (mode 2), and whether
    mode 2 found a certified intersecting pair."""
    out = np.empty((64, 2), dtype=np.int64)
    found = 0
    stack = np.empty((64, 2), dtype=np.int64)
    stack, top = push(stack, 0, 0, 0)
    ta = np.empty((3, 3))
    tb = np.empty((3, 3))
    while top > 0:
        top -= 1
        a = stack[top, 0]
        b = stack[top, 1]
        if apart(lo_a, hi_a, a, lo_b, hi_b, b):
            continue
        leaf_a = left_a[a] < 0
        leaf_b = left_b[b] < 0
        if leaf_a and leaf_b:
            for s in range(start_a[a], start_a[a] + count_a[a]):
                i = order_a[s]
                for r in range(start_b[b], start_b[b] + count_b[b]):
                    j = order_b[r]
                    if apart(tlo_a, thi_a, i, tlo_b, thi_b, j):
                        continue
                    if mode == 2:
                        for v in range(3):
                            for k in range(3):
                                ta[v, k] = world_a[faces_a[i, v], k]
                                tb[v, k] = world_b[faces_b[j, v], k]
                        answer, certain = certify_pair(ta, tb)
                        if certain:
                            if answer:
                                return out[:found], True
                            continue
                    if found == out.shape[0]:
                        grown = np.empty((2 * found, 2), dtype=np.int64)
                        grown[:found] = out
                        out = grown
                    out[found, 0] = i
                    out[found, 1] = j
                    found += 1
                    if mode == 1:
                        return out[:found], False
            continue
        size_a = (hi_a[a, 0] - lo_a[a, 0]) + (hi_a[a, 1] - lo_a[a, 1]) \
            + (hi_a[a, 2] - lo_a[a, 2])
        size_b = (hi_b[b, 0] - lo_b[b, 0]) + (hi_b[b, 1] - lo_b[b, 1]) \
            + (hi_b[b, 2] - lo_b[b, 2])
        if leaf_b or (not leaf_a and size_a >= size_b):     # open the bigger node
            stack, top = push(stack, top, right_a[a], b)
            stack, top = push(stack, top, left_a[a], b)
        else:
            stack, top = push(stack, top, a, right_b[b])
            stack, top = push(stack, top, a, left_b[b])
    return out[:found], False
