"""Bounding spheres about the centroid: the coarsest of the seed's four types
of body-body collision test (seed S4; DESIGN.md names it the fourth type).

Each body gets the sphere centred at the seed's centroid (the average of its
vertices, S9) with radius the largest distance from there to a vertex. Two
bodies "collide" at this level when their spheres overlap (closed).

This level is conservative (it never misses a real contact) but it is not a
step of the box hierarchy: two bodies can have overlapping boxes and apart
spheres (long thin bodies side by side, tested near their corners), or the
reverse. Cost: O(n) per body for the radius (once), O(1) per test.
"""

from __future__ import annotations

import numpy as np

from refsim.types import Pose

#: The radius is inflated by this relative amount, so that the rounding of
#: the square root and of the transformed centre (a few ulps each) can never
#: make the sphere miss a vertex: 16 ulps is far above that error and far
#: below any geometric effect.
SPHERE_PAD = 16 * np.finfo(np.float64).eps


def bounding_sphere(mesh) -> tuple[np.ndarray, float]:
    """``(centre, radius)`` in body space about the vertex-average centroid."""

    def build(m):
        centre = m.centroid_vertex_average
        radius = float(np.sqrt(((m.vertices - centre) ** 2).sum(axis=1).max()))
        return centre, radius * (1.0 + SPHERE_PAD)

    return mesh.derived("bounding_sphere", build)


def spheres_overlap(mesh_a, pose_a: Pose, mesh_b, pose_b: Pose) -> bool:
    """Whether the bodies' bounding spheres overlap (touching counts)."""
    ca, ra = bounding_sphere(mesh_a)
    cb, rb = bounding_sphere(mesh_b)
    wa = pose_a[0] @ ca + pose_a[1]
    wb = pose_b[0] @ cb + pose_b[1]
    gap = float(np.linalg.norm(wa - wb))
    reach = ra + rb
    return bool(gap <= reach * (1.0 + SPHERE_PAD) + SPHERE_PAD * float(
        np.abs(wa).max() + np.abs(wb).max()))
