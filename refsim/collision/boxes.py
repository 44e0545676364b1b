"""Axis-aligned boxes of bodies and triangles, and the body-level broad phase
(seed S4, test 1).

The seed's test 1 is a "pairwise O(n2) fast axis-aligned object bounding box
overlap test" over all bodies. ``overlapping_pairs_all`` is exactly that;
``overlapping_pairs_sweep`` gives the same pairs by sort-and-sweep along one
axis, the one-dimensional core of I-COLLIDE's sweep and prune (J. D. Cohen,
M. C. Lin, D. Manocha, M. K. Ponamgi, "I-COLLIDE: An Interactive and Exact
Collision Detection System for Large-Scale Environments", 1995, sec. 4).

Boxes are closed: boxes that share a face, an edge or a corner overlap, so
that touching bodies are never rejected here (FCL's convention, and the one
refsim's exact test uses).

Cost: all pairs O(n^2); sweep O(n log n + k) for k pairs overlapping on the
sweep axis.
"""

from __future__ import annotations

import numpy as np

from refsim.bounds.aabb_linear import transform_vertices
from refsim.types import Pose


def world_vertices(mesh, pose: Pose) -> np.ndarray:
    """The mesh's vertices in world space, (n, 3).

    Every collision path uses this arithmetic (refsim's one definition of a
    transformed coordinate, :func:`refsim.bounds.aabb_linear.transform_vertices`:
    ``(R[k,0] x + R[k,1] y) + R[k,2] z + t[k]``, each operation rounded once),
    so the seed's path, the hierarchy and its compiled kernel see the same
    floats and report the same touching pairs.
    """
    return transform_vertices(mesh.vertices, pose)


def triangle_boxes(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per-triangle boxes ``(lo, hi)``, each (m, 3), of the given vertices."""
    corners = vertices[faces]
    return corners.min(axis=1), corners.max(axis=1)


def boxes_overlap(lo_a, hi_a, lo_b, hi_b) -> bool:
    """Closed interval overlap on all three axes."""
    return bool(np.all(lo_a <= hi_b) and np.all(lo_b <= hi_a))


def overlapping_pairs_all(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Every pair ``i < j`` of overlapping boxes, by testing all pairs (the seed).

    ``lo``, ``hi``: (n, 3). Returns (k, 2) int64, rows sorted.
    """
    n = len(lo)
    pairs = [(i, j) for i in range(n) for j in range(i + 1, n)
             if boxes_overlap(lo[i], hi[i], lo[j], hi[j])]
    return np.array(pairs, dtype=np.int64).reshape(-1, 2)


def overlapping_pairs_sweep(lo: np.ndarray, hi: np.ndarray, axis: int = 0) -> np.ndarray:
    """The same pairs as :func:`overlapping_pairs_all`, by sort and sweep.

    Sort the boxes by their low end on ``axis``; walking in that order, box i
    can only overlap the boxes that start before its high end. Those are
    checked on the other two axes. Ties in the low end are fine: closed
    intervals that start at the same point overlap.
    """
    n = len(lo)
    order = np.argsort(lo[:, axis], kind="stable")
    starts = lo[order, axis]
    pairs = []
    for rank, i in enumerate(order):
        # boxes after i in the sweep whose start is <= i's end on the axis
        stop = np.searchsorted(starts, hi[i, axis], side="right")
        for j in order[rank + 1:stop]:
            if boxes_overlap(lo[i], hi[i], lo[j], hi[j]):
                pairs.append((min(i, j), max(i, j)))
    result = np.array(sorted(pairs), dtype=np.int64).reshape(-1, 2)
    return result if n else result[:0]
