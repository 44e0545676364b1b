"""The body-body stages of the simulation step (stages 6-8 of
:mod:`refsim.dynamics.simulation`): the broad phase over the bodies' boxes
or spheres (S4 test 1), the narrow phase at the scene's collision level
(S4), and the response to each pair in contact: the seed's velocity
exchange (S8) or the corrected impulses, solved in one island with the
walls the bodies in contact rest on.

Each function takes the :class:`~refsim.dynamics.simulation.Simulation` and
reads and writes its state; the simulation holds them as its methods
(``Simulation._body_response`` is :func:`body_response`, and so on).

Seed sections: S4, S8.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from refsim.collision.bodies import bodies_collide
from refsim.collision.broad_phase import overlapping_pairs
from refsim.collision.contact import contact_points
from refsim.dynamics import impulse
from refsim.dynamics.body_response import (
    WALL_TOUCH,
    contact_geometry,
    exchange_velocities_seed,
    separate_bodies,
)
from refsim.dynamics.products import matvec
from refsim.dynamics.rotation_impulse import world_inertia
from refsim.dynamics.trajectory import Contact
from refsim.dynamics.walls import wall_name

if TYPE_CHECKING:
    from refsim.dynamics.simulation import Simulation


# 6. broad phase (S4 test 1)
def broad_phase(sim: Simulation) -> np.ndarray:
    if sim.plan.level == "sphere":
        from refsim.collision.spheres import bounding_sphere

        centres = np.empty((len(sim.bodies), 3))
        radii = np.empty(len(sim.bodies))
        for i, b in enumerate(sim.bodies):
            c, radii[i] = bounding_sphere(b.mesh)
            R, origin = sim.pose(i)
            centres[i] = matvec(R, c) + origin
        return overlapping_pairs(centres - radii[:, None], centres + radii[:, None],
                                 kernel=sim.kernel)
    return overlapping_pairs(sim.lo, sim.hi, kernel=sim.kernel)


# 7. narrow phase (S4 at the scene's level)
def narrow_phase(sim: Simulation, pairs: np.ndarray) -> list:
    if sim.kernel == "compiled" and sim.plan.level == "exact" and len(pairs):
        return sim._narrow_phase_compiled(pairs)
    hits = []
    for a, b in pairs:
        if bodies_collide(sim.bodies[a].mesh, sim.pose(a), sim.bodies[b].mesh,
                          sim.pose(b), level=sim.plan.level, kernel=sim.kernel):
            hits.append((a, b))
    return hits


def narrow_phase_compiled(sim: Simulation, pairs: np.ndarray) -> list:
    """The exact level's pairs in one compiled call
    (:func:`refsim.collision.bodies.exact_answers`: the
    hierarchy query of :func:`~refsim.collision.bodies.bodies_collide`
    for every pair); a pair it leaves undecided, or whose pose it
    rejects, goes to :func:`~refsim.collision.bodies.bodies_collide`,
    which decides it or raises. The same pairs as the readable kernel."""
    from refsim.collision.bodies import APART, TOUCH, exact_answers

    rows = np.ascontiguousarray(pairs, dtype=np.int64)
    origin = sim.x - matvec(sim.R, sim.center)        # pose(i)'s, all at once
    codes = exact_answers(sim._packed_meshes(), sim.R, origin, rows)
    hits = []
    for (a, b), code in zip(rows.tolist(), codes.tolist(), strict=True):
        if code == TOUCH or (
                code != APART
                and bodies_collide(sim.bodies[a].mesh, sim.pose(a), sim.bodies[b].mesh,
                                   sim.pose(b), level=sim.plan.level, kernel=sim.kernel)):
            hits.append((a, b))
    return hits


def packed_meshes(sim: Simulation) -> tuple:
    """The bodies' meshes packed for :func:`_narrow_phase_compiled`
    (``floats, float_start, ints, int_start, mesh_of``), built once."""
    if sim._packed is None:
        from refsim.collision.bvh_exact import pack_frame_tree

        meshes: dict[int, int] = {}
        arrays: list[tuple[np.ndarray, np.ndarray]] = []
        mesh_of = np.empty(len(sim.bodies), dtype=np.int64)
        for i, body in enumerate(sim.bodies):
            if id(body.mesh) not in meshes:
                meshes[id(body.mesh)] = len(arrays)
                arrays.append(pack_frame_tree(body.mesh))
            mesh_of[i] = meshes[id(body.mesh)]
        float_start = np.cumsum([0] + [len(f) for f, _ in arrays]).astype(np.int64)
        int_start = np.cumsum([0] + [len(k) for _, k in arrays]).astype(np.int64)
        sim._packed = (np.concatenate([f for f, _ in arrays]), float_start,
                        np.concatenate([k for _, k in arrays]), int_start, mesh_of)
    return sim._packed


# 8. body-body response (S8, or corrected)
def body_response(sim: Simulation, pairs, touching: set) -> None:
    contacts = []
    for a, b in pairs:
        a, b = int(a), int(b)
        if sim.loads.fixed[a] and sim.loads.fixed[b]:
            continue                  # two fixed bodies: nothing can move
        touching.add(Contact("body", sim.names[a], sim.names[b]))
        if sim.plan.seed_exchange:
            sim.v[a], sim.v[b], _ = exchange_velocities_seed(
                sim.x[a], sim.x[b], sim.v[a], sim.v[b])
            continue
        geometry = contact_geometry(sim.world_vertices(a), sim.world_vertices(b),
                                    sim.x[a], sim.x[b], sim.R[a], sim.R[b],
                                    kernel=sim.kernel)
        if geometry.depth < 0.0:
            continue                  # a separating axis: coarse-level false contact
        # the impulses act over the corners of the region where the
        # meshes overlap (an offset stack is held along its whole strip);
        # at a coarse level the meshes may not meet: the normal's point
        points = contact_points(sim.bodies[a].mesh, sim.pose(a), sim.bodies[b].mesh,
                                sim.pose(b), geometry.n, kernel=sim.kernel)
        if not len(points):
            points = geometry.point[None, :]
        contacts.append((a, b, points, geometry))
    if not contacts:
        return
    sim._solve_island(contacts)
    for a, b, _, geometry in contacts:
        dx_a, dx_b = separate_bodies(geometry, sim.inv_mass[a], sim.inv_mass[b])
        for i, dx in ((a, dx_a), (b, dx_b)):
            sim.x[i] += dx
            if sim.plan.exact_rotation and dx.any():
                sim._keep_angular_momentum(i, dx)


def keep_angular_momentum(sim: Simulation, i: int, dx: np.ndarray) -> None:
    """Body i was moved by ``dx`` to end an overlap: its momentum ``p``
    then has the moment ``dx x p`` more about every fixed point, which no
    force supplied. Its spin takes that much less angular momentum,
    ``w -= I^-1 (dx x p)`` (world inverse inertia), so that the total
    about any fixed point is what the impulses left. The rotational
    energy changes by ``-w . (dx x p)`` to first order, with ``dx`` a
    fraction of a step's travel."""
    p = sim.v[i] / sim.inv_mass[i]
    moment = np.array([dx[1] * p[2] - dx[2] * p[1], dx[2] * p[0] - dx[0] * p[2],
                       dx[0] * p[1] - dx[1] * p[0]])
    I_inv = world_inertia(sim.R[i:i + 1], sim.I_body_inv[i:i + 1])[0]
    sim.w[i] -= matvec(I_inv, moment)


def solve_island(sim: Simulation, contacts) -> None:
    """One impulse solve (:func:`refsim.dynamics.impulse.solve_island`)
    over all of the step's body contacts and, with the corrected wall
    response, the walls the bodies in them touch: the vertices the wall
    stage found past a wall in this step (a body resting on the floor
    sinks into it by ``g h^2`` each step, all its supporting vertices at
    once), else those the wall stage left on it. With the seed's wall
    response the walls keep the seed's law and are not in the solve."""
    world = sim.scene.world
    H = world.half_size
    B = len(sim.bodies)
    loads = sim.loads
    sets = []                                  # (a, b, r_a, r_b, n, e, mu)
    touched = sorted({c[0] for c in contacts} | {c[1] for c in contacts})
    for i in touched if sim.plan.impulse_walls else ():
        if loads.fixed[i]:
            continue                  # no wall impulse can move it
        W = sim.world_vertices(i)
        for k in range(3):
            for low in (True, False):
                if not (loads.low[k] if low else loads.high[k]):
                    continue                              # a missing wall
                r = sim._wall_contacts.get((i, k, low))
                if r is None or not len(r):
                    column = W[:, k]
                    on = (column <= -H + WALL_TOUCH * H if low
                          else column >= H - WALL_TOUCH * H)
                    r = W[on] - sim.x[i]
                if len(r):
                    n = np.zeros(3)
                    n[k] = 1.0 if low else -1.0
                    sets.append((i, B, r, np.zeros_like(r), n, loads.wall_e[i],
                                 loads.wall_mu[i]))
    for a, b, points, geometry in contacts:
        sets.append((a, b, points - sim.x[a], points - sim.x[b], geometry.n,
                     loads.pair_e[a, b], loads.pair_mu[a, b]))
    starts = np.cumsum([0] + [len(s[2]) for s in sets]).astype(np.int64)
    static = np.zeros((1, 3))
    v, w = np.concatenate([sim.v, static]), np.concatenate([sim.w, static])
    I_inv = np.zeros((B + 1, 3, 3))
    if sim.plan.rotates:
        I_inv[:B] = world_inertia(sim.R, sim.I_body_inv)     # 0 for a fixed body
    P = np.empty((int(starts[-1]), 4))
    impulse.solve_island(
        starts, np.array([s[0] for s in sets], dtype=np.int64),
        np.array([s[1] for s in sets], dtype=np.int64),
        np.concatenate([s[2] for s in sets]), np.concatenate([s[3] for s in sets]),
        np.array([s[4] for s in sets]), np.concatenate([sim.inv_mass, [0.0]]), I_inv, v, w,
        np.array([s[5] for s in sets]), np.array([s[6] for s in sets]), loads.threshold,
        impulse.ITERATIONS, P, kernel=sim.kernel)
    sim.v[...] = v[:B]
    sim.w[...] = w[:B]
    for s, (a, b, r_a, _, n, _, _) in enumerate(sets):
        other = sim.names[b] if b < B else wall_name(int(np.flatnonzero(n)[0]), n.sum())
        impulse.contact_sum_python(P[starts[s]:starts[s + 1]], n, r_a, sim.x[a],
                                   sim._impulse_record(a, other))
