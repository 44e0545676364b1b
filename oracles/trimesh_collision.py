"""trimesh's ``CollisionManager`` as a body-level collision oracle (seed S4).

``trimesh.collision.CollisionManager`` (trimesh 4.x/5.x, collision.py) puts
meshes into python-fcl's ``DynamicAABBTreeCollisionManager`` and answers
"does anything collide?". It is an independent path to FCL (its own mesh
conversion, its own transforms, FCL's broad phase), and it answers a
different question from refsim's in two documented ways:

1. **Volume against surface.** ``CollisionManager._get_fcl_obj`` turns a mesh
   that trimesh finds convex (``Trimesh.is_convex``) into an ``fcl.Convex``, a
   solid tested with GJK; only a non-convex mesh stays an ``fcl.BVHModel``, a
   triangle surface. So for trimesh a small body entirely inside a convex one
   collides (two Convex solids: GJK; a BVHModel's triangles inside a Convex
   solid: each triangle against the solid), while for refsim (and FCL on two
   BVHModels, :mod:`refsim.oracles.fcl_adapter`) two surfaces that do not meet do
   not collide. A body inside a *non-convex* one (a cube in the torus's hole,
   or inside a non-convex solid) is not found by trimesh either: the
   non-convex mesh is only a surface. GJK also stops at a tolerance (FCL's
   default GJK tolerance is about 1e-6), so a gap or an overlap of that size
   between convex bodies can go either way.
2. **float32 transforms.** ``add_object`` casts the 4x4 transform to
   ``np.float32`` before building the ``fcl.Transform``: every rotation entry
   and translation is rounded to 24 bits (relative error up to 2**-24, about
   6e-8; the rounded rotation is orthonormal only to about that). A touching
   or grazing configuration, or one whose answer turns on a gap smaller than
   ~1e-7 of the coordinates, can flip. (``in_collision_single`` does not cast;
   this adapter adds both bodies with ``add_object``, the manager's normal
   use, so both poses are rounded.) :func:`float32_pose` returns the pose
   trimesh really applies, so a disagreement can be re-run in refsim with it.

Conventions converted here and nowhere else:

- A refsim ``Mesh`` becomes ``trimesh.Trimesh(vertices, faces, process=False)``
  (no merging or dropping of faces: the same triangles refsim tests).
- A pose ``(R, t)`` becomes the homogeneous 4x4 ``[[R, t], [0, 1]]``.

Cost: per query, building the FCL objects (a Convex is O(n); a BVHModel is
O(m log m)) plus FCL's broad and narrow phase. Trimesh objects are cached per
refsim mesh (keyed by ``id(mesh)``, the mesh kept alive alongside), so their
convexity test runs once.
"""

from __future__ import annotations

import numpy as np
from refsim.oracles import OracleUnavailable, import_engine
from refsim.oracles.trimesh_adapter import pose_matrix

from refsim.engines.cache import MeshCache


def float32_pose(pose):
    """The pose trimesh's ``add_object`` really applies: every entry of the
    4x4 rounded to float32 (then widened back to float64 exactly)."""
    matrix = pose_matrix(pose).astype(np.float32).astype(np.float64)
    return matrix[:3, :3].copy(), matrix[:3, 3].copy()


class TrimeshCollisionOracle:
    """``trimesh.collision.CollisionManager`` behind the engine contract's
    boolean query (capability ``collide``).

    Besides ``bodies_collide`` it declares its conventions, which the levels
    study and the conformance kit use to classify a disagreement
    (:func:`refsim.engines.body_conventions`): :meth:`pose_used` (the
    float32 pose it applies), :meth:`is_solid` (a convex mesh is a solid to
    it) and ``distance_tolerance``.

    Raises :class:`refsim.oracles.OracleUnavailable` when trimesh or python-fcl is
    not installed.
    """

    name = "trimesh"

    #: Metres (:func:`refsim.engines.declarations`): FCL's GJK, which the
    #: CollisionManager runs on two convex meshes, stops at a tolerance of
    #: about 1e-6 (its default ``gjk_tolerance``), so a gap or an overlap that
    #: small between convex bodies can go either way (the conformance kit's
    #: trimesh engine, :class:`refsim.oracles.trimesh_engine.TrimeshEngine`,
    #: declares the same).
    distance_tolerance = 1e-6

    def __init__(self):
        self.trimesh = import_engine("trimesh", "trimesh")
        import_engine("fcl", "python-fcl")          # CollisionManager needs it
        self.collision = import_engine("trimesh.collision", "trimesh")
        if getattr(self.collision, "fcl", None) is None:
            raise OracleUnavailable("trimesh.collision could not import python-fcl")
        self._meshes = MeshCache(lambda v, f: self.trimesh.Trimesh(
            vertices=np.asarray(v, dtype=np.float64), faces=np.asarray(f, dtype=np.int64),
            process=False))

    def is_solid(self, vertices, faces) -> bool:
        """Whether trimesh treats the mesh as a solid ``fcl.Convex`` (else a
        surface ``fcl.BVHModel``)."""
        return bool(self._meshes.get(vertices, faces).is_convex)

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b,
                       pose_b) -> bool:
        """trimesh's answer: both bodies added to a fresh CollisionManager
        (``add_object``, float32 transforms), then ``in_collision_internal``."""
        manager = self.collision.CollisionManager()
        manager.add_object("a", self._meshes.get(vertices_a, faces_a),
                           transform=pose_matrix(pose_a))
        manager.add_object("b", self._meshes.get(vertices_b, faces_b),
                           transform=pose_matrix(pose_b))
        return bool(manager.in_collision_internal())

    @staticmethod
    def pose_used(pose):
        """The pose trimesh applies for ``pose`` (see :func:`float32_pose`)."""
        return float32_pose(pose)


def engine() -> TrimeshCollisionOracle:
    """The engine factory (``refsim.oracles.trimesh_collision:engine``)."""
    return TrimeshCollisionOracle()
