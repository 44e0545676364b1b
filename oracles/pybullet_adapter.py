"""pybullet as the oracle for wall bounces: the same scene, run by Bullet.

pybullet (E. Coumans and Y. Bai, https://pybullet.org; Bullet's
``btSequentialImpulseConstraintSolver``, a projected Gauss-Seidel solver of
velocity-level contact constraints, E. Catto, "Iterative Dynamics with
Temporal Coherence", GDC 2005) is an independent rigid-body engine. Here it
runs a refsim :class:`~refsim.scenes.schema.Scene`: the world cube's walls as
static boxes, each body as the convex hull of its mesh with its true mass
properties, the scene's gravity and time step (and the keys beyond the
seed's world: Scene keys, below). The result is a
:class:`~refsim.dynamics.trajectory.Trajectory`, frame for frame comparable
with ``refsim.simulate``.

Conventions converted here and nowhere else
-------------------------------------------

- Frames: refsim's orientation is a 3x3 matrix whose columns are the body's
  axes; pybullet's is a quaternion ``[x, y, z, w]`` (scipy's scalar-last
  order). pybullet's base pose and velocity are those of the *inertial* frame
  (centre of mass, principal axes); refsim's position and orientation are
  the mesh origin's and the mesh's axes, its velocity is the centre of
  mass's (:mod:`refsim.dynamics.trajectory`), as pybullet's is.
  :meth:`PybulletOracle.simulate` converts the pose both ways:
  ``R_link = R_inertial R_i^T`` and ``p_link = p_com - R_link c``, where ``c``
  and ``R_i`` are the centre of mass and principal axes in the mesh frame.
- Mass properties: pybullet's mesh shapes get the inertia of their bounding
  box (padded by the margin) unless told otherwise. Each body's principal
  moments (uniform solid of the body's mass, from trimesh's integrals, see
  :mod:`refsim.oracles.trimesh_adapter`) are passed with ``changeDynamics(mass=...,
  localInertiaDiagonal=...)``, and its centre of mass and principal axes as
  ``baseInertialFramePosition/Orientation`` of ``createMultiBody``.
  :func:`mass_properties` computes them (scale applied).
- Shape: ``createCollisionShape(GEOM_MESH, vertices=..., meshScale=...)``
  without indices builds a ``btConvexHullShape`` of the vertices, so a
  non-convex body (l-beam, star, torus) collides as its convex hull while its
  mass properties stay those of the mesh's solid. The bounce studies use
  convex bodies only.
- Angular velocity is in rad/s in both.

Every setting, and why (:class:`PybulletSettings` holds them)
--------------------------------------------------------------

- ``useMaximalCoordinates=True``: a single free body is a plain
  ``btRigidBody``, not a ``btMultiBody``. Measured here (sphere, e = 0.8,
  h = 1e-3, :func:`refsim.studies.bounce.measure_pybullet_settings`): the
  multibody path returns apex ratios 12% above e^2, the rigid-body path
  0.04% below.
- ``setTimeStep(scene.integration.step)``, ``numSubSteps=0``: one Bullet step
  per refsim step. Bullet integrates semi-implicit (symplectic) Euler:
  ``v += h F/m`` then ``x += h v``.
- ``contactProcessingThreshold=0`` (``changeDynamics``, every body and wall):
  Bullet otherwise hands the solver every contact point within the breaking
  threshold (0.02 m) and treats those still apart as *speculative*: the
  approach is stopped so that the gap closes exactly, with no restitution.
  High bounces are unaffected, but once a bounce travels less than the
  threshold per step it is swallowed: measured (e = 0.8), the apexes fall
  below 1e-3 of the drop height after bounce 9 instead of 17 (analytic 16).
  With 0 a contact is solved only once the shapes touch or overlap, as
  refsim's wall test does.
- ``useSplitImpulse=1`` and ``splitImpulsePenetrationThreshold=1e9``: Bullet
  corrects penetration with a Baumgarte term folded into the velocity (adding
  energy: ``erp * depth / h`` of extra rebound speed) whenever
  ``penetration > threshold``; penetration is negative when overlapping, so
  with Bullet's default threshold (-0.04) every overlap shallower than 4 cm
  takes the energy-adding path (measured: apex ratios 11% above e^2 without
  split impulse). A huge positive threshold sends every overlap through the
  split impulse, a separate pseudo-velocity that moves the body out without
  changing its velocity. (pybullet ignores negative values of this
  parameter.)
- Restitution: Bullet's contact restitution is the *product* of the two
  bodies' (``btManifoldResult::calculateCombinedRestitution``). Every body
  and every wall gets ``sqrt(e)`` of the scene's ``e``, so that a body-wall
  contact and a body-body contact both see ``e`` (1 on the walls and ``e`` on
  the bodies would give ``e^2`` between two bodies); coefficients per body
  or pair: Scene keys, below.
- Friction likewise multiplies (``calculateCombinedFriction``): every body
  and wall gets ``sqrt(mu)`` of the scene's ``friction`` read as the Coulomb
  coefficient ``mu``, so that every contact sees ``mu``. This is a
  different law from the seed's: the seed keeps ``(1 - friction)`` of the
  lateral velocity at every bounce; Coulomb friction removes at most
  ``mu (1 + e) |v_n|`` of it and stops at sticking
  (:mod:`refsim.dynamics.analytic`).
- Spinning friction (``spinning_friction=True``, the default): each body's
  is ``sqrt(mu)`` times the mean lever arm of its flattest side
  (:func:`spin_lever`), the walls' 0, so that a body spinning flat on a
  wall feels Coulomb's torque ``mu N lever``; Bullet's point contacts give
  it none otherwise. Measured: a unit cube spinning flat at 5 rad/s with
  mu = 0.5 kept 5 rad/s for 8 s with 0; with the lever it slows at
  11.26 rad/s^2 and stops at 0.44 s, Coulomb's 0.444 s. Bullet's solver of
  maximal-coordinate bodies applies spinning friction only with a positive
  rolling friction (``SPIN_ENABLING_ROLLING``, 1e-9; rolling friction is
  otherwise 0).
- ``restitutionVelocityThreshold=1e-3`` m/s: below this approach speed Bullet
  sets the restitution to 0 (an inelastic, resting contact). Bullet's default
  (0.2 m/s) would end a bounce sequence at apex heights of about 2 mm, where
  the analytic series still has bounces. 1e-3 m/s keeps the restitution law
  down to apex heights of 5e-8 m, far below what the studies measure, while a
  body at rest (approach speed ``g h`` per step, 1e-2 m/s at h = 1e-3 s)
  still micro-bounces; the bounce study's rest criterion (apexes below 1e-3
  of the drop height) does not count those. At 0.2 the same first bounces
  and the same settling bounce are measured; only the micro-bounces stop.
- ``contactBreakingThreshold``: process-global in pybullet (a static of
  Bullet's ``gContactBreakingThreshold``), so a value set by one client leaks
  into every other client in the process. It is set explicitly, to the same
  value (0.02, Bullet's default), every time a client is configured and before
  every ``simulate``.
- Linear and angular damping 0 (``changeDynamics``): pybullet's defaults are
  0.04, a velocity decay ``(1 - 0.04)^h`` per step that is not in the scene
  (measured: apex ratios 3.5% below e^2 with it).
- ``numSolverIterations=50`` (pybullet's default, kept explicit): a single
  body against a wall converges in a few; 50 covers a cube's four face
  contacts and the benchmark's many bodies.
- ``enableConeFriction=1``: asks for a friction cone instead of Bullet's
  two-direction pyramid. Measured: no effect in this maximal-coordinates
  rigid-body path (oblique bounces give the same velocities to the last bit
  with 0 or 1; the option acts in the multibody solver). Harmless here,
  because Bullet aligns its first friction direction with the sliding
  velocity, so one sliding contact sees the Coulomb law either way.
- ``collisionMargin=0`` for the hull shapes (``changeDynamics``): pybullet
  reports a margin of 1e-3 for mesh hulls, an inflation that would make the
  body touch the wall 1 mm early; set to 0 for definiteness (measured: no
  difference in the bounces at 1e-3 either, so the hull's contact appears
  not to use it). Box walls keep Bullet's margin, which lies inside the
  box's extents and so does not move the wall.
- Drag: the scene's drag is applied each step as an external force at the
  centre of mass (``applyExternalForce``, world frame): ``F = -k v`` (linear)
  or ``F = -k |v| v`` (quadratic), with ``v`` the velocity at the start of the
  step. Bullet folds external forces into its symplectic Euler step, so this
  is a first-order drag integration whatever refsim's solver does.
- ``deterministicOverlappingPairs=1``: the broadphase's pairs are sorted, so
  the solver visits contacts in the same order on every run (the report's
  numbers are the same bytes each time).
- Sleeping (deactivation) is disabled per body (``activationState``), so a
  body near rest is still stepped, as in refsim.

Scene keys
----------

The keys beyond the seed's world (:data:`refsim.scenes.support.LOAD_KEYS`;
:attr:`PybulletOracle.honoured_keys`). :meth:`PybulletOracle.load` calls
:func:`refsim.scenes.support.refuse_unhonoured` before it builds anything.

- ``world.gravity_direction``: ``setGravity`` of ``gravity_vector``.
- ``world.walls``: only the named walls' boxes are built. The floor and the
  other boxes reach ``3 half_size`` from the centre (``wall_thickness``), so
  a body that leaves through a missing wall keeps a wall under it to there,
  not beyond.
- ``world.mu``: the Coulomb coefficient everywhere the adapter reads one
  (``coulomb_mu``: ``friction`` when unset, as before).
- ``body.fixed``: mass 0, a static Bullet body (no inertia is set, no
  velocity: the loader makes it 0). Two static objects never touch.
- ``body.force``, ``body.torque``: ``applyExternalForce`` at the centre of
  mass and ``applyExternalTorque``, world frame, before every step: Bullet
  clears both after each step (measured: a force applied once changes the
  velocity of one step only).
- ``world.restitution_threshold``: Bullet's ``restitutionVelocityThreshold``
  (no restitution below that approach speed, as refsim's rule) takes the
  scene's value when the scene sets the key; otherwise the adapter keeps its
  1e-3 m/s (below), so the bounce studies' long bounce series keep the
  restitution law where refsim's default (0.05 m/s) would stop them early.
- ``body.restitution``, ``body.mu``, ``pair``: Bullet multiplies the two
  objects' values at a contact (and clamps the friction product to
  :data:`BULLET_MAX_FRICTION`); pybullet exposes no coefficient per pair
  (``changeDynamics`` is per body; Bullet's combining callbacks are C++
  only). So each body and the walls get a factor, and the coefficients
  :meth:`refsim.scenes.schema.Scene.coefficients` resolves are honoured when
  factors exist whose products give every contact the scene can have (a
  body with each wall, two bodies not both fixed): :func:`contact_factors`
  derives the condition and finds them. When every such contact sees the
  world's value, every factor is its square root (the adapter's convention
  before these keys, to the bit). One body with its own coefficient among
  others at the world's, or a pair among two or three bodies, always has
  factors; three bodies at the world's value and a pair of two of them at
  another have none. Where none exist, or a friction exceeds Bullet's
  clamp, the scene is refused with the key that sets the coefficient.

Cost: building is O(vertices) per body for the hull; a step is Bullet's
broadphase plus GJK/EPA per overlapping pair plus the solver's iterations.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
from refsim.oracles import c_banner_dropped, import_engine, run_recorded, seconds_per_step

from refsim.dynamics.world import WALL_NAMES
from refsim.errors import SceneError
from refsim.scenes.support import LOAD_KEYS, keys_in_use, refuse_unhonoured

#: Bullet clamps a contact's combined friction (the product) to this
#: (``MAX_FRICTION`` in ``btManifoldResult::calculateCombinedFriction``;
#: measured: a plate pushed at 12 m g over a contact of 4 x 4 slides at 2 g).
BULLET_MAX_FRICTION = 10.0
#: The products of :func:`contact_factors` give the scene's coefficients to
#: this relative error: a square root, a quotient and a product, each
#: rounded to half an ulp (1.1e-16), with room for a chain of a few bodies.
FACTOR_RTOL = 1e-12


@dataclass(frozen=True)
class PybulletSettings:
    """The pybullet settings the oracle uses (module docstring: why each)."""

    use_maximal_coordinates: bool = True
    contact_processing_threshold: float = 0.0
    contact_breaking_threshold: float = 0.02
    use_split_impulse: int = 1
    split_impulse_penetration_threshold: float = 1e9
    restitution_velocity_threshold: float = 1e-3
    num_solver_iterations: int = 50
    enable_cone_friction: int = 1
    linear_damping: float = 0.0
    angular_damping: float = 0.0
    hull_collision_margin: float = 0.0
    #: Wall boxes are this thick (as a fraction of the half size): thick
    #: enough that no step carries a body through one.
    wall_thickness: float = 1.0
    #: Give each body Bullet's spinning friction of its flattest side
    #: (:func:`spin_lever`): False leaves it 0, as before, and a body
    #: spinning flat on the floor never slows.
    spinning_friction: bool = True


@dataclass(frozen=True)
class MassProperties:
    """A body's mass properties in its (scaled) mesh frame.

    ``inertia`` (3,) principal moments about the centre of mass,
    ``axes`` (3, 3) whose columns are the principal axes (a rotation),
    ``center`` (3,) the centre of mass, ``mass`` the body's mass.
    """

    mass: float
    center: np.ndarray
    inertia: np.ndarray
    axes: np.ndarray


def mass_properties(vertices, faces, mass: float, scale: float = 1.0) -> MassProperties:
    """Uniform-solid mass properties of the closed mesh, by trimesh's integrals.

    The density is chosen so that the solid weighs ``mass``; the mesh is
    scaled by ``scale`` first. The inertia tensor about the centre of mass is
    diagonalised (``numpy.linalg.eigh``); its eigenvectors become the columns
    of ``axes``, made right-handed.
    """
    trimesh = import_engine("trimesh", "trimesh")
    mesh = trimesh.Trimesh(vertices=np.asarray(vertices, dtype=np.float64) * scale,
                           faces=np.asarray(faces, dtype=np.int64), process=False)
    volume = float(mesh.volume)
    if not volume > 0:
        raise ValueError("mass properties need a closed mesh of positive volume")
    mesh.density = mass / volume
    tensor = np.asarray(mesh.moment_inertia, dtype=np.float64)   # about the centre of mass
    inertia, axes = np.linalg.eigh(0.5 * (tensor + tensor.T))
    if np.linalg.det(axes) < 0:
        axes[:, 2] = -axes[:, 2]
    return MassProperties(mass=float(mass), center=np.asarray(mesh.center_mass, dtype=np.float64),
                          inertia=inertia, axes=axes)


#: Bullet's solver of maximal-coordinate bodies adds a contact's spinning
#: friction only when its rolling friction is positive
#: (``btSequentialImpulseConstraintSolver::convertContact``): so much rolling
#: friction (a lever in metres) enables it and bounds the rolling torque by
#: 1e-9 of the normal force times a metre, nothing the kit can see.
SPIN_ENABLING_ROLLING = 1e-9

#: Each triangle of a flat side is cut into this many squared sub-triangles
#: to average the distance over it: the midpoint rule's error, of order
#: 1 / n^2, is under 1e-3 of the lever.
LEVER_SUBDIVISIONS = 32


def spin_lever(vertices, scale: float = 1.0) -> float:
    """The mean distance from its centroid of the largest flat side of the
    convex hull of ``vertices`` (times ``scale``): the lever arm of Coulomb
    friction under a uniform pressure on that side, so that a body spinning
    flat on it feels the torque ``mu N lever``. (A unit square's is
    ``(sqrt 2 + ln(1 + sqrt 2)) / 6`` = 0.3826.)

    Bullet's contact is a few points, not a pressure over a face: its
    friction at a point centred under a body spinning flat exerts no
    torque. Its spinning friction ``s`` bounds the torque about the normal
    by ``s`` times the normal force, and a contact combines
    ``s_a f_b + s_b f_a`` (``btManifoldResult``, ``f`` the lateral friction
    factors). A body's ``s = f lever`` against a wall's ``s = 0`` gives the
    Coulomb torque of its flattest side, the only side a body spins flat
    on in the kit's scenes; on a corner or an edge the true torque is
    smaller, and on a curved body's facet (a sphere's) the lever is small.
    Two bodies' contact gets ``mu (lever_a + lever_b)``.
    """
    from scipy.spatial import ConvexHull

    points = np.asarray(vertices, dtype=np.float64) * scale
    hull = ConvexHull(points)
    # group the hull's triangles by their plane (normals and offsets to 1e-9)
    planes: dict[tuple, list[int]] = {}
    for k, equation in enumerate(hull.equations):
        planes.setdefault(tuple(np.round(equation, 9)), []).append(k)

    def area(k: int) -> float:
        a, b, c = points[hull.simplices[k]]
        return 0.5 * float(np.linalg.norm(np.cross(b - a, c - a)))

    side = max(planes.values(), key=lambda ks: sum(area(k) for k in ks))
    n = LEVER_SUBDIVISIONS
    # barycentric centroids of the n^2 equal sub-triangles of a triangle
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    up = (i + j) < n
    down = (i + j) < n - 1
    bary = np.concatenate([
        np.stack([(i[up] + 1 / 3), (j[up] + 1 / 3)], axis=1),
        np.stack([(i[down] + 2 / 3), (j[down] + 2 / 3)], axis=1)]) / n
    samples, weights = [], []
    for k in side:
        a, b, c = points[hull.simplices[k]]
        samples.append(a + bary[:, :1] * (b - a) + bary[:, 1:] * (c - a))
        weights.append(np.full(len(bary), area(k) / len(bary)))
    xs, ws = np.concatenate(samples), np.concatenate(weights)
    centroid = (ws[:, None] * xs).sum(axis=0) / ws.sum()
    return float((ws * np.linalg.norm(xs - centroid, axis=1)).sum() / ws.sum())


def restitution_threshold(scene, settings: PybulletSettings) -> float:
    """Bullet's ``restitutionVelocityThreshold`` for ``scene``: the scene's
    ``world.restitution_threshold`` when it sets one, else the adapter's
    setting (module docstring: why 1e-3 m/s)."""
    if "world.restitution_threshold" in keys_in_use(scene):
        return scene.world.restitution_threshold
    return settings.restitution_velocity_threshold


def contact_factors(n: int, values: dict[tuple[int, int], float], *,
                    free: float = 1.0) -> np.ndarray | None:
    """Factors ``x`` (n,) of n objects with ``x_u x_v = c`` for every
    contact ``(u, v)`` of ``values`` (each ``c >= 0``), or None when no
    factors give them all; an object in no contact gets ``free``.

    Derivation. A zero ``c`` needs a zero factor, which makes every contact
    of that object zero; so the objects whose contacts are all zero get 0
    (harmless: nothing else depends on them), and a zero contact between two
    other objects has no factors. What remains is positive: in each
    connected set of contacts, the root's factor ``t`` fixes every other
    along a spanning tree, ``x_v = c_v t^(s_v)`` with ``s_v = +-1`` by the
    parity of its depth. A contact closing an even cycle (``s_u = -s_v``)
    must satisfy ``c_u c_v = c`` (t cancels); one closing an odd cycle fixes
    ``t^2 = (c / (c_u c_v))^(s_u)``. With no odd cycle, ``t`` is free and
    is taken as the square root of the root's first contact (two objects
    in one contact get ``sqrt(c)`` each). Every product is then checked
    against ``c`` to :data:`FACTOR_RTOL`.

    Cost: O(n + contacts).
    """
    neighbours: list[list[tuple[int, float]]] = [[] for _ in range(n)]
    for (u, v), c in values.items():
        neighbours[u].append((v, c))
        neighbours[v].append((u, c))
    zero = [bool(nb) and all(c == 0.0 for _, c in nb) for nb in neighbours]
    x = np.full(n, free)
    seen = [False] * n
    for root in range(n):
        if seen[root] or zero[root]:
            continue
        seen[root] = True
        scale, parity = {root: 1.0}, {root: 1}         # x_v = scale_v t^parity_v
        order, t2 = [root], None
        for u in order:
            for v, c in neighbours[u]:
                if zero[v]:
                    continue
                if c == 0.0:
                    return None                          # zero between two non-zero factors
                if not seen[v]:
                    seen[v] = True
                    scale[v], parity[v] = c / scale[u], -parity[u]
                    order.append(v)
                elif parity[v] == parity[u] and t2 is None:
                    t2 = (c / (scale[u] * scale[v])) ** parity[u]
        if len(order) == 1:
            continue                                     # in no contact: free
        if t2 is None:
            t2 = next(c for v, c in neighbours[root] if not zero[v])
        t = math.sqrt(t2)
        for v in order:
            x[v] = scale[v] * t ** parity[v]
    for i, z in enumerate(zero):
        if z:
            x[i] = 0.0
    for (u, v), c in values.items():
        if abs(x[u] * x[v] - c) > FACTOR_RTOL * c:
            return None
    return x


def _coefficient_key(scene, name: str) -> str:
    """The first key that sets coefficient ``name`` ("restitution" or
    "mu"): a pair's, a body's, else the world's."""
    for i, pair in enumerate(scene.pairs):
        if getattr(pair, name) is not None:
            return f"pair[{i}].{name}"
    for i, body in enumerate(scene.bodies):
        if getattr(body, name) is not None:
            return f"body[{i}].{name}"
    if name == "mu":
        return "world.mu" if scene.world.mu is not None else "world.friction"
    return "world.restitution"


def _quat(rotation) -> list[float]:
    from scipy.spatial.transform import Rotation

    return [float(q) for q in Rotation.from_matrix(np.asarray(rotation, float)).as_quat()]


def _matrix(quat) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(np.asarray(quat, float)).as_matrix()


class PybulletOracle:
    """pybullet behind the wall-bounce queries (own DIRECT client, lazy import).

    Use as a context manager or call :meth:`close`. Raises
    :class:`refsim.oracles.OracleUnavailable` when pybullet is not installed.
    """

    name = "pybullet"
    #: The scene keys beyond the seed's world this adapter honours (module
    #: docstring, Scene keys): all of them; coefficients per body and pair
    #: only where Bullet's products can give them (refused by name otherwise).
    honoured_keys = frozenset(LOAD_KEYS)
    #: The order of its time step (:func:`refsim.engines.declarations`):
    #: Bullet's btSequentialImpulseConstraintSolver world steps velocities,
    #: then positions with the new velocities (semi-implicit Euler), first
    #: order.
    integrator_order = 1

    def __init__(self, settings: PybulletSettings | None = None):
        with c_banner_dropped("pybullet build time:"):      # printed as it loads
            self.p = import_engine("pybullet", "pybullet")
        self.settings = settings or PybulletSettings()
        self.client = self.p.connect(self.p.DIRECT)
        self.bodies: list[int] = []
        self.walls: list[int] = []
        self.wall_names: list[str] = []
        self._loads: list = []
        self.properties: list[MassProperties] = []
        self._scene = None

    # -- lifetime -----------------------------------------------------------------

    def close(self) -> None:
        if self.client is not None:
            self.p.disconnect(physicsClientId=self.client)
            self.client = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        try:
            self.close()
        except Exception:  # noqa: BLE001 - interpreter shutdown: nothing to report to
            pass

    # -- building -----------------------------------------------------------------

    def _configure(self, scene) -> None:
        p, s, c = self.p, self.settings, self.client
        p.resetSimulation(physicsClientId=c)
        p.setGravity(*scene.world.gravity_vector, physicsClientId=c)
        p.setPhysicsEngineParameter(
            fixedTimeStep=scene.integration.step, numSubSteps=0,
            numSolverIterations=s.num_solver_iterations,
            useSplitImpulse=s.use_split_impulse,
            splitImpulsePenetrationThreshold=s.split_impulse_penetration_threshold,
            restitutionVelocityThreshold=restitution_threshold(scene, s),
            enableConeFriction=s.enable_cone_friction,
            contactBreakingThreshold=s.contact_breaking_threshold,
            deterministicOverlappingPairs=1,
            physicsClientId=c)

    def _add_walls(self, world, factors: tuple[float, float]) -> None:
        """The scene's walls as static boxes, each with the wall factors
        ``(restitution, friction)`` (:meth:`_contact_factors`)."""
        p, s, c = self.p, self.settings, self.client
        half_size = world.half_size
        t = s.wall_thickness * half_size                 # half thickness of a wall box
        span = half_size + 2.0 * t                       # walls overlap at the edges
        self.walls = []
        self.wall_names = []
        for k, name in enumerate(WALL_NAMES):
            if name not in world.walls:
                continue
            axis, sign = k // 2, (-1.0 if name.endswith("-") else 1.0)
            extents = [span, span, span]
            extents[axis] = t
            center = [0.0, 0.0, 0.0]
            center[axis] = sign * (half_size + t)
            shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=extents,
                                           physicsClientId=c)
            wall = p.createMultiBody(0.0, shape, basePosition=center,
                                     useMaximalCoordinates=s.use_maximal_coordinates,
                                     physicsClientId=c)
            p.changeDynamics(wall, -1, restitution=factors[0],
                             lateralFriction=factors[1],
                             rollingFriction=0.0,
                             spinningFriction=0.0,
                             contactProcessingThreshold=s.contact_processing_threshold,
                             physicsClientId=c)
            self.walls.append(wall)
            self.wall_names.append(name)

    def _add_body(self, scene, body, factors: tuple[float, float]) -> int:
        """``body`` as a hull with its mass properties (static, mass 0, when
        it is fixed), with the factors ``(restitution, friction)``."""
        p, s, c = self.p, self.settings, self.client
        mesh = scene.mesh(body)
        props = mass_properties(mesh.vertices, mesh.faces, body.mass, body.scale)
        shape = p.createCollisionShape(p.GEOM_MESH, vertices=mesh.vertices.tolist(),
                                       meshScale=[body.scale] * 3, physicsClientId=c)
        r = np.asarray(body.orientation, dtype=np.float64)
        x = np.asarray(body.position, dtype=np.float64)
        mass = 0.0 if body.fixed else body.mass             # Bullet: mass 0 is static
        uid = p.createMultiBody(
            baseMass=mass, baseCollisionShapeIndex=shape, basePosition=x.tolist(),
            baseOrientation=_quat(r),
            baseInertialFramePosition=props.center.tolist(),
            baseInertialFrameOrientation=_quat(props.axes),
            useMaximalCoordinates=s.use_maximal_coordinates, physicsClientId=c)
        inertia = {} if body.fixed else {"mass": body.mass,
                                         "localInertiaDiagonal": props.inertia.tolist()}
        spin = factors[1] * spin_lever(mesh.vertices, body.scale) if s.spinning_friction else 0.0
        p.changeDynamics(uid, -1, **inertia,
                         restitution=factors[0],
                         lateralFriction=factors[1],
                         rollingFriction=SPIN_ENABLING_ROLLING if spin > 0.0 else 0.0,
                         spinningFriction=spin, linearDamping=s.linear_damping,
                         angularDamping=s.angular_damping,
                         contactProcessingThreshold=s.contact_processing_threshold,
                         collisionMargin=s.hull_collision_margin,
                         activationState=p.ACTIVATION_STATE_DISABLE_SLEEPING,
                         physicsClientId=c)
        # The scene's velocity is the centre of mass's, as pybullet's is (a
        # fixed body's is zero: the loader requires it).
        p.resetBaseVelocity(uid, [float(a) for a in body.velocity],
                            [float(a) for a in body.angular_velocity], physicsClientId=c)
        self.properties.append(props)
        return uid

    def _contact_factors(self, scene) -> tuple[np.ndarray, np.ndarray]:
        """Each body's and the walls' restitution and friction factors,
        (B + 1,) each (the walls last), whose products at every contact the
        scene can have are the coefficients :meth:`Scene.coefficients`
        resolves (module docstring, Scene keys).

        Raises
        ------
        SceneError
            Naming the key that sets the coefficients no factors can give,
            or a friction above :data:`BULLET_MAX_FRICTION`.
        """
        world, bodies = scene.world, scene.bodies
        B = len(bodies)
        walls = len(world.walls) > 0
        # the contacts the scene can have: two static objects never touch
        edges: dict[tuple[int, int], tuple[float, float]] = {}
        for i, a in enumerate(bodies):
            if walls and not a.fixed:
                edges[(i, B)] = scene.coefficients(a)
            for j in range(i + 1, B):
                if not (a.fixed and bodies[j].fixed):
                    edges[(i, j)] = scene.coefficients(a, bodies[j])
        result = []
        for k, (name, uniform) in enumerate((("restitution", world.restitution),
                                             ("mu", world.coulomb_mu))):
            values = {edge: c[k] for edge, c in edges.items()}
            if name == "mu" and any(v > BULLET_MAX_FRICTION for v in values.values()):
                raise SceneError(f"pybullet clamps a contact's friction to "
                                 f"{BULLET_MAX_FRICTION:g} (the product of two bodies')",
                                 scene.path, _coefficient_key(scene, name))
            if all(v == uniform for v in values.values()):
                # every contact sees the world's value: sqrt of it everywhere
                result.append(np.full(B + 1, math.sqrt(uniform)))
                continue
            x = contact_factors(B + 1, values, free=math.sqrt(uniform))
            if x is None:
                raise SceneError(f"pybullet multiplies two objects' {name} at a contact, and "
                                 f"no factor per body and wall gives every contact the "
                                 f"{name} the scene resolves", scene.path,
                                 _coefficient_key(scene, name))
            result.append(x)
        return result[0], result[1]

    def load(self, scene) -> None:
        """Build ``scene`` in this client (replacing whatever was there).

        Raises
        ------
        SceneError
            For a scene key this adapter does not honour
            (:attr:`honoured_keys`, module docstring: Scene keys).
        """
        refuse_unhonoured(scene, self.name, self.honoured_keys)
        e, mu = self._contact_factors(scene)
        self._configure(scene)
        self._add_walls(scene.world, (float(e[-1]), float(mu[-1])))
        self.bodies = []
        self.properties = []
        for i, body in enumerate(scene.bodies):
            self.bodies.append(self._add_body(scene, body, (float(e[i]), float(mu[i]))))
        # constant loads, world frame, applied every step (Bullet clears its
        # external forces after each step)
        self._loads = [(uid, tuple(map(float, b.force)), tuple(map(float, b.torque)))
                       for uid, b in zip(self.bodies, scene.bodies, strict=True)
                       if not b.fixed and (any(b.force) or any(b.torque))]
        self._scene = scene

    # -- stepping and reading ------------------------------------------------------

    def _apply_drag(self) -> None:
        world = self._scene.world
        if world.drag == 0.0:
            return
        p, c = self.p, self.client
        for uid in self.bodies:
            v = np.asarray(p.getBaseVelocity(uid, physicsClientId=c)[0])
            k = world.drag * (np.linalg.norm(v) if world.drag_model == "quadratic" else 1.0)
            com = p.getBasePositionAndOrientation(uid, physicsClientId=c)[0]
            p.applyExternalForce(uid, -1, (-k * v).tolist(), com, p.WORLD_FRAME,
                                 physicsClientId=c)

    def _apply_loads(self) -> None:
        """The bodies' constant forces (at the centre of mass) and torques,
        world frame: Bullet clears external forces after every step."""
        p, c = self.p, self.client
        for uid, force, torque in self._loads:
            if any(force):
                com = p.getBasePositionAndOrientation(uid, physicsClientId=c)[0]
                p.applyExternalForce(uid, -1, force, com, p.WORLD_FRAME, physicsClientId=c)
            if any(torque):
                p.applyExternalTorque(uid, -1, torque, p.WORLD_FRAME, physicsClientId=c)

    def step(self) -> None:
        """One Bullet step of the loaded scene (drag and loads applied first)."""
        self._apply_drag()
        self._apply_loads()
        self.p.stepSimulation(physicsClientId=self.client)

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(B, 3) positions of the mesh origins, (B, 3) velocities of the
        centres of mass, (B, 3) angular velocities, (B, 3, 3) orientations
        (columns are the body axes)."""
        p, c = self.p, self.client
        n = len(self.bodies)
        x = np.empty((n, 3))
        v = np.empty((n, 3))
        w = np.empty((n, 3))
        r = np.empty((n, 3, 3))
        for i, (uid, props) in enumerate(zip(self.bodies, self.properties, strict=True)):
            com, quat = p.getBasePositionAndOrientation(uid, physicsClientId=c)
            v_com, w_i = p.getBaseVelocity(uid, physicsClientId=c)
            r_link = _matrix(quat) @ props.axes.T
            com = np.asarray(com)
            x[i] = com - r_link @ props.center
            w[i] = w_i
            v[i] = v_com
            r[i] = r_link
        return x, v, w, r

    def simulate(self, scene, *, every: int = 1):
        """Run ``scene`` for its duration; a frame every ``every`` steps (and
        the first). Returns a :class:`~refsim.dynamics.trajectory.Trajectory`
        whose events are the wall contacts that began in a step;
        ``stage_seconds`` splits the wall time into "step" (``stepSimulation``
        and the drag forces) and "record" (reading state and contacts)."""
        self.load(scene)
        p, c = self.p, self.client
        p.setPhysicsEngineParameter(
            contactBreakingThreshold=self.settings.contact_breaking_threshold,
            physicsClientId=c)

        wall_name = dict(zip(self.walls, self.wall_names, strict=True))

        def wall_contacts() -> set[tuple[int, str]]:
            # one query a body (its contacts with anything), kept where the
            # other body (point[1] or [2]) is a wall and the distance
            # (point[8]) is <= 0: touching
            now = set()
            for i, uid in enumerate(self.bodies):
                for point in p.getContactPoints(uid, physicsClientId=c):
                    other = point[2] if point[1] == uid else point[1]
                    if other in wall_name and point[8] <= 0.0:
                        now.add((i, wall_name[other]))
            return now

        settings = asdict(self.settings)
        settings["restitution_velocity_threshold"] = restitution_threshold(scene, self.settings)
        return run_recorded(self, scene, every, wall_contacts,
                            {"engine": "pybullet", **settings})

    def step_time(self, scene, steps: int, warmup: int = 0) -> float:
        """Seconds per step of ``scene`` (mean over ``steps`` steps after
        loading and ``warmup`` untimed steps; reading no state)."""
        self.load(scene)
        self.p.setPhysicsEngineParameter(
            contactBreakingThreshold=self.settings.contact_breaking_threshold,
            physicsClientId=self.client)
        return seconds_per_step(self, steps, warmup)

    def dynamics_info(self, index: int) -> dict:
        """pybullet's own view of body ``index``: mass and inertia diagonal."""
        info = self.p.getDynamicsInfo(self.bodies[index], -1, physicsClientId=self.client)
        return {"mass": info[0], "lateral_friction": info[1],
                "inertia": np.asarray(info[2], dtype=np.float64), "restitution": info[5],
                "collision_margin": info[11]}


def engine(**settings) -> PybulletOracle:
    """The engine factory (``refsim.oracles.pybullet_adapter:engine``);
    keyword arguments set fields of :class:`PybulletSettings`."""
    return PybulletOracle(PybulletSettings(**settings))
