"""trimesh as the oracle for boxes of transformed meshes, convexity and mass
properties (seeds S1, S2).

trimesh (M. Dawson-Haggerty et al., https://trimesh.org) is an independent
mesh library: its bounds come from its own transform code, its convexity test
from its own face-adjacency projections, its volume and centre of mass from
the integrals of D. Eberly, "Polyhedral Mass Properties (Revisited)", 2002.

Conventions converted here and nowhere else:

- ``trimesh.Trimesh(vertices, faces, process=False)``: the default
  ``process=True`` merges duplicate vertices and drops degenerate faces,
  which would change the mesh being checked.
- A pose ``(R, t)`` becomes the homogeneous 4x4 ``[[R, t], [0, 1]]``, applied
  to the vertices with ``PointCloud.apply_transform`` (trimesh's
  ``transform_points``, the code ``Trimesh.apply_transform`` uses too);
  ``.bounds`` is the (2, 3) array
  ``[lo, hi]``. trimesh computes ``matrix @ [v, 1]`` with BLAS (fused
  multiply-adds, its own summation order), so its coordinates may differ
  from refsim's in the last bits, by at most the arithmetic bound of any
  float64 evaluation of ``R v + t``
  (:func:`refsim.studies.bounds.bounds_tolerance`).
- trimesh skips a transform within 1e-8 of the identity (every entry;
  ``transform_points`` returns early), so for such poses its box is the
  untransformed one. :func:`trimesh_skips_transform` tells when.
- ``is_convex``, ``volume``, ``center_mass`` are trimesh's (the solid's
  centroid, not refsim's vertex average).

Cost: building a Trimesh is O(n + m); a transform is O(n); convexity is
O(m) after trimesh's adjacency (O(m log m)).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np
from refsim.oracles import import_engine

#: trimesh's identity shortcut: ``apply_transform`` returns early when every
#: entry of the 4x4 is within this of the identity's (trimesh.base, 4.x).
TRIMESH_IDENTITY_ATOL = 1e-8

class MeshFactsOracle(Protocol):
    """The queries refsim's mesh facts are checked with."""

    def is_convex(self, vertices, faces) -> bool: ...

    def is_watertight(self, vertices, faces) -> bool: ...

    def volume(self, vertices, faces) -> float: ...

    def center_mass(self, vertices, faces) -> np.ndarray: ...

    def moment_inertia(self, vertices, faces, mass: float) -> np.ndarray: ...


def pose_matrix(pose) -> np.ndarray:
    """The homogeneous 4x4 of refsim's pose ``(R, t)``."""
    rotation, translation = pose
    matrix = np.eye(4)
    matrix[:3, :3] = rotation
    matrix[:3, 3] = translation
    return matrix


def trimesh_skips_transform(pose) -> bool:
    """Whether trimesh would treat ``pose`` as the identity and not apply it."""
    return bool(np.abs(pose_matrix(pose) - np.eye(4)).max() < TRIMESH_IDENTITY_ATOL)


class TrimeshOracle:
    """trimesh behind the engine contract's ``aabb`` and refsim's mesh-facts
    interface (lazy import).

    Raises :class:`refsim.oracles.OracleUnavailable` when trimesh is not installed.
    """

    name = "trimesh"

    def __init__(self):
        self.trimesh = import_engine("trimesh", "trimesh")

    def _mesh(self, vertices, faces):
        return self.trimesh.Trimesh(vertices=np.asarray(vertices, dtype=np.float64),
                                    faces=np.asarray(faces, dtype=np.int64), process=False)

    def aabb(self, vertices, pose) -> tuple[np.ndarray, np.ndarray]:
        """World box ``(lo, hi)`` of the points under ``pose``, by trimesh (a
        ``PointCloud`` transformed by its own ``apply_transform``)."""
        cloud = self.trimesh.PointCloud(np.array(vertices, dtype=np.float64))
        cloud.apply_transform(pose_matrix(pose))
        bounds = np.asarray(cloud.bounds, dtype=np.float64)
        return bounds[0].copy(), bounds[1].copy()

    def is_convex(self, vertices, faces) -> bool:
        return bool(self._mesh(vertices, faces).is_convex)

    def is_watertight(self, vertices, faces) -> bool:
        """Closed: every edge shared by exactly two consistently wound faces."""
        return bool(self._mesh(vertices, faces).is_watertight)

    def volume(self, vertices, faces) -> float:
        return float(self._mesh(vertices, faces).volume)

    def center_mass(self, vertices, faces) -> np.ndarray:
        return np.asarray(self._mesh(vertices, faces).center_mass, dtype=np.float64)

    def moment_inertia(self, vertices, faces, mass: float) -> np.ndarray:
        """(3, 3) inertia tensor about the centre of mass of the uniform solid
        of total ``mass`` (trimesh works with a density: converted here)."""
        mesh = self._mesh(vertices, faces)
        mesh.density = mass / mesh.volume
        return np.asarray(mesh.moment_inertia, dtype=np.float64)


def engine() -> TrimeshOracle:
    """The engine factory (``refsim.oracles.trimesh_adapter:engine``)."""
    return TrimeshOracle()
