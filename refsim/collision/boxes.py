"""Axis-aligned boxes of bodies and triangles (seed S4): world vertices, the
boxes of triangles, and the closed overlap test.

Boxes are closed: boxes that share a face, an edge or a corner overlap, so
that touching bodies are never rejected (FCL's convention, and the one
refsim's exact test uses). The body-level broad phase over many boxes is
:mod:`refsim.collision.broad_phase`.

Cost: O(n) for the world vertices, O(m) for the triangle boxes, O(1) a test.
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
