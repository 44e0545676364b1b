"""Many steps per compiled call: the bridge between :class:`Simulation
<refsim.dynamics.simulation.Simulation>` and its compiled loop
(:func:`refsim.dynamics._numba_kernels.advance`).

The readable step is the reference; the loop takes the same steps in one
numba call, K at a time, for the choices it covers, and hands a step back
to the readable stages whenever that step needs something it does not do
(:func:`loop_support` says which scenes it covers;
:mod:`refsim.dynamics._numba_kernels` says when it hands back). What this
module adds is bookkeeping: the arrays the kernel reads (tableau, masses,
vertices), the contacts as flags instead of a set, and the kernel's event
rows turned into :class:`~refsim.dynamics.trajectory.Event` in the readable
order.

Why a loop and not faster stages: the readable step's cost is mostly the
interpreter's calls between little arithmetic; stage kernels keep the calls,
and the per-call cost of a numba function with many array arguments stays
above a peer engine's whole step for a few bodies. One call for K steps pays
it once (docs/decisions/compiled-loop.md has the figures).

Seed sections: as the readable step (S2, S3, S5-S9). Cost: the kernel's
per step, plus O(B + events) per call here, plus O(B^2) when the contacts
were changed by a readable step since the last call.
"""

from __future__ import annotations

import time
from typing import TYPE_CHECKING

import numpy as np

from refsim.bounds.aabb_incremental import IncrementalAABB
from refsim.dynamics import impulse
from refsim.dynamics.trajectory import Event

if TYPE_CHECKING:
    from refsim.dynamics.simulation import Simulation

#: Rows of the kernel's event buffer per call, at least (more for scenes
#: with many bodies: room for several steps' worth of contacts).
EVENT_ROWS = 4096
#: Vertices per leaf of :func:`vertex_leaves`, at most.
LEAF_VERTICES = 16
WALLS = tuple("xyz"[k // 2] + "-+"[k % 2] for k in range(6))     # flag index -> wall name


def loop_support(sim: Simulation) -> str | None:
    """Why the compiled loop cannot run ``sim``'s scene (one line), or None.

    It covers every rotation model ("off", "seed", "impulse"), both wall
    responses (the seed's, with either wall speed, and the corrected
    impulses), any solver, linear or quadratic drag, ``world.mu`` and the
    restitution threshold, and body-body contacts at every level but
    "sphere" (the seed's exchange at level "aabb" in the loop; any other
    level or response hands the steps with overlapping boxes back). The
    loads of :mod:`refsim.dynamics.loads` beyond these (a tilted gravity,
    forces, torques, fixed bodies, missing walls, coefficients per body)
    run on the readable step.
    """
    if sim.body_body and sim.level == "sphere":
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
    (:func:`refsim.dynamics._numba_kernels._vertices_past_wall`).

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


class CompiledLoop:
    """The compiled loop of one simulation: its constant arrays, the contact
    flags, and :meth:`advance`."""

    def __init__(self, sim: Simulation):
        from refsim.dynamics import _numba_kernels as kernels

        self.kernels = kernels
        self.STOP_READABLE = kernels.STOP_READABLE
        self.sim = sim
        B = len(sim.bodies)
        h = sim.h
        world = sim.scene.world
        method = sim.method
        self.hA = np.ascontiguousarray(h * method.A_)
        self.hb = np.ascontiguousarray(h * method.b_)
        # the drag rate r = k / m, as translational_rhs divides it
        self.drag_rate = np.ascontiguousarray(world.drag / np.asarray(sim.mass, np.float64))
        self.quadratic = world.drag_model == "quadratic"
        vertices = [b.mesh.vertices for b in sim.bodies]
        self.first_vertex = np.zeros(B + 1, np.int64)
        self.first_vertex[1:] = np.cumsum([len(vs) for vs in vertices])
        self.vertices_t = np.ascontiguousarray(np.concatenate(vertices).T)
        self.center = np.ascontiguousarray(sim.center, dtype=np.float64)
        self.rotation_mode = {"off": kernels.ROTATION_OFF, "seed": kernels.ROTATION_SEED,
                              "impulse": kernels.ROTATION_EXACT}[sim.rotation]
        self.Q = np.ascontiguousarray(sim.Q, dtype=np.float64)
        self.moments = np.ascontiguousarray(sim.moments, dtype=np.float64)
        self.I_body_inv = np.ascontiguousarray(sim.I_body_inv, dtype=np.float64)
        self._lay_out_trackers()
        # the leaves serve the corrected wall response only
        self._lay_out_leaves(vertices if sim.wall_response == "impulse" else [])
        if not sim.body_body:
            self.body_mode = kernels.BODY_NONE
        elif sim.level == "aabb" and sim.body_response == "seed":
            self.body_mode = kernels.BODY_EXCHANGE
        else:
            self.body_mode = kernels.BODY_HAND_BACK
        self.walls = np.zeros((B, 6), np.bool_)
        self.bodies = np.zeros((B, B), np.bool_)
        self.events = np.zeros((max(EVENT_ROWS, 4 * (6 * B + B * (B - 1) // 2)), 4), np.int64)
        self.event_data = np.zeros((len(self.events), impulse.IMPULSE_RECORD))
        self.impulse_now = np.zeros((B, 6, impulse.IMPULSE_RECORD))
        self._index = {name: i for i, name in enumerate(sim.names)}
        self._flags_stale = False        # the set changed since the flags were built
        self._set_stale = False          # the flags changed since the set was built

    def _lay_out_trackers(self) -> None:
        """The incremental trackers of the bodies that have one (the readable
        step's ``_tracked`` bodies with a convex mesh), as slices of two flat
        arrays (:data:`refsim.dynamics._numba_kernels.T_N` and on). The loop's
        walks keep their own extremes and stamps: a walk from any start
        finds the same box."""
        sim, k = self.sim, self.kernels
        self.tracked = np.full(len(sim.bodies), -1, np.int64)
        rows: list[list[int]] = []
        floats: list[np.ndarray] = []
        ints: list[np.ndarray] = []
        n_f = n_i = 0

        def put(chunks: list[np.ndarray], array, size: int, start: int) -> int:
            chunks.append(np.ascontiguousarray(array).ravel())
            assert chunks[-1].size == size
            return start + size

        for b in sim._tracked:
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
        self.tracker_rows = np.array(rows, np.int64).reshape(-1, 14)
        self.trackers_f = np.concatenate(floats) if floats else np.zeros(1)
        self.trackers_i = np.concatenate(ints) if ints else np.zeros(1, np.int64)

    def _lay_out_leaves(self, vertices: list[np.ndarray]) -> None:
        """Every body's :func:`vertex_leaves`, concatenated: body b's leaves
        are ``first_leaf[b]:first_leaf[b + 1]``, their vertex indices count
        from ``first_vertex[b]`` (columns of ``vertices_t``). Bodies of one
        mesh share its leaves' layout. No ``vertices`` (a scene without the
        corrected wall response): no leaves."""
        made: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        orders, starts = [np.zeros(0, np.int64)], [np.zeros(1, np.int64)]
        spheres = [np.zeros((0, 5))]
        self.first_leaf = np.zeros(len(self.sim.bodies) + 1, np.int64)
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
        self.leaf_order = np.concatenate(orders)
        self.leaf_start = np.concatenate(starts)
        self.leaf_spheres = np.ascontiguousarray(np.concatenate(spheres))

    # -- contacts: the set of the readable step <-> the loop's flags -----------------------

    def touching_changed(self) -> None:
        """The readable step changed ``sim._touching``."""
        self._flags_stale = True
        self._set_stale = False

    def sync_set(self) -> None:
        """Bring ``sim._touching`` up to date with the flags (before a readable step)."""
        if not self._set_stale:
            return
        from refsim.dynamics.simulation import Contact

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

    def advance(self, n_steps: int) -> tuple[int, int]:
        """Up to ``n_steps`` steps in the compiled loop: ``(steps taken, stop)``,
        ``stop`` one of the kernel's ``DONE``, ``STOP_READABLE``, ``STOP_EVENTS``."""
        sim = self.sim
        world = sim.scene.world
        self._sync_flags()
        start = time.perf_counter()
        done, n_events, stop = self.kernels.advance(
            n_steps, sim.h, self.hA, self.hb, world.gravity, self.drag_rate, self.quadratic,
            self.rotation_mode, world.restitution,
            world.coulomb_mu if sim.wall_response == "impulse" else world.friction,
            sim.wall_speed == "wall", sim.wall_response == "impulse",
            sim.loads.threshold, impulse.ITERATIONS, world.half_size,
            self.vertices_t, self.first_vertex, sim._centred, self.center, sim._lambda_max,
            sim.mass, sim.inv_mass, self.Q, self.moments, self.I_body_inv, sim._energy_limit,
            self.leaf_order, self.leaf_start, self.leaf_spheres, self.first_leaf,
            self.body_mode, sim.x, sim.v, sim.w, sim.R, sim.lo, sim.hi, self.walls,
            self.bodies, self.events, self.tracked, self.tracker_rows, self.trackers_f,
            self.trackers_i, self.impulse_now, self.event_data)
        sim.loop_seconds += time.perf_counter() - start
        if done:
            self._note_events(n_events)
            sim.steps += done
            sim.t = sim.steps * sim.h
            sim.loop_steps += done
            self._set_stale = True
        return done, stop

    def _note_events(self, n_events: int) -> None:
        """The kernel's rows as Events, each step's sorted by (body, other)
        names as :meth:`Simulation._note_events` sorts them."""
        if not n_events:
            return
        sim = self.sim
        names = sim.names
        rows = self.events[:n_events].tolist()
        base = sim.steps
        found = []
        for row, (step, kind, i, j) in enumerate(rows):
            if kind == 0:
                found.append((step, names[i], WALLS[j], "wall", row))
            else:
                found.append((step, names[i], names[j], "body", row))
        found.sort(key=lambda r: (r[0], r[1], r[2]))
        for step, body, other, kind, row in found:
            n = base + step + 1
            J, point = impulse.impulse_and_point(self.event_data[row])
            sim.events.append(Event(kind=kind, step=n, time=n * sim.h, body=body, other=other,
                                    impulse=J, point=point))
