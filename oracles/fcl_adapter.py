"""python-fcl as the oracle for triangle-triangle overlap and mesh-mesh
intersecting face pairs (seed S4).

FCL (J. Pan, S. Chitta, D. Manocha, "FCL: A General Purpose Library for
Collision and Proximity Queries", ICRA 2012) tests mesh pairs with a bounding
volume hierarchy and a floating-point triangle-triangle test. Its answers are
float answers: on touching and near-degenerate pairs they may differ from
refsim's exact ones, and ``refsim.studies.triangles`` classifies every such
difference.

Conventions converted here and nowhere else:

- A pose is refsim's ``(R (3, 3), t (3,))`` with world point ``R p + t``;
  FCL's ``fcl.Transform(R, t)`` means the same map.
- Each triangle or mesh becomes an ``fcl.BVHModel`` (beginModel, addSubModel,
  endModel: a model used without endModel crashes the interpreter).
  ``fcl.TriangleP`` is NOT used: python-fcl's ``collide`` does not support it
  and silently reports no collision.
- FCL reports contacts, not face pairs: with ``enable_contact`` a triangle
  pair can yield several contacts (two points for one crossing). They are
  reduced to sorted unique ``(b1, b2)`` face-index pairs.

BVH models are built once per mesh and cached in the adapter object
(:class:`refsim.engines.cache.MeshCache`: by identity for read-only arrays,
such as a ``refsim.Mesh``'s, else by content).

The adapter is an engine (:mod:`refsim.engines`) with the capabilities
``triangles``, ``pairs`` and ``collide``: ``refsim.oracles.fcl_adapter:engine``.

Cost: building a model is O(m log m) for m faces; a query is FCL's BVH
traversal, output-sensitive in the number of intersecting pairs.
"""

from __future__ import annotations

import numpy as np
from refsim.oracles import import_engine

from refsim.engines.cache import MeshCache

#: Upper bound on contacts requested from FCL when listing all intersecting
#: face pairs. FCL stops collecting at this count; it only needs to exceed
#: the pairs any test mesh pair produces (m_a * m_b * 2 for the largest
#: meshes we compare, 2k x 2k triangles, is 8e6).
MAX_CONTACTS = 100_000_000


class FCLOracle:
    """python-fcl behind the engine contract (lazy import)."""

    name = "fcl"

    def __init__(self):
        self.fcl = import_engine("fcl", "python-fcl")
        self._models = MeshCache(self._bvh)
        # side (0: first body, 1: second) -> (model, its CollisionObject)
        self._posed: dict[int, tuple] = {}

    # -- models --------------------------------------------------------------

    def _bvh(self, vertices, faces):
        fcl = self.fcl
        model = fcl.BVHModel()
        model.beginModel(len(vertices), len(faces))
        model.addSubModel(np.ascontiguousarray(vertices, dtype=np.float64),
                          np.ascontiguousarray(faces, dtype=np.int32))
        model.endModel()
        return model

    def _object(self, model, pose=None):
        fcl = self.fcl
        if pose is None:
            return fcl.CollisionObject(model, fcl.Transform())
        rotation, translation = pose
        return fcl.CollisionObject(model, fcl.Transform(
            np.asarray(rotation, dtype=np.float64), np.asarray(translation, dtype=np.float64)))

    def _objects(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b):
        """The two bodies' collision objects at their poses, as a simulation
        loop uses FCL: one object per side, built once for its model and
        posed per query (``setTransform``). Building two objects per query
        cost about as much again as FCL's query of bodies close together."""
        return (self._posed_object(0, self._models.get(vertices_a, faces_a), pose_a),
                self._posed_object(1, self._models.get(vertices_b, faces_b), pose_b))

    def _posed_object(self, side: int, model, pose):
        fcl = self.fcl
        entry = self._posed.get(side)
        if entry is None or entry[0] is not model:
            entry = self._posed[side] = (model, fcl.CollisionObject(model, fcl.Transform()))
        rotation, translation = pose
        entry[1].setTransform(fcl.Transform(np.asarray(rotation, dtype=np.float64),
                                            np.asarray(translation, dtype=np.float64)))
        return entry[1]

    # -- queries -------------------------------------------------------------

    def triangles_intersect(self, a, b) -> bool:
        """FCL's answer for two triangles (3, 3), each a one-face BVHModel."""
        face = np.array([[0, 1, 2]])
        o1 = self._object(self._bvh(np.asarray(a, np.float64), face))
        o2 = self._object(self._bvh(np.asarray(b, np.float64), face))
        request = self.fcl.CollisionRequest()
        result = self.fcl.CollisionResult()
        return self.fcl.collide(o1, o2, request, result) > 0

    def intersecting_pairs(self, vertices_a, faces_a, pose_a, vertices_b, faces_b,
                           pose_b) -> np.ndarray:
        """All (face of a, face of b) pairs FCL finds intersecting.

        Returns a (k, 2) int64 array of sorted unique rows.
        """
        fcl = self.fcl
        o1, o2 = self._objects(vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b)
        request = fcl.CollisionRequest(num_max_contacts=MAX_CONTACTS, enable_contact=True)
        result = fcl.CollisionResult()
        fcl.collide(o1, o2, request, result)
        pairs = np.array([(c.b1, c.b2) for c in result.contacts], dtype=np.int64)
        if len(pairs) == 0:
            return np.zeros((0, 2), dtype=np.int64)
        return np.unique(pairs.reshape(-1, 2), axis=0)

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b,
                       pose_b) -> bool:
        """FCL's boolean answer: do the two posed meshes touch or overlap?"""
        fcl = self.fcl
        o1, o2 = self._objects(vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b)
        return fcl.collide(o1, o2, fcl.CollisionRequest(), fcl.CollisionResult()) > 0


def engine() -> FCLOracle:
    """The engine factory (``refsim.oracles.fcl_adapter:engine``)."""
    return FCLOracle()
