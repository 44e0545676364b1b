"""Many steps per compiled call: the bridge between :class:`Simulation
<refsim.dynamics.simulation.Simulation>` and its compiled loop
(:func:`refsim.dynamics._numba_kernels.advance`).

The readable step is the reference; the loop takes the same steps in one
numba call, K at a time, for the choices it covers, and hands a step back
to the readable stages whenever that step needs something it does not do
(:func:`loop_support` says which scenes it covers;
:mod:`refsim.dynamics._numba_kernels` says when it hands back). What this
module adds is bookkeeping: the arrays the kernel reads (tableau, masses,
vertices), packed with the simulation's state in three flat arrays
(:mod:`refsim.dynamics.loop_layout`), the contacts as flags instead of a
set, and the kernel's event rows turned into
:class:`~refsim.dynamics.trajectory.Event` in the readable order; and the
body stage of a step whose boxes overlap when the scene's body stage is
not the loop's (:meth:`CompiledLoop.body_stage`: the readable narrow
phase and body response on the kernel's pairs, between two calls).

Why a loop and not faster stages: the readable step's cost is mostly the
interpreter's calls between little arithmetic; stage kernels keep the calls,
and the per-call cost of a numba function with many array arguments stays
above a peer engine's whole step for a few bodies. One call for K steps pays
it once (docs/decisions/compiled-loop.md has the figures).

Seed sections: as the readable step (S2, S3, S5-S9). Cost: the kernel's
per step, plus O(1) per call here (O(events) when the call found some),
plus O(B^2) when the contacts were changed by a readable step since the
last call.
"""

from __future__ import annotations

from time import perf_counter
from typing import TYPE_CHECKING

import numpy as np

from refsim.bounds.aabb_incremental import IncrementalAABB
from refsim.dynamics import impulse
from refsim.dynamics import loop_layout as slot
from refsim.dynamics.trajectory import Contact, Event

if TYPE_CHECKING:
    from refsim.dynamics.simulation import Simulation

#: Rows of the kernel's event buffer per call, at least (more for scenes
#: with many bodies: room for several steps' worth of contacts).
EVENT_ROWS = 4096
#: Vertices per leaf of :func:`vertex_leaves`, at most.
LEAF_VERTICES = 16
WALLS = tuple("xyz"[k // 2] + "-+"[k % 2] for k in range(6))     # flag index -> wall name
_WALL_INDEX = {name: k for k, name in enumerate(WALLS)}


def loop_support(sim: Simulation) -> str | None:
    """Why the compiled loop cannot run ``sim``'s scene (one line), or None.

    It covers every rotation model ("off", "seed", "impulse"), both wall
    responses (the seed's, with either wall speed, and the corrected
    impulses), any solver, linear or quadratic drag, ``world.mu`` and the
    restitution threshold, and body-body contacts at every level but
    "sphere" (the seed's exchange at level "aabb" in the loop; at any other
    level or with any other response, a step with overlapping boxes runs
    its narrow phase and body response in Python between two calls of the
    loop, :meth:`CompiledLoop.body_stage`, and stays the loop's step). The
    loads of :mod:`refsim.dynamics.loads` beyond these (a tilted gravity,
    forces, torques, fixed bodies, missing walls, coefficients per body)
    run on the readable step.
    """
    if sim.plan.body_body and sim.plan.level == "sphere":
        return "collision level 'sphere' (its broad phase is not the boxes')"
    loads, world = sim.loads, sim.scene.world
    if not loads.uniform:
        return "a field other than gravity along -y (gravity_direction, force or fixed)"
    if loads.torque.any():
        return "a torque"
    if not loads.all_walls:
        return "a world without some of its walls"
    if ((loads.wall_e != world.restitution).any()
            or (loads.wall_mu != world.coulomb_mu).any()):
        return "restitution or mu per body"
    return None


def vertex_leaves(vertices: np.ndarray, size: int = LEAF_VERTICES):
    """Groups of at most ``size`` nearby vertices of one mesh and a sphere
    around each, for the kernel's wall stage: a leaf whose sphere is clear
    of a wall has no vertex past it, and its vertices are not looked at
    (:func:`refsim.dynamics._numba_walls.vertices_past_wall`).

    The groups come from halving: a group of more than ``size`` vertices is
    split at the median of its widest coordinate (a stable sort, so the
    same mesh always gives the same leaves). Each leaf's sphere is centred
    on its box's midpoint ``c``, with radius ``rho`` the largest distance to
    a vertex. Rounding in ``rho`` does not matter: the kernel's test has a
    slack far above it.

    Returns ``order`` (n,) int64, the vertex indices leaf by leaf;
    ``start`` (L + 1,) int64, leaf l's indices are ``order[start[l]:
    start[l + 1]]``; and ``spheres`` (L, 5) float64, the rows ``(c_x, c_y,
    c_z, rho, |c| + rho)`` (the last bounds every vertex's distance from
    the mesh origin).
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    groups = [np.arange(len(vertices), dtype=np.int64)]
    leaves = []
    while groups:
        group = groups.pop()
        points = vertices[group]
        if len(group) <= size:
            leaves.append(group)
            continue
        widest = int(np.argmax(points.max(axis=0) - points.min(axis=0)))
        ranked = group[np.argsort(points[:, widest], kind="stable")]
        half = len(ranked) // 2
        groups += [ranked[half:], ranked[:half]]       # the lower half becomes a leaf first
    order = np.concatenate(leaves)
    start = np.zeros(len(leaves) + 1, np.int64)
    start[1:] = np.cumsum([len(leaf) for leaf in leaves])
    spheres = np.empty((len(leaves), 5))
    for l, leaf in enumerate(leaves):
        points = vertices[leaf]
        c = 0.5 * (points.max(axis=0) + points.min(axis=0))
        d = points - c
        rho = np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2]).max()
        spheres[l, :3] = c
        spheres[l, 3] = rho
        spheres[l, 4] = np.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) + rho
    return order, start, spheres


class _Packing:
    """Arrays laid out in the loop's three flat arrays
    (:mod:`refsim.dynamics.loop_layout`): :meth:`put` each, then :meth:`pack`."""

    def __init__(self) -> None:
        self.header = np.zeros(4 * slot.ARRAYS, np.int64)
        self.parts: dict[type, list[np.ndarray]] = {np.float64: [], np.int64: [], np.bool_: []}
        self.size: dict[type, int] = {np.float64: 0, np.int64: len(self.header), np.bool_: 0}
        self.placed: dict[int, tuple[type, int, tuple[int, ...]]] = {}   # dtype, offset, shape

    def put(self, k: int, array, dtype: type) -> None:
        """Array number ``k`` (a copy of ``array``, as ``dtype``)."""
        array = np.ascontiguousarray(array, dtype=dtype)
        self.placed[k] = (dtype, self.size[dtype], array.shape)
        self.header[4 * k] = self.size[dtype]
        self.header[4 * k + 1:4 * k + 4] = array.shape + (1,) * (3 - array.ndim)
        self.parts[dtype].append(array.ravel())
        self.size[dtype] += array.size

    def pack(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(floats, ints, flags)``."""
        ints = np.concatenate([self.header, *self.parts[np.int64]])
        return (np.concatenate([np.zeros(0), *self.parts[np.float64]]), ints,
                np.concatenate([np.zeros(0, np.bool_), *self.parts[np.bool_]]))


class _KeptWallContacts(dict):
    """``Simulation._wall_contacts`` during :meth:`CompiledLoop.body_stage`:
    ``get((body, axis, low))`` is the kernel's kept rows of that wall (a
    view of ``WALL_R``), or ``default`` where the wall stage found no vertex
    past it (which the island solve treats as the readable stage's empty
    entry). Only ``get`` is used there."""

    def __init__(self, wall_r: np.ndarray, wall_at: np.ndarray):
        super().__init__()
        self.wall_r, self.wall_at = wall_r, wall_at

    def get(self, key, default=None):
        i, k, low = key
        start, count = self.wall_at[i, 2 * k + (0 if low else 1)].tolist()
        return self.wall_r[start:start + count] if count else default


class _StepRecords(dict):
    """``Simulation._impulses`` during :meth:`CompiledLoop.body_stage`: a
    wall's record is the kernel's (a view of ``IMPULSE_NOW``, holding what
    the wall stage added), so that the island solve adds to it in place as
    the readable step adds to the one its wall stage made; a body pair's
    record is an entry of the dict itself."""

    def __init__(self, impulse_now: np.ndarray):
        super().__init__()
        self.impulse_now = impulse_now

    def __contains__(self, key) -> bool:
        return key[1] in _WALL_INDEX or dict.__contains__(self, key)

    def __getitem__(self, key):
        k = _WALL_INDEX.get(key[1])
        return dict.__getitem__(self, key) if k is None else self.impulse_now[key[0], k]


class CompiledLoop:
    """The compiled loop of one simulation: its arrays, packed (the constant
    ones, the simulation's state, the contact flags, the event buffer, the
    kernel's scratch), and :meth:`advance`.

    The simulation's ``x``, ``v``, ``w``, ``R``, ``lo``, ``hi`` and its
    counters become views of the packed arrays here (their values kept), so
    that a call of the kernel passes four arguments
    (:mod:`refsim.dynamics.loop_layout` says why)."""

    def __init__(self, sim: Simulation):
        from refsim.dynamics import _numba_kernels as kernels

        self.kernels = kernels
        self.DONE, self.STOP_READABLE = kernels.DONE, kernels.STOP_READABLE
        self.STOP_BODY_STAGE = kernels.STOP_BODY_STAGE
        self.sim = sim
        B = len(sim.bodies)
        world = sim.scene.world
        method = sim.method
        vertices = [b.mesh.vertices for b in sim.bodies]
        self.first_vertex = np.zeros(B + 1, np.int64)
        self.first_vertex[1:] = np.cumsum([len(vs) for vs in vertices])
        self._lay_out_trackers()
        # the leaves serve the corrected wall response only
        plan = sim.plan
        self._lay_out_leaves(vertices if plan.impulse_walls else [])
        capacity = max(EVENT_ROWS, 4 * (6 * B + B * (B - 1) // 2))
        # the wall stage's contacts, kept for the body stage (at most three walls a body)
        keep = plan.loop_body == slot.BODY_HAND_BACK and plan.impulse_walls
        wall_rows = max(1, 3 * int(self.first_vertex[-1])) if keep else 1
        most = max(1, max(len(vs) for vs in vertices))     # vertices of a body, at most
        s = len(method.b_)
        f, i, b = np.float64, np.int64, np.bool_
        scalars = np.zeros(7)
        scalars[[slot.S_H, slot.S_GRAVITY, slot.S_RESTITUTION, slot.S_FRICTION,
                 slot.S_THRESHOLD, slot.S_HALF_SIZE, slot.S_ENERGY_LIMIT]] = (
            sim.h, world.gravity, world.restitution,
            world.coulomb_mu if plan.impulse_walls else world.friction,
            sim.loads.threshold, world.half_size, sim.energy_limit)
        settings = np.zeros(7, np.int64)
        settings[[slot.G_QUADRATIC, slot.G_ROTATION_MODE, slot.G_WALL_SPEED_AT_WALL,
                  slot.G_WALL_IMPULSE, slot.G_ITERATIONS, slot.G_CENTRED, slot.G_BODY_MODE]] = (
            world.drag_model == "quadratic", plan.loop_rotation, plan.speed_at_wall,
            plan.impulse_walls, impulse.ITERATIONS, sim.centred, plan.loop_body)
        packing = _Packing()
        for k, array, dtype in (
                (slot.SCALARS, scalars, f), (slot.HA, sim.h * method.A_, f),
                (slot.HB, sim.h * method.b_, f),
                # the drag rate r = k / m, as translational_rhs divides it
                (slot.DRAG_RATE, world.drag / np.asarray(sim.mass, np.float64), f),
                (slot.VERTICES_T, np.concatenate(vertices).T, f), (slot.CENTER, sim.center, f),
                (slot.LAM, sim.lambda_max, f), (slot.MASS, sim.mass, f),
                (slot.INV_MASS, sim.inv_mass, f), (slot.Q, sim.Q, f),
                (slot.MOMENTS, sim.moments, f), (slot.I_BODY_INV, sim.I_body_inv, f),
                (slot.LEAF_SPHERES, self.leaf_spheres, f), (slot.TRACKERS_F, self.trackers_f, f),
                (slot.IMPULSE_NOW, np.zeros((B, 6, impulse.IMPULSE_RECORD)), f),
                (slot.EVENT_DATA, np.zeros((capacity, impulse.IMPULSE_RECORD)), f),
                (slot.X, sim.x, f), (slot.V, sim.v, f), (slot.W, sim.w, f), (slot.R, sim.R, f),
                (slot.LO, sim.lo, f), (slot.HI, sim.hi, f),
                (slot.Y, np.zeros(6 * B), f), (slot.Y_I, np.zeros(6 * B), f),
                (slot.K, np.zeros((s, 6 * B)), f), (slot.X0, np.zeros((B, 3)), f),
                (slot.V0, np.zeros((B, 3)), f), (slot.W0, np.zeros((B, 3)), f),
                (slot.R0, np.zeros((B, 3, 3)), f), (slot.A, np.zeros((3, 3)), f),
                (slot.E, np.zeros((3, 3)), f), (slot.L, np.zeros(3), f),
                (slot.CORR, np.zeros(3), f), (slot.R_A, np.zeros((most, 3)), f),
                (slot.P, np.zeros((most, 4)), f), (slot.N, np.zeros(3), f),
                (slot.ORIGIN, np.zeros((B, 3)), f), (slot.WALL_R, np.zeros((wall_rows, 3)), f),
                (slot.SETTINGS, settings, i), (slot.COUNTERS, sim._counters, i),
                (slot.FIRST_VERTEX, self.first_vertex, i), (slot.LEAF_ORDER, self.leaf_order, i),
                (slot.LEAF_START, self.leaf_start, i), (slot.FIRST_LEAF, self.first_leaf, i),
                (slot.TRACKED, self.tracked, i), (slot.TRACKER_ROWS, self.tracker_rows, i),
                (slot.TRACKERS_I, self.trackers_i, i), (slot.EVENTS, np.zeros((capacity, 4)), i),
                (slot.PAST, np.zeros(most), i),
                (slot.PAIRS, np.zeros((max(B * (B - 1) // 2, 1), 2)), i),
                (slot.WALL_AT, np.zeros((B, 6, 2)), i),
                (slot.WALLS, np.zeros((B, 6)), b), (slot.BODIES, np.zeros((B, B)), b),
                (slot.NOW_WALLS, np.zeros((B, 6)), b)):
            packing.put(k, array, dtype)
        self.floats, self.ints, self.flags = packing.pack()
        self._placed = packing.placed
        # the simulation's state and counters from here on: views of the packed arrays
        sim.x, sim.v, sim.w, sim.R, sim.lo, sim.hi = (
            self.view(k) for k in (slot.X, slot.V, slot.W, slot.R, slot.LO, slot.HI))
        sim._counters = self.counters = self.view(slot.COUNTERS)
        self.walls = self.view(slot.WALLS)
        self.bodies = self.view(slot.BODIES)
        self.events = self.view(slot.EVENTS)
        self.event_data = self.view(slot.EVENT_DATA)
        self._body_stage_arrays = (self.view(slot.PAIRS), self.view(slot.NOW_WALLS),
                                   self.view(slot.IMPULSE_NOW), self.view(slot.WALL_R),
                                   self.view(slot.WALL_AT))
        self._start_of_step = tuple(self.view(k) for k in (slot.X0, slot.V0, slot.W0, slot.R0))
        self._call = (kernels.advance, self.floats, self.ints, self.flags)
        self._index = {name: i for i, name in enumerate(sim.names)}
        self._flags_stale = False        # the set changed since the flags were built
        self._set_stale = False          # the flags changed since the set was built
        #: Why the last call of :meth:`advance` stopped short (``STOP_READABLE``:
        #: the next step is the readable step's), else ``DONE``.
        self.stop = self.DONE

    def view(self, k: int) -> np.ndarray:
        """Array number ``k`` of :mod:`refsim.dynamics.loop_layout`: a view."""
        dtype, at, shape = self._placed[k]
        flat = {np.float64: self.floats, np.int64: self.ints, np.bool_: self.flags}[dtype]
        return flat[at:at + int(np.prod(shape))].reshape(shape)

    def _lay_out_trackers(self) -> None:
        """The incremental trackers of the bodies that have one (the readable
        step's ``tracked`` bodies with a convex mesh), as slices of two flat
        arrays (:data:`refsim.dynamics._numba_kernels.T_N` and on). The loop's
        walks keep their own extremes and stamps: a walk from any start
        finds the same box."""
        sim, k = self.sim, self.kernels
        self.tracked: np.ndarray = np.full(len(sim.bodies), -1, np.int64)
        rows: list[list[int]] = []
        floats: list[np.ndarray] = []
        ints: list[np.ndarray] = []
        n_f = n_i = 0

        def put(chunks: list[np.ndarray], array, size: int, start: int) -> int:
            chunks.append(np.ascontiguousarray(array).ravel())
            assert chunks[-1].size == size
            return start + size

        for b in sim.tracked:
            tracker = sim.bodies[b].tracker
            if not isinstance(tracker, IncrementalAABB):
                continue                              # the linear scan, in the loop
            mesh = sim.bodies[b].mesh
            n = mesh.n_vertices
            row = [0] * 14
            row[k.T_N] = n
            row[k.T_XYZ] = n_f
            n_f = put(floats, mesh.vertices.T.astype(np.float64), 3 * n, n_f)
            row[k.T_VALUE] = n_f
            n_f = put(floats, np.zeros(3 * n), 3 * n, n_f)
            row[k.T_TIE] = n_f
            n_f = put(floats, np.array([tracker.tie_window], np.float64), 1, n_f)
            row[k.T_OFFSETS] = n_i
            n_i = put(ints, mesh.neighbor_offsets.astype(np.int64), n + 1, n_i)
            row[k.T_INDICES] = n_i
            n_indices = len(mesh.neighbor_indices)
            n_i = put(ints, mesh.neighbor_indices.astype(np.int64), n_indices, n_i)
            row[k.T_INDICES_END] = n_i
            row[k.T_EXTREMES] = n_i
            n_i = put(ints, np.full(6, -1, np.int64), 6, n_i)       # no frame yet
            for column, size in ((k.T_STAMP, 3 * n), (k.T_TOUCHED, n), (k.T_SEEN, n),
                                 (k.T_QUEUE, n), (k.T_GENERATION, 2), (k.T_COUNTS, 2)):
                row[column] = n_i
                n_i = put(ints, np.zeros(size, np.int64), size, n_i)
            self.tracked[b] = len(rows)
            rows.append(row)
        self.tracker_rows: np.ndarray = np.array(rows, np.int64).reshape(-1, 14)
        self.trackers_f: np.ndarray = np.concatenate(floats) if floats else np.zeros(1)
        self.trackers_i: np.ndarray = np.concatenate(ints) if ints else np.zeros(1, np.int64)

    def _lay_out_leaves(self, vertices: list[np.ndarray]) -> None:
        """Every body's :func:`vertex_leaves`, concatenated: body b's leaves
        are ``first_leaf[b]:first_leaf[b + 1]``, their vertex indices count
        from ``first_vertex[b]`` (columns of ``vertices_t``). Bodies of one
        mesh share its leaves' layout. No ``vertices`` (a scene without the
        corrected wall response): no leaves."""
        made: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        orders, starts = [np.zeros(0, np.int64)], [np.zeros(1, np.int64)]
        spheres = [np.zeros((0, 5))]
        self.first_leaf: np.ndarray = np.zeros(len(self.sim.bodies) + 1, np.int64)
        n_leaves = 0
        for b, vs in enumerate(vertices):
            key = id(self.sim.bodies[b].mesh)
            if key not in made:
                made[key] = vertex_leaves(vs)
            order, start, sphere = made[key]
            orders.append(order + self.first_vertex[b])
            starts.append(start[1:] + starts[-1][-1])
            spheres.append(sphere)
            n_leaves += len(sphere)
            self.first_leaf[b + 1] = n_leaves
        self.leaf_order: np.ndarray = np.concatenate(orders)
        self.leaf_start: np.ndarray = np.concatenate(starts)
        self.leaf_spheres: np.ndarray = np.ascontiguousarray(np.concatenate(spheres))

    # -- contacts: the set of the readable step <-> the loop's flags -----------------------

    def touching_changed(self) -> None:
        """The readable step changed ``sim._touching``."""
        self._flags_stale = True
        self._set_stale = False

    def sync_set(self) -> None:
        """Bring ``sim._touching`` up to date with the flags (before a readable step)."""
        if not self._set_stale:
            return
        names = self.sim.names
        touching = set()
        for i, k in zip(*np.nonzero(self.walls), strict=True):
            touching.add(Contact("wall", names[i], WALLS[k]))
        for i, j in zip(*np.nonzero(self.bodies), strict=True):
            touching.add(Contact("body", names[i], names[j]))
        self.sim._touching = touching
        self._set_stale = False

    def _sync_flags(self) -> None:
        if not self._flags_stale:
            return
        self.walls[...] = False
        self.bodies[...] = False
        index = self._index
        for contact in self.sim._touching:
            i = index[contact.body]
            if contact.kind == "wall":
                self.walls[i, WALLS.index(contact.other)] = True
            else:
                j = index[contact.other]
                self.bodies[min(i, j), max(i, j)] = True
        self._flags_stale = False

    # -- the loop ---------------------------------------------------------------------------

    def advance(self, n_steps: int) -> int:
        """Up to ``n_steps`` (at least 1) steps in the compiled loop; returns
        how many of them it did not take (0: all), and :attr:`stop` says why.

        The kernel counts the steps and event rows itself
        (:mod:`refsim.dynamics.loop_layout`), and the contacts are the
        kernel's flags from the call on (``_set_stale`` is set before it), so
        whatever interrupts this method leaves steps, time and contacts
        accounting for the state, and the events are added at the next
        :meth:`note_events` (:attr:`Simulation.events` calls it).

        A step the kernel stops in with ``STOP_BODY_STAGE`` (its boxes
        overlap, and the scene's body stage is not the loop's) is ended here
        by :meth:`body_stage`, and the kernel is called again for the steps
        left. If an exception (a signal's ``KeyboardInterrupt``) comes
        before :meth:`body_stage` has committed that step, the state goes
        back to the step's start, where steps, time, contacts and events
        still are, and the exception goes on.
        """
        if self._flags_stale:
            self._sync_flags()
        self._set_stale = True
        kernel, floats, ints, flags = self._call
        counters = self.counters
        sim = self.sim
        try:
            start = perf_counter()
            busy = kernel(n_steps, floats, ints, flags)
            sim.loop_seconds += perf_counter() - start
            if not busy:                       # every step taken, no event
                return 0
            left = int(counters[slot.C_LEFT])
            stop = int(counters[slot.C_STOP]) if left else self.DONE
            while stop == self.STOP_BODY_STAGE:
                self.body_stage()
                left -= 1
                stop = self.DONE
                if left:
                    start = perf_counter()
                    kernel(left, floats, ints, flags)
                    sim.loop_seconds += perf_counter() - start
                    left = int(counters[slot.C_LEFT])
                    stop = int(counters[slot.C_STOP]) if left else self.DONE
        except BaseException:
            if counters[slot.C_STOP] == self.STOP_BODY_STAGE:     # a step not committed
                self.kernels._restore(sim.x, sim.v, sim.w, sim.R, *self._start_of_step)
                counters[slot.C_STOP] = self.DONE
            raise
        self.note_events()
        self.stop = stop
        return left

    def body_stage(self) -> None:
        """The body stage of the step the kernel stopped in with
        ``STOP_BODY_STAGE`` (stages 1-6 done), as :meth:`Simulation.step
        <refsim.dynamics.simulation.Simulation.step>` runs it after its
        broad phase: the narrow phase on the kernel's pairs of boxes, then
        the body response (:mod:`refsim.dynamics.body_stage`, with its
        compiled kernels), whose island solve reads the wall contacts the
        kernel's wall stage kept (``WALL_R``, ``WALL_AT``: what the readable
        wall stage leaves in ``Simulation._wall_contacts``) and adds to its
        wall impulse records (``IMPULSE_NOW``). Then one compiled call,
        :func:`refsim.dynamics._numba_kernels.finish_body_step`, notes the
        step's contacts and events and counts the step. The same state,
        contacts and events as the readable step, bit for bit."""
        sim = self.sim
        pairs, now_walls, impulse_now, wall_r, wall_at = self._body_stage_arrays
        candidates = pairs[:int(self.counters[slot.C_PAIRS])]
        sim._wall_contacts = _KeptWallContacts(wall_r, wall_at)
        records = sim._impulses = _StepRecords(impulse_now)
        timer = sim.timer
        timer.start()
        hits: np.ndarray | list = candidates
        if sim.plan.narrow_phase:
            hits = sim._narrow_phase(candidates)
            timer.lap("narrow-phase")
        sim._body_response(hits, set())          # the contacts: every pair in hits
        timer.lap("body-response")
        rows = np.array(hits, np.int64).reshape(-1, 2)
        found = np.zeros((len(rows), impulse.IMPULSE_RECORD))
        names = sim.names
        for q, (a, b) in enumerate(rows.tolist()):
            record = dict.get(records, (a, names[b]))
            if record is not None:
                found[q] = record
        ordered = self.kernels.finish_body_step(rows, found, self.walls, now_walls, self.bodies,
                                                impulse_now, self.events, self.event_data,
                                                self.counters)
        assert ordered, "the narrow phase's pairs are a subsequence of the broad phase's rows"

    def note_events(self) -> None:
        """The kernel's pending event rows as Events in the simulation's list,
        each step's sorted by (body, other) names as
        :meth:`Simulation._note_events` sorts them; then no row is pending.

        It may be cut short (a signal) and called again: the rows are sorted
        the same way each time, and those after the first ``C_EVENT_BASE``
        events that the list already holds are not added again. The list
        grows in one ``extend`` and the two counters are reset in one
        assignment, so no event is lost or added twice.
        """
        counters = self.counters
        pending = int(counters[slot.C_PENDING])
        if not pending:
            return
        sim = self.sim
        names = sim.names
        rows = self.events[:pending].tolist()
        # the records as Python floats: impulse_and_point's tests and quotients
        # are the same IEEE operations on them, at a fraction of the cost
        data = self.event_data[:pending].tolist()
        found = []
        for row, (step, kind, i, j) in enumerate(rows):
            if kind == 0:
                found.append((step, names[i], WALLS[j], "wall", row))
            else:
                found.append((step, names[i], names[j], "body", row))
        found.sort(key=lambda r: (r[0], r[1], r[2]))
        listed = sim._events
        noted = max(0, len(listed) - int(counters[slot.C_EVENT_BASE]))   # by a cut call
        new = []
        for step, body, other, kind, row in found[noted:]:
            n = step + 1
            J, point = impulse.impulse_and_point(data[row])
            new.append(Event(kind=kind, step=n, time=n * sim.h, body=body, other=other,
                             impulse=J, point=point))
        listed.extend(new)
        counters[slot.C_EVENT_BASE:slot.C_PENDING + 1] = (len(listed), 0)
