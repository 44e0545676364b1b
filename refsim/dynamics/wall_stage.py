"""The wall stage of the simulation step (stage 5 of
:mod:`refsim.dynamics.simulation`): the world-cube test of each body's box
(S3) and the response to each wall it crossed.

Two responses, chosen once per scene (``dynamics.wall_response``):

- the seed's per-axis response (S7), after S9's change of angular velocity
  at the contact vertex when the rotation model is the seed's
  (:func:`wall_seed`);
- the corrected impulses at the vertices past the wall, with the bounce
  carried on from the instant of the crossing (:func:`wall_impulse`,
  choices D6 and D10 of :mod:`refsim.dynamics.choices`).

Each function takes the :class:`~refsim.dynamics.simulation.Simulation` and
reads and writes its state; the simulation holds them as its methods
(``Simulation._walls`` is :func:`walls`, and so on).

Seed sections: S3, S7, S9.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from refsim.bounds.world_cube import world_cube_test
from refsim.dynamics import impulse
from refsim.dynamics.loads import keep_walls
from refsim.dynamics.rotation_impulse import past_wall, wall_contacts, world_inertia
from refsim.dynamics.rotation_seed import contact_spin_seed, contact_vertex_seed
from refsim.dynamics.trajectory import Contact
from refsim.dynamics.walls import (
    bounce_advance,
    crossing_time,
    deepest_speed,
    wall_name,
    wall_response_seed,
    wall_speed,
)

if TYPE_CHECKING:
    from refsim.dynamics.simulation import Simulation


# 5. walls (S3, S7, S9 or corrected)
def walls(sim: Simulation, touching: set) -> None:
    H = sim.scene.world.half_size
    loads = sim.loads
    beyond = np.flatnonzero(((sim.lo < -H) | (sim.hi > H)).any(axis=1))
    for i in beyond.tolist():
        correction = world_cube_test(sim.lo[i], sim.hi[i], H).correction
        if not loads.all_walls:
            correction = keep_walls(correction, loads.low, loads.high)
        if loads.fixed[i] or not correction.any():
            continue                  # a fixed body stays; a missing wall does not push
        sim._wall(i, correction)
        sim.lo[i] += correction
        sim.hi[i] += correction
        for k in np.flatnonzero(correction).tolist():
            touching.add(Contact("wall", sim.names[i], wall_name(k, correction[k])))


def wall_seed(sim: Simulation, i: int, correction: np.ndarray) -> None:
    """The seed's per-axis response (S7), after S9's change of w at the
    contact vertex when the rotation model is the seed's."""
    if sim.plan.seed_rotation:
        sim._wall_spin_seed(i, correction)
    world = sim.scene.world
    sim.x[i], sim.v[i] = wall_response_seed(
        sim.x[i], sim.v[i], correction, world.restitution, world.friction,
        world.gravity, sim.plan.wall_speed)


def wall_spin_seed(sim: Simulation, i: int, correction: np.ndarray) -> None:
    """S9 at each crossed wall: the contact vertex, then w += Pi x I."""
    world = sim.scene.world
    W = sim.world_vertices(i)
    for k in np.flatnonzero(correction).tolist():
        low = correction[k] > 0.0
        N = np.zeros(3)
        N[k] = 1.0 if low else -1.0                     # into the body
        Pi = W[contact_vertex_seed(W, k, low)] - sim.x[i]   # R (p_i - c)
        sim.w[i] = contact_spin_seed(sim.w[i], sim.v[i], Pi, N,
                                      world.restitution, world.friction).w


def wall_impulse(sim: Simulation, i: int, correction: np.ndarray) -> None:
    """Corrected wall contact: push back, speed at the wall, impulses at
    the vertices past the wall (the deepest of them for an impact), and a
    bounce carried on from the instant of the crossing to the end of the
    step (:func:`~refsim.dynamics.walls.crossing_time`,
    :func:`~refsim.dynamics.walls.bounce_advance`)."""
    world = sim.scene.world
    H = world.half_size
    I_inv = world_inertia(sim.R[i:i + 1], sim.I_body_inv[i:i + 1])[0]
    for k in np.flatnonzero(correction).tolist():
        low = correction[k] > 0.0
        W = sim.world_vertices(i)
        # DEVIATION (D6): the speed at the wall (energy of the push-back, as in S7), but
        # only for a real bounce: in resting contact this torque-free change
        # at the centroid would cancel gravity by itself and leave the
        # contact impulses (and with them friction and the torque that
        # topples a body balanced on an edge) with nothing to do.
        bounce = sim.v[i, k] * correction[k] < -sim.loads.threshold * abs(correction[k])
        # every vertex past the wall holds a body at rest (and supports it in
        # a body contact's solve); an impact (its deepest contact moving into
        # the wall faster than the threshold) began at the deepest ones
        sim._wall_contacts[i, k, low] = r_a = W[past_wall(W, k, -H if low else H, low)] \
            - sim.x[i]
        u = deepest_speed(r_a, len(r_a), k, low, sim.v[i], sim.w[i]) if len(r_a) else 0.0
        if bounce or (u < -sim.loads.threshold if low else u > sim.loads.threshold):
            r_a = W[wall_contacts(W, k, -H if low else H, low)] - sim.x[i]
        a_k = sim.loads.accel[i, k]
        # a bounce acts at the instant of the crossing, tau before the step's end
        tau = crossing_time(u, a_k, correction[k], low, sim.h) if bounce else 0.0
        sim.x[i, k] += correction[k]                   # no interpenetration persists
        if bounce:
            sim.v[i, k] = wall_speed(sim.v[i, k], a_k, correction[k])
        if not len(r_a):
            continue
        n = np.zeros(3)
        n[k] = 1.0 if low else -1.0
        v_contact, w_contact = sim.v[i].copy(), sim.w[i].copy()
        P = impulse.wall_impulses(r_a, n, sim.inv_mass[i], I_inv, sim.v[i], sim.w[i],
                                  sim.loads.wall_e[i], sim.loads.wall_mu[i],
                                  sim.loads.threshold, kernel=sim.kernel)
        impulse.contact_sum_python(P, n, r_a, sim.x[i],
                                   sim._impulse_record(i, wall_name(k, correction[k])))
        if tau > 0.0:
            w = sim.w[i]
            bounce_advance(sim.x[i], sim.v[i], v_contact, sim.R[i], w,
                           w[0] - w_contact[0], w[1] - w_contact[1], w[2] - w_contact[2],
                           np.empty((3, 3)), sim.lo[i], sim.hi[i], k, low, a_k, tau)
