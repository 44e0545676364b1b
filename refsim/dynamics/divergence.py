"""The divergence check of the simulation step (stage 3 of
:mod:`refsim.dynamics.simulation`), right after the motion, so that no later
stage ever sees a non-finite state: every stage after it maps finite to
finite.

The step stops with :class:`~refsim.errors.DivergenceError` when the state
is not finite, or when the mechanical energy ``E`` (kinetic, potential above
the floor, and rotational, bounded above by ``lambda_max |w|^2 / 2`` with the
body's largest principal moment, so that the check costs O(B)) exceeds
``DIVERGENCE_FACTOR * (E_0 + E_scale)``, with ``E_scale = sum_b m_b (g 2H +
(2H / 1 s)^2 / 2)`` (every body raised across the cube, and moving across it
in one second), so that a scene starting at rest has a sensible scale. The
frames recorded so far are in the error's ``partial``.

Each function takes the :class:`~refsim.dynamics.simulation.Simulation`; the
simulation holds them as its methods (``Simulation._check`` is :func:`check`,
and so on).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from refsim.dynamics.loads import field_potential
from refsim.errors import DivergenceError

if TYPE_CHECKING:
    from refsim.dynamics.simulation import Simulation

#: Energy growth that counts as divergence (see the module docstring): far
#: beyond anything a bounded scene with restitution <= 1 reaches (the seed's
#: rotation model pumps energy, but by factors of a few), far below overflow.
DIVERGENCE_FACTOR = 1e6


def energy_bound(sim: Simulation) -> np.ndarray:
    """(B,) the energy with the rotational part bounded by
    ``lambda_max |w|^2 / 2``: a cheap upper bound of
    :meth:`Simulation.energy <refsim.dynamics.simulation.Simulation.energy>` for
    the divergence check (O(B) without (B, 3, 3) products)."""
    world = sim.scene.world
    kinetic = 0.5 * (sim.mass * np.einsum("bi,bi->b", sim.v, sim.v)
                     + sim.lambda_max * np.einsum("bi,bi->b", sim.w, sim.w))
    if sim.loads.uniform:
        return kinetic + sim.mass * world.gravity * (sim.x[:, 1] + world.half_size)
    return kinetic + field_potential(sim.mass, sim.loads.accel, sim.x, world.half_size)


def energy_scale(sim: Simulation) -> float:
    world = sim.scene.world
    span = 2.0 * world.half_size
    field = (world.gravity if sim.loads.uniform
             else np.sqrt(np.einsum("bi,bi->b", sim.loads.accel, sim.loads.accel)))
    return float((sim.mass * (field * span + 0.5 * span * span)).sum())


def check(sim: Simulation) -> None:
    # One O(B) sum answers both questions: a non-finite x, v or w makes
    # the energy NaN or inf, and "not (E <= limit)" is then true (R stays
    # finite while w is: it is built from w by finite operations).
    energy = sim._energy_bound()
    total = energy.sum()
    if total <= sim.energy_limit:
        return
    bad = ~(np.isfinite(sim.x).all(axis=1) & np.isfinite(sim.v).all(axis=1)
            & np.isfinite(sim.w).all(axis=1) & np.isfinite(sim.R).all(axis=(1, 2)))
    if bad.any():
        sim._diverged("state is not finite", int(np.flatnonzero(bad)[0]))
    # finite state whose energy is beyond the limit (or overflows)
    sim._diverged(f"energy {total:.6g} exceeds {DIVERGENCE_FACTOR:.0e} times its "
                   f"initial value plus scale ({sim.energy_limit:.6g})",
                   int(np.argmax(energy)))


def diverged(sim: Simulation, message: str, i: int):
    # raised within the step being taken: step sim.steps + 1
    raise DivergenceError(message, step=sim.steps + 1, time=(sim.steps + 1) * sim.h,
                          body=sim.names[i], partial=sim.trajectory())
