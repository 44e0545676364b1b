"""World boxes of many bodies that share one mesh, at once (seed S2, the
linear scan, batched for the simulation's bounds stage).

What: for bodies b with orientations ``R_b`` and mesh origins ``t_b``, the box
``lo_bk = min_v r_k(R_b, v) + t_bk``, ``hi_bk = max_v ...`` with the linear
scan's one arithmetic, ``r_k(R, v) = (R[k, 0] x + R[k, 1] y) + R[k, 2] z``
(:mod:`refsim.bounds.aabb_linear`), so the boxes equal, bit for bit, those
of :func:`refsim.aabb_linear` and, for a convex mesh, of the incremental
tracker (which finds the same extreme vertex and adds the translation the
same way).

Two paths doing that arithmetic in that order: :func:`boxes_numpy` (the plain
kernel, (B, 3, n) arrays) and :func:`boxes_compiled` (the same loops
compiled by numba: the numpy path is a dozen array calls of overhead;
docs/decisions/batched-boxes.md).

Cost: O(B n) for B bodies of n vertices.
"""

from __future__ import annotations

import numpy as np

from refsim.kernels import BATCHED_BOXES, compile_kernel


def boxes_numpy(vertices_t: np.ndarray, R: np.ndarray, origin: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray]:
    """``(lo, hi)``, each (B, 3), for ``vertices_t`` (3, n) body-space rows
    x, y, z, orientations R (B, 3, 3) and origins (B, 3)."""
    x, y, z = vertices_t
    r = (R[:, :, 0:1] * x + R[:, :, 1:2] * y) + R[:, :, 2:3] * z     # (B, 3, n)
    return r.min(axis=2) + origin, r.max(axis=2) + origin


def boxes_loops(vertices_t: np.ndarray, R: np.ndarray, origin: np.ndarray, lo: np.ndarray,
                hi: np.ndarray) -> None:
    """:func:`boxes_numpy` as loops, into ``lo`` and ``hi`` (B, 3)."""
    n = vertices_t.shape[1]
    for b in range(R.shape[0]):
        for k in range(3):
            a0, a1, a2 = R[b, k, 0], R[b, k, 1], R[b, k, 2]
            least = greatest = (a0 * vertices_t[0, 0] + a1 * vertices_t[1, 0]) \
                + a2 * vertices_t[2, 0]
            for i in range(1, n):
                r = (a0 * vertices_t[0, i] + a1 * vertices_t[1, i]) + a2 * vertices_t[2, i]
                if r < least:
                    least = r
                if r > greatest:
                    greatest = r
            lo[b, k] = least + origin[b, k]
            hi[b, k] = greatest + origin[b, k]


def boxes_compiled(vertices_t, R, origin) -> tuple[np.ndarray, np.ndarray]:
    """Mirrors :func:`boxes_numpy`: its loops (:func:`boxes_loops`) compiled
    by numba, the same bits."""
    lo = np.empty((R.shape[0], 3))
    hi = np.empty((R.shape[0], 3))
    compile_kernel(boxes_loops)(vertices_t, np.ascontiguousarray(R),
                                np.ascontiguousarray(origin), lo, hi)
    return lo, hi


def boxes_kernel(vertices_t, R, origin, *, kernel: str | None = None
                 ) -> tuple[np.ndarray, np.ndarray]:
    """The boxes of all bodies of one mesh on the chosen kernel
    (:mod:`refsim.kernels`)."""
    return BATCHED_BOXES(kernel)(vertices_t, R, origin)
