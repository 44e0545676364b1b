"""Bounding spheres about the centroid: the coarsest of the seed's four types
of body-body collision test (seed S4: the fourth type of test).

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

from refsim.types import Pose, transform_points, unit_exponent

#: The radius is inflated by this relative amount, so that the rounding of
#: the square root and of the transformed centre (a few ulps each) can never
#: make the sphere miss a vertex: 16 ulps is far above that error and far
#: below any geometric effect.
SPHERE_PAD = 16 * np.finfo(np.float64).eps


def _unit_sphere(mesh) -> tuple[np.ndarray, float, int]:
    """``(centre, rho, e)``: the centre in body space and the padded radius
    ``rho * 2**e``, with ``rho`` computed in the mesh's unit coordinates
    (:func:`refsim.types.unit_exponent`), so that it is finite for any mesh."""

    def build(m):
        e = unit_exponent(m.vertices)
        u = np.ldexp(m.vertices, -e)
        d = u - u.mean(axis=0)
        rho = float(np.sqrt((d * d).sum(axis=1).max()))
        return m.centroid_vertex_average, rho * (1.0 + SPHERE_PAD), e

    return mesh.derived("bounding_sphere", build)


def bounding_sphere(mesh) -> tuple[np.ndarray, float]:
    """``(centre, radius)`` in body space about the vertex-average centroid
    (the radius is inf for a mesh whose size float64 cannot hold)."""
    centre, rho, e = _unit_sphere(mesh)
    return centre, float(np.ldexp(rho, e))


def spheres_overlap(mesh_a, pose_a: Pose, mesh_b, pose_b: Pose) -> bool:
    """Whether the bodies' bounding spheres overlap (touching counts).

    Conservative for every finite input: the centres, radii and translations
    are first scaled by one power of two ``2**-k`` that brings the largest of
    them below 1 (exact), so that neither the centres' difference nor its
    square can overflow; a radius that underflows in that scale is below the
    pad's absolute term, which still covers it.
    """
    ca, rho_a, ea = _unit_sphere(mesh_a)
    cb, rho_b, eb = _unit_sphere(mesh_b)
    k = max(unit_exponent(ca), unit_exponent(cb), unit_exponent(pose_a[1]),
            unit_exponent(pose_b[1]), ea, eb)
    wa = transform_points(np.ldexp(ca, -k)[None], (pose_a[0], np.ldexp(pose_a[1], -k)))[0]
    wb = transform_points(np.ldexp(cb, -k)[None], (pose_b[0], np.ldexp(pose_b[1], -k)))[0]
    d = wa - wb
    gap = float(np.sqrt((d * d).sum()))
    reach = float(np.ldexp(rho_a, ea - k) + np.ldexp(rho_b, eb - k))
    return bool(gap <= reach * (1.0 + SPHERE_PAD) + SPHERE_PAD * float(
        np.abs(wa).max() + np.abs(wb).max()))
