"""Dot products, matrix-vector and 3x3 matrix products for one body or for B
bodies at once, each sum written out in one order.

What: for 3-vectors ``a``, ``b`` and 3x3 matrices ``M``, ``N`` (shapes
``(3,)`` and ``(3, 3)``, or ``(B, 3)`` and ``(B, 3, 3)`` for B bodies):

    a . b          = (a0 b0 + a1 b1) + a2 b2
    (M x)_i        = (M_i0 x0 + M_i1 x1) + M_i2 x2
    (M^T x)_i      = (M_0i x0 + M_1i x1) + M_2i x2
    (M N)_ij       = (M_i0 N_0j + M_i1 N_1j) + M_i2 N_2j
    (M N^T)_ij     = (M_i0 N_j0 + M_i1 N_j1) + M_i2 N_j2

each product and sum rounded once, left to right, as
:mod:`refsim.bounds.aabb_linear` does for a transformed coordinate.

Why not ``@``, ``np.dot``, ``np.einsum`` or ``np.linalg.norm``: numpy hands
them to BLAS or to SIMD loops whose summation order and fused multiply-adds
depend on the processor (measured on this project's machine: ``np.dot`` of
two 3-vectors differs from the left-to-right sum in a third of random cases,
a stacked 3x3 ``@`` in all of them). Written out, the dynamics stages give
the same bits on every machine, and the compiled simulation loop
(:mod:`refsim.dynamics._numba_kernels`) repeats the same operations in the
same order, so it agrees with them bit for bit.

Seed sections: none of their own; used by S8, S9 and the corrected models.

Cost: O(1) per body, a handful of numpy calls per product.
"""

from __future__ import annotations

import numpy as np


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
    return dot(np.swapaxes(M, -1, -2), x[..., np.newaxis, :])


def matmul(M: np.ndarray, N: np.ndarray) -> np.ndarray:
    """``M N``: (..., 3, 3), (..., 3, 3) -> (..., 3, 3)."""
    # (M N)_ij: row i of M against column j of N (row j of N^T)
    return dot(M[..., :, np.newaxis, :], np.swapaxes(N, -1, -2)[..., np.newaxis, :, :])


def matmul_transposed(M: np.ndarray, N: np.ndarray) -> np.ndarray:
    """``M N^T``: (..., 3, 3), (..., 3, 3) -> (..., 3, 3)."""
    return dot(M[..., :, np.newaxis, :], N[..., np.newaxis, :, :])
