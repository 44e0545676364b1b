"""Dot products and matrix-vector products for one body or for B bodies at
once, each sum written out in one order.

What: for 3-vectors ``a``, ``b`` and 3x3 matrices ``M`` (shapes ``(3,)`` and
``(3, 3)``, or ``(B, 3)`` and ``(B, 3, 3)`` for B bodies):

    a . b          = (a0 b0 + a1 b1) + a2 b2
    |a|            = sqrt(a . a)
    (M x)_i        = (M_i0 x0 + M_i1 x1) + M_i2 x2
    (M^T x)_i      = (M_0i x0 + M_1i x1) + M_2i x2
    (A B)_ij       = (A_i0 B_0j + A_i1 B_1j) + A_i2 B_2j

and the Gram-Schmidt orthonormalisation of a 3x3 matrix's columns
(:func:`orthonormalize_columns`), which the seed's rotation step and the
corrected one share.

each product and sum rounded once, left to right, as
:mod:`refsim.bounds.aabb_linear` does for a transformed coordinate.

Why not ``@``, ``np.dot``, ``np.einsum`` or ``np.linalg.norm``: numpy hands
them to BLAS or to SIMD loops whose summation order and fused multiply-adds
depend on the processor; on random inputs they differ from the
left-to-right sum in the last bit in a large fraction of cases
(docs/decisions/compiled-loop.md). Written out, the dynamics stages give
the same bits on every machine, and the compiled simulation loop
(:mod:`refsim.dynamics._numba_kernels`) repeats the same operations in the
same order, so it agrees with them bit for bit.

Seed sections: none of their own; used by S8 (the seed's exchange), for
the mesh origin ``x - R c`` of every body (S2, S9), and by the corrected
rotation model (:mod:`refsim.dynamics.rotation_impulse`).

Functions marked :func:`jitable` are plain Python when called from Python
and compiled inline when a numba-compiled kernel calls them, so the readable
and compiled paths run one source.

Cost: O(1) per body, a handful of numpy calls per product.
"""

from __future__ import annotations

import math

import numpy as np

try:
    # register_jitable: a plain Python function when called from Python, and
    # compiled inline when called from a numba-compiled function.
    from numba.extending import register_jitable as jitable
except Exception:  # numba missing or unusable: the plain path only
    # The same name for the identity decorator, the usual optional import.
    def jitable(f):                                 # type: ignore[no-redef]
        return f


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a . b`` over the last axis: (..., 3), (..., 3) -> (...)."""
    return (a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1]) + a[..., 2] * b[..., 2]


def norm(a: np.ndarray) -> np.ndarray:
    """``sqrt(a . a)`` over the last axis: (..., 3) -> (...)."""
    return np.sqrt(dot(a, a))


def matvec(M: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``M x``: (..., 3, 3), (..., 3) -> (..., 3)."""
    return dot(M, x[..., np.newaxis, :])


def matTvec(M: np.ndarray, x: np.ndarray) -> np.ndarray:
    """``M^T x``: (..., 3, 3), (..., 3) -> (..., 3)."""
    return matvec(np.swapaxes(M, -1, -2), x)


def matmul(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``A B``: (..., 3, 3), (..., 3, 3) -> (..., 3, 3)."""
    return ((A[..., :, 0:1] * B[..., 0:1, :] + A[..., :, 1:2] * B[..., 1:2, :])
            + A[..., :, 2:3] * B[..., 2:3, :])


def inverse(M: np.ndarray) -> np.ndarray:
    """``M^-1`` of invertible 3x3 matrices: (..., 3, 3) -> (..., 3, 3), by
    the adjugate over the determinant, each cofactor ``(a d - b c)`` and the
    determinant ``(M_00 C_00 + M_01 C_10) + M_02 C_20`` rounded in one order
    (``np.linalg.inv`` goes to LAPACK, whose last bits depend on the
    processor's kernels). Each matrix is first scaled by a power of two that
    brings its largest entry near 1 (exact), so that the determinant, a
    product of three entries, neither overflows nor underflows for a body
    of any size; the inverse is scaled back by the same power."""
    M = np.asarray(M, dtype=np.float64)
    largest = np.abs(M).max(axis=(-2, -1), keepdims=True)
    e = np.frexp(np.where(largest > 0.0, largest, 1.0))[1]
    A = np.ldexp(M, -e)
    a = [[A[..., i, j] for j in range(3)] for i in range(3)]

    def cofactor(i0, j0, i1, j1):                 # a[i0][j0] a[i1][j1] - a[i0][j1] a[i1][j0]
        return a[i0][j0] * a[i1][j1] - a[i0][j1] * a[i1][j0]

    # each entry a difference, none negated: an exact zero stays +0.0
    adjugate = np.stack([
        np.stack([cofactor(1, 1, 2, 2), cofactor(0, 2, 2, 1), cofactor(0, 1, 1, 2)], axis=-1),
        np.stack([cofactor(1, 2, 2, 0), cofactor(0, 0, 2, 2), cofactor(0, 2, 1, 0)], axis=-1),
        np.stack([cofactor(1, 0, 2, 1), cofactor(0, 1, 2, 0), cofactor(0, 0, 1, 1)], axis=-1),
    ], axis=-2)
    det = (a[0][0] * adjugate[..., 0, 0] + a[0][1] * adjugate[..., 1, 0]) \
        + a[0][2] * adjugate[..., 2, 0]
    return np.ldexp(adjugate / det[..., np.newaxis, np.newaxis], -e)


@jitable
def orthonormalize_columns(A, out):
    """Gram-Schmidt on the columns of A (3, 3), into out (3, 3), which may be
    A itself: the first column normalised, the second made orthogonal to it
    and normalised, the third their cross product (right-handed). Every sum
    left to right; A is read whole before out is written."""
    n0 = math.sqrt((A[0, 0] * A[0, 0] + A[1, 0] * A[1, 0]) + A[2, 0] * A[2, 0])
    u0, u1, u2 = A[0, 0] / n0, A[1, 0] / n0, A[2, 0] / n0
    d = (A[0, 1] * u0 + A[1, 1] * u1) + A[2, 1] * u2
    t0, t1, t2 = A[0, 1] - d * u0, A[1, 1] - d * u1, A[2, 1] - d * u2
    n1 = math.sqrt((t0 * t0 + t1 * t1) + t2 * t2)
    t0, t1, t2 = t0 / n1, t1 / n1, t2 / n1
    out[0, 0], out[1, 0], out[2, 0] = u0, u1, u2
    out[0, 1], out[1, 1], out[2, 1] = t0, t1, t2
    out[0, 2] = u1 * t2 - u2 * t1
    out[1, 2] = u2 * t0 - u0 * t2
    out[2, 2] = u0 * t1 - u1 * t0
