"""Open3D (PyPI ``open3d``, a library for 3D data processing) as a refsim engine.

Capabilities and the library calls behind them:

- ``triangles``: each triangle becomes a one-triangle
  ``open3d.geometry.TriangleMesh`` and ``TriangleMesh.is_intersecting``
  ("Tests if the triangle mesh is intersecting the other triangle mesh")
  answers.
- ``collide``: both meshes are built in their body frames, put in the world
  by ``Geometry3D.transform`` (the pose as a 4x4 matrix, "Apply
  transformation (4x4 matrix) to the geometry coordinates"), and
  ``is_intersecting`` answers.
- ``pairs``: Open3D has no pair query between two meshes, but
  ``TriangleMesh.get_self_intersecting_triangles`` ("Returns a list of
  indices to triangles that intersect the mesh") on the two world meshes
  joined by ``+`` (which appends B's vertices and triangles after A's)
  returns every intersecting pair of the union; the pairs with one triangle
  from each mesh are the answer. The self test skips pairs that share a
  vertex index, and A and B share none, so no cross pair is skipped.
- ``aabb``: the vertices as an ``open3d.geometry.PointCloud``, ``transform``
  by the pose, then ``get_axis_aligned_bounding_box``.

Conventions: refsim's pose ``(R, t)`` maps a body point ``p`` to ``R p + t``;
the 4x4 matrix ``[[R, t], [0, 1]]`` is the same map. Open3D stores every
coordinate as a double (``Vector3dVector``), so nothing is rounded to
float32.

What the library documents, and what is declared from it:

- All three collision capabilities end in ``IntersectionTest::
  TriangleTriangle3d``, which centres and scales the six vertices per axis
  (by their mean and standard deviation) and calls Tomas Moeller's
  ``NoDivTriTriIsect`` ("A Fast Triangle-Triangle Intersection Test", JGT
  2(2), 1997), bundled in ``3rdparty/tomasakeninemoeller/opttritri.h``
  with ``USE_EPSILON_TEST TRUE`` and ``EPSILON 0.000001``: "if |dv|<EPSILON
  then dv=0.0". A vertex's plane value ``dv`` (the plane normal's length
  times its distance, in the scaled coordinates) below 1e-6 is snapped onto
  the other triangle's plane. This is a tolerance of the algorithm, in
  scaled units, not in metres: for the kit's triangles (about 1 m, scale
  about 1), it is about 1e-6 m. ``distance_tolerance`` declares that,
  ``MOLLER_EPSILON_METRES``; a miss beyond it is a finding (see
  ``open3d.md``).
- ``box_slack``: 0. ``get_axis_aligned_bounding_box`` is the min and max of
  the points, with no margin.
"""

from __future__ import annotations

import numpy as np
import open3d as o3d

#: Moeller's EPSILON (opttritri.h), read in metres for unit-scale triangles
#: (module docstring).
MOLLER_EPSILON_METRES = 1e-6


def _matrix(pose) -> np.ndarray:
    R, t = pose
    m = np.eye(4)
    m[:3, :3] = np.asarray(R, dtype=np.float64)
    m[:3, 3] = np.asarray(t, dtype=np.float64)
    return m


def _mesh(vertices, faces, pose=None) -> o3d.geometry.TriangleMesh:
    # np.array copies: the kit's arrays are read-only, and Open3D's
    # Vector3dVector refuses a buffer it cannot write ("array is not writeable").
    mesh = o3d.geometry.TriangleMesh(
        o3d.utility.Vector3dVector(np.array(vertices, dtype=np.float64).reshape(-1, 3)),
        o3d.utility.Vector3iVector(np.array(faces, dtype=np.int32).reshape(-1, 3)))
    if pose is not None:
        mesh.transform(_matrix(pose))
    return mesh


class Open3DEngine:
    """TriangleMesh.is_intersecting for triangles and collide,
    get_self_intersecting_triangles for pairs, PointCloud's
    get_axis_aligned_bounding_box for aabb."""

    name = "open3d"
    distance_tolerance = MOLLER_EPSILON_METRES
    box_slack = 0.0

    def triangles_intersect(self, a, b) -> bool:
        face = [[0, 1, 2]]
        return bool(_mesh(a, face).is_intersecting(_mesh(b, face)))

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b) -> bool:
        return bool(_mesh(vertices_a, faces_a, pose_a).is_intersecting(
            _mesh(vertices_b, faces_b, pose_b)))

    def intersecting_pairs(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b):
        a = _mesh(vertices_a, faces_a, pose_a)
        both = a + _mesh(vertices_b, faces_b, pose_b)
        found = np.asarray(both.get_self_intersecting_triangles(), dtype=np.int64).reshape(-1, 2)
        na = len(a.triangles)
        found = np.sort(found, axis=1)          # (lower index, higher index)
        cross = found[(found[:, 0] < na) & (found[:, 1] >= na)]
        return np.column_stack([cross[:, 0], cross[:, 1] - na]).astype(np.int64)

    def aabb(self, vertices, pose):
        points = o3d.utility.Vector3dVector(np.array(vertices, dtype=np.float64).reshape(-1, 3))
        cloud = o3d.geometry.PointCloud(points)
        cloud.transform(_matrix(pose))
        box = cloud.get_axis_aligned_bounding_box()
        return np.asarray(box.min_bound, dtype=np.float64), np.asarray(box.max_bound,
                                                                       dtype=np.float64)


def make_engine() -> Open3DEngine:
    return Open3DEngine()
