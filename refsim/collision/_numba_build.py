"""Compiled twin of the hierarchies' build (seed S4's "more levels of
hierarchy"): the triangle tree of :func:`refsim.collision.bvh.build_tree`
under either split rule, and the oriented node boxes of
:func:`refsim.collision.bvh_exact.build_frame_tree`, as plain loops.

What: the same arrays, bit for bit, as the readable build. Every float the
readable build computes is computed here by the same operations in the same
order, including the order numpy sums in, which the readable code leaves
implicit:

- ``x.mean(axis=0)`` of an (n, 3) array and ``x.mean(axis=1)`` of a
  (k, 3, 3) one add the rows one after another, starting from 0.0, and then
  divide by the count;
- ``np.sum`` of a contiguous 1-d array is numpy's pairwise summation
  (``pairwise_sum`` in numpy's ``loops_utils.h.src``): fewer than 8 terms
  one after another; up to 128 in eight interleaved partial sums added as
  ``((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))`` and then the rest;
  more, split in two at a multiple of 8 below the half and the halves'
  sums added; the reduction then adds that to 0.0;
- ``x.max(axis=0)`` and ``x.min(axis=0)`` of an (n, 3) array take the rows
  one after another, and of two equal values (0.0 and -0.0) keep the later
  (``np.maximum(a, b)`` returns ``b`` then). Only the sign of a zero
  depends on this, and only a node box's centre can carry it;
- ``np.lexsort((members, key))`` orders by key, then by triangle index;
  keys that compare equal (0.0 and -0.0 among them) are ties;
- ``np.ldexp`` is a product by a power of two, rounded once.

tests/collision/test_tree_build.py checks every array of both trees on the
bundled meshes and on generated ones; numba compiles without fast-math, so
each operation is rounded once and nothing is fused. No BLAS or LAPACK is
called, so the tree is the same on every machine, as the readable one.

How it is made cheaper than the readable build without changing a bit:
the six candidate halves of a node above SMALL_NODE triangles have their
covariances formed first and their eigenvectors found two at a time, each
matrix's entries in locals
(:func:`refsim.collision._numba_axes.eigenvectors_of_pair`: the processor
overlaps the two chains of dependent divisions and square roots); a
covariance's six sums take one pass (:mod:`refsim.collision._numba_axes`); a
node's own principal axes are those of the half its parent chose (the same
triangles in the same order), so each node's eigenproblem is solved once;
keys are ranked by buckets and insertion instead of a general sort
(:func:`rank`); a node box's vertex list is filtered from its parent's
instead of sorted (:func:`visit_nodes`); hot loops call no helper that
takes an array (such calls, even inlined, measured more than the loops'
work); a mesh's whole FrameTree and its packed arrays come from one call
(:func:`frame_tree_arrays`), not from numpy copies around several calls.
Measured against FCL: docs/decisions/tree-build.md.

Cost: the least-volume split forms, at each node of k > SMALL_NODE
triangles, the covariances of its six candidate halves (a few passes over
9k points) and solves six 3 x 3 eigenproblems; a smaller node measures
the same halves' points along its own axes, with one covariance and one
eigenproblem (its own) when its parent was small too: O(k) a node,
O(m log m) for the tree of m triangles (ranking is O(k) a node for keys
spread evenly, O(k log k) at worst); the node boxes add O(k) and one
eigenproblem a node. Each function here says which readable function it
mirrors.

This module imports numba at import time; import it only when the compiled
kernel is chosen.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from refsim.collision._numba_axes import (
    axes_scratch,
    covariance,
    extents,
    largest_of,
    project,
    symmetric_eigenvectors,
    unit_exponent,
)

#: :func:`refsim.kernels.sources_digest` of the refsim modules this one imports:
#: an edit there must change this line, so that numba renews its cache of
#: this module (tests/test_kernels.py checks it).
SOURCES_DIGEST = "018ac9600c10128b"

#: Split rules of :func:`build_tree` (the readable split functions they mirror:
#: ``bvh.least_area_split``, ``bvh_exact.least_volume_split``).
LEAST_AREA, LEAST_VOLUME = 0, 1

#: bvh_exact.VOLUME_TIE: volumes within this fraction of the least tie, and
#: the area breaks the tie (:func:`chosen_axis`).
VOLUME_TIE = 0.1

#: bvh_exact.SMALL_NODE: nodes of at most this many triangles measure their
#: candidate halves in the node's frame (:func:`least_volume_split`).
SMALL_NODE = 64

#: Runs of at most this many keys are ranked by insertion sort.
INSERTION_RUN = 24


# Working arrays, allocated once a build. Coordinates are kept one array per
# axis, so that the loops over points read consecutive floats.


@numba.njit(cache=True)
def split_scratch(m):
    """What a split works in, for m triangles: ``(x, y, z)`` (9m,) sets of
    points (the six candidate halves' at once), ``keys`` (3, m) the
    triangles' centroids along three axes and ``ranked`` (3, m) their ranks
    along each, ``bucket`` (m,) and ``counts``
    (m + 1,) int64, and for the six candidate halves (the first and second
    of each axis, and the node itself last) their covariance matrices
    ``a`` and principal ``axes`` (7, 3, 3)."""
    m = max(m, 1)
    return (np.empty(9 * m), np.empty(9 * m), np.empty(9 * m), np.empty((3, m)),
            np.empty((3, m), dtype=np.int64), np.empty(m, dtype=np.int64),
            np.empty(m + 1, dtype=np.int64), np.empty((7, 3, 3)), np.empty((7, 3, 3)))




# -- ranking ------------------------------------------------------------------------


@numba.njit("(float64[::1], intp[::1], intp[::1], intp, intp)", cache=True)
def insertion_sort(key, members, ranked, lo, hi):
    """``ranked[lo:hi]`` put in ``np.lexsort((members, key))`` order (keys
    without NaN): by key, ties by member."""
    for r in range(lo + 1, hi):
        p = ranked[r]
        kp, mp = key[p], members[p]
        s = r
        while s > lo:
            q = ranked[s - 1]
            if not (kp < key[q] or (kp == key[q] and mp < members[q])):
                break
            ranked[s] = q
            s -= 1
        ranked[s] = p


@numba.njit("(float64[::1], intp[::1], intp, intp)", cache=True)
def ranks_before(key, members, p, q):
    """Whether position p comes before q in ``np.lexsort((members, key))``
    order: by key, a NaN after every number, ties (equal keys, -0.0 and 0.0
    among them, or both NaN) by member."""
    kp, kq = key[p], key[q]
    if kp == kp and kq == kq:
        return kp < kq or (kp == kq and members[p] < members[q])
    if kp != kp and kq != kq:
        return members[p] < members[q]
    return kp == kp                           # a number before a NaN


@numba.njit("(float64[::1], intp[::1], intp[::1], intp, intp)", cache=True)
def merge_sort(key, members, ranked, lo, hi):
    """``ranked[lo:hi]`` put in ``np.lexsort((members, key))`` order
    (:func:`ranks_before`) by a bottom-up merge sort: O(k log k) for the runs
    the buckets of :func:`rank` cannot split. The order is unique (members
    differ), so it is numpy's whatever the sort. Written out rather than
    numpy's argsort, whose compiled sorts cost seconds of every empty
    cache's compile."""
    k = hi - lo
    source, target = ranked[lo:hi], np.empty(k, dtype=np.intp)
    in_ranked = True                          # source is ranked[lo:hi] itself
    width = 1
    while width < k:
        for first in range(0, k, 2 * width):
            mid, end = min(first + width, k), min(first + 2 * width, k)
            i, j = first, mid
            for out in range(first, end):
                if j >= end or (i < mid and not ranks_before(key, members, source[j],
                                                             source[i])):
                    target[out] = source[i]
                    i += 1
                else:
                    target[out] = source[j]
                    j += 1
        source, target = target, source
        in_ranked = not in_ranked
        width *= 2
    if not in_ranked:
        for i in range(k):
            ranked[lo + i] = source[i]


@numba.njit(cache=True)
def rank(key, members, k, ranked, bucket, counts):
    """Positions ``0..k-1`` into ``ranked[:k]`` in the order of
    ``np.lexsort((members[:k], key[:k]))``: by key, ties by member.

    The order is unique (members differ), so any sort that compares the same
    pairs gives it: the keys are dealt into k buckets by ``(key - lo) *
    (k / (hi - lo))`` rounded down, which never decreases as the key grows
    (each operation is monotone) and puts equal keys together, and each
    bucket is then sorted by comparisons. Keys with a NaN, or too close for
    the buckets, go to :func:`merge_sort`. ``bucket`` (k,) and
    ``counts`` (k + 1,) are scratch."""
    for i in range(k):
        ranked[i] = i
    if k <= INSERTION_RUN:
        for i in range(k):
            if key[i] != key[i]:
                merge_sort(key, members, ranked, 0, k)
                return
        insertion_sort(key, members, ranked, 0, k)
        return
    lo, hi = np.inf, -np.inf
    for i in range(k):
        if key[i] != key[i]:
            merge_sort(key, members, ranked, 0, k)
            return
        lo, hi = min(lo, key[i]), max(hi, key[i])
    scale = k / (hi - lo) if hi > lo else np.inf
    if not scale < np.inf:
        merge_sort(key, members, ranked, 0, k)
        return
    counts[:k + 1] = 0
    for i in range(k):
        b = min(int((key[i] - lo) * scale), k - 1)
        bucket[i] = b
        counts[b + 1] += 1
    for b in range(k):
        counts[b + 1] += counts[b]
    for i in range(k):
        ranked[counts[bucket[i]]] = i
        counts[bucket[i]] += 1
    first = 0                                   # counts[b]: now the end of bucket b
    for b in range(k):
        end = counts[b]
        if end - first > INSERTION_RUN:
            merge_sort(key, members, ranked, first, end)
        elif end - first > 1:
            insertion_sort(key, members, ranked, first, end)
        first = end


# -- the split rules ----------------------------------------------------------------


@numba.njit(cache=True)
def least_axis(measures):
    """The axis (0, 1, 2) of least ``measures``, as both readable splits
    choose it: ``if measure < best`` from inf, so ties keep the lower axis."""
    best, chosen = np.inf, 0
    for axis in range(3):
        if measures[axis] < best:
            best, chosen = measures[axis], axis
    return chosen


@numba.njit("(float64[::1], float64[::1], float64[::1], intp[::1], intp[::1], intp, intp,"
            " float64[::1], float64[::1], float64[::1])", cache=True)
def gather(tx, ty, tz, members, ranked, lo, hi, x, y, z):
    """The vertices of triangles ``members[ranked[lo:hi]]`` into x, y, z,
    three a triangle (``triangles[...].reshape(-1, 3)``): ``(their number,
    their largest magnitude)``."""
    n = 0
    largest = 0.0
    for r in range(lo, hi):
        t = 3 * members[ranked[r]]
        for v in range(t, t + 3):
            x[n], y[n], z[n] = tx[v], ty[v], tz[v]
            largest = largest_of(largest, tx[v], ty[v], tz[v])
            n += 1
    return n, largest


#: Where :func:`split_scratch` keeps the node's own principal axes.
NODE = 6


@numba.njit(cache=True)
def least_volume_split(tx, ty, tz, members, k, mid, known, work, axes_work):
    """Mirrors: bvh_exact.least_volume_split, of ``members[:k]``: returns
    ``(axis, children_known)``: the chosen axis, whose order (positions in
    members) is ``ranked[axis]``, and whether the principal axes of its
    halves were found (``axes[2 axis]`` and ``axes[2 axis + 1]``: a node of
    more than SMALL_NODE triangles, whose halves are measured each in its
    own frame; a smaller node measures them in the node's frame,
    ``axes[NODE]``).

    The node's own principal axes are those of the half its parent chose
    (the same triangles in the same order): given in ``axes[NODE]`` when
    ``known``, else computed. Above SMALL_NODE, the six halves'
    covariances are formed first and their eigenvectors found together
    (:func:`symmetric_eigenvectors`); then the halves' volumes and areas
    are compared (:func:`chosen_axis`)."""
    x, y, z, keys, ranked, bucket, counts, a, axes = work
    if not known:
        for i in range(k):
            ranked[0, i] = i
        n, largest = gather(tx, ty, tz, members, ranked[0], 0, k, x, y, z)
        covariance(x, y, z, n, largest, a[NODE], axes_work)
        symmetric_eigenvectors(a[NODE:], axes[NODE:], 1)
    node = axes[NODE]
    a00, a01, a02 = node[0, 0], node[0, 1], node[0, 2]
    a10, a11, a12 = node[1, 0], node[1, 1], node[1, 2]
    a20, a21, a22 = node[2, 0], node[2, 1], node[2, 2]
    for r in range(k):
        t = 3 * members[r]                    # mean(axis=1): from 0.0, then / 3
        c0 = (((0.0 + tx[t]) + tx[t + 1]) + tx[t + 2]) / 3.0
        c1 = (((0.0 + ty[t]) + ty[t + 1]) + ty[t + 2]) / 3.0
        c2 = (((0.0 + tz[t]) + tz[t + 1]) + tz[t + 2]) / 3.0
        keys[0, r] = project(c0, c1, c2, a00, a10, a20)
        keys[1, r] = project(c0, c1, c2, a01, a11, a21)
        keys[2, r] = project(c0, c1, c2, a02, a12, a22)
    own_frames = k > SMALL_NODE
    for axis in range(3):                     # each half's points at 3 lo of its axis's third
        rank(keys[axis], members, k, ranked[axis], bucket, counts)
        for half, (lo, hi) in enumerate(((0, mid), (mid, k))):
            at = 3 * (axis * k + lo)
            n, largest = gather(tx, ty, tz, members, ranked[axis], lo, hi, x[at:], y[at:],
                                z[at:])
            if own_frames:
                covariance(x[at:], y[at:], z[at:], n, largest, a[2 * axis + half], axes_work)
    if own_frames:
        symmetric_eigenvectors(a, axes, 6)
    v0 = v1 = v2 = s0 = s1 = s2 = 0.0
    for axis in range(3):
        volume = area = 0.0
        for half, (lo, hi) in enumerate(((0, mid), (mid, k))):
            at, n = 3 * (axis * k + lo), 3 * (hi - lo)
            frame = axes[2 * axis + half] if own_frames else node
            low, high = extents(x[at:], y[at:], z[at:], n, frame)
            d0, d1, d2 = high[0] - low[0], high[1] - low[1], high[2] - low[2]
            part, face = (d0 * d1) * d2, (d0 * d1 + d1 * d2) + d2 * d0
            volume, area = (part, face) if half == 0 else (volume + part, area + face)
        if axis == 0:
            v0, s0 = volume, area
        elif axis == 1:
            v1, s1 = volume, area
        else:
            v2, s2 = volume, area
    return chosen_axis(v0, v1, v2, s0, s1, s2), own_frames


@numba.njit(cache=True)
def chosen_axis(v0, v1, v2, s0, s1, s2):
    """Mirrors the choice of bvh_exact.least_volume_split among three axes
    of total volumes v and areas s: the least area among the volumes within
    VOLUME_TIE of the least volume (``min``: the first least), area ties
    keeping the lower axis."""
    least = v0
    if v1 < least:
        least = v1
    if v2 < least:
        least = v2
    bound = least * (1.0 + VOLUME_TIE)
    best, best_area = -1, 0.0
    for axis, volume, area in ((0, v0, s0), (1, v1, s1), (2, v2, s2)):
        if volume <= bound and (best < 0 or area < best_area):
            best, best_area = axis, area
    return best


@numba.njit("(float64[:, ::1], float64[:, ::1], intp[::1], intp, intp)", cache=True)
def surface_area(tri_lo, tri_hi, ranked, lo, hi):
    """Mirrors: bvh._surface_area, of the boxes ``ranked[lo:hi]`` (columns
    of ``tri_lo``, ``tri_hi`` (3, k))."""
    top0 = top1 = top2 = -np.inf
    bottom0 = bottom1 = bottom2 = np.inf
    for r in range(lo, hi):
        t = ranked[r]
        top0, top1, top2 = max(top0, tri_hi[0, t]), max(top1, tri_hi[1, t]), \
            max(top2, tri_hi[2, t])
        bottom0, bottom1, bottom2 = min(bottom0, tri_lo[0, t]), min(bottom1, tri_lo[1, t]), \
            min(bottom2, tri_lo[2, t])
    d0, d1, d2 = top0 - bottom0, top1 - bottom1, top2 - bottom2
    return (d0 * d1 + d1 * d2) + d2 * d0


@numba.njit(cache=True)
def least_area_split(tx, ty, tz, members, k, mid, work):
    """Mirrors: bvh.least_area_split, of ``members[:k]``: returns the chosen
    axis; its order (positions in members) is ``ranked[axis]``."""
    x, y, _, keys, ranked, bucket, counts, _, _ = work
    tri_lo = x[:3 * k].reshape((3, k))       # scratch: (3, k) each
    tri_hi = y[:3 * k].reshape((3, k))
    for r in range(k):
        t = 3 * members[r]
        for j, c in enumerate((tx, ty, tz)):
            x0, x1, x2 = c[t], c[t + 1], c[t + 2]
            keys[j, r] = (((0.0 + x0) + x1) + x2) / 3.0
            tri_lo[j, r] = min(min(x0, x1), x2)
            tri_hi[j, r] = max(max(x0, x1), x2)
    areas = np.empty(3)
    for axis in range(3):
        rank(keys[axis], members, k, ranked[axis], bucket, counts)
        areas[axis] = (surface_area(tri_lo, tri_hi, ranked[axis], 0, mid)
                       + surface_area(tri_lo, tri_hi, ranked[axis], mid, k))
    return least_axis(areas)


# -- the build ----------------------------------------------------------------------


@numba.njit("(float64[:, ::1], float64[:, ::1])", cache=True)
def copy3x3(src, dst):
    """``dst[:] = src`` for two (3, 3) arrays, written out: numba's array
    assignment checks the shapes with an error message whose text
    formatting costs seconds of every empty cache's compile."""
    for i in range(3):
        for j in range(3):
            dst[i, j] = src[i, j]


@numba.njit(cache=True)
def build_tree(tx, ty, tz, leaf_size, rule):
    """Mirrors: bvh.build_tree, with its split ``bvh.least_area_split``
    (``rule`` LEAST_AREA) or ``bvh_exact.least_volume_split`` (LEAST_VOLUME).

    tx, ty, tz : (3m,) the coordinates of the faces' vertices as build_tree
        scales them (times ``2**-unit_exponent(vertices)``), three a face.

    Returns ``(left, right, start, count, order)``, int64 arrays as
    :class:`refsim.collision.bvh.TriangleTree` holds them."""
    m = len(tx) // 3
    capacity = max(2 * m, 1)
    left = np.full(capacity, -1, dtype=np.int64)
    right = np.full(capacity, -1, dtype=np.int64)
    start = np.zeros(capacity, dtype=np.int64)
    count = np.zeros(capacity, dtype=np.int64)
    order = np.arange(m, dtype=np.int64)
    members = np.empty(max(m, 1), dtype=np.int64)
    work, axes_work = split_scratch(m), axes_scratch(3 * max(m, 1))
    ranked, axes = work[4], work[8]
    count[0] = m
    nodes = 1
    # pending nodes, (node, lo, hi, axes known), with their principal axes if known
    stack = np.empty((capacity, 4), dtype=np.int64)
    stack_axes = np.empty((capacity, 3, 3))
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = 0, 0, m, 0
    top = 1
    while top > 0:
        top -= 1
        node, lo, hi, known = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
        if hi - lo <= leaf_size:
            continue
        k, mid = hi - lo, (hi - lo) // 2
        for r in range(k):                    # element by element: an array assignment
            members[r] = order[lo + r]        # compiles numba's shape-error text
        children_known = False                # each child's axes: its half's, if found
        if rule == LEAST_AREA:
            chosen = least_area_split(tx, ty, tz, members, k, mid, work)
        else:
            copy3x3(stack_axes[top], axes[NODE])
            chosen, children_known = least_volume_split(tx, ty, tz, members, k, mid, known,
                                                        work, axes_work)
        for r in range(k):
            order[lo + r] = members[ranked[chosen, r]]
        a, b = nodes, nodes + 1
        nodes += 2
        start[a], count[a] = lo, mid
        start[b], count[b] = lo + mid, k - mid
        left[node], right[node] = a, b
        known = 1 if children_known else 0
        stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = b, lo + mid, hi, known
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2], stack[top + 1, 3] = \
            a, lo, lo + mid, known
        if children_known:
            copy3x3(axes[2 * chosen + 1], stack_axes[top])
            copy3x3(axes[2 * chosen], stack_axes[top + 1])
        top += 2                              # a, then its subtree, before b
    return (left[:nodes].copy(), right[:nodes].copy(), start[:nodes].copy(),
            count[:nodes].copy(), order)


# -- the oriented node boxes --------------------------------------------------------


@numba.njit(cache=True)
def axes_deviation(axes):
    """Mirrors: bvh_exact.axes_deviation."""
    worst = 0.0
    for i in range(3):
        for j in range(3):
            gram = (axes[0, i] * axes[0, j] + axes[1, i] * axes[1, j]) + axes[2, i] * axes[2, j]
            off = abs(gram - (1.0 if i == j else 0.0))
            if off > worst or off != off:     # np.max: a NaN wins
                worst = off
    return worst


#: Nodes whose axes :func:`frame_boxes` finds together.
BOX_BATCH = 16


@numba.njit(cache=True)
def node_points(vx, vy, vz, vertices, n, x, y, z):
    """The mesh vertices whose indices are ``vertices[:n]`` into x, y, z;
    returns their largest magnitude."""
    largest = 0.0
    for r in range(n):
        x[r], y[r], z[r] = vx[vertices[r]], vy[vertices[r]], vz[vertices[r]]
        largest = largest_of(largest, x[r], y[r], z[r])
    return largest


@numba.njit(cache=True)
def oriented_box(x, y, z, n, axes, box):
    """Mirrors: bvh_exact.oriented_box, of the first n points along
    ``axes``; writes ``box`` (15,), a row of
    :class:`refsim.collision.bvh_exact.FrameTree`'s boxes."""
    lo, hi = extents(x, y, z, n, axes)
    mid0, mid1, mid2 = (lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2
    for i in range(3):
        box[i] = (axes[i, 0] * mid0 + axes[i, 1] * mid1) + axes[i, 2] * mid2
    a00, a01, a02 = axes[0, 0], axes[0, 1], axes[0, 2]
    a10, a11, a12 = axes[1, 0], axes[1, 1], axes[1, 2]
    a20, a21, a22 = axes[2, 0], axes[2, 1], axes[2, 2]
    c0, c1, c2 = box[0], box[1], box[2]
    h0 = h1 = h2 = 0.0
    for r in range(n):
        d0, d1, d2 = x[r] - c0, y[r] - c1, z[r] - c2
        p0 = abs(project(d0, d1, d2, a00, a10, a20))
        p1 = abs(project(d0, d1, d2, a01, a11, a21))
        p2 = abs(project(d0, d1, d2, a02, a12, a22))
        h0, h1, h2 = h0 if h0 > p0 else p0, h1 if h1 > p1 else p1, h2 if h2 > p2 else p2
    box[3], box[4], box[5] = h0, h1, h2
    for i in range(3):
        for j in range(3):
            box[6 + 3 * i + j] = axes[i, j]


@numba.njit("(float64[::1], float64[::1], float64[::1], intp[:, ::1], intp[::1], intp[::1],"
            " intp[::1], intp[::1], intp[::1], boolean, float64[:, :, ::1], float64[:, :, ::1],"
            " float64[:, ::1])", cache=True)
def visit_nodes(vx, vy, vz, faces, left, right, start, count, order, boxing, a, axes, boxes):
    """Each node's points, ``vertices[np.unique(faces[members])]`` (its
    vertex indices in increasing order), in turn: their covariance into
    ``a[node]`` (``boxing`` False), or their box along ``axes[node]`` into
    ``boxes[node]`` (True).

    The root's indices are every vertex a face uses, and a child's are
    those of its parent's that its own faces use, in the same order; so
    the nodes are visited depth first, each child's list filtered from its
    parent's (``marks`` flags a child's vertices) and kept on a stack of
    lists while its subtree is done: O(k) a node of k triangles, no sort."""
    m = len(order)
    x, y, z = np.empty(3 * m), np.empty(3 * m), np.empty(3 * m)
    axes_work = axes_scratch(3 * m)
    marks = np.full(len(vx), -1, dtype=np.int64)
    lists = np.empty(6 * m + 3, dtype=np.int64)      # a path's lists: at most 3 (2m) long
    for t in range(m):
        for v in range(3):
            marks[faces[t, v]] = 0
    length = 0
    for i in range(len(vx)):
        if marks[i] == 0:
            lists[length] = i
            length += 1
    stack = np.empty((len(left) + 1, 4), dtype=np.int64)  # node, list start, length, phase
    stack[0, 0], stack[0, 1], stack[0, 2], stack[0, 3] = 0, 0, length, 0
    top = 1
    while top > 0:
        node, at, length, phase = stack[top - 1, 0], stack[top - 1, 1], stack[top - 1, 2], \
            stack[top - 1, 3]
        if phase == 0:
            largest = node_points(vx, vy, vz, lists[at:at + length], length, x, y, z)
            if boxing:
                oriented_box(x, y, z, length, axes[node], boxes[node])
            else:
                covariance(x, y, z, length, largest, a[node], axes_work)
            if left[node] < 0:
                top -= 1
                continue
        if phase == 2:
            top -= 1
            continue
        child = left[node] if phase == 0 else right[node]
        stack[top - 1, 3] = phase + 1
        for r in range(start[child], start[child] + count[child]):
            for v in range(3):
                marks[faces[order[r], v]] = child
        kept = at + length
        for i in range(at, at + length):
            if marks[lists[i]] == child:
                lists[kept] = lists[i]
                kept += 1
        stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = \
            child, at + length, kept - at - length, 0
        top += 1


@numba.njit(cache=True)
def frame_boxes(vx, vy, vz, faces, left, right, start, count, order):
    """Mirrors: bvh_exact.build_frame_tree (with its default axes,
    bvh_exact.principal_axes), its boxes and axes deviation: ``(boxes
    (nodes, 15), axes_deviation)`` for the tree of ``left``, ``right``,
    ``start``, ``count``, ``order``; vx, vy, vz (n,) the mesh's vertex
    coordinates. Each node's covariance is formed (:func:`visit_nodes`), the
    eigenvectors found BOX_BATCH nodes at a time, then each box formed."""
    n_nodes = len(left)
    a, axes = np.empty((n_nodes, 3, 3)), np.empty((n_nodes, 3, 3))
    boxes = np.empty((n_nodes, 15))
    visit_nodes(vx, vy, vz, faces, left, right, start, count, order, False, a, axes, boxes)
    worst = 0.0
    for first in range(0, n_nodes, BOX_BATCH):
        last = min(first + BOX_BATCH, n_nodes)
        symmetric_eigenvectors(a[first:last], axes[first:last], last - first)
        for node in range(first, last):
            off = axes_deviation(axes[node])
            if not (off <= worst):            # max(worst, off), a NaN counted as inf
                worst = off if off < np.inf else np.inf
    visit_nodes(vx, vy, vz, faces, left, right, start, count, order, True, a, axes, boxes)
    return boxes, worst


# -- one call from a mesh's arrays ------------------------------------------------------


@numba.njit(cache=True)
def scaled_columns(vertices, faces):
    """Mirrors: bvh.scaled_triangles, one array per coordinate:
    ``np.ldexp(vertices, -unit_exponent(vertices))[faces]`` as the (3m,)
    columns :func:`build_tree` takes, and the vertices' largest magnitude
    (``np.abs(vertices).max()``, 0.0 for none; coordinates finite, as a
    Mesh's are). vertices (n, 3) float64, faces (m, 3) int64."""
    largest = 0.0
    for i in range(vertices.shape[0]):
        largest = largest_of(largest, vertices[i, 0], vertices[i, 1], vertices[i, 2])
    k = -unit_exponent(largest)
    m = faces.shape[0]
    tx, ty, tz = np.empty(3 * m), np.empty(3 * m), np.empty(3 * m)
    for t in range(m):
        for v in range(3):
            i = faces[t, v]
            tx[3 * t + v] = math.ldexp(vertices[i, 0], k)
            ty[3 * t + v] = math.ldexp(vertices[i, 1], k)
            tz[3 * t + v] = math.ldexp(vertices[i, 2], k)
    return tx, ty, tz, largest


@numba.njit(cache=True)
def build_tree_of(vertices, faces, leaf_size, rule):
    """:func:`build_tree` of a mesh's arrays (:func:`scaled_columns`): one
    call, no copies made in Python."""
    tx, ty, tz, _ = scaled_columns(vertices, faces)
    return build_tree(tx, ty, tz, leaf_size, rule)


@numba.njit(cache=True)
def frame_tree_arrays(vertices, faces, leaf_size):
    """Mirrors: bvh_exact.build_frame_tree (default axes) and
    bvh_exact.pack_frame_tree, from a mesh's vertices (n, 3) float64 and
    faces (m, 3) int64, in one call: the least-volume tree
    (:func:`build_tree`), its boxes (:func:`frame_boxes`), the links and
    the packed arrays.

    Returns ``(left, right, start, count, order, links, boxes,
    axes_deviation, reach, floats, ints)``: the TriangleTree's arrays, the
    FrameTree's, and pack_frame_tree's two arrays, each laid out as those
    functions lay them out."""
    tx, ty, tz, reach = scaled_columns(vertices, faces)
    left, right, start, count, order = build_tree(tx, ty, tz, leaf_size, LEAST_VOLUME)
    n, m, nodes = vertices.shape[0], faces.shape[0], len(left)
    vx, vy, vz = np.empty(n), np.empty(n), np.empty(n)
    for i in range(n):
        vx[i], vy[i], vz[i] = vertices[i, 0], vertices[i, 1], vertices[i, 2]
    writable_faces = faces.copy()
    boxes, deviation = frame_boxes(vx, vy, vz, writable_faces, left, right, start, count, order)
    links = np.empty((nodes, 4), dtype=np.int64)
    for node in range(nodes):
        links[node, 0], links[node, 1] = left[node], right[node]
        links[node, 2], links[node, 3] = start[node], count[node]
    # laid end to end element by element: numba's array assignment compiles
    # its shape-error text, seconds of every empty cache's compile (and one
    # helper for the five arrays would compile a version per array type)
    floats = np.empty(2 + 3 * n + 15 * nodes)
    floats[0], floats[1] = reach, deviation
    at = 2
    for i in range(n):
        for j in range(3):
            floats[at + 3 * i + j] = vertices[i, j]
    at += 3 * n
    for node in range(nodes):
        for j in range(15):
            floats[at + 15 * node + j] = boxes[node, j]
    ints = np.empty(3 + 3 * m + 4 * nodes + m, dtype=np.int64)
    ints[0], ints[1], ints[2] = n, m, nodes
    at = 3
    for i in range(m):
        for j in range(3):
            ints[at + 3 * i + j] = faces[i, j]
    at += 3 * m
    for node in range(nodes):
        for j in range(4):
            ints[at + 4 * node + j] = links[node, j]
    at += 4 * nodes
    for i in range(m):
        ints[at + i] = order[i]
    return left, right, start, count, order, links, boxes, deviation, reach, floats, ints
