"""Drake as a third rigid-body engine: the same scene, run by a MultibodyPlant.

Drake (R. Tedrake and the Drake Development Team, https://drake.mit.edu;
its discrete contact solvers after A. Castro, F. Permenter, X. Han,
"An Unconstrained Convex Formulation of Compliant Contact", IEEE T-RO 2023)
treats contact as *compliant*: a point contact pushes with the
Hunt-Crossley force ``f_n = k x (1 + d x')_+`` (K. H. Hunt, F. R. E.
Crossley, "Coefficient of restitution interpreted as damping in
vibroimpact", J. Appl. Mech. 1975) for a penetration ``x``, a stiffness
``k`` and a dissipation ``d`` (s/m). There is no coefficient of
restitution: the bounce follows from ``k`` and ``d`` and depends on the
impact speed. The engine therefore declares ``contact_law =
"hunt-crossley"`` (:func:`refsim.engines.declarations`), and the second
factory :func:`engine_hydroelastic` declares ``"hydroelastic"``.

Here Drake runs a refsim :class:`~refsim.scenes.schema.Scene`: a discrete
MultibodyPlant whose time step is the scene's, connected to a SceneGraph;
the world cube's six walls as half-spaces, each body a free rigid body
with its true mass properties colliding as the convex hull of its mesh,
gravity along -y. The result is a
:class:`~refsim.dynamics.trajectory.Trajectory`, frame for frame
comparable with ``refsim.simulate`` and the pybullet and MuJoCo oracles.

The adapter is an engine (:mod:`refsim.engines`) with the capability
``rigid``: ``refsim.oracles.drake_adapter:engine`` (point contact) and
``refsim.oracles.drake_adapter:engine_hydroelastic``.

Conventions converted here and nowhere else
-------------------------------------------

- Frames. Each body's Drake frame B is the mesh's own frame (refsim's
  reference point and axes); the centre of mass ``c`` and the central
  inertia ``A diag(I) A^T`` (principal moments ``I`` and axes ``A`` in the
  mesh frame) go into its ``SpatialInertia``. A free body's state in Drake
  is the pose ``X_WB`` (a quaternion and the origin's position) and the
  spatial velocity ``V_WB``: the angular velocity in the world frame and
  the velocity of the frame's *origin* Bo, in world coordinates
  (``SetFreeBodySpatialVelocity``, ``EvalBodySpatialVelocityInWorld``;
  measured here: the l-beam, its centre of mass 0.22 m off its origin,
  spinning at 5 rad/s without gravity, keeps its centre of mass on its
  straight line to 3.9e-4 m over 0.2 s, Drake integrating the origin's
  velocity with a first-order step as MuJoCo does, 3.9e-4 m too; read as
  the centre's velocity it would swing by more than 5 cm). refsim's
  velocity is the centre of mass's (:mod:`refsim.dynamics.trajectory`):
  ``v_origin = v_com - w x (R c)``
  when setting the initial state, ``v_com = v_origin + w x (R c)`` when
  reading (:func:`_origin_velocity`, :func:`_com_velocity`).
- Meshes. ``Convex(points, label, scale)``: Drake computes the convex hull
  of the scaled vertices in memory (no file), so the l-beam, the star and
  the torus collide as their hulls, as in pybullet and MuJoCo.
- Mass properties: the uniform solid of the body's mass, from trimesh's
  integrals (:func:`refsim.oracles.pybullet_adapter.mass_properties`).
- Units and gravity: SI; gravity ``(0, -g, 0)`` (y up, as refsim).

Every setting, and why (:class:`DrakeSettings` holds them)
------------------------------------------------------------

- Discrete plant, ``time_step = scene.integration.step``, advanced one
  step at a time (``Simulator.AdvanceTo(k h)``: the plant's update at
  ``(k - 1) h`` is the last one done, so that frame ``k`` is after exactly
  ``k`` steps; checked against the free fall's ``v = -g k h``). The
  scene's ``solver`` is not used: Drake's discrete step is its own
  (implicit in the contact forces, symplectic Euler in the free motion),
  as Bullet's and MuJoCo's are.
- ``DiscreteContactApproximation.kLagged`` (``approximation="lagged"``,
  Drake's default in the installed version, kept explicit): the convex SAP
  solver with Hunt-Crossley dissipation, stable at any stiffness, with
  Coulomb's bound taken from the previous step's normal impulse
  (``|gamma_t| <= mu gamma_n0``). Drake's documentation prefers
  ``kSimilar`` (``approximation="similar"``) where strong transients must be
  resolved, as in impacts; measured on the kit's scenes the two bounce
  alike, ``kLagged`` meets Coulomb's oblique impacts and holds the stacks
  more closely, ``kSimilar`` decelerates the sliding cube more truly (the
  lagged bound lets a chattering single contact brake 24 % too hard):
  docs/decisions/drake.md has the numbers.
- Point contact (``ContactModel.kPoint``) in :func:`engine`: one contact
  point per pair of geometries (the deepest), with the combined stiffness
  ``k1 k2 / (k1 + k2)`` and dissipation ``(k2 d1 + k1 d2) / (k1 + k2)``
  (Drake's combination rules). Every geometry gets the same ``2 k`` and
  ``d``, so every contact, body-wall or body-body, sees ``k`` and ``d``.
- Stiffness ``k`` from the scene: an impact of the lightest body ``m`` on a
  wall lasts ``contact_steps`` steps (the undamped half period
  ``pi sqrt(m / k) = N h``), ``k = m pi^2 / (N h)^2``, with ``N = 8``.
  Two limits meet here. At rest a body sinks ``m g / k = g h^2 N^2 /
  pi^2``, 6.5 ``g h^2`` at ``N = 8`` (6.4e-5 m at h = 1e-3), inside the
  kit's allowance of 10 ``g h^2`` (``N`` must stay below ``pi sqrt(10)
  = 9.9``). And Drake's discrete step is implicit in the contact force, so
  a contact resolved in few steps loses energy of its own, with no
  dissipation at all: measured (:func:`drake_restitution` with ``d = 0``),
  the restitution is 0.33 at ``N = 2``, 0.58 at ``N = 8``, 0.64 at
  ``N = 10``, 0.85 at ``N = 30``, 0.95 at ``N = 100``. A scene's ``e``
  above the ``N = 8`` value (0.584) cannot be met by any dissipation: the
  engine then bounces with 0.584 (``d = 0``). ``N = 8`` keeps the resting
  depth inside the kit's allowance; meeting e = 0.8 would take ``N`` of
  about 22 and a resting depth of 4.8e-4 m, e = 1 no ``N`` at all.
- Dissipation ``d`` from the scene's ``e``, *by measurement*: for a linear
  spring the restitution of one impact depends on ``d v0`` and ``N`` alone
  (scale ``x`` by ``v0 sqrt(m / k)``), so :func:`drake_dv` bisects ``d
  v0`` on Drake's own discrete impact (:func:`drake_restitution`, a probe
  plant of one sphere and one half-space with the same settings) until
  the restitution is ``e``, and ``d = (d v0) / v0``. A formula for the
  continuous law (Hunt and Crossley's ``d = 3 (1 - e) / (2 v0)``, or the
  exact inversion of ``x'' = -x (1 + d v0 x')_+``) would miss by the
  discrete step's own loss above. ``v0`` is the scene's largest impact
  speed, estimated from the start (:func:`impact_speed`: each body's speed
  after falling from its lowest vertex to the floor, or its speed in a
  scene without gravity), at least ``min_impact_speed`` (1 m/s, for
  scenes at rest). So the scene's first impact bounces with ``e``; slower
  impacts bounce higher (the Hunt-Crossley law's restitution rises as the
  impact speed falls), what the kit's apex-ratio check sees. ``e = 0`` has
  no finite ``d`` (the exit speed is at most ``v0 / (d v0)``): it is taken
  as ``e = min_restitution`` (0.01).
- Friction: ``CoulombFriction(mu, mu)`` on every geometry (Drake combines
  two coefficients as ``2 mu1 mu2 / (mu1 + mu2)``, which is ``mu``). SAP
  regularises friction: a contact sticks up to a small slip speed, no
  stiction threshold to set.
- Walls: six ``HalfSpace`` geometries on the world body at ``+-half_size``,
  normals into the cube.
- Hydroelastic contact (:func:`engine_hydroelastic`): every body a
  compliant ``Convex`` (Drake builds its pressure field from the hull; a
  compliant half-space may not meet a compliant body, so the walls are
  rigid hydroelastic half-spaces), with the hydroelastic modulus ``E = k L
  / A`` for the body's hull (``L`` its extent along its thinnest principal
  axis, ``A = V / L`` its mean section): a modulus whose contact stiffness
  is of the order of the point contact's ``k``. Dissipation and friction
  as above (the dissipation measured for point contact, so the bounce is
  only near ``e``). Body-body contacts are compliant-compliant. A contact
  is a patch, not a point: a face landing flat pushes over the whole face.
- Drag: the scene's drag as a force at the centre of mass each step (the
  plant's applied spatial force input), ``F = -k v`` or ``-k |v| v`` with
  the centre of mass's velocity at the start of the step, first order, as
  in the other oracles.

Scene keys beyond the seed's world: ``world.gravity_direction`` (the
gravity field's vector), ``world.walls`` (only the named half-spaces) and
``world.mu`` (the Coulomb coefficient of every contact) are posed. Fixed
bodies, applied forces and torques, coefficients per body or pair and the
restitution threshold (Drake's law has no threshold) are refused before
anything is built, with one line naming the key
(:func:`refsim.scenes.support.refuse_unhonoured`).

What the adapter refuses besides: a scene with particles (``[particles]``),
one line naming the key and the engine (:class:`refsim.errors.OptionError`).
A missing Drake raises :class:`refsim.oracles.OracleUnavailable` (``pip
install 'refsim[drake]'``).

Cost: building is the hull of each mesh (O(n log n)) and, for
hydroelastic contact, a tetrahedral mesh of each hull; a step is Drake's
broad and narrow phase (per pair) and the SAP solve (a few Newton
iterations over the active contacts).
"""

from __future__ import annotations

import contextlib
import functools
import math
from dataclasses import asdict, dataclass

import numpy as np
from refsim.oracles import (
    import_engine,
    install_hint,
    rotation_of_quaternion,
    run_recorded,
    seconds_per_step,
)

#: Wall names in the order of refsim's events (x-, x+, y-, y+, z-, z+).
WALL_NAMES = ("x-", "x+", "y-", "y+", "z-", "z+")

#: The bisection of :func:`drake_dv` stops when ``d v0`` is known to this
#: relative width (the restitution it meets then to about 1e-4 of itself).
DV_TOLERANCE = 1e-4


@dataclass(frozen=True)
class DrakeSettings:
    """The Drake settings the engine uses (module docstring: why each)."""

    contact_model: str = "point"
    approximation: str = "lagged"
    #: Steps an impact of the lightest body on a wall lasts (sets ``k``).
    contact_steps: float = 8.0
    #: m/s: the impact speed ``d`` is chosen for is at least this.
    min_impact_speed: float = 1.0
    #: The restitution taken for ``e`` below it (Hunt-Crossley has no e = 0).
    min_restitution: float = 0.01


def _approximation(name: str):
    """Drake's ``DiscreteContactApproximation`` named ``name`` ("lagged",
    "similar"; the ones with Hunt-Crossley dissipation and convex)."""
    from pydrake.multibody.plant import DiscreteContactApproximation

    from refsim.errors import OptionError

    choices = {"lagged": DiscreteContactApproximation.kLagged,
               "similar": DiscreteContactApproximation.kSimilar}
    if name not in choices:
        raise OptionError(f"engine drake: approximation must be one of "
                          f"{', '.join(choices)}, got {name!r}")
    return choices[name]


def drake_restitution(dv: float, contact_steps: float, h: float = 1e-3,
                      approximation: str = "lagged") -> float:
    """The coefficient of restitution of one of Drake's discrete point
    impacts, measured: a sphere of 1 kg meets a half-space at 1 m/s without
    gravity, stiffness ``k = pi^2 / (contact_steps h)^2`` and dissipation
    ``dv`` (the same settings as :meth:`DrakeEngine.load`, the discrete
    ``approximation`` among them), stepped until it is out of contact; its
    exit speed. Dimensionless: for a linear spring
    the restitution depends on ``d v0`` and ``sqrt(k / m) h`` alone
    (``x`` scaled by ``v0 sqrt(m / k)``), so this one run stands for every
    mass and impact speed at the same ``contact_steps``."""
    from pydrake.geometry import AddContactMaterial, HalfSpace, ProximityProperties, Sphere
    from pydrake.math import RigidTransform
    from pydrake.multibody.math import SpatialVelocity
    from pydrake.multibody.plant import (
        AddMultibodyPlantSceneGraph,
        ContactModel,
        CoulombFriction,
    )
    from pydrake.multibody.tree import SpatialInertia, UnitInertia
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder

    k = math.pi ** 2 / (contact_steps * h) ** 2
    radius = 0.1
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=h)
    plant.set_discrete_contact_approximation(_approximation(approximation))
    plant.set_contact_model(ContactModel.kPoint)
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, 0.0])
    ball = plant.AddRigidBody("probe", SpatialInertia(1.0, np.zeros(3),
                                                      UnitInertia.SolidSphere(radius)))
    for body, shape in ((ball, Sphere(radius)), (plant.world_body(), HalfSpace())):
        props = ProximityProperties()
        AddContactMaterial(dv, 2.0 * k, CoulombFriction(0.0, 0.0), props)
        plant.RegisterCollisionGeometry(body, RigidTransform(), shape, "g", props)
    plant.Finalize()
    with _deformable_note_dropped():
        simulator = Simulator(builder.Build())
    context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    start = radius + 0.5 * h                        # half a step's travel above the plane
    plant.SetFreeBodyPose(context, ball, RigidTransform([0.0, 0.0, start]))
    plant.SetFreeBodySpatialVelocity(context, ball, SpatialVelocity(np.zeros(3),
                                                                    [0.0, 0.0, -1.0]))
    simulator.Initialize()
    for step in range(1, int(40 * contact_steps) + 2):
        simulator.AdvanceTo(step * h)
        if plant.EvalBodyPoseInWorld(context, ball).translation()[2] > start:
            break
    return float(plant.EvalBodySpatialVelocityInWorld(context, ball).translational()[2])


@functools.lru_cache(maxsize=64)
def drake_dv(e: float, contact_steps: float, approximation: str = "lagged") -> float:
    """``d v0`` whose discrete Drake impact (:func:`drake_restitution`) has
    restitution ``e``, by bisection on ``log(d v0)`` (the restitution falls
    from its value at ``d = 0`` towards 0, at most ``1 / (d v0)``); 0 when
    ``e`` is above the restitution at ``d = 0`` (the discrete step alone
    loses more)."""
    if not 0.0 < e <= 1.0:
        raise ValueError(f"restitution must be in (0, 1], got {e}")
    if drake_restitution(0.0, contact_steps, approximation=approximation) <= e:
        return 0.0
    lo, hi = -6.0, math.log(2.0 / e)                # e(exp(lo)) > e > e(exp(hi))
    while hi - lo > DV_TOLERANCE:
        mid = 0.5 * (lo + hi)
        if drake_restitution(math.exp(mid), contact_steps,
                             approximation=approximation) > e:
            lo = mid
        else:
            hi = mid
    return math.exp(0.5 * (lo + hi))


def impact_speed(scene) -> float:
    """The largest speed (m/s) at which a body of ``scene`` can first meet
    the floor or another body, from its start: its speed after falling
    from its lowest vertex to the floor under gravity (energy), or its
    own speed in a scene without gravity."""
    g = scene.world.gravity
    floor = -scene.world.half_size
    speed = 0.0
    for body in scene.bodies:
        v = np.asarray(body.velocity, dtype=np.float64)
        if g > 0.0:
            r = np.asarray(body.orientation, dtype=np.float64)
            lowest = body.position[1] + float(np.min(
                (np.asarray(scene.mesh(body).vertices, dtype=np.float64) * body.scale) @ r[1]))
            speed = max(speed, math.sqrt(v @ v + 2.0 * g * max(lowest - floor, 0.0)))
        else:
            speed = max(speed, math.sqrt(v @ v))
    return speed


@dataclass(frozen=True)
class ContactParameters:
    """The contact parameters of one scene: ``stiffness`` (N/m, what every
    contact sees; each geometry gets twice it), ``dissipation`` (s/m),
    ``impact_speed`` (m/s, the ``v0`` it was chosen for) and the
    ``restitution`` it meets at ``v0`` (the scene's, or the floor)."""

    stiffness: float
    dissipation: float
    impact_speed: float
    restitution: float


def contact_parameters(scene, settings: DrakeSettings | None = None) -> ContactParameters:
    """``k`` and ``d`` for ``scene`` (module docstring: the rule)."""
    s = settings or DrakeSettings()
    h = scene.integration.step
    m = min(float(b.mass) for b in scene.bodies)
    k = m * math.pi ** 2 / (s.contact_steps * h) ** 2
    v0 = max(impact_speed(scene), s.min_impact_speed)
    e = min(max(scene.world.restitution, s.min_restitution), 1.0)
    return ContactParameters(stiffness=k,
                             dissipation=drake_dv(e, s.contact_steps, s.approximation) / v0,
                             impact_speed=v0, restitution=e)


def _cross(a, b) -> np.ndarray:
    """``a x b`` of two 3-vectors (``numpy.cross`` costs more than a step of
    Drake's on the kit's scenes)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


def _origin_velocity(v_com, w, r, c) -> np.ndarray:
    """The body frame origin's velocity from the centre of mass's."""
    return np.asarray(v_com, dtype=np.float64) - _cross(w, r @ c)


def _com_velocity(v_origin, w, r, c) -> np.ndarray:
    """The centre of mass's velocity from the body frame origin's."""
    return np.asarray(v_origin, dtype=np.float64) + _cross(w, r @ c)


class DrakeEngine:
    """Drake's MultibodyPlant behind the engine contract's ``rigid``
    capability (lazy import)."""

    #: The scene keys beyond the seed's world it poses (module docstring:
    #: What the adapter refuses); any other it refuses by name.
    honoured_keys = frozenset({"world.gravity_direction", "world.walls", "world.mu"})
    #: The order of its time step (:func:`refsim.engines.declarations`): a
    #: discrete MultibodyPlant advances velocities, then positions with the
    #: new velocities (Castro et al., "An unconstrained convex formulation
    #: of compliant contact", IEEE T-RO 2022: first order in h).
    integrator_order = 1

    def __init__(self, settings: DrakeSettings | None = None):
        self.settings = settings or DrakeSettings()
        if self.settings.contact_model not in ("point", "hydroelastic"):
            from refsim.errors import OptionError

            raise OptionError(f"engine drake: contact_model must be 'point' or 'hydroelastic', "
                              f"got {self.settings.contact_model!r}")
        self.name = "drake" if self.settings.contact_model == "point" else "drake-hydroelastic"
        self.contact_law = ("hunt-crossley" if self.settings.contact_model == "point"
                            else "hydroelastic")
        self.pydrake = import_engine("pydrake", "drake", install_hint(["drake"]))
        self.properties: list = []
        self.parameters: ContactParameters | None = None
        self._scene = None

    # -- building -----------------------------------------------------------------

    def _refuse(self, scene) -> None:
        from refsim.errors import OptionError
        from refsim.scenes.support import refuse_unhonoured

        refuse_unhonoured(scene, self.name, self.honoured_keys)
        if scene.particles is not None:
            raise OptionError(f"scene key particles: engine {self.name} simulates rigid "
                              "bodies only")

    def load(self, scene) -> None:
        """Build ``scene`` as a plant and set its initial state."""
        from pydrake.geometry import (
            AddCompliantHydroelasticProperties,
            AddContactMaterial,
            AddRigidHydroelasticProperties,
            Convex,
            HalfSpace,
            ProximityProperties,
        )
        from pydrake.math import RigidTransform, RotationMatrix
        from pydrake.multibody.math import SpatialVelocity
        from pydrake.multibody.plant import (
            AddMultibodyPlantSceneGraph,
            ContactModel,
            CoulombFriction,
        )
        from pydrake.multibody.tree import RotationalInertia, SpatialInertia
        from pydrake.systems.analysis import Simulator
        from pydrake.systems.framework import DiagramBuilder
        from refsim.oracles.pybullet_adapter import mass_properties

        self._refuse(scene)
        s = self.settings
        self.parameters = p = contact_parameters(scene, s)
        mu = scene.world.coulomb_mu
        H = scene.world.half_size
        hydro = s.contact_model == "hydroelastic"

        builder = DiagramBuilder()
        plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=scene.integration.step)
        plant.set_discrete_contact_approximation(_approximation(s.approximation))
        plant.set_contact_model(ContactModel.kHydroelastic if hydro else ContactModel.kPoint)
        plant.mutable_gravity_field().set_gravity_vector(list(scene.world.gravity_vector))

        def material(modulus: float | None = None, wall: bool = False):
            props = ProximityProperties()
            AddContactMaterial(p.dissipation, 2.0 * p.stiffness, CoulombFriction(mu, mu), props)
            if modulus is not None:
                AddCompliantHydroelasticProperties(1.0, modulus, props)
            elif wall and hydro:
                AddRigidHydroelasticProperties(props)
            return props

        self.bodies = []
        self.properties = []
        self._hulls = []
        for i, body in enumerate(scene.bodies):
            mesh = scene.mesh(body)
            props = mass_properties(mesh.vertices, mesh.faces, body.mass, body.scale)
            self.properties.append(props)
            tensor = props.axes @ np.diag(props.inertia) @ props.axes.T
            inertia = SpatialInertia.MakeFromCentralInertia(
                float(body.mass), props.center,
                RotationalInertia(tensor[0, 0], tensor[1, 1], tensor[2, 2],
                                  tensor[0, 1], tensor[0, 2], tensor[1, 2]))
            rigid = plant.AddRigidBody(f"b{i}", inertia)
            modulus = None
            if hydro:
                modulus = _hydroelastic_modulus(mesh.vertices, body.scale, props, p.stiffness)
            shape = Convex(np.asarray(mesh.vertices, dtype=np.float64).T.copy(), f"b{i}",
                           float(body.scale))
            plant.RegisterCollisionGeometry(rigid, RigidTransform(), shape, f"g{i}",
                                            material(modulus))
            self._hulls.append(np.asarray(mesh.vertices, dtype=np.float64) * body.scale)
            self.bodies.append(rigid)
        for k, wall in enumerate(WALL_NAMES):
            if wall not in scene.world.walls:
                continue                                  # a world without that wall
            axis, sign = k // 2, (-1.0 if wall.endswith("-") else 1.0)
            point = np.zeros(3)
            point[axis] = sign * H
            normal = np.zeros(3)
            normal[axis] = -sign                          # into the cube
            plant.RegisterCollisionGeometry(plant.world_body(),
                                            HalfSpace.MakePose(normal, point), HalfSpace(),
                                            f"w{k}", material(wall=True))
        plant.Finalize()
        self.plant = plant
        with _deformable_note_dropped():
            self.diagram = builder.Build()
        self.simulator = Simulator(self.diagram)
        self.context = self.simulator.get_mutable_context()
        self.plant_context = plant.GetMyMutableContextFromRoot(self.context)
        for body, rigid, props in zip(scene.bodies, self.bodies, self.properties, strict=True):
            r = np.asarray(body.orientation, dtype=np.float64)
            w = np.asarray(body.angular_velocity, dtype=np.float64)
            plant.SetFreeBodyPose(self.plant_context, rigid,
                                  RigidTransform(RotationMatrix(r),
                                                 np.asarray(body.position, dtype=np.float64)))
            plant.SetFreeBodySpatialVelocity(
                self.plant_context, rigid,
                SpatialVelocity(w, _origin_velocity(body.velocity, w, r, props.center)))
        self._scene = scene
        self._step = 0
        self._force_port = plant.get_applied_spatial_force_input_port()
        self._force_port.FixValue(self.plant_context, [])
        self.simulator.Initialize()

    # -- stepping and reading ------------------------------------------------------

    def _apply_drag(self) -> None:
        world = self._scene.world
        if world.drag == 0.0:
            return
        from pydrake.multibody.math import SpatialForce
        from pydrake.multibody.plant import ExternallyAppliedSpatialForce

        forces = []
        q = self.plant.GetPositions(self.plant_context)
        u = self.plant.GetVelocities(self.plant_context)
        for i, (rigid, props) in enumerate(zip(self.bodies, self.properties, strict=True)):
            _, v_com, _, _ = self._body_state(i, q, u)
            k = world.drag * (np.linalg.norm(v_com) if world.drag_model == "quadratic" else 1.0)
            force = ExternallyAppliedSpatialForce()
            force.body_index = rigid.index()
            force.p_BoBq_B = props.center
            force.F_Bq_W = SpatialForce(np.zeros(3), -k * v_com)
            forces.append(force)
        self._force_port.FixValue(self.plant_context, forces)

    def step(self) -> None:
        """One Drake step of the loaded scene (drag applied first)."""
        self._apply_drag()
        self._step += 1
        self.simulator.AdvanceTo(self._step * self._scene.integration.step)

    def _body_state(self, i: int, q, u):
        """Body ``i``'s (x, v_com, w, R) from the plant's state vectors ``q``
        and ``u``: a free body's positions are its quaternion ``(w, x, y,
        z)`` and its origin, its velocities ``w`` and the origin's
        velocity, in world (``MultibodyPlant``'s free-body layout; checked
        against ``EvalBodyPoseInWorld`` and
        ``EvalBodySpatialVelocityInWorld``)."""
        rigid = self.bodies[i]
        k, j = rigid.floating_positions_start(), rigid.floating_velocities_start_in_v()
        r = rotation_of_quaternion(q[k:k + 4])
        w = np.array(u[j:j + 3])
        v_com = _com_velocity(u[j + 3:j + 6], w, r, self.properties[i].center)
        return np.array(q[k + 4:k + 7]), v_com, w, r

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(B, 3) positions of the mesh origins, (B, 3) velocities of the
        centres of mass, (B, 3) angular velocities (world frame), (B, 3, 3)
        orientations (columns: body axes)."""
        q = self.plant.GetPositions(self.plant_context)
        u = self.plant.GetVelocities(self.plant_context)
        parts = [self._body_state(i, q, u) for i in range(len(self.bodies))]
        return tuple(np.array([p[k] for p in parts]) for k in range(4))

    def _poses(self) -> tuple[list, list]:
        """Each body's mesh origin and orientation, from the positions alone
        (what the wall test needs; :meth:`state` also builds the
        velocities)."""
        q = self.plant.GetPositions(self.plant_context)
        starts = [rigid.floating_positions_start() for rigid in self.bodies]
        return ([q[k + 4:k + 7] for k in starts],
                [rotation_of_quaternion(q[k:k + 4]) for k in starts])

    def _wall_contacts(self, x, r) -> set[tuple[int, int]]:
        """(body, wall) pairs touching where each body ``i`` has its mesh
        origin at ``x[i]`` (3,) and its orientation ``r[i]`` (3, 3): a hull
        meets a wall's half-space exactly when one of its vertices does
        (Drake's contact results would say the same, at the cost of a
        second contact query per step)."""
        H = self._scene.world.half_size
        touching = set()
        for i, vertices in enumerate(self._hulls):
            world = vertices @ r[i].T
            lo, hi = world.min(axis=0) + x[i], world.max(axis=0) + x[i]
            if (lo > -H).all() and (hi < H).all():
                continue                              # inside: the common case, kept cheap
            touching.update((i, 2 * int(a)) for a in np.flatnonzero(lo <= -H))
            touching.update((i, 2 * int(a) + 1) for a in np.flatnonzero(hi >= H))
        return touching

    def simulate(self, scene, *, every: int = 1):
        """Run ``scene`` for its duration; a frame every ``every`` steps (and
        the first and the last). Returns a
        :class:`~refsim.dynamics.trajectory.Trajectory` whose events are the
        wall contacts that began in a step; ``stage_seconds`` splits the
        wall time into "step" (the discrete update and the drag forces) and
        "record"."""
        self.load(scene)

        def wall_contacts() -> set[tuple[int, str]]:
            x, r = self._poses()
            return {(i, WALL_NAMES[j]) for i, j in self._wall_contacts(x, r)}

        return run_recorded(self, scene, every, wall_contacts,
                            {"engine": self.name, "version": _version(),
                             **asdict(self.settings), **asdict(self.parameters)})

    def step_time(self, scene, steps: int, warmup: int = 0) -> float:
        """Seconds per step of ``scene`` (mean over ``steps`` steps after
        loading and ``warmup`` untimed steps; reading no state)."""
        self.load(scene)
        return seconds_per_step(self, steps, warmup)


#: What Drake logs (a warning) as it builds a diagram whose SceneGraph holds
#: a half-space: the scene has no deformable bodies, so the note does not
#: apply.
DEFORMABLE_NOTE = "Rigid (non-deformable) half spaces are not currently supported"


@contextlib.contextmanager
def _deformable_note_dropped():
    """Drake's logger (Python's ``drake``) without :data:`DEFORMABLE_NOTE`
    for the block; everything else it logs still shows."""
    import logging

    def keep(record: logging.LogRecord) -> bool:
        return not record.getMessage().startswith(DEFORMABLE_NOTE)

    logger = logging.getLogger("drake")
    logger.addFilter(keep)
    try:
        yield
    finally:
        logger.removeFilter(keep)


def _hydroelastic_modulus(vertices, scale: float, props, stiffness: float) -> float:
    """A hydroelastic modulus (Pa) for a body's hull whose contact stiffness
    is of the order of ``stiffness`` (N/m): ``E = k L / A``, ``L`` the hull's
    extent along its thinnest principal axis, ``A`` the hull's volume over
    ``L``."""
    from scipy.spatial import ConvexHull

    points = np.asarray(vertices, dtype=np.float64) * scale
    extents = np.ptp((points - props.center) @ props.axes, axis=0)
    L = float(np.min(extents))
    A = float(ConvexHull(points).volume) / L
    return stiffness * L / A


def _version() -> str:
    try:
        from importlib.metadata import version

        return version("drake")
    except Exception:  # noqa: BLE001 - metadata missing: the version is only a label
        return "unknown"


def engine(**settings) -> DrakeEngine:
    """The engine factory (``refsim.oracles.drake_adapter:engine``): point
    contact; keyword arguments set fields of :class:`DrakeSettings`."""
    return DrakeEngine(DrakeSettings(**settings))


def engine_hydroelastic(**settings) -> DrakeEngine:
    """Hydroelastic contact (``refsim.oracles.drake_adapter:engine_hydroelastic``),
    named "drake-hydroelastic", law "hydroelastic"."""
    return DrakeEngine(DrakeSettings(**{"contact_model": "hydroelastic", **settings}))
