"""MuJoCo as a second rigid-body oracle: the same scene, run by MuJoCo.

MuJoCo (E. Todorov, T. Erez, Y. Tassa, "MuJoCo: A physics engine for
model-based control", IROS 2012; E. Todorov, "Convex and analytically-invertible
dynamics with contacts and constraints", ICRA 2014) solves contacts as soft
constraints in one convex optimisation per step. Here it runs a refsim
:class:`~refsim.scenes.schema.Scene`: the world cube's walls as planes,
each body as the convex hull of its mesh with its true mass properties on a
free joint, the scene's gravity and step (and the keys beyond the seed's
world: Scene keys, below). The result is a
:class:`~refsim.dynamics.trajectory.Trajectory`, frame for frame comparable
with ``refsim.simulate`` and the pybullet oracle.

The adapter is an engine (:mod:`refsim.engines`) with the capability
``rigid``: ``refsim.oracles.mujoco_adapter:engine``.

Conventions converted here and nowhere else
-------------------------------------------

- Frames. Each body's MuJoCo frame is the mesh's own frame (refsim's
  reference point and axes); its centre of mass and principal axes go into
  ``<inertial pos quat>``. MuJoCo's free joint holds the frame's position and
  its orientation as a quaternion ``(w, x, y, z)`` (scalar first, unlike
  pybullet and scipy); its velocity ``qvel[0:3]`` is the frame origin's, in
  world coordinates, where refsim's is the centre of mass's
  (:mod:`refsim.dynamics.trajectory`): ``v_com = v_origin + w x (R c)`` when
  reading, ``v_origin = v_com - w x (R c)`` when setting the initial state,
  for the centre of mass ``c`` in the mesh frame. Its angular velocity
  ``qvel[3:6]`` is in the **body** frame: ``w_world = R w_body`` when
  reading, ``w_body = R^T w_world`` when setting the initial state (measured
  here: a body spinning about its tilted axis).
- Meshes. ``<mesh vertex="...">`` without faces: MuJoCo collides a mesh as
  the convex hull of its vertices (qhull), so the l-beam, the star and the
  torus collide as their hulls, as in pybullet. The scene's ``scale`` is
  the mesh's ``scale``.
- Mass properties. Given explicitly (``<inertial>``, ``inertiafromgeom``
  off): the uniform solid of the body's mass, from trimesh's integrals, as
  the pybullet oracle computes them
  (:func:`refsim.oracles.pybullet_adapter.mass_properties`).
- Units and gravity: SI, ``gravity="0 -g 0"`` by default (y up, as refsim).

Every setting, and why (:class:`MujocoSettings` holds them)
------------------------------------------------------------

- Walls: six ``plane`` geoms at ``+-half_size`` with ``zaxis`` pointing into
  the cube (a MuJoCo plane is the infinite half-space below its z axis).
- Contacts only between explicit ``<pair>`` elements (every geom has
  ``contype = conaffinity = 0``): body-wall and body-body. A pair carries its
  own ``solref``, ``solreffriction``, ``solimp``, ``friction`` and
  ``margin``, which is what lets normal and friction rows differ (below).
- Restitution. MuJoCo's default soft contact (``solref="0.02 1"``, a
  critically damped spring) does not bounce. A bounce of restitution ``e``
  needs the normal row's reference acceleration to reverse the approach
  speed in one step: ``solref="0 -b"`` with ``b = (1 + e) / h`` (the
  "direct" form ``-stiffness -damping``: stiffness 0, damping ``b``, so
  ``a_ref = -b v`` and one step of it turns ``v`` into ``-e v``), rebuilt
  for each scene's ``h``, with ``solimp="0.9999 0.9999 0.001 0.5 2"`` (the
  impedance ``d ~ 1``: the reference acceleration is nearly all applied, a
  near-hard constraint). Measured here (sphere, e = 0.8, Euler): apex
  ratios within 0.64 % of e^2 at h = 1e-3 and 0.08 % at h = 1e-4.
- Friction. With the same damper on the friction rows a sticking contact's
  tangential speed is *reversed* (by ``e``); so the friction rows get their
  own one-step damper ``solreffriction="0 -1/h"`` (tangential speed brought
  to 0 in one step, within the friction cone) and ``cone="elliptic"``
  (``solreffriction`` applies to elliptic cones only). ``friction`` is
  ``mu mu 0 0 0``: sliding friction ``mu`` (``world.coulomb_mu``, or the
  pair's: Scene keys) in both
  tangent directions, no torsional or rolling friction, ``condim=3``. It is
  still MuJoCo's law, not Coulomb's impact law: an oblique bounce leaves
  with MuJoCo's own tangential speed (measured: 3.738 m/s where Coulomb
  gives 3.795). The stiff friction reference is a trade-off, measured on a
  cube spinning flat on the floor at 5 rad/s: through the elliptic cone it
  lifts the cube (hops up to 6 cm) while stopping the spin (below 1 % by
  0.69 s); a soft reference (``"0.02 1"``) keeps the cube down but barely
  acts within a one-step impact (4.857 m/s). docs/decisions/conformance.md
  has the table.
- MuJoCo's other friction options, measured one at a time on the kit's
  friction problems (docs/decisions/mujoco-friction.md), none nearer
  Coulomb: ``cone="elliptic"`` is kept because a pyramidal cone mixes the
  normal and friction rows and so gives friction the restitution damper
  (the rolling impact leaves at 0.973 m/s where Coulomb gives 1.430);
  ``impratio`` 1 and ``noslip_iterations`` 0 (MuJoCo's defaults) because
  both act on the friction rows' regularisation, which the impedance
  ``d ~ 1`` already makes negligible (neither moves an oblique bounce by
  more than 1e-4 m/s);
  ``condim=3`` because torsional friction (condim 4, ``mu`` times the
  body's spin lever, as the pybullet oracle's) slows the spinning cube's
  stop instead of hastening it. What lifts the spinning and the sliding
  cube is MuJoCo's convex contact model: a contact starts to slip only by
  moving along its normal (MuJoCo's Computation chapter, "Physical realism
  and soft contacts"), and a friction reference that asks for more than the
  cone allows sends the body off the floor at about ``mu`` times its slip
  speed. ``impratio``, ``noslip_iterations``, ``condim`` and
  ``solreffriction`` are :class:`MujocoSettings` fields too, for that
  page's script.
- ``integrator="Euler"`` (semi-implicit Euler, as Bullet's); ``margin=0``
  and ``gap=0`` on every pair (no contact before the shapes touch).
- Drag: the scene's drag as a force at the centre of mass each step
  (``xfrc_applied``, world frame), ``F = -k v`` or ``-k |v| v`` with the
  centre of mass's velocity at the start of the step (first order, as in
  the pybullet oracle).

Scene keys
----------

The keys beyond the seed's world (:data:`refsim.scenes.support.LOAD_KEYS`;
:attr:`MujocoOracle.honoured_keys`). :meth:`MujocoOracle.load` calls
:func:`refsim.scenes.support.refuse_unhonoured` before it compiles anything.

- ``world.gravity_direction``: ``<option gravity>`` of ``gravity_vector``.
- ``world.walls``: only the named walls' planes (a plane is infinite: a
  body leaving through a missing wall keeps the floor under it).
- ``world.mu``, ``body.restitution``, ``body.mu``, ``pair``: every contact
  is an explicit ``<pair>`` with its own ``friction`` and ``solref``, so
  each gets the ``e`` and ``mu`` :meth:`refsim.scenes.schema.Scene.coefficients`
  resolves for its two bodies (or the body and the wall): any combination
  the scene can pose.
- ``body.fixed``: a body without a free joint (welded to the world; its
  state is the scene's pose at rest). No pair is made between a fixed body
  and a wall or another fixed body.
- ``body.force``, ``body.torque``: ``xfrc_applied`` (world frame, at the
  centre of mass), set once; MuJoCo keeps it between steps, and the drag,
  when the scene has one, is added to the force each step.
- Refused: ``world.restitution_threshold``. The one-step damper is a
  constant of each pair's ``solref``: it reverses every approach speed by
  ``e``, however slow, and nothing in MuJoCo's contact model switches it
  off below a speed (changing ``pair_solref`` between steps from a
  separate collision pass would be this adapter's law, not MuJoCo's).

A missing MuJoCo raises :class:`refsim.oracles.OracleUnavailable`.

Cost: building compiles the model (a convex hull per mesh, O(n log n)); a
step is MuJoCo's collision (hull against plane or hull, per pair) plus its
constraint solver (Newton, a few iterations over the active contacts).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from xml.sax.saxutils import quoteattr

import numpy as np
from refsim.oracles import (
    import_engine,
    rotation_of_quaternion,
    run_recorded,
    seconds_per_step,
)

from refsim.dynamics.world import WALL_NAMES
from refsim.scenes.support import LOAD_KEYS, refuse_unhonoured


@dataclass(frozen=True)
class MujocoSettings:
    """The MuJoCo settings the oracle uses (module docstring: why each)."""

    integrator: str = "Euler"
    cone: str = "elliptic"
    solimp: tuple = (0.9999, 0.9999, 0.001, 0.5, 2.0)
    margin: float = 0.0
    #: Newton solver iterations and tolerance: MuJoCo's defaults (100, 1e-8)
    #: kept explicit.
    iterations: int = 100
    tolerance: float = 1e-8
    #: ``<option impratio>``: the friction rows' impedance over the normal
    #: rows' (elliptic cones).
    impratio: float = 1.0
    #: ``<option noslip_iterations>``: 0 leaves MuJoCo's post-processing
    #: pass of the friction rows off.
    noslip_iterations: int = 0
    #: Each pair's ``condim``: 3 (sliding friction), 4 (and torsional
    #: friction ``mu`` times the contact's spin lever), 6 (and rolling
    #: friction, MuJoCo's least coefficient).
    condim: int = 3
    #: Each pair's ``solreffriction``: None is the one-step damper
    #: ``"0 -1/h"``; a pair of numbers is used as given (``(0, 0)``:
    #: MuJoCo's default, the normal rows' ``solref``).
    solreffriction: tuple | None = None


def _floats(values) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def _quat_wxyz(rotation) -> np.ndarray:
    """The unit quaternion ``(w, x, y, z)`` of a rotation matrix."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(np.asarray(rotation, dtype=np.float64)).as_quat()
    return np.array([w, x, y, z])


class MujocoOracle:
    """MuJoCo behind the engine contract's ``rigid`` capability (lazy import)."""

    name = "mujoco"
    #: The scene keys beyond the seed's world this adapter honours (module
    #: docstring, Scene keys): all but the restitution threshold.
    honoured_keys = frozenset(LOAD_KEYS) - {"world.restitution_threshold"}
    #: The order of its time step (:func:`refsim.engines.declarations`):
    #: ``integrator="Euler"`` is MuJoCo's semi-implicit Euler, first order.
    integrator_order = 1

    def __init__(self, settings: MujocoSettings | None = None):
        self.mujoco = import_engine("mujoco", "mujoco")
        self.settings = settings or MujocoSettings()
        if self.settings.condim not in (3, 4, 6):
            from refsim.errors import OptionError

            raise OptionError(f"engine mujoco: condim must be 3, 4 or 6, not "
                              f"{self.settings.condim!r}")
        self.model = None
        self.data = None
        self.properties: list = []
        self.wall_names: list[str] = []
        self._address: list = []
        self._wall_geom: dict[int, str] = {}
        self._body_geom: dict[int, int] = {}
        self._loads = np.zeros((0, 6))
        self._scene = None

    # -- building -----------------------------------------------------------------

    def mjcf(self, scene) -> str:
        """The MJCF document of ``scene`` (module docstring: every setting)."""
        from refsim.oracles.pybullet_adapter import mass_properties, spin_lever

        s = self.settings
        h = scene.integration.step
        world = scene.world
        H = world.half_size
        solreffriction = (f"0 {-1.0 / h!r}" if s.solreffriction is None
                          else _floats(s.solreffriction))
        solimp = _floats(s.solimp)
        assets, bodies, pairs, levers = [], [], [], []
        self.properties = []
        meshes = {}
        for i, body in enumerate(scene.bodies):
            mesh = scene.mesh(body)
            key = (id(mesh), body.scale)
            if key not in meshes:
                meshes[key] = f"mesh{len(meshes)}"
                assets.append(f'<mesh name="{meshes[key]}" vertex="{_floats(mesh.vertices)}" '
                              f'scale="{_floats([body.scale] * 3)}"/>')
            props = mass_properties(mesh.vertices, mesh.faces, body.mass, body.scale)
            if s.condim > 3:
                levers.append(spin_lever(mesh.vertices, body.scale))
            self.properties.append(props)
            r = np.asarray(body.orientation, dtype=np.float64)
            joint = "" if body.fixed else f'<freejoint name="j{i}"/>'   # fixed: welded to the world
            bodies.append(
                f'<body name="b{i}" pos="{_floats(body.position)}" quat="{_floats(_quat_wxyz(r))}">'
                f'{joint}'
                f'<inertial pos="{_floats(props.center)}" quat="{_floats(_quat_wxyz(props.axes))}" '
                f'mass="{float(body.mass)!r}" diaginertia="{_floats(props.inertia)}"/>'
                f'<geom name="g{i}" type="mesh" mesh="{meshes[key]}" contype="0" '
                f'conaffinity="0"/></body>')
        walls = []
        self.wall_names = [w for w in WALL_NAMES if w in world.walls]
        for k, wall in enumerate(WALL_NAMES):
            if wall not in world.walls:
                continue
            axis, sign = k // 2, (-1.0 if wall.endswith("-") else 1.0)
            pos = [0.0, 0.0, 0.0]
            pos[axis] = sign * H
            zaxis = [0.0, 0.0, 0.0]
            zaxis[axis] = -sign                          # into the cube
            walls.append(f'<geom name="w{k}" type="plane" size="{H!r} {H!r} 0.1" '
                         f'pos="{_floats(pos)}" zaxis="{_floats(zaxis)}" contype="0" '
                         f'conaffinity="0"/>')

        def pair(geom1: str, geom2: str, e: float, mu: float, lever: float = 0.0) -> str:
            # the pair's own coefficients: restitution through the one-step
            # damper, Coulomb's mu in both tangent directions (and, condim 4
            # and 6, mu times the spin lever about the normal)
            return (f'<pair geom1="{geom1}" geom2="{geom2}" condim="{s.condim}" '
                    f'friction="{_floats([mu, mu, mu * lever, 0.0, 0.0])}" '
                    f'solref="0 {-(1.0 + e) / h!r}" solreffriction="{solreffriction}" '
                    f'solimp="{solimp}" margin="{s.margin!r}" gap="0"/>')

        n = len(scene.bodies)
        for i, a in enumerate(scene.bodies):
            if not a.fixed:                              # a fixed body never meets a wall
                for k, wall in enumerate(WALL_NAMES):
                    if wall in world.walls:
                        pairs.append(pair(f"g{i}", f"w{k}", *scene.coefficients(a),
                                          levers[i] if levers else 0.0))
            for j in range(i + 1, n):
                b = scene.bodies[j]
                if not (a.fixed and b.fixed):
                    pairs.append(pair(f"g{i}", f"g{j}", *scene.coefficients(a, b),
                                      min(levers[i], levers[j]) if levers else 0.0))
        return (
            '<mujoco model="refsim">'
            '<compiler angle="radian" inertiafromgeom="false"/>'
            f'<option timestep="{h!r}" gravity="{_floats(world.gravity_vector)}" '
            f'integrator={quoteattr(s.integrator)} '
            f'cone={quoteattr(s.cone)} iterations="{s.iterations}" '
            f'tolerance="{s.tolerance!r}" impratio="{float(s.impratio)!r}" '
            f'noslip_iterations="{int(s.noslip_iterations)}"/>'
            f'<asset>{"".join(assets)}</asset>'
            f'<worldbody>{"".join(walls)}{"".join(bodies)}</worldbody>'
            f'<contact>{"".join(pairs)}</contact>'
            '</mujoco>')

    def load(self, scene) -> None:
        """Compile ``scene`` and set its initial state.

        Raises
        ------
        SceneError
            For a scene key this adapter does not honour
            (:attr:`honoured_keys`, module docstring: Scene keys).
        """
        refuse_unhonoured(scene, self.name, self.honoured_keys)
        mj = self.mujoco
        self.model = mj.MjModel.from_xml_string(self.mjcf(scene))
        self.data = mj.MjData(self.model)
        model = self.model
        # each body's joint addresses (None: fixed, no joint)
        self._address = []
        for i in range(len(scene.bodies)):
            b = i + 1                                    # body 0 is the world
            if model.body_jntnum[b] == 0:
                self._address.append(None)
                continue
            jnt = model.body_jntadr[b]
            self._address.append((int(model.jnt_qposadr[jnt]), int(model.jnt_dofadr[jnt])))
        geom = mj.mjtObj.mjOBJ_GEOM
        self._wall_geom = {mj.mj_name2id(model, geom, f"w{WALL_NAMES.index(w)}"): w
                           for w in self.wall_names}
        self._body_geom = {mj.mj_name2id(model, geom, f"g{i}"): i
                           for i in range(len(scene.bodies))}
        # constant loads (world frame, at the centre of mass), added to drag
        self._loads = np.zeros((len(scene.bodies), 6))
        for i, body in enumerate(scene.bodies):
            if not body.fixed:
                self._loads[i] = [*body.force, *body.torque]
        for i, body in enumerate(scene.bodies):
            if self._address[i] is None:
                continue
            _, dof = self._address[i]
            r = np.asarray(body.orientation, dtype=np.float64)
            w_world = np.asarray(body.angular_velocity, dtype=np.float64)
            v_com = np.asarray(body.velocity, dtype=np.float64)
            self.data.qvel[dof:dof + 3] = v_com - np.cross(w_world,
                                                           r @ self.properties[i].center)
            self.data.qvel[dof + 3:dof + 6] = r.T @ w_world
        self.data.xfrc_applied[1:] = self._loads
        mj.mj_forward(self.model, self.data)
        self._scene = scene

    # -- stepping and reading ------------------------------------------------------

    def _apply_drag(self) -> None:
        """``xfrc_applied``: each body's constant force and torque, plus the
        drag of its centre's velocity at the start of the step."""
        world = self._scene.world
        if world.drag == 0.0:
            return
        d = self.data
        for i in range(len(self.properties)):
            if self._address[i] is None:
                continue
            _, v_com, _, _ = self._body_state(i)
            k = world.drag * (np.linalg.norm(v_com) if world.drag_model == "quadratic" else 1.0)
            d.xfrc_applied[i + 1, :3] = self._loads[i, :3] - k * v_com   # body 0: the world

    def step(self) -> None:
        """One MuJoCo step of the loaded scene (drag applied first)."""
        self._apply_drag()
        self.mujoco.mj_step(self.model, self.data)

    def _body_state(self, i: int):
        if self._address[i] is None:                    # fixed: the scene's pose, at rest
            body = self._scene.bodies[i]
            return (np.array(body.position, dtype=np.float64), np.zeros(3), np.zeros(3),
                    np.array(body.orientation, dtype=np.float64))
        qpos, qvel = self.data.qpos, self.data.qvel
        q, dof = self._address[i]
        r = rotation_of_quaternion(qpos[q + 3:q + 7])
        x = np.array(qpos[q:q + 3])
        w = r @ np.array(qvel[dof + 3:dof + 6])
        v_com = np.array(qvel[dof:dof + 3]) + np.cross(w, r @ self.properties[i].center)
        return x, v_com, w, r

    def state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(B, 3) positions of the mesh origins, (B, 3) velocities of the
        centres of mass, (B, 3) angular velocities (world frame), (B, 3, 3)
        orientations (columns: body axes)."""
        parts = [self._body_state(i) for i in range(len(self._scene.bodies))]
        return tuple(np.array([p[k] for p in parts]) for k in range(4))

    def _wall_contacts(self) -> set[tuple[int, str]]:
        """(body index, wall name) of every body touching a wall."""
        d = self.data
        touching = set()
        for c in range(d.ncon):
            contact = d.contact[c]
            if contact.dist > 0.0:
                continue
            for g1, g2 in ((int(contact.geom1), int(contact.geom2)),
                           (int(contact.geom2), int(contact.geom1))):
                if g1 in self._body_geom and g2 in self._wall_geom:
                    touching.add((self._body_geom[g1], self._wall_geom[g2]))
        return touching

    def simulate(self, scene, *, every: int = 1):
        """Run ``scene`` for its duration; a frame every ``every`` steps (and
        the first and the last). Returns a
        :class:`~refsim.dynamics.trajectory.Trajectory` whose events are the
        wall contacts that began in a step; ``stage_seconds`` splits the
        wall time into "step" (``mj_step`` and the drag forces) and "record"."""
        self.load(scene)
        return run_recorded(self, scene, every, self._wall_contacts,
                            {"engine": "mujoco", "version": self.mujoco.__version__,
                             **asdict(self.settings)})

    def step_time(self, scene, steps: int, warmup: int = 0) -> float:
        """Seconds per step of ``scene`` (mean over ``steps`` steps after
        loading and ``warmup`` untimed steps; reading no state)."""
        self.load(scene)
        return seconds_per_step(self, steps, warmup)


def engine(**settings) -> MujocoOracle:
    """The engine factory (``refsim.oracles.mujoco_adapter:engine``); keyword
    arguments set fields of :class:`MujocoSettings`."""
    return MujocoOracle(MujocoSettings(**settings))
