"""The seed's three-level hierarchy for one pair of bodies (seed S4), as the
seed describes it, with no further acceleration.

- Test 1: the bodies' world boxes overlap ("pairwise O(n2) fast axis-aligned
  object bounding box overlap test").
- Test 2: "for objects overlapping in Test 1, we then perform pairwise testing
  of the triangle AABBs": every triangle box of one body against every
  triangle box of the other. Only triangles whose boxes reach into the
  overlap of the two object boxes can pass, so the others are dropped first;
  this loses no pair, because two triangle boxes can only overlap inside both
  object boxes.
- Test 3: "pairs of triangles passing Test 2 are then tested for exact overlap
  using edge-triangle intersection tests" (the exact kernel,
  :func:`refsim.collision.triangle_batch.triangles_intersect_batch`).

Cost: test 2 is O(ka kb) for the ka, kb triangles in the overlap region,
vectorized in blocks of ``BLOCK_PAIRS``; test 3 is O(pairs passing test 2).
"""

from __future__ import annotations

import numpy as np

from refsim.collision.boxes import triangle_boxes
from refsim.errors import StateError
from refsim.kernels import CERTIFIED_FILTER

#: Box pairs tested per vectorized block: bounds the temporary arrays to a
#: few tens of MB (6 bool arrays of this many entries) whatever the meshes.
BLOCK_PAIRS = 1 << 22


def candidate_triangles(lo: np.ndarray, hi: np.ndarray, region_lo, region_hi) -> np.ndarray:
    """Indices of the triangle boxes that reach into the region (closed)."""
    inside = np.all(lo <= region_hi, axis=1) & np.all(hi >= region_lo, axis=1)
    return np.flatnonzero(inside)


def triangle_box_pairs(world_a, faces_a, world_b, faces_b) -> np.ndarray:
    """Test 2: every (i, j) whose triangle boxes overlap; (k, 2) int64, sorted.

    ``world_a``, ``world_b`` are the bodies' vertices already in world space.
    """
    lo_a, hi_a = triangle_boxes(world_a, faces_a)
    lo_b, hi_b = triangle_boxes(world_b, faces_b)
    # Test 1 on the same floats: the object boxes are the unions of the
    # triangle boxes.
    region_lo = np.maximum(lo_a.min(axis=0), lo_b.min(axis=0))
    region_hi = np.minimum(hi_a.max(axis=0), hi_b.max(axis=0))
    if np.any(region_lo > region_hi):
        return np.empty((0, 2), dtype=np.int64)
    ia = candidate_triangles(lo_a, hi_a, region_lo, region_hi)
    ib = candidate_triangles(lo_b, hi_b, region_lo, region_hi)
    if len(ia) == 0 or len(ib) == 0:
        return np.empty((0, 2), dtype=np.int64)
    found = []
    rows = max(1, BLOCK_PAIRS // len(ib))
    for start in range(0, len(ia), rows):
        block = ia[start:start + rows]
        overlap = np.all(lo_a[block, None, :] <= hi_b[None, ib, :], axis=2)
        overlap &= np.all(lo_b[None, ib, :] <= hi_a[block, None, :], axis=2)
        r, c = np.nonzero(overlap)
        found.append(np.column_stack([block[r], ib[c]]))
    pairs = np.concatenate(found).astype(np.int64)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


def exact_pairs(world_a, faces_a, world_b, faces_b, candidates: np.ndarray,
                kernel: str = "readable") -> np.ndarray:
    """Test 3: the candidate pairs whose triangles really intersect.

    ``kernel``: "readable" uses the numpy batch kernel, "compiled" its compiled
    copy; both hand the pairs their float filter cannot certify to the
    readable exact kernel, so the answers are the same.
    """
    if len(candidates) == 0:
        return candidates
    return candidates[CERTIFIED_FILTER.pick(kernel)(world_a, faces_a, world_b, faces_b,
                                                    candidates)]


def intersecting_batch(world_a, faces_a, world_b, faces_b, candidates: np.ndarray
                       ) -> np.ndarray:
    """(k,) bool: which candidate face pairs intersect, by the numpy batch
    kernel (:func:`refsim.collision.triangle_batch.triangles_intersect_batch`)."""
    from refsim.collision.triangle_batch import triangles_intersect_batch

    return triangles_intersect_batch(world_a[faces_a[candidates[:, 0]]],
                                     world_b[faces_b[candidates[:, 1]]])


def intersecting_compiled(world_a, faces_a, world_b, faces_b, candidates: np.ndarray
                          ) -> np.ndarray:
    """:func:`intersecting_batch` by the compiled filter and exact stage
    (:func:`refsim.collision.triangle_numba.intersecting_indexed`): the same
    answers."""
    from refsim.collision.triangle_numba import intersecting_indexed

    if not (np.isfinite(world_a).all() and np.isfinite(world_b).all()):
        raise StateError("a transformed vertex is not finite (pose too large?)")
    return intersecting_indexed(world_a, faces_a, world_b, faces_b, candidates)
