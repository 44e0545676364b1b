"""DART (dartpy) as a refsim engine: capabilities ``rigid`` and ``collide``.

Library: dartpy 6.20.0 (PyPI ``dartpy``), the Python binding of DART, the Dynamic
Animation and Robotics Toolkit (https://dartsim.github.io/).

Meshes. dartpy builds a ``MeshShape`` only from an assimp ``aiScene`` (its constructor
takes one), so each mesh is written to a temporary OBJ file and loaded by
``dartpy.utils.DartLoader.parseSkeletonString`` from a one-link URDF whose
``<collision>`` is that file, as a ``Skeleton`` with a ``FreeJoint``.

``simulate(scene)``: a ``dartpy.simulation.World`` with the scene's step
(``World.setTimeStep``) and gravity vector (``World.setGravity``); ``World.step()``
once per step of the duration, every step recorded (frame 0 is the start). Each
body's URDF ``<inertial>`` is the uniform solid's mass, centre and inertia, computed
here from the closed mesh. Each present wall is a 1 m thick ``BoxShape`` slab just
outside the cube on one immobile skeleton (``Skeleton.setMobile(False)``). Contact:
DART's defaults, FCL collision detection (``make_engine``; ``bullet`` and ``ode``
choose DART's other detectors, ``World.getConstraintSolver().setCollisionDetector``)
and the boxed-LCP contact solver; DART's step is semi-implicit Euler (World::step
integrates velocities, solves contacts, then integrates positions). The scene's
``integration.solver`` is not DART's to choose and is ignored.

``bodies_collide``: the two meshes as ``SimpleFrame`` shapes in two collision groups
of the same detector, ``CollisionGroup.collide(other, CollisionOption(False, 1))``.
No ``intersecting_pairs``: DART's contact list is a set of contact points, repeated
and collinear ones removed (``markRepeatedPoints``, ``markColinearPoints`` in
dart/collision/fcl/FCLCollisionDetector.cpp), so its ``triID1``/``triID2`` name only
the surviving points' triangles (measured: dartpy.md).

Coefficients. DART combines a contact's two shapes as ``e = e_A * e_B`` and
``mu = min(mu_A, mu_B)`` (dart/constraint/ContactConstraint.cpp:
``mRestitutionCoeff = restitutionCoeffA * restitutionCoeffB``, ``std::min(
primaryFrictionCoeffA, primaryFrictionCoeffB)``). Every body and wall gets
``sqrt(e)`` and the world's Coulomb mu (``WorldConfig.coulomb_mu``: ``mu``, else
``friction``), so every contact has the scene's e and mu. Per-body and per-pair
coefficients are refused by name (``honoured_keys``); DART's bounce threshold is its
own, 0.1 m/s (``DART_BOUNCING_VELOCITY_THRESHOLD``), so a scene's
``restitution_threshold`` is refused too.

Declarations:

- ``distance_tolerance`` = sqrt(3) 2^-24 2 m = 2.1e-7 m: assimp stores vertices as
  ``ai_real``, ``float`` unless built with ``ASSIMP_DOUBLE_PRECISION`` (assimp's
  include/assimp/defs.h, https://github.com/assimp/assimp); measured, 0.1 comes back
  0.10000000149 (``MeshShape.getBoundingBox``). Half a float32 ulp of each of three
  coordinates up to 2 m (every mesh the kit poses lies within 1.46 m of its origin).
- ``contact_law``: the default, ``"restitution"`` (ContactConstraint.cpp, above).
- ``integrator_order`` = 1: ``World::step`` integrates velocities, solves the
  contacts, then integrates positions with the new velocities (semi-implicit
  Euler, first order).
- No ``box_slack``: no ``aabb`` capability.
"""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import dartpy as dart
import numpy as np

from refsim import Trajectory
from refsim.scenes.support import refuse_unhonoured

WALL_THICKNESS = 1.0          # metres: the slab of each wall, outside the cube
#: Half a float32 ulp (2^-24 relative) of a coordinate up to 2 m, on each of three axes.
FLOAT32_ROUNDING = math.sqrt(3.0) * 2.0**-24 * 2.0
DETECTORS = {"fcl": dart.collision.FCLCollisionDetector,
             "bullet": dart.collision.BulletCollisionDetector,
             "ode": dart.collision.OdeCollisionDetector}
URDF = """<robot name="{name}"><link name="{name}">
<inertial><origin xyz="{c[0]!r} {c[1]!r} {c[2]!r}"/><mass value="{m!r}"/>
<inertia ixx="{I[0][0]!r}" ixy="{I[0][1]!r}" ixz="{I[0][2]!r}" iyy="{I[1][1]!r}"
 iyz="{I[1][2]!r}" izz="{I[2][2]!r}"/></inertial>
<collision><geometry><mesh filename="{uri}"/></geometry></collision>
</link></robot>"""


def solid_properties(vertices, faces, mass):
    """Centre of mass and inertia about it (mesh frame) of the uniform solid of
    ``mass`` bounded by the closed, outward-wound mesh (tetrahedra from the origin)."""
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    volume = det.sum() / 6.0
    centre = (det[:, None] * (a + b + c)).sum(axis=0) / (24.0 * volume)
    s = a + b + c
    second = sum(np.einsum("i,ij,ik->jk", det, p, p) for p in (a, b, c, s)) / 120.0
    second *= mass / volume                     # integral of rho x x^T about the origin
    origin = np.trace(second) * np.eye(3) - second
    shift = mass * (centre @ centre * np.eye(3) - np.outer(centre, centre))
    return centre, origin - shift


def _isometry(R, t):
    T = dart.math.Isometry3()
    T.set_rotation(np.asarray(R, dtype=np.float64))
    T.set_translation(np.asarray(t, dtype=np.float64))
    return T


class DartEngine:
    #: metres: assimp stores a mesh's vertices as float32 (module docstring).
    distance_tolerance = FLOAT32_ROUNDING
    #: semi-implicit Euler (module docstring).
    integrator_order = 1
    honoured_keys = ("world.gravity_direction", "world.walls", "world.mu",
                     "body.fixed", "body.force", "body.torque")

    def __init__(self, detector: str = "fcl"):
        self.detector = detector
        self.name = f"dartpy-{detector}"
        self._shapes: dict = {}               # mesh bytes -> (skeleton kept alive, shape)

    def simulate(self, scene):
        refuse_unhonoured(scene, self.name, self.honoured_keys)
        world = dart.simulation.World()
        if self.detector != "fcl":            # FCL is the World's default
            world.getConstraintSolver().setCollisionDetector(DETECTORS[self.detector]())
        h = scene.integration.step
        world.setTimeStep(h)
        world.setGravity(np.asarray(scene.world.gravity_vector, dtype=np.float64))
        world.addSkeleton(self._walls(scene.world))
        with tempfile.TemporaryDirectory() as tmp:
            nodes = [self._body(world, scene, body, i, Path(tmp))
                     for i, body in enumerate(scene.bodies)]
        n = scene.integration.n_steps
        B = len(nodes)
        pos, vel, ang = (np.zeros((n + 1, B, 3)) for _ in range(3))
        rot = np.zeros((n + 1, B, 3, 3))
        for k in range(n + 1):
            for i, ((node, centre), body) in enumerate(zip(nodes, scene.bodies, strict=True)):
                T = node.getWorldTransform()
                pos[k, i], rot[k, i] = T.translation(), T.rotation()
                vel[k, i] = node.getCOMLinearVelocity()
                ang[k, i] = node.getAngularVelocity()
                if k < n and not body.fixed:
                    node.addExtForce(np.asarray(body.force, dtype=np.float64),
                                     centre, False, True)
                    node.addExtTorque(np.asarray(body.torque, dtype=np.float64), False)
            if k < n:
                world.step()
        return Trajectory(t=np.arange(n + 1) * h, position=pos, velocity=vel,
                          angular_velocity=ang, orientation=rot,
                          names=tuple(b.name for b in scene.bodies))

    def _walls(self, world_config):
        walls = dart.dynamics.Skeleton("walls")
        H, T = world_config.half_size, WALL_THICKNESS
        for name in world_config.walls:
            axis, sign = "xyz".index(name[0]), (1.0 if name[1] == "+" else -1.0)
            size = np.full(3, 2 * (H + T))
            size[axis] = T
            centre = np.zeros(3)
            centre[axis] = sign * (H + T / 2)
            joint, node = walls.createWeldJointAndBodyNodePair()
            joint.setTransformFromParentBodyNode(_isometry(np.eye(3), centre))
            shape = node.createShapeNode(dart.dynamics.BoxShape(size))
            shape.createCollisionAspect()
            dynamics = shape.createDynamicsAspect()
            dynamics.setRestitutionCoeff(math.sqrt(world_config.restitution))
            dynamics.setFrictionCoeff(world_config.coulomb_mu)
        walls.setMobile(False)
        return walls

    def _body(self, world, scene, body, i, tmp):
        mesh = scene.mesh(body)
        vertices = np.asarray(mesh.vertices, dtype=np.float64) * body.scale
        faces = np.asarray(mesh.faces)
        centre, inertia = solid_properties(vertices, faces, body.mass)
        skeleton = load_mesh(vertices, faces, tmp / f"body{i}", centre, body.mass, inertia)
        node = skeleton.getBodyNode(0)
        dynamics = node.getShapeNode(0).getDynamicsAspect()
        dynamics.setRestitutionCoeff(math.sqrt(scene.world.restitution))
        dynamics.setFrictionCoeff(scene.world.coulomb_mu)
        R = np.asarray(body.orientation, dtype=np.float64)
        joint = skeleton.getJoint(0)
        joint.setTransform(_isometry(R, body.position))
        if body.fixed:
            skeleton.setMobile(False)
        else:
            w = np.asarray(body.angular_velocity, dtype=np.float64)
            world_frame = dart.dynamics.Frame.World()
            joint.setAngularVelocity(w, world_frame, world_frame)
            # The scene's velocity is the centre of mass's; the joint's, the origin's.
            v_origin = np.asarray(body.velocity, dtype=np.float64) - np.cross(w, R @ centre)
            joint.setLinearVelocity(v_origin, world_frame, world_frame)
        world.addSkeleton(skeleton)
        return node, centre

    # -- collide: one binary query of DART's collision detector ---------------------

    def _shape(self, vertices, faces):
        key = (vertices.tobytes(), np.asarray(faces).tobytes())
        if key not in self._shapes:
            with tempfile.TemporaryDirectory() as tmp:
                skeleton = load_mesh(np.asarray(vertices, dtype=np.float64),
                                     np.asarray(faces), Path(tmp) / "mesh")
            self._shapes[key] = (skeleton, skeleton.getBodyNode(0).getShapeNode(0).getShape())
        return self._shapes[key][1]

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b):
        detector = DETECTORS[self.detector]()
        frames, groups = [], []
        for name, v, f, (R, t) in (("a", vertices_a, faces_a, pose_a),
                                   ("b", vertices_b, faces_b, pose_b)):
            frame = dart.dynamics.SimpleFrame(dart.dynamics.Frame.World(), name,
                                              _isometry(R, t))
            frame.setShape(self._shape(v, f))
            group = detector.createCollisionGroup()
            group.addShapeFrame(frame)
            frames.append(frame)
            groups.append(group)
        option = dart.collision.CollisionOption(False, 1)    # a yes/no answer
        return bool(groups[0].collide(groups[1], option, dart.collision.CollisionResult()))


def load_mesh(vertices, faces, stem: Path, centre=(0.0, 0.0, 0.0), mass=1.0,
              inertia=None):
    """A one-body skeleton (free joint) whose collision shape is the mesh, by way of
    an OBJ file and a URDF (dartpy builds a MeshShape only from an assimp scene)."""
    obj = stem.with_suffix(".obj")
    obj.write_text("".join(f"v {x!r} {y!r} {z!r}\n" for x, y, z in vertices.tolist())
                   + "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces.tolist()))
    loader = dart.utils.DartLoader()
    options = loader.getOptions()
    options.mDefaultRootJointType = dart.utils.DartLoaderRootJointType.FLOATING
    loader.setOptions(options)
    urdf = URDF.format(name=stem.name, c=list(map(float, centre)), m=float(mass),
                       I=(np.eye(3) if inertia is None else inertia).tolist(),
                       uri=obj.as_uri())
    return loader.parseSkeletonString(urdf, dart.common.Uri(stem.parent.as_uri() + "/"))


def make_engine():
    """DART as it comes: the World's default collision detector, FCL."""
    return DartEngine("fcl")


def bullet():
    return DartEngine("bullet")


def ode():
    return DartEngine("ode")
