"""MeshLib (PyPI ``meshlib``, MeshInspector's C++ mesh library) as a refsim engine.

Capabilities and the library calls behind them:

- ``triangles``: each triangle becomes a one-face ``Mesh``
  (``mrmeshnumpy.meshFromFacesVerts``) and ``mrmeshpy.findCollidingTriangles(a,
  b, None, firstIntersectionOnly=True)`` answers; a non-empty answer is
  "they intersect".
- ``pairs``: the same query on the two whole meshes, every colliding
  ``FaceFace`` (``aFace``, ``bFace``) returned as a row.
- ``collide``: the same query with ``firstIntersectionOnly=True``; any pair
  means the surfaces meet.
- ``aabb``: the vertices as a ``PointCloud`` (``mrmeshnumpy.pointCloudFromPoints``)
  and ``PointCloud.computeBoundingBox(toWorld)``, the pose as an ``AffineXf3f``.

Two factories, for MeshLib's two collision methods: ``make_engine`` uses
``findCollidingTriangles`` (float predicates, ``doTrianglesIntersect`` in
double); ``make_engine_precise`` uses ``findCollidingEdgeTrisPrecise(a, b,
getVectorConverters(a, b).toInt)``, exact integer predicates with
simulation of simplicity ("removes the degenerate cases (segment passing
exactly through an edge or vertex of the triangle, or lying in the
triangle's plane), so the answer is always a clean yes/no", docstring of
``mrmeshpy.doTriangleSegmentIntersect``). It returns edge-triangle
crossings; both faces of a crossing edge meet the triangle, and every
crossing pair of triangles has such an edge, so those face pairs are the
answer. ``aabb`` is the same in both.

Conventions: refsim's pose ``(R, t)`` maps a body point ``p`` to ``R p + t``,
as MeshLib's ``AffineXf3f(A, b)`` does (``x -> A x + b``). For the three
collision capabilities the vertices are put in the world frame in float64
here and handed to MeshLib once, with no ``rigidB2A`` transform, so that
each coordinate is rounded only once. For ``aabb`` the pose is MeshLib's
``toWorld`` transform, applied by the library itself in float32.

What the library documents, and what is declared from it:

- ``Mesh::points`` is a ``VertCoords``, ``Vector<Vector3f, VertId>``
  (``source/MRMesh/MRMeshFwd.h``): every coordinate is a float32, and
  ``meshFromFacesVerts`` and ``pointCloudFromPoints`` round the float64
  array to it. The triangle test
  itself runs in double on those float32 points
  (``MRMeshCollide.cpp``: ``doTrianglesIntersect( Vector3d{ av[0] }, ...)``).
- ``doTrianglesIntersect``: "checks whether triangles ABC and DEF
  intersect; returns false if ABC and DEF are coplanar"
  (https://github.com/MeshInspector/MeshLib/blob/master/source/MRMesh/MRTriangleIntersection.h).
  Coplanar and touching pairs are therefore expected misses, listed in
  ``meshlib.expected``.
- ``distance_tolerance``: the float32 storage is a tolerance of the
  algorithm. Rounding a coordinate of magnitude ``|x| <= L`` to float32
  moves it by at most ``L * 2**-24``, a vertex by at most ``sqrt(3)`` times
  that, so two triangles' gap changes by at most ``2 * sqrt(3) * L *
  2**-24``. ``L`` is not known before the cases are seen; the declared value
  (1.65e-6 m) is for ``L = 8 m`` (``FLOAT32_SCALE``), above the largest world
  coordinate of the kit's triangle and mesh cases (7.4 m at 2000 cases,
  measured, see ``meshlib.md``). The kit's boxes reach 6.5e8 m, where float32
  spacing is 64 m: no absolute tolerance covers those.
- ``unit_roundoff`` = 2**-24: MeshLib computes on float32 points
  (``Vector3f``), so the kit scales its float64 rounding bounds to float32's,
  relative to each case's coordinates: the boxes' float32 rounding at any
  magnitude is class tolerance, not bug.
- ``box_slack``: 0. ``computeBoundingBox`` is documented as "the minimal
  bounding box", not a fattened one.
"""

from __future__ import annotations

import math

import numpy as np
from meshlib import mrmeshnumpy, mrmeshpy

#: The largest coordinate magnitude (metres) the declared tolerance covers.
FLOAT32_SCALE = 8.0
#: Two triangles' gap moves by at most this when every coordinate is rounded
#: to float32 (module docstring).
FLOAT32_GAP = 2.0 * math.sqrt(3.0) * FLOAT32_SCALE * 2.0**-24


def _world(vertices, pose) -> np.ndarray:
    R, t = pose
    return np.asarray(vertices, dtype=np.float64) @ np.asarray(R, dtype=np.float64).T \
        + np.asarray(t, dtype=np.float64)


def _mesh(vertices, faces) -> mrmeshpy.Mesh:
    faces = np.ascontiguousarray(faces, dtype=np.int32).reshape(-1, 3)
    mesh = mrmeshnumpy.meshFromFacesVerts(faces, np.ascontiguousarray(vertices, dtype=np.float64))
    if mesh.topology.faceSize() != len(faces):
        # A face index of MeshLib must be the row of ``faces`` it came from.
        raise ValueError(f"meshlib built {mesh.topology.faceSize()} faces from {len(faces)}")
    return mesh


def _xf(pose) -> mrmeshpy.AffineXf3f:
    R, t = (np.asarray(x, dtype=np.float64) for x in pose)
    rows = [mrmeshpy.Vector3f(*map(float, row)) for row in R]
    return mrmeshpy.AffineXf3f(mrmeshpy.Matrix3f(*rows), mrmeshpy.Vector3f(*map(float, t)))


class MeshLibEngine:
    """findCollidingTriangles for triangles, pairs and collide;
    computeBoundingBox for aabb."""

    name = "meshlib"
    distance_tolerance = FLOAT32_GAP
    unit_roundoff = 2.0 ** -24
    box_slack = 0.0

    def _colliding(self, va, fa, vb, fb, first_only: bool):
        a, b = _mesh(va, fa), _mesh(vb, fb)
        return mrmeshpy.findCollidingTriangles(mrmeshpy.MeshPart(a), mrmeshpy.MeshPart(b),
                                               None, first_only)

    def triangles_intersect(self, a, b) -> bool:
        face = np.array([[0, 1, 2]])
        return len(self._colliding(a, face, b, face, True)) > 0

    def intersecting_pairs(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b):
        found = self._colliding(_world(vertices_a, pose_a), faces_a,
                                _world(vertices_b, pose_b), faces_b, False)
        return np.array([(ff.aFace.get(), ff.bFace.get()) for ff in found],
                        dtype=np.int64).reshape(-1, 2)

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b) -> bool:
        return len(self._colliding(_world(vertices_a, pose_a), faces_a,
                                   _world(vertices_b, pose_b), faces_b, True)) > 0

    def aabb(self, vertices, pose):
        points = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        cloud = mrmeshnumpy.pointCloudFromPoints(points)
        box = cloud.computeBoundingBox(_xf(pose))
        return (np.array([box.min.x, box.min.y, box.min.z]),
                np.array([box.max.x, box.max.y, box.max.z]))

class MeshLibPreciseEngine(MeshLibEngine):
    """findCollidingEdgeTrisPrecise for triangles, pairs and collide (exact
    integer predicates); aabb as MeshLibEngine."""

    name = "meshlib-precise"

    def _edge_tris(self, va, fa, vb, fb, any_only: bool):
        a, b = _mesh(va, fa), _mesh(vb, fb)
        part_a, part_b = mrmeshpy.MeshPart(a), mrmeshpy.MeshPart(b)
        to_int = mrmeshpy.getVectorConverters(part_a, part_b).toInt
        found = mrmeshpy.findCollidingEdgeTrisPrecise(part_a, part_b, to_int, None, any_only)
        pairs = set()
        for hit in found:
            # An edge crossing a triangle is a point shared by both faces of the edge.
            edge_mesh = a if hit.isEdgeATriB() else b
            tri = hit.tri().get()
            for face in (edge_mesh.topology.left(hit.edge), edge_mesh.topology.right(hit.edge)):
                if face.valid():
                    pairs.add((face.get(), tri) if hit.isEdgeATriB() else (tri, face.get()))
        return sorted(pairs)

    def triangles_intersect(self, a, b) -> bool:
        face = np.array([[0, 1, 2]])
        return len(self._edge_tris(a, face, b, face, True)) > 0

    def intersecting_pairs(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b):
        found = self._edge_tris(_world(vertices_a, pose_a), faces_a,
                                _world(vertices_b, pose_b), faces_b, False)
        return np.array(found, dtype=np.int64).reshape(-1, 2)

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b) -> bool:
        return len(self._edge_tris(_world(vertices_a, pose_a), faces_a,
                                   _world(vertices_b, pose_b), faces_b, True)) > 0


def make_engine() -> MeshLibEngine:
    """findCollidingTriangles: float predicates on float32 points."""
    return MeshLibEngine()


def make_engine_precise() -> MeshLibPreciseEngine:
    """findCollidingEdgeTrisPrecise: exact predicates on the float32 points."""
    return MeshLibPreciseEngine()
