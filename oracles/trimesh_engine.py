"""trimesh as one conformance-kit engine: its boxes
(:mod:`refsim.oracles.trimesh_adapter`) and its CollisionManager
(:mod:`refsim.oracles.trimesh_collision`) are two adapters, one per
question trimesh answers; :class:`TrimeshEngine` puts them behind one
engine so that the kit's matrix has one trimesh column. The report asks
each adapter on its own (the registry's "trimesh-mesh" and
"trimesh-collision", :mod:`refsim.engines.registry`).

Cost: building the engine is O(1); each adapter loads trimesh (and
python-fcl) lazily, on its first answer.
"""

from __future__ import annotations


class TrimeshEngine:
    """trimesh's boxes (``aabb``) and its CollisionManager (``collide``) as
    one engine named "trimesh"; both adapters load lazily and raise
    :class:`refsim.oracles.OracleUnavailable` when trimesh (or python-fcl,
    for the CollisionManager) is missing."""

    name = "trimesh"

    #: Metres (:func:`refsim.engines.declarations`). The CollisionManager tests
    #: convex meshes as GJK solids, and FCL's GJK stops at a tolerance of 1e-6
    #: (its default ``gjk_tolerance``); it also rounds both poses to float32
    #: (6e-8 relative: below 3e-7 m at the kit's coordinates of a few metres).
    #: The boxes skip a transform within 1e-8 of the identity
    #: (:data:`refsim.oracles.trimesh_adapter.TRIMESH_IDENTITY_ATOL`), off by
    #: at most 1e-8 (|x| + |y| + |z| + 1), within the same tolerance.
    distance_tolerance = 1e-6

    #: The CollisionManager tests a convex mesh as the solid it bounds (GJK on
    #: its hull), so a body wholly inside another collides; :meth:`is_solid`
    #: says which meshes (a non-convex one stays a surface).
    solid = True

    def __init__(self):
        from refsim.oracles.trimesh_adapter import TrimeshOracle
        from refsim.oracles.trimesh_collision import TrimeshCollisionOracle

        self._boxes = TrimeshOracle()
        self._collision = TrimeshCollisionOracle()

    def aabb(self, vertices, pose):
        return self._boxes.aabb(vertices, pose)

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b) -> bool:
        return self._collision.bodies_collide(vertices_a, faces_a, pose_a, vertices_b, faces_b,
                                              pose_b)

    def is_solid(self, vertices, faces) -> bool:
        """Whether the CollisionManager tests the mesh as a solid (a convex
        mesh only): the container of a "containment" must be one."""
        return self._collision.is_solid(vertices, faces)

    @staticmethod
    def pose_used(pose):
        """The float32 pose the CollisionManager applies
        (:func:`refsim.oracles.trimesh_collision.float32_pose`)."""
        from refsim.oracles.trimesh_collision import float32_pose

        return float32_pose(pose)


def engine() -> TrimeshEngine:
    """The engine factory (``refsim.oracles.trimesh_engine:engine``)."""
    return TrimeshEngine()
