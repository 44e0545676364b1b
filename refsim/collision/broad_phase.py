"""Body-level broad phase: which bodies' boxes overlap (seed S4, test 1).

The seed's test 1 is a "pairwise O(n2) fast axis-aligned object bounding box
overlap test" over all bodies: :func:`overlapping_pairs_all` is exactly that.
The seed also points to the faster way, "more sophisticated sweep-and-prune
collision detection systems (like I-COLLIDE)": :func:`overlapping_pairs_sweep`
gives the same pairs by sort and sweep along one axis, the one-dimensional
core of sweep and prune. Boxes are closed: boxes that share a face, an edge
or a corner overlap, so touching bodies are never rejected here.

Sort and sweep: sort the boxes by their low end on ``axis``; walking in that
order, box i can only overlap the boxes that start at or before its high end
(a contiguous run of the sorted order); each of those is tested on the other
two axes. Ties in the low end are fine: closed intervals that start at the
same point overlap.

Reference: J. D. Cohen, M. C. Lin, D. Manocha, M. K. Ponamgi, "I-COLLIDE: an
interactive and exact collision detection system for large-scale
environments", Proc. ACM Symposium on Interactive 3D Graphics, 1995,
section 4 (sort and sweep).

Cost: all pairs O(B^2); sort and sweep O(B log B + k) for k pairs that
overlap on the sweep axis. The sweep is plain loops, compiled by numba as it
stands for the simulation loop (:data:`refsim.kernels.PAIRS`).
"""

from __future__ import annotations

import numpy as np

from refsim.collision.boxes import boxes_overlap
from refsim.kernels import BROAD_PHASE_SWEEP, compile_kernel


def overlapping_pairs_all(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Every pair ``i < j`` of overlapping boxes, by testing all pairs (the seed).

    ``lo``, ``hi``: (B, 3). Returns (k, 2) int64, rows sorted.
    """
    n = len(lo)
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)
             if boxes_overlap(lo[i], hi[i], lo[j], hi[j])]
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def overlapping_pairs_sweep(lo: np.ndarray, hi: np.ndarray, axis: int = 0) -> np.ndarray:
    """The pairs of :func:`overlapping_pairs_all` by sort and sweep (module
    docstring); (k, 2) int64, rows sorted. The readable kernel, which numba
    compiles unchanged (:func:`overlapping_pairs_sweep_compiled`)."""
    n = lo.shape[0]
    order = np.argsort(lo[:, axis], kind="mergesort")       # stable
    out = np.empty((max(n * (n - 1) // 2, 1), 2), dtype=np.int64)
    k = 0
    for r in range(n):
        i = order[r]
        end = hi[i, axis]
        for s in range(r + 1, n):
            j = order[s]
            if lo[j, axis] > end:
                break                                     # sorted: no later box starts before
            if (lo[i, 0] <= hi[j, 0] and lo[j, 0] <= hi[i, 0] and lo[i, 1] <= hi[j, 1]
                    and lo[j, 1] <= hi[i, 1] and lo[i, 2] <= hi[j, 2] and lo[j, 2] <= hi[i, 2]):
                out[k, 0] = min(i, j)
                out[k, 1] = max(i, j)
                k += 1
    pairs = out[:k]
    keys = pairs[:, 0] * n + pairs[:, 1]                  # rows sorted (i, then j)
    return pairs[np.argsort(keys)]


def overlapping_pairs_sweep_compiled(lo: np.ndarray, hi: np.ndarray,
                                     axis: int = 0) -> np.ndarray:
    """:func:`overlapping_pairs_sweep` compiled by numba (the same source)."""
    return compile_kernel(overlapping_pairs_sweep)(lo, hi, axis)


def overlapping_pairs(lo: np.ndarray, hi: np.ndarray, *, kernel: str | None = None
                      ) -> np.ndarray:
    """Overlapping pairs of the B boxes ``lo``, ``hi`` (B, 3) by sort and
    sweep, on the chosen kernel (:mod:`refsim.kernels`)."""
    return BROAD_PHASE_SWEEP(kernel)(lo, hi)
