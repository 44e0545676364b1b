"""Compiled principal axes of a set of points, for the hierarchies' build
(:mod:`refsim.collision._numba_build`): the covariance of a node's points
and its eigenvectors by Jacobi rotations, the same floats as the readable
:func:`refsim.collision.bvh_exact.covariance` and
:func:`refsim.collision.bvh_exact.symmetric_eigenvectors`, bit for bit.

How the floats match numpy's (its pairwise summation, the order of a mean)
and how the build calls these: :mod:`refsim.collision._numba_build`. No
BLAS or LAPACK is called. Each function here says which readable function
it mirrors.

Cost: a covariance is one pass over its points (:func:`block_sums`); a
3 x 3 eigenproblem at most :data:`JACOBI_SWEEPS` sweeps of three rotations,
two problems at a time (:func:`eigenvectors_of_pair`).

This module imports numba at import time; import it only when the compiled
kernel is chosen.
"""

from __future__ import annotations

import math

import numba
import numpy as np

#: Most sweeps of :func:`symmetric_eigenvectors` (bvh_exact.JACOBI_SWEEPS).
JACOBI_SWEEPS = 50

#: A rotation with ``|t| <= 2**-27`` has ``c = 1.0`` and ``s = t`` exactly:
#: ``t * t <= 2**-54`` is below half an ulp of 1, so ``1.0 + t * t`` rounds to
#: 1.0, whose square root and reciprocal are 1.0 (the later rotations of a
#: sweep, once the off-diagonal entries are small, are all such: this skips
#: a square root and a division on their chain of dependent operations).
TINY_ROTATION = 2.0 ** -27

#: numpy's pairwise summation: blocks of at most this many terms, summed in
#: eight interleaved partial sums.
PAIRWISE_BLOCK = 128

#: Rows of the explicit stacks of :func:`pairwise_sums` (its splits halve a
#: range: 2 log2(n / 64) + 1 frames for n terms).
PAIRWISE_STACK = 130


@numba.njit(cache=True)
def axes_scratch(n):
    """What :func:`covariance` works in, for up to n points: (3, n), the
    points times 2**-e."""
    return np.empty((3, max(n, 1)))



# -- the principal axes ---------------------------------------------------------------


@numba.njit(cache=True, inline="always")
def largest_of(largest, x0, x1, x2):
    """The largest of ``largest`` and the magnitudes of x0, x1, x2 (finite)."""
    for c in (abs(x0), abs(x1), abs(x2)):
        if c > largest:
            largest = c
    return largest


@numba.njit(cache=True)
def unit_exponent(largest):
    """Mirrors: refsim.types.unit_exponent, given the largest magnitude."""
    if largest == 0.0:
        return -1075
    return math.frexp(largest)[1]


@numba.njit("(float64[::1], float64[::1], float64[::1], float64, intp, intp,"
            " float64, float64, float64)", cache=True)
def block_sums(x, y, z, f, lo, n, m0, m1, m2):
    """numpy's pairwise sum of at most PAIRWISE_BLOCK terms (module
    docstring) of each of the six products ``d_i d_j`` a covariance needs,
    d = (x[r] f - m0, y[r] f - m1, z[r] f - m2) for r in ``lo..lo+n`` (f the
    points' scale, a power of two), in one pass: fewer than 8 terms one
    after another; else eight partial sums over the multiples of 8, added
    as ``((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))``, then the rest.
    Returns (xx, yy, zz, xy, xz, yz). Each sum takes numpy's operations in
    numpy's order (the same bits as six separate sums); the differences are
    formed once a point instead of four times."""
    if n < 8:
        xx = yy = zz = xy = xz = yz = 0.0
        for r in range(lo, lo + n):
            d0, d1, d2 = x[r] * f - m0, y[r] * f - m1, z[r] * f - m2
            xx += d0 * d0
            yy += d1 * d1
            zz += d2 * d2
            xy += d0 * d1
            xz += d0 * d2
            yz += d1 * d2
        return xx, yy, zz, xy, xz, yz
    d0, d1, d2 = x[lo + 0] * f - m0, y[lo + 0] * f - m1, z[lo + 0] * f - m2
    xx0, yy0, zz0 = d0 * d0, d1 * d1, d2 * d2
    xy0, xz0, yz0 = d0 * d1, d0 * d2, d1 * d2
    d0, d1, d2 = x[lo + 1] * f - m0, y[lo + 1] * f - m1, z[lo + 1] * f - m2
    xx1, yy1, zz1 = d0 * d0, d1 * d1, d2 * d2
    xy1, xz1, yz1 = d0 * d1, d0 * d2, d1 * d2
    d0, d1, d2 = x[lo + 2] * f - m0, y[lo + 2] * f - m1, z[lo + 2] * f - m2
    xx2, yy2, zz2 = d0 * d0, d1 * d1, d2 * d2
    xy2, xz2, yz2 = d0 * d1, d0 * d2, d1 * d2
    d0, d1, d2 = x[lo + 3] * f - m0, y[lo + 3] * f - m1, z[lo + 3] * f - m2
    xx3, yy3, zz3 = d0 * d0, d1 * d1, d2 * d2
    xy3, xz3, yz3 = d0 * d1, d0 * d2, d1 * d2
    d0, d1, d2 = x[lo + 4] * f - m0, y[lo + 4] * f - m1, z[lo + 4] * f - m2
    xx4, yy4, zz4 = d0 * d0, d1 * d1, d2 * d2
    xy4, xz4, yz4 = d0 * d1, d0 * d2, d1 * d2
    d0, d1, d2 = x[lo + 5] * f - m0, y[lo + 5] * f - m1, z[lo + 5] * f - m2
    xx5, yy5, zz5 = d0 * d0, d1 * d1, d2 * d2
    xy5, xz5, yz5 = d0 * d1, d0 * d2, d1 * d2
    d0, d1, d2 = x[lo + 6] * f - m0, y[lo + 6] * f - m1, z[lo + 6] * f - m2
    xx6, yy6, zz6 = d0 * d0, d1 * d1, d2 * d2
    xy6, xz6, yz6 = d0 * d1, d0 * d2, d1 * d2
    d0, d1, d2 = x[lo + 7] * f - m0, y[lo + 7] * f - m1, z[lo + 7] * f - m2
    xx7, yy7, zz7 = d0 * d0, d1 * d1, d2 * d2
    xy7, xz7, yz7 = d0 * d1, d0 * d2, d1 * d2
    end = lo + n - n % 8
    for i in range(lo + 8, end, 8):
        d0, d1, d2 = x[i + 0] * f - m0, y[i + 0] * f - m1, z[i + 0] * f - m2
        xx0 += d0 * d0
        yy0 += d1 * d1
        zz0 += d2 * d2
        xy0 += d0 * d1
        xz0 += d0 * d2
        yz0 += d1 * d2
        d0, d1, d2 = x[i + 1] * f - m0, y[i + 1] * f - m1, z[i + 1] * f - m2
        xx1 += d0 * d0
        yy1 += d1 * d1
        zz1 += d2 * d2
        xy1 += d0 * d1
        xz1 += d0 * d2
        yz1 += d1 * d2
        d0, d1, d2 = x[i + 2] * f - m0, y[i + 2] * f - m1, z[i + 2] * f - m2
        xx2 += d0 * d0
        yy2 += d1 * d1
        zz2 += d2 * d2
        xy2 += d0 * d1
        xz2 += d0 * d2
        yz2 += d1 * d2
        d0, d1, d2 = x[i + 3] * f - m0, y[i + 3] * f - m1, z[i + 3] * f - m2
        xx3 += d0 * d0
        yy3 += d1 * d1
        zz3 += d2 * d2
        xy3 += d0 * d1
        xz3 += d0 * d2
        yz3 += d1 * d2
        d0, d1, d2 = x[i + 4] * f - m0, y[i + 4] * f - m1, z[i + 4] * f - m2
        xx4 += d0 * d0
        yy4 += d1 * d1
        zz4 += d2 * d2
        xy4 += d0 * d1
        xz4 += d0 * d2
        yz4 += d1 * d2
        d0, d1, d2 = x[i + 5] * f - m0, y[i + 5] * f - m1, z[i + 5] * f - m2
        xx5 += d0 * d0
        yy5 += d1 * d1
        zz5 += d2 * d2
        xy5 += d0 * d1
        xz5 += d0 * d2
        yz5 += d1 * d2
        d0, d1, d2 = x[i + 6] * f - m0, y[i + 6] * f - m1, z[i + 6] * f - m2
        xx6 += d0 * d0
        yy6 += d1 * d1
        zz6 += d2 * d2
        xy6 += d0 * d1
        xz6 += d0 * d2
        yz6 += d1 * d2
        d0, d1, d2 = x[i + 7] * f - m0, y[i + 7] * f - m1, z[i + 7] * f - m2
        xx7 += d0 * d0
        yy7 += d1 * d1
        zz7 += d2 * d2
        xy7 += d0 * d1
        xz7 += d0 * d2
        yz7 += d1 * d2
    xx = ((xx0 + xx1) + (xx2 + xx3)) + ((xx4 + xx5) + (xx6 + xx7))
    yy = ((yy0 + yy1) + (yy2 + yy3)) + ((yy4 + yy5) + (yy6 + yy7))
    zz = ((zz0 + zz1) + (zz2 + zz3)) + ((zz4 + zz5) + (zz6 + zz7))
    xy = ((xy0 + xy1) + (xy2 + xy3)) + ((xy4 + xy5) + (xy6 + xy7))
    xz = ((xz0 + xz1) + (xz2 + xz3)) + ((xz4 + xz5) + (xz6 + xz7))
    yz = ((yz0 + yz1) + (yz2 + yz3)) + ((yz4 + yz5) + (yz6 + yz7))
    for r in range(end, lo + n):
        d0, d1, d2 = x[r] * f - m0, y[r] * f - m1, z[r] * f - m2
        xx += d0 * d0
        yy += d1 * d1
        zz += d2 * d2
        xy += d0 * d1
        xz += d0 * d2
        yz += d1 * d2
    return xx, yy, zz, xy, xz, yz



@numba.njit(cache=True)
def pairwise_sums(x, y, z, f, n, m0, m1, m2):
    """numpy's pairwise sums (module docstring) of the six products of
    :func:`block_sums` over the first n points, before numpy adds each to
    0.0: a range longer than PAIRWISE_BLOCK is split at a multiple of 8 below
    its half and the halves' sums added; the six sums share the splits (they
    have the same n). Written with explicit stacks (``frames`` of (start,
    length, halves done), ``values`` of sums), not by recursion: numba's
    cache reloads recursive functions wrongly (numba bug report 6061,
    github.com/numba/numba)."""
    if n <= PAIRWISE_BLOCK:
        return block_sums(x, y, z, f, 0, n, m0, m1, m2)
    frames = np.empty((PAIRWISE_STACK, 3), dtype=np.int64)
    values = np.empty((PAIRWISE_STACK, 6))
    frames[0, 0], frames[0, 1], frames[0, 2] = 0, n, 0
    top, stored = 1, 0
    while top > 0:
        lo, length, split = frames[top - 1, 0], frames[top - 1, 1], frames[top - 1, 2]
        if length <= PAIRWISE_BLOCK:
            sums = block_sums(x, y, z, f, lo, length, m0, m1, m2)
            for j in range(6):
                values[stored, j] = sums[j]
            stored += 1
            top -= 1
        elif split == 0:
            half = length // 2
            half -= half % 8
            frames[top - 1, 2] = 1
            frames[top, 0], frames[top, 1], frames[top, 2] = lo + half, length - half, 0
            frames[top + 1, 0], frames[top + 1, 1], frames[top + 1, 2] = lo, half, 0
            top += 2                            # the first half on top: summed first
        else:
            for j in range(6):                  # first + second
                values[stored - 2, j] = values[stored - 2, j] + values[stored - 1, j]
            stored -= 1
            top -= 1
    return (values[0, 0], values[0, 1], values[0, 2], values[0, 3], values[0, 4],
            values[0, 5])


@numba.njit(cache=True)
def covariance(x, y, z, n, largest, a, scaled):
    """The covariance matrix that bvh_exact.principal_axes diagonalizes, of
    the first n points (largest magnitude ``largest``), into ``a`` (3, 3);
    for fewer than two points zeros (whose eigenvectors,
    :func:`symmetric_eigenvectors`, are the identity principal_axes returns
    then). ``scaled`` (3, n) is scratch."""
    if n < 2:
        a[:, :] = 0.0
        return
    # np.ldexp(points, -e): a product by f = 2**-e when that is a normal
    # float (both round the exact value once; 1.0 when e = 0, coordinates
    # already in [0.5, 1), as build_tree leaves many sets), formed where each
    # point is read; else ldexp itself, into ``scaled``
    k = -unit_exponent(largest)
    f = 1.0
    if -1022 <= k <= 1023:
        f = math.ldexp(1.0, k)
    else:
        for r in range(n):
            scaled[0, r], scaled[1, r], scaled[2, r] = math.ldexp(x[r], k), \
                math.ldexp(y[r], k), math.ldexp(z[r], k)
        x, y, z = scaled[0], scaled[1], scaled[2]
    m0 = m1 = m2 = 0.0                    # points.mean(axis=0): rows in turn, from 0.0
    for r in range(n):
        m0 += x[r] * f
        m1 += y[r] * f
        m2 += z[r] * f
    m0, m1, m2 = m0 / n, m1 / n, m2 / n
    # np.sum adds the pairwise sum to 0.0 (which turns a -0.0 into 0.0)
    xx, yy, zz, xy, xz, yz = pairwise_sums(x, y, z, f, n, m0, m1, m2)
    a[0, 0] = 0.0 + xx
    a[1, 1] = 0.0 + yy
    a[2, 2] = 0.0 + zz
    a[0, 1] = a[1, 0] = 0.0 + xy
    a[0, 2] = a[2, 0] = 0.0 + xz
    a[1, 2] = a[2, 1] = 0.0 + yz


@numba.njit(cache=True, inline="always")
def jacobi_rotation(app, apq, apr, aqp, aqq, aqr, arp, arq, v0p, v0q, v1p, v1q, v2p, v2q):
    """One rotation of bvh_exact.symmetric_eigenvectors, the one that zeroes
    entry (p, q) of a 3 x 3 matrix (r the third index), on the entries it
    changes, given and returned in the order (p, p), (p, q), (p, r), (q, p),
    (q, q), (q, r), (r, p), (r, q), then the rotations' columns p and q row
    by row: ``A <- J^T (A J)`` and ``V <- V J``, each entry formed by the
    readable code's operations in its order, then ``a_pq = a_qp = 0``."""
    tau = (aqq - app) / (2.0 * apq)
    t = (1.0 if tau >= 0.0 else -1.0) / (abs(tau) + math.sqrt(1.0 + tau * tau))
    if abs(t) <= TINY_ROTATION:
        c, s = 1.0, t
    else:
        c = 1.0 / math.sqrt(1.0 + t * t)
        s = t * c
    app, apq = c * app - s * apq, s * app + c * apq          # A J: columns p, q
    aqp, aqq = c * aqp - s * aqq, s * aqp + c * aqq
    arp, arq = c * arp - s * arq, s * arp + c * arq
    app, aqp = c * app - s * aqp, s * app + c * aqp          # J^T (A J): rows p, q
    apq, aqq = c * apq - s * aqq, s * apq + c * aqq
    apr, aqr = c * apr - s * aqr, s * apr + c * aqr
    apq = aqp = 0.0
    v0p, v0q = c * v0p - s * v0q, s * v0p + c * v0q
    v1p, v1q = c * v1p - s * v1q, s * v1p + c * v1q
    v2p, v2q = c * v2p - s * v2q, s * v2p + c * v2q
    return app, apq, apr, aqp, aqq, aqr, arp, arq, v0p, v0q, v1p, v1q, v2p, v2q


@numba.njit(cache=True)
def eigenvectors_of_pair(a, axes, first, second):
    """Mirrors: bvh_exact.symmetric_eigenvectors, of matrices ``a[first]``
    and ``a[second]`` (each (3, 3), left unchanged) into ``axes[first]`` and
    ``axes[second]``: each matrix's rotations in the readable order, on its
    entries held in locals, the two matrices in turns so that the processor
    overlaps their chains of divisions and square roots. A matrix whose
    off-diagonal entries are all zero takes no rotation (each is skipped
    when its entry is zero), so sweeping it on while the other converges
    changes nothing: the same bits as one matrix alone."""
    a00_0, a01_0, a02_0 = a[first, 0, 0], a[first, 0, 1], a[first, 0, 2]
    a10_0, a11_0, a12_0 = a[first, 1, 0], a[first, 1, 1], a[first, 1, 2]
    a20_0, a21_0, a22_0 = a[first, 2, 0], a[first, 2, 1], a[first, 2, 2]
    v00_0, v01_0, v02_0 = 1.0, 0.0, 0.0
    v10_0, v11_0, v12_0 = 0.0, 1.0, 0.0
    v20_0, v21_0, v22_0 = 0.0, 0.0, 1.0
    a00_1, a01_1, a02_1 = a[second, 0, 0], a[second, 0, 1], a[second, 0, 2]
    a10_1, a11_1, a12_1 = a[second, 1, 0], a[second, 1, 1], a[second, 1, 2]
    a20_1, a21_1, a22_1 = a[second, 2, 0], a[second, 2, 1], a[second, 2, 2]
    v00_1, v01_1, v02_1 = 1.0, 0.0, 0.0
    v10_1, v11_1, v12_1 = 0.0, 1.0, 0.0
    v20_1, v21_1, v22_1 = 0.0, 0.0, 1.0
    for _ in range(JACOBI_SWEEPS):
        if (abs(a01_0) + abs(a02_0) + abs(a12_0) == 0.0
                and abs(a01_1) + abs(a02_1) + abs(a12_1) == 0.0):
            break
        if a01_0 != 0.0:
            a00_0, a01_0, a02_0, a10_0, a11_0, a12_0, a20_0, a21_0, \
                v00_0, v01_0, v10_0, v11_0, v20_0, v21_0 = jacobi_rotation(
                    a00_0, a01_0, a02_0, a10_0, a11_0, a12_0, a20_0, a21_0,
                    v00_0, v01_0, v10_0, v11_0, v20_0, v21_0)
        if a01_1 != 0.0:
            a00_1, a01_1, a02_1, a10_1, a11_1, a12_1, a20_1, a21_1, \
                v00_1, v01_1, v10_1, v11_1, v20_1, v21_1 = jacobi_rotation(
                    a00_1, a01_1, a02_1, a10_1, a11_1, a12_1, a20_1, a21_1,
                    v00_1, v01_1, v10_1, v11_1, v20_1, v21_1)
        if a02_0 != 0.0:
            a00_0, a02_0, a01_0, a20_0, a22_0, a21_0, a10_0, a12_0, \
                v00_0, v02_0, v10_0, v12_0, v20_0, v22_0 = jacobi_rotation(
                    a00_0, a02_0, a01_0, a20_0, a22_0, a21_0, a10_0, a12_0,
                    v00_0, v02_0, v10_0, v12_0, v20_0, v22_0)
        if a02_1 != 0.0:
            a00_1, a02_1, a01_1, a20_1, a22_1, a21_1, a10_1, a12_1, \
                v00_1, v02_1, v10_1, v12_1, v20_1, v22_1 = jacobi_rotation(
                    a00_1, a02_1, a01_1, a20_1, a22_1, a21_1, a10_1, a12_1,
                    v00_1, v02_1, v10_1, v12_1, v20_1, v22_1)
        if a12_0 != 0.0:
            a11_0, a12_0, a10_0, a21_0, a22_0, a20_0, a01_0, a02_0, \
                v01_0, v02_0, v11_0, v12_0, v21_0, v22_0 = jacobi_rotation(
                    a11_0, a12_0, a10_0, a21_0, a22_0, a20_0, a01_0, a02_0,
                    v01_0, v02_0, v11_0, v12_0, v21_0, v22_0)
        if a12_1 != 0.0:
            a11_1, a12_1, a10_1, a21_1, a22_1, a20_1, a01_1, a02_1, \
                v01_1, v02_1, v11_1, v12_1, v21_1, v22_1 = jacobi_rotation(
                    a11_1, a12_1, a10_1, a21_1, a22_1, a20_1, a01_1, a02_1,
                    v01_1, v02_1, v11_1, v12_1, v21_1, v22_1)
    sorted_columns(a00_0, a11_0, a22_0, ((v00_0, v10_0, v20_0), (v01_0, v11_0, v21_0),
                                         (v02_0, v12_0, v22_0)), axes[first])
    sorted_columns(a00_1, a11_1, a22_1, ((v00_1, v10_1, v20_1), (v01_1, v11_1, v21_1),
                                         (v02_1, v12_1, v22_1)), axes[second])


@numba.njit(cache=True, inline="always")
def sorted_columns(d0, d1, d2, columns, axes):
    """The eigenvectors ``columns`` (eigenvalues d0, d1, d2) into ``axes``
    (3, 3) as bvh_exact.symmetric_eigenvectors orders and signs them: by
    increasing eigenvalue, ties by index (a stable sort of three), each
    column's first largest component made positive."""
    o0, o1, o2 = 0, 1, 2
    e0, e1, e2 = d0, d1, d2
    if e1 < e0:
        o0, o1, e0, e1 = o1, o0, e1, e0
    if e2 < e1:
        o1, o2, e1, e2 = o2, o1, e2, e1
        if e1 < e0:
            o0, o1, e0, e1 = o1, o0, e1, e0
    for column, i in enumerate((o0, o1, o2)):
        c0, c1, c2 = columns[i]
        big, largest = c0, abs(c0)            # np.argmax: the first largest
        if abs(c1) > largest:
            big, largest = c1, abs(c1)
        if abs(c2) > largest:
            big = c2
        if big < 0.0:
            c0, c1, c2 = -c0, -c1, -c2
        axes[0, column], axes[1, column], axes[2, column] = c0, c1, c2


@numba.njit("(float64[:, :, ::1], float64[:, :, ::1], intp)", cache=True)
def symmetric_eigenvectors(a, axes, count):
    """Mirrors: bvh_exact.symmetric_eigenvectors, of ``count`` matrices
    ``a`` (count, 3, 3), left unchanged; the eigenvectors (columns) go to
    ``axes`` (count, 3, 3). Two at a time (:func:`eigenvectors_of_pair`),
    the last of an odd count with itself."""
    for m in range(0, count, 2):
        eigenvectors_of_pair(a, axes, m, min(m + 1, count - 1))


@numba.njit(cache=True, inline="always")
def project(p0, p1, p2, a0, a1, a2):
    """Mirrors: bvh_exact.project, one entry: ``(p0 a0j + p1 a1j) + p2 a2j``
    for the axis column ``(a0, a1, a2)``."""
    return (p0 * a0 + p1 * a1) + p2 * a2


@numba.njit(cache=True)
def extents(x, y, z, n, axes):
    """``(lo, hi)``: ``project(points, axes).min(axis=0)`` and ``.max(axis=0)``
    of the first n points, three floats each; of two equal values (0.0 and
    -0.0) the later, as numpy's."""
    a00, a01, a02 = axes[0, 0], axes[0, 1], axes[0, 2]
    a10, a11, a12 = axes[1, 0], axes[1, 1], axes[1, 2]
    a20, a21, a22 = axes[2, 0], axes[2, 1], axes[2, 2]
    lo0 = hi0 = project(x[0], y[0], z[0], a00, a10, a20)
    lo1 = hi1 = project(x[0], y[0], z[0], a01, a11, a21)
    lo2 = hi2 = project(x[0], y[0], z[0], a02, a12, a22)
    for r in range(1, n):
        p0 = project(x[r], y[r], z[r], a00, a10, a20)
        p1 = project(x[r], y[r], z[r], a01, a11, a21)
        p2 = project(x[r], y[r], z[r], a02, a12, a22)
        lo0 = lo0 if lo0 < p0 else p0
        lo1 = lo1 if lo1 < p1 else p1
        lo2 = lo2 if lo2 < p2 else p2
        hi0 = hi0 if hi0 > p0 else p0
        hi1 = hi1 if hi1 > p1 else p1
        hi2 = hi2 if hi2 > p2 else p2
    return (lo0, lo1, lo2), (hi0, hi1, hi2)
