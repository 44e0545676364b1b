"""coal (the maintained successor of FCL) as the engine for triangle-triangle
overlap, mesh-mesh intersecting face pairs and body collision (seed S4).

coal (formerly hpp-fcl; J. Carpentier, L. Montaut and others,
github.com/coal-library/coal) keeps FCL's bounding volume hierarchies but
decides each leaf pair of a mesh-mesh query by GJK on the two triangles
(L. Montaut, Q. Le Lidec, V. Petrik, J. Sivic, J. Carpentier, "Collision
Detection Accelerated: An Optimization Perspective", RSS 2022), not by a
triangle-triangle test: ``MeshCollisionTraversalNode::leafCollides``
(``include/coal/internal/traversal_node_bvhs.h``) makes the two triangles
``TriangleP`` shapes and takes their distance from
``ShapeShapeDistance<TriangleP, TriangleP>``
(``src/distance/triangle_triangle.cpp``), which runs GJK alone. GJK
(``src/narrowphase/gjk.cpp``) reports a collision once its estimate of the
distance, an upper bound of the true one, falls below ``gjk_tolerance``
(1e-6 by default, ``narrowphase_defaults.h``; its check "A: rl <
tolerance"), so two triangles less than 1e-6 m apart may be called touching:
the engine declares that as its ``distance_tolerance``. The conformance kit
classes every difference from the exact answers.

Conventions converted here and nowhere else:

- A pose is refsim's ``(R (3, 3), t (3,))`` with world point ``R p + t``;
  ``coal.Transform3s(R, t)`` means the same map.
- Each triangle or mesh becomes a ``coal.BVHModelOBBRSS`` built by
  ``beginModel``, ``addVertices``, ``addTriangles``, ``endModel``
  (``addSubModel`` does not take numpy arrays; a model used before
  ``endModel`` crashes the interpreter).
- coal reports contacts, not face pairs: a ``CollisionRequest`` with room
  for every pair (:data:`MAX_CONTACTS`) lists one contact per colliding
  triangle pair; they are reduced to sorted unique ``(b1, b2)`` rows.

No ``aabb``: coal's world box of a posed object,
``CollisionObject::computeAABB`` (``include/coal/collision_object.h``), is
the box of the rotated local box (J. Arvo, "Transforming Axis-Aligned
Bounding Boxes", Graphics Gems, 1990), not of the rotated vertices. It
encloses them, but under a rotation it is wider by a fraction of the
model's size (up to 4/sqrt(3) times its largest half-extent, per side), a
slack in proportion to size that a ``box_slack`` in metres cannot declare
for bodies from 1e-12 to 1e3 m; docs/decisions/coal.md has the measurement.

BVH models are built once per mesh and cached in the adapter object
(:class:`refsim.engines.cache.MeshCache`: by identity for read-only arrays,
such as a ``refsim.Mesh``'s, else by content).

The adapter is an engine (:mod:`refsim.engines`) with the capabilities
``triangles``, ``pairs`` and ``collide``: ``refsim.oracles.coal_adapter:engine``.

Cost: building a model is O(m log m) for m faces; a query is coal's BVH
traversal, output-sensitive in the number of intersecting pairs, each leaf
pair one GJK run of at most ``gjk_max_iterations`` (128) steps.
"""

from __future__ import annotations

import numpy as np
from refsim.oracles import import_engine, install_hint

from refsim.engines.cache import MeshCache

#: Upper bound on contacts requested from coal when listing all intersecting
#: face pairs: coal stops collecting at this count, and records one contact
#: per colliding triangle pair, so it need only exceed m_a * m_b for the
#: largest meshes compared (2k x 2k triangles: 4e6).
MAX_CONTACTS = 100_000_000


class CoalEngine:
    """coal behind the engine contract (lazy import)."""

    name = "coal"

    #: Metres (:func:`refsim.engines.declarations`): GJK's default
    #: ``gjk_tolerance``, below which coal's triangle-triangle leaf test
    #: reports a collision (module docstring).
    distance_tolerance = 1e-6

    def __init__(self):
        self.coal = import_engine("coal", "coal", install_hint(["coal"]))
        self._models = MeshCache(self._bvh)
        # side (0: first body, 1: second) -> (model, its CollisionObject)
        self._posed: dict[int, tuple] = {}

    # -- models --------------------------------------------------------------

    def _bvh(self, vertices, faces):
        """A ``BVHModelOBBRSS`` of ``vertices`` (n, 3) and ``faces`` (m, 3)."""
        model = self.coal.BVHModelOBBRSS()
        model.beginModel(len(faces), len(vertices))
        model.addVertices(np.ascontiguousarray(vertices, dtype=np.float64))
        model.addTriangles(np.ascontiguousarray(faces, dtype=np.int64))
        model.endModel()
        return model

    def _transform(self, pose):
        rotation, translation = pose
        return self.coal.Transform3s(np.asarray(rotation, dtype=np.float64),
                                     np.asarray(translation, dtype=np.float64))

    def _objects(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b):
        """The two bodies' collision objects at their poses: one object per
        side, built once for its model and posed per query
        (``setTransform``), as a simulation loop uses coal."""
        return (self._posed_object(0, self._models.get(vertices_a, faces_a), pose_a),
                self._posed_object(1, self._models.get(vertices_b, faces_b), pose_b))

    def _posed_object(self, side: int, model, pose):
        entry = self._posed.get(side)
        if entry is None or entry[0] is not model:
            entry = self._posed[side] = (model, self.coal.CollisionObject(model))
        entry[1].setTransform(self._transform(pose))
        return entry[1]

    # -- queries -------------------------------------------------------------

    def triangles_intersect(self, a, b) -> bool:
        """coal's answer for two triangles (3, 3), each a one-face model."""
        coal = self.coal
        face = np.array([[0, 1, 2]])
        o1 = coal.CollisionObject(self._bvh(np.asarray(a, np.float64), face))
        o2 = coal.CollisionObject(self._bvh(np.asarray(b, np.float64), face))
        return coal.collide(o1, o2, coal.CollisionRequest(), coal.CollisionResult()) > 0

    def intersecting_pairs(self, vertices_a, faces_a, pose_a, vertices_b, faces_b,
                           pose_b) -> np.ndarray:
        """All (face of a, face of b) pairs coal finds intersecting.

        Returns a (k, 2) int64 array of sorted unique rows.
        """
        coal = self.coal
        o1, o2 = self._objects(vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b)
        request = coal.CollisionRequest()
        request.num_max_contacts = MAX_CONTACTS
        result = coal.CollisionResult()
        coal.collide(o1, o2, request, result)
        pairs = np.array([(c.b1, c.b2) for c in result.getContacts()], dtype=np.int64)
        if len(pairs) == 0:
            return np.zeros((0, 2), dtype=np.int64)
        return np.unique(pairs.reshape(-1, 2), axis=0)

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b,
                       pose_b) -> bool:
        """coal's boolean answer: do the two posed meshes touch or overlap?"""
        coal = self.coal
        o1, o2 = self._objects(vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b)
        return coal.collide(o1, o2, coal.CollisionRequest(), coal.CollisionResult()) > 0


def engine() -> CoalEngine:
    """The engine factory (``refsim.oracles.coal_adapter:engine``)."""
    return CoalEngine()
