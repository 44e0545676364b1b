"""The simulation loop: every body of a scene stepped through the seed's
stages, each run only when the scene needs it (seed S5-S9, S11).

One step (:meth:`Simulation.step`), as an outline:

1. integrate   forces (S5) and the scene's solver (S6) for the centroids'
               positions and velocities of all B bodies at once;
2. rotation    the orientation step: the seed's Euler step of the axes (S9)
               or the exact rotation with angular momentum (corrected);
3. check       divergence: a non-finite state, or energy beyond all bounds
               (right after the motion, so that no later stage ever sees a
               non-finite state: every stage after it maps finite to finite);
4. bounds      each body's world box (S2: the linear scan, or the incremental
               tracker for convex bodies, ``collision.aabb``; small meshes
               batched, see ``boxes``);
5. walls       the world-cube test (S3) and the response (S7, plus S9's
               change of w at the contact vertex; or the corrected impulses);
6. broad-phase sort and sweep over the B boxes (S4 test 1; compiled by numba);
7. narrow-phase the scene's collision level on the pairs that pass (S4);
8. body-response  the seed's velocity exchange (S8) or the corrected impulse.

On the compiled kernel, :meth:`Simulation.run` and :meth:`Simulation.advance`
take their steps K at a time in one compiled call
(:mod:`refsim.dynamics.compiled_loop`, :mod:`refsim.dynamics._numba_kernels`)
for the choices the loop covers, and hand each step it does not take back to
:meth:`Simulation.step`; the same state, events and frames, bit for bit. The
loop's wall time is ``loop_seconds`` (not split into stages), its steps
``loop_steps``. A step whose boxes overlap, when the scene's body stage
is not the loop's (any level or body response but the seed's exchange at
level "aabb"), stays the loop's: its narrow phase and body response run
in Python between two calls (``loop_body_steps`` counts them; their time
is in ``stage_seconds``).

Stages 2, 6-8 run only when needed: no rotation work with ``rotation =
"off"``; no body-body work for one body, ``collision.level = "none"`` or
``body_response = "off"``; no narrow phase at level "aabb" (the boxes are
the answer). ``Trajectory.stages`` lists the stages that ran and
``Trajectory.stage_seconds`` the wall time of each.

State, for B bodies (structure of arrays): ``x`` (B, 3) centroid positions,
``v`` (B, 3) centroid velocities (the seed's Pos and Vel), ``w`` (B, 3)
angular velocities in rad/s (world frame), ``R`` (B, 3, 3) orientations
(columns: the body's axes). The reported position is the body's reference
point, its mesh's origin, ``x - R c`` for the body-space centroid ``c``.

Divergence (stage 3): the step stops with
:class:`~refsim.errors.DivergenceError` when the state is not finite or its
energy grows beyond all bounds (:mod:`refsim.dynamics.divergence`).

Where the stages live: the scene's choices are resolved once, by
:func:`refsim.dynamics.plan.stage_plan`, into the plan every stage and the
compiled loop read; this module holds the state, the outline and the
short stages (1, 2, 4); the divergence check, the wall stage and the
body-body stages are base classes of :class:`Simulation`, each in its own
module (:mod:`refsim.dynamics.divergence`, :mod:`refsim.dynamics.wall_stage`,
:mod:`refsim.dynamics.body_stage`), whose methods are the simulation's own.
:func:`refsim.dynamics.simulate.simulate` runs a scene whole.

Seed sections: S5-S9; the choices where the seed is silent or wrong are
listed in :mod:`refsim.dynamics.choices`.

Cost per step: O(s B) for the solver with s stages, O(B) for the rotation,
O(B) box updates (O(1) each, incremental; O(n) each, linear), O(B log B + k)
for the broad phase and the narrow-phase cost of the k candidate pairs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import cast

import numpy as np

from refsim.bounds.aabb_linear import transform_vertices
from refsim.bounds.tracker import AABBTracker, make_aabb_tracker
from refsim.dynamics import body_stage, divergence, impulse, wall_stage
from refsim.dynamics import loop_layout as slot
from refsim.dynamics.boxes import boxes_kernel
from refsim.dynamics.compiled_loop import CompiledLoop, loop_support
from refsim.dynamics.divergence import DIVERGENCE_FACTOR
from refsim.dynamics.energy import EnergyParts, body_energy
from refsim.dynamics.forces import field_rhs, translational_rhs
from refsim.dynamics.loads import apply_torques, scene_loads
from refsim.dynamics.mass_properties import body_mass_properties, inertia_problem
from refsim.dynamics.plan import StagePlan, stage_plan
from refsim.dynamics.products import inverse, matvec
from refsim.dynamics.rotation_impulse import principal_frame
from refsim.dynamics.rotation_seed import orientation_step_seed_kernel
from refsim.dynamics.trajectory import FRAME_ENTRIES, Contact, Event, Trajectory
from refsim.errors import ArgumentTypeError, StateError, check_count, check_option
from refsim.kernels import FREE_ROTATION_STEPS, choose_kernel
from refsim.limits import MAX_STEPS
from refsim.models.mesh import Mesh
from refsim.signals import SignalHold, held_signals
from refsim.solvers.explicit_rk import rk_step
from refsim.solvers.integrate import resolve_method
from refsim.storage.frames import FrameSink, MemorySink

#: Meshes with at most this many vertices get their boxes from one batched
#: linear scan over all their bodies under ``boxes="auto"``: for a cube (8
#: vertices) the batched scan of many bodies costs less than a few calls of
#: the compiled incremental tracker, whose per-call overhead dominates when
#: the walk visits a handful of vertices (docs/decisions/batched-boxes.md).
#: Larger meshes keep the scene's choice of tracker (``collision.aabb``),
#: where the incremental walk pays off (claim C1).
BATCH_VERTICES = 64

BOXES = ("auto", "trackers", "batched")

#: Steps per call of the compiled loop, at most: a call holds the interpreter
#: (no signal handler runs until it returns), so a call must stay short (a
#: few milliseconds for tens of bodies), while the fixed cost of a call
#: (argument passing) stays a small fraction of it for a single cube
#: (docs/decisions/compiled-loop.md has the figures).
LOOP_CHUNK = 4096



def _quiet_overflow() -> np.errstate:
    """numpy's warnings of overflow on the way to a non-finite state,
    silenced around readable steps: the check stage raises DivergenceError,
    and the warnings would repeat the news once per operation, unattributed.
    (The compiled loop raises none, so a one-step ``advance`` call on it
    does not pay for entering this.)"""
    return np.errstate(over="ignore", invalid="ignore", divide="ignore")


class StageTimer:
    """Wall time per stage of the step: :meth:`lap` adds the time since the
    last lap (or :meth:`start`) to a stage's total, in ``seconds``."""

    def __init__(self, stages):
        self.seconds = dict.fromkeys(stages, 0.0)
        self._last = 0.0

    def start(self) -> None:
        self._last = time.perf_counter()

    def lap(self, stage: str) -> None:
        now = time.perf_counter()
        self.seconds[stage] += now - self._last
        self._last = now


def _plan_field(name: str) -> property:
    """A read-only attribute of :class:`Simulation` that is its plan's
    ``name`` (:class:`refsim.dynamics.plan.StagePlan`)."""
    return property(lambda sim: getattr(sim.plan, name), doc=f"``plan.{name}``.")


def check_scene(scene) -> None:
    """Raises ArgumentTypeError unless ``scene`` is a :class:`refsim.Scene`
    (a type of :data:`refsim.dynamics.plan.SCENE_TYPES`)."""
    from refsim.dynamics.plan import SCENE_TYPES

    if not isinstance(scene, tuple(SCENE_TYPES)):
        raise ArgumentTypeError(f"scene must be a refsim.Scene (refsim.load_scene(path)), "
                                f"got {type(scene).__name__}")


@dataclass(frozen=True)
class Body:
    """What the loop knows of one body that does not change: its (scaled)
    mesh, box tracker, mass properties and centroid in body space."""

    name: str
    mesh: Mesh
    tracker: AABBTracker
    mass: float
    center: np.ndarray          # body-space centroid the body rotates about
    inertia: np.ndarray         # (3, 3) body-space, about the solid's centre of mass


class Simulation:
    """The bodies of a scene and their state; :meth:`step` advances all of them.

    The scene's choices are resolved once, into ``plan``
    (:func:`refsim.dynamics.plan.stage_plan`): which rotation step (none,
    the seed's, the exact one), which wall response (the seed's per-axis
    one, with S9's spin change when the rotation model is the seed's, or
    the corrected impulses; ``dynamics.wall_response``), which body
    response, which stages run at all. Every stage reads the plan, and so
    does the compiled loop.

    Parameters
    ----------
    scene : refsim.Scene
    wall_speed : {"wall", "seed"}, optional
        The normal speed the seed's wall response flips (see
        :mod:`refsim.dynamics.walls`): at the wall (energy-consistent) or the
        seed's literal one; default the scene's ``world.wall_speed``.
    boxes : {"auto", "trackers", "batched"}
        How the bounds stage gets each body's box. "trackers": each body's own
        :func:`refsim.make_aabb_tracker` (``collision.aabb``: the incremental
        walk for convex meshes, the linear scan otherwise), one call per body
        (the plain path). "batched": the linear scan's arithmetic for all the
        bodies of one mesh at once. "auto" (default): batched for meshes of at
        most ``BATCH_VERTICES`` vertices, trackers otherwise. All three give
        the same boxes, bit for bit (the incremental walk finds the linear
        scan's extreme vertex on a convex mesh and adds the translation the
        same way); only the cost differs.
    kernel : {"readable", "compiled"}, optional
        The kernels of every stage (:mod:`refsim.kernels`); the same
        trajectory, bit for bit, on either.
    sink : refsim.storage.frames.FrameSink, optional
        Where :meth:`record` puts frames: a :class:`refsim.storage.frames.MemorySink`
        by default (growing by doubling), or e.g. a
        :class:`refsim.storage.frames.SpillSink` that writes them to disk as they come.

    Attributes
    ----------
    x, v, w : (B, 3) float64
        Centroid positions, velocities, angular velocities (rad/s); views that
        tests may write to construct states, in place (on the compiled loop
        these and ``R``, ``lo``, ``hi`` are views of the loop's packed arrays:
        an array bound in their place would not be the one the loop steps).
    R : (B, 3, 3) float64
        Orientations.
    stages : tuple of str (the stages this scene runs: ``plan.stages``)
    timer : StageTimer (``timer.seconds``: dict of stage -> seconds)
    centred : bool
        Every body's centroid is its mesh's origin (the reported position
        needs no ``R c``).
    tracked : list of int
        The bodies whose boxes come from their own tracker (the others: the
        batched scan, ``boxes``).
    lambda_max : (B,) float64
        Each body's largest principal moment (the divergence check's bound).
    energy_limit : float
        The energy beyond which the state has diverged
        (:mod:`refsim.dynamics.divergence`).
    """

    def __init__(self, scene, *, wall_speed: str | None = None, boxes: str = "auto",
                 kernel: str | None = None, sink: FrameSink | None = None):
        check_scene(scene)
        world, col = scene.world, scene.collision
        self._plan = plan = stage_plan(scene, wall_speed)
        self.boxes = check_option("boxes", boxes, BOXES)
        self.kernel = choose_kernel(kernel)
        self.scene = scene
        self.h = scene.integration.step
        self.method = resolve_method(scene.integration.solver)
        # the stage functions, chosen once
        self._rotate = {"off": None, "seed": self._rotate_seed,
                        "impulse": self._rotate_exact}[plan.rotation]
        self._wall = self._wall_impulse if plan.impulse_walls else self._wall_seed
        B = len(scene.bodies)
        if B == 0:
            raise StateError("the scene has no [[body]] to simulate (a particle-only "
                             "scene runs with refsim.ParticleSystem)")
        # what acts beyond the seed's world (refsim.dynamics.loads); refuses a
        # key these choices cannot honour
        self.loads = scene_loads(scene, rotation=plan.rotation,
                                 body_response=plan.body_response,
                                 wall_response=plan.wall_response)

        bodies = []
        for cfg in scene.bodies:
            mesh = scene.mesh(cfg).scaled(cfg.scale)
            props = body_mass_properties(mesh, cfg.mass)
            problem = inertia_problem(props)      # (the loader checked a scene file's bodies)
            if problem:
                raise StateError(f"body {cfg.name!r}: {problem}")
            # AMBIGUITY (seed S9): the seed's centroid is the vertex average
            # ("assuming equal masses for each vertex"); the corrected model
            # rotates about the solid's centre of mass. Equal for every
            # bundled model but the l-beam and the star.
            center = props.center if plan.mass_centre else mesh.centroid_vertex_average
            bodies.append(Body(name=cfg.name, mesh=mesh,
                               tracker=make_aabb_tracker(mesh, col.aabb, kernel=self.kernel),
                               mass=cfg.mass,
                               center=np.array(center), inertia=props.inertia))
        self.bodies = tuple(bodies)
        self.names = tuple(b.name for b in bodies)
        self._index = {name: i for i, name in enumerate(self.names)}
        self.mass = np.array([b.mass for b in bodies])
        self.inv_mass = np.where(self.loads.fixed, 0.0, 1.0 / self.mass)   # fixed: no push
        self.center = np.array([b.center for b in bodies])                  # (B, 3)
        self.centred = not self.center.any()          # every centroid at the mesh origin
        self.I_body = np.array([b.inertia for b in bodies])                 # (B, 3, 3)
        self.I_body_inv = inverse(self.I_body)           # not LAPACK: the same bits anywhere
        self.I_body_inv[self.loads.fixed] = 0.0           # fixed: no turn either
        self._torqued = bool(self.loads.torque.any())
        # the principal axes (mesh frame) and moments of each body: the
        # corrected rotation step's frame (rotation_impulse.free_rotation_step)
        # and the divergence check's largest moment; by fixed-order Jacobi
        # rotations, not LAPACK (the same bits anywhere), once per distinct tensor
        solved: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}
        frames = []
        for b in bodies:
            key = b.inertia.tobytes()
            if key not in solved:
                solved[key] = principal_frame(b.inertia)
            frames.append(solved[key])
        self.Q = np.zeros((B, 3, 3))
        self.moments = np.zeros((B, 3))
        if plan.exact_rotation:
            for i, (Q, moments) in enumerate(frames):
                self.Q[i], self.moments[i] = Q, moments
        self._free_steps = FREE_ROTATION_STEPS.pick(self.kernel)

        # Bodies whose boxes come from the batched scan, one group per mesh;
        # the others call their own tracker (see ``boxes``).
        groups: dict[int, list[int]] = {}
        self.tracked = []
        for i, b in enumerate(bodies):
            batched = boxes == "batched" or (
                boxes == "auto" and b.mesh.n_vertices <= BATCH_VERTICES)
            if batched:
                groups.setdefault(id(b.mesh), []).append(i)
            else:
                self.tracked.append(i)
        # a group of all bodies indexes by a slice (a view, no copy)
        self._linear_groups = [(slice(None) if len(idx) == B else np.array(idx),
                                np.ascontiguousarray(bodies[idx[0]].mesh.vertices.T))
                               for idx in groups.values()]

        # State.
        # orientation rows as written; its columns are the body's axes
        self.R = np.array([c.orientation for c in scene.bodies], dtype=np.float64)
        origin = np.array([c.position for c in scene.bodies], dtype=np.float64)
        self.x = origin + np.einsum("bij,bj->bi", self.R, self.center)
        self.v = np.array([c.velocity for c in scene.bodies], dtype=np.float64)
        self.w = np.array([c.angular_velocity for c in scene.bodies], dtype=np.float64)
        if not plan.rotates:
            self.w[:] = 0.0                       # DEVIATION D7: rotation off, no turning
        # the steps taken and the loop's event bookkeeping (refsim.dynamics.loop_layout;
        # on the compiled loop, a view of its packed arrays that the kernel writes)
        self._counters = np.zeros(slot.COUNTER_COUNT, np.int64)
        if not (np.isfinite(self.x).all() and np.isfinite(self.v).all()
                and np.isfinite(self.w).all()):
            raise StateError("initial state has a non-finite value")

        self._f = (translational_rhs(world.gravity, world.drag, self.mass, world.drag_model)
                   if self.loads.uniform else
                   field_rhs(self.loads.accel, world.drag, self.mass, world.drag_model))
        self.lo = np.empty((B, 3))
        self.hi = np.empty((B, 3))
        self._events: list[Event] = []
        self._touching: set[Contact] = set()
        # what each contact's impulses did in this step, (body index, other
        # name) -> impulse.contact_sum_python's record
        self._impulses: dict[tuple[int, str], np.ndarray] = {}
        # the wall stage's contacts of the step, (body, axis, low wall) -> r
        self._wall_contacts: dict[tuple[int, int, bool], np.ndarray] = {}
        self.stages = plan.stages
        self.timer = StageTimer(self.stages)
        self._frames: FrameSink = MemorySink() if sink is None else sink
        # the largest principal moment of each body: 1/2 lambda_max |w|^2 bounds
        # the rotational energy without a rotation of the inertia tensor
        # (contiguous: the compiled loop then has one signature for any number
        # of bodies, not a second compile for a strided column)
        self.lambda_max = np.array([moments.max() for _, moments in frames])
        self.energy_limit = DIVERGENCE_FACTOR * (self._energy_bound().sum()
                                                  + self._energy_scale())
        # The compiled loop (many steps per call), when the kernel is compiled
        # and the loop does this scene's choices (loop_support).
        self.loop_seconds = 0.0
        self._packed: tuple | None = None       # the meshes for the compiled narrow phase
        self._loop: CompiledLoop | None = None
        if self.kernel == "compiled" and loop_support(self) is None:
            self._loop = CompiledLoop(self)

    @property
    def plan(self) -> StagePlan:
        """The scene's choices, resolved when the simulation was made
        (:func:`refsim.dynamics.plan.stage_plan`; read-only: the stages and
        the compiled loop were set up from it)."""
        return self._plan

    # The choices by the names they had before the plan (read-only: the plan's).
    rotation = _plan_field("rotation")
    body_response = _plan_field("body_response")
    wall_response = _plan_field("wall_response")
    wall_speed = _plan_field("wall_speed")
    level = _plan_field("level")
    body_body = _plan_field("body_body")

    @property
    def steps(self) -> int:
        """The steps taken since the start (int)."""
        return int(self._counters[slot.C_STEPS])

    @steps.setter
    def steps(self, value: int) -> None:
        self._counters[slot.C_STEPS] = value

    @property
    def t(self) -> float:
        """The time, ``steps * h`` (float, seconds)."""
        return int(self._counters[slot.C_STEPS]) * self.h

    @property
    def loop_steps(self) -> int:
        """The steps the compiled loop took (the others: :meth:`step`)."""
        return int(self._counters[slot.C_LOOP_STEPS])

    @property
    def loop_body_steps(self) -> int:
        """Of :attr:`loop_steps`, those whose body stage (narrow phase and
        body response) ran in Python between two calls of the loop
        (:meth:`CompiledLoop.body_stage
        <refsim.dynamics.compiled_loop.CompiledLoop.body_stage>`)."""
        return int(self._counters[slot.C_BODY_STEPS])

    @property
    def events(self) -> list[Event]:
        """The onsets of wall and body contacts so far (the compiled loop's
        last ones added first, :meth:`CompiledLoop.note_events
        <refsim.dynamics.compiled_loop.CompiledLoop.note_events>`)."""
        if self._loop is not None:
            self._loop.note_events()
        return self._events

    @property
    def stage_seconds(self) -> dict[str, float]:
        """Wall time so far of each stage that runs (``timer.seconds``)."""
        return self.timer.seconds

    # -- the reported state ------------------------------------------------------------

    @property
    def position(self) -> np.ndarray:
        """(B, 3) reference points (mesh origins): ``x - R c``, ``R c`` summed
        left to right (:func:`refsim.dynamics.products.matvec`, no einsum or
        BLAS: the same bits on every machine and in the compiled loop)."""
        if self.centred:
            return self.x.copy()
        return self.x - matvec(self.R, self.center)

    @property
    def velocity(self) -> np.ndarray:
        return self.v

    @property
    def angular_velocity(self) -> np.ndarray:
        return self.w

    @property
    def orientation(self) -> np.ndarray:
        return self.R

    def pose(self, i: int) -> tuple[np.ndarray, np.ndarray]:
        """Body i's pose ``(R, origin)``, for the collision and box functions."""
        return self.R[i], self.x[i] - matvec(self.R[i], self.center[i])

    def world_vertices(self, i: int) -> np.ndarray:
        return transform_vertices(self.bodies[i].mesh.vertices, self.pose(i))

    def energy(self) -> np.ndarray:
        """(B,) mechanical energy: ``m |v|^2 / 2 + w . I w / 2 + m g (y + H)``
        (potential measured from the floor; rotational with the body's
        inertia), by :func:`refsim.dynamics.energy.mechanical_energy`."""
        return self.energy_parts().total

    def energy_parts(self) -> EnergyParts:
        """The (B,) kinetic, rotational and potential parts of :meth:`energy`
        (the potential of each body's field, :mod:`refsim.dynamics.loads`)."""
        return body_energy(self, self.x, self.R, self.v, self.w)

    # -- the step ---------------------------------------------------------------------

    def step(self) -> None:
        """One step of size h for all bodies (the outline in the module docstring).

        Raises
        ------
        DivergenceError
            The state became non-finite or its energy grew without bound; the
            frames recorded so far are in ``error.partial``.
        """
        if self._loop is not None:
            self._loop.sync_set()     # the contacts of the loop's last step, as a set
            self._loop.note_events()  # its events, before this step's
        timer = self.timer
        timer.start()
        self._integrate()
        timer.lap("integrate")
        if self._rotate is not None:
            self._rotate()
            if self._torqued:
                apply_torques(self.w, self.R, self.I_body_inv, self.loads.torque, self.h)
            timer.lap("rotation")
        self._check()
        timer.lap("check")
        self._bounds()
        timer.lap("bounds")
        touching: set[Contact] = set()
        self._wall_contacts = {}
        self._impulses = {}
        # AMBIGUITY (A9): walls before bodies, the order of the seed's text
        self._walls(touching)
        timer.lap("walls")
        if self.plan.body_body:
            candidates = self._broad_phase()
            timer.lap("broad-phase")
            pairs: np.ndarray | list = candidates
            if self.plan.narrow_phase:
                pairs = self._narrow_phase(candidates)
                timer.lap("narrow-phase")
            self._body_response(pairs, touching)
            timer.lap("body-response")
        self.steps += 1
        self._note_events(touching)

    def run(self, n_steps: int, every: int = 1) -> None:
        """Take ``n_steps`` steps, recording a frame after every ``every``-th
        step (counted from the start of the simulation).

        Overflow on the way to a non-finite state raises DivergenceError
        from the check stage; numpy's own warnings of it are silenced here
        (they would repeat the news once per operation, unattributed).
        ``n_steps`` above ``refsim.limits.MAX_STEPS`` is a StateError.
        """
        n_steps = check_count("n_steps", n_steps, maximum=MAX_STEPS)
        every = check_count("every", every, minimum=1)
        with held_signals() as hold:
            while n_steps:
                stretch = min(n_steps, every - self.steps % every)   # to the next frame
                self._advance(stretch, hold)
                n_steps -= stretch
                if self.steps % every == 0:
                    self.record()
                hold.check()

    def advance(self, n_steps: int) -> None:
        """Take ``n_steps`` steps and record no frame (:meth:`run` without
        frames): on the compiled kernel, through the compiled loop where the
        scene allows it (:attr:`loop`), else one :meth:`step` at a time. The
        same state, events and frames either way, bit for bit.

        The fast path, for a caller that steps a few times per call (a
        control loop, a viewer's frame): on the compiled loop, a plain
        ``int`` of steps from 1 to ``LOOP_CHUNK`` goes straight to one call
        of the kernel (:meth:`CompiledLoop.advance
        <refsim.dynamics.compiled_loop.CompiledLoop.advance>`), without the
        signal hold and the general check of the count. The same bits: it
        is the same kernel call on the same arrays that :meth:`_advance`
        makes for these steps. No hold is needed around it: the kernel
        counts its steps and event rows itself before returning
        (:mod:`refsim.dynamics.loop_layout`), so a signal acted on after it
        finds steps, time and events accounting for the state. When the
        kernel stops short (a step that needs the readable stages, a full
        event buffer), the rest of the steps go the general way below.
        """
        loop = self._loop
        if loop is not None and n_steps.__class__ is int and 0 < n_steps <= LOOP_CHUNK:
            n_steps = loop.advance(n_steps)          # the steps it did not take
            if not n_steps:
                return
        n_steps = check_count("n_steps", n_steps, maximum=MAX_STEPS)
        with held_signals() as hold:
            self._advance(n_steps, hold)

    def snapshot(self) -> dict:
        """The state to come back to with :meth:`restore`: copies of ``x``,
        ``v``, ``w``, ``R``, the boxes, ``t``, ``steps``, the contacts and
        the number of events (frames already recorded are not part of it).
        Steps from a restored snapshot repeat the same bits (a box tracker's
        starting vertices may differ; its boxes do not)."""
        if self._loop is not None:
            self._loop.sync_set()
        return {"x": self.x.copy(), "v": self.v.copy(), "w": self.w.copy(),
                "R": self.R.copy(), "lo": self.lo.copy(), "hi": self.hi.copy(),
                "t": self.t, "steps": self.steps, "events": len(self.events),
                "touching": set(self._touching)}

    def restore(self, snapshot: dict) -> None:
        """Go back to a :meth:`snapshot` of this simulation (in place)."""
        for name in ("x", "v", "w", "R", "lo", "hi"):
            getattr(self, name)[...] = snapshot[name]
        self.steps = snapshot["steps"]
        del self._events[snapshot["events"]:]
        # no event row of the loop pending (those after the snapshot are dropped)
        self._counters[slot.C_EVENT_BASE:slot.C_PENDING + 1] = (len(self._events), 0)
        self._touching = set(snapshot["touching"])
        if self._loop is not None:
            self._loop.touching_changed()

    @property
    def loop(self) -> str | None:
        """Why :meth:`run` and :meth:`advance` take one step at a time (the
        scene needs what the compiled loop does not do, or the kernel is
        the readable one), or None when they run the compiled loop."""
        if self.kernel != "compiled":
            return "the readable kernel"
        return loop_support(self)

    def _advance(self, n_steps: int, hold: SignalHold) -> None:
        """``n_steps`` steps; a held signal (Ctrl-C, SIGTERM) is acted on
        between steps or compiled calls, where steps, time and events
        account for the whole state (refsim.signals.held_signals)."""
        loop = self._loop
        if loop is None:
            with _quiet_overflow():
                for _ in range(n_steps):
                    self.step()
                    hold.check()
            return
        while n_steps:
            if loop.stop == loop.STOP_READABLE:
                loop.stop = loop.DONE
                with _quiet_overflow():
                    self.step()       # a step the loop does not take: the readable stages
                n_steps -= 1
            else:
                # at most LOOP_CHUNK steps per call, so a held signal waits at
                # most one call (milliseconds)
                chunk = min(n_steps, LOOP_CHUNK)
                n_steps -= chunk - loop.advance(chunk)
            hold.check()

    # 1. forces and the solver, all bodies at once (S5, S6)
    def _integrate(self) -> None:
        B = len(self.bodies)
        y = np.concatenate([self.x.reshape(-1), self.v.reshape(-1)])
        y = rk_step(self.method, self._f, self.t, y, self.h)  # arguments known good
        Y = y.reshape(2, B, 3)
        self.x[...] = Y[0]
        self.v[...] = Y[1]

    # 2. orientation (S9, or the corrected exact rotation)
    def _rotate_seed(self) -> None:
        self.R[...] = orientation_step_seed_kernel(self.R, self.w, self.h, kernel=self.kernel)

    def _rotate_exact(self) -> None:
        self._free_steps(self.R, self.w, self.Q, self.moments, self.h)

    # 4. boxes (S2)
    def _bounds(self) -> None:
        origin = self.position
        for idx, vertices_t in self._linear_groups:
            # the linear scan's r_k(v) = (R_k0 x + R_k1 y) + R_k2 z, batched
            self.lo[idx], self.hi[idx] = boxes_kernel(vertices_t, self.R[idx], origin[idx],
                                                      kernel=self.kernel)
        for i in self.tracked:
            tracker = self.bodies[i].tracker
            # The loop's poses are finite and orthonormal by construction (the
            # check stage), so the tracker's per-call validation is skipped.
            self.lo[i], self.hi[i] = tracker.update_unchecked(self.R[i], origin[i])

    # 3. divergence (refsim.dynamics.divergence)
    _check = divergence.check
    _diverged = divergence.diverged
    _energy_bound = divergence.energy_bound
    _energy_scale = divergence.energy_scale

    # 5. walls (S3, S7, S9 or corrected: refsim.dynamics.wall_stage)
    _walls = wall_stage.walls
    _wall_seed = wall_stage.wall_seed
    _wall_spin_seed = wall_stage.wall_spin_seed
    _wall_impulse = wall_stage.wall_impulse

    # 6-8. broad phase, narrow phase, body-body response (S4, S8 or
    # corrected: refsim.dynamics.body_stage)
    _broad_phase = body_stage.broad_phase
    _narrow_phase = body_stage.narrow_phase
    _narrow_phase_compiled = body_stage.narrow_phase_compiled
    _packed_meshes = body_stage.packed_meshes
    _body_response = body_stage.body_response
    _keep_angular_momentum = body_stage.keep_angular_momentum
    _solve_island = body_stage.solve_island

    def _impulse_record(self, i: int, other: str) -> np.ndarray:
        """The step's impulse record of body ``i``'s contact with ``other``."""
        key = (i, other)
        if key not in self._impulses:
            self._impulses[key] = np.zeros(impulse.IMPULSE_RECORD)
        return self._impulses[key]

    def _note_events(self, touching: set[Contact]) -> None:
        """An event for each contact that began in this step (in the order of
        the bodies' and the others' names, so that runs compare)."""
        for contact in sorted(touching - self._touching, key=lambda c: (c.body, c.other)):
            J, point = impulse.impulse_and_point(
                self._impulses.get((self._index[contact.body], contact.other)))
            self._events.append(Event(kind=contact.kind, step=self.steps, time=self.t,
                                      body=contact.body, other=contact.other, impulse=J,
                                      point=point))
        self._counters[slot.C_EVENT_BASE] = len(self._events)    # the loop's rows come after
        self._touching = touching
        if self._loop is not None:
            self._loop.touching_changed()

    # -- frames ---------------------------------------------------------------------------

    def record(self) -> None:
        """Append the current state to the sink as a frame: ``t``, and the
        (B, 3) ``position``, ``velocity``, ``angular_velocity`` and (B, 3, 3)
        ``orientation`` (the sink copies them)."""
        self._frames.append({"t": self.t, "position": self.position, "velocity": self.v,
                             "angular_velocity": self.w, "orientation": self.R})

    def trajectory(self, settings: dict | None = None) -> Trajectory:
        """The frames recorded so far as a :class:`Trajectory`.

        Its arrays are what the sink holds: with the default memory sink,
        views of its buffers (no copy; later records do not change them);
        with a spill sink, :class:`refsim.storage.frames.SpilledArray` views of its
        files, valid while the sink is open.
        """
        B = len(self.bodies)
        if self._frames.n_frames:
            frames = self._frames.arrays()
            # Trajectory's frame fields are typed for numpy arrays, what the
            # default memory sink gives; a spill sink's SpilledArray views
            # stand in for them (see refsim.dynamics.trajectory), enough to save.
            t, x, v, w, R = (cast(np.ndarray, frames[name]) for name in FRAME_ENTRIES)
        else:
            t = np.empty(0)
            x, v, w = (np.empty((0, B, 3)) for _ in range(3))
            R = np.empty((0, B, 3, 3))
        ran = tuple(s for s in self.stages)
        return Trajectory(t=t, position=x, velocity=v, angular_velocity=w, orientation=R,
                          names=self.names, events=list(self.events), stages=ran,
                          stage_seconds=dict(self.timer.seconds),
                          settings=dict(settings or self._settings()))

    def _settings(self) -> dict:
        s, plan = self.scene, self.plan
        return {"solver": s.integration.solver, "step": self.h,
                "rotation": plan.rotation, "body_response": plan.body_response,
                "wall_response": plan.wall_response, "collision_level": plan.level,
                "aabb": s.collision.aabb, "wall_speed": plan.wall_speed, "boxes": self.boxes,
                "kernel": self.kernel, "steps": self.steps}
