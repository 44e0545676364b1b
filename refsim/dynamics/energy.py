"""The mechanical energy of rigid bodies: one formula for every place that
needs it.

The simulation's divergence check and ``Simulation.energy``, the studies of
rotation and bouncing, the viewer's energy plot and the conformance kit's
energy check all evaluate

    E = m |v|^2 / 2  +  w_b . I w_b / 2  +  m g (y_c - floor)

per body, with ``v`` the velocity of the centre of mass, ``w_b = R^T w`` the
angular velocity in the body's frame (so the body-frame inertia ``I`` is used
as it is, without forming ``R I R^T``), and ``y_c`` the height of the centre
of mass. The three parts are kept apart (:class:`EnergyParts`) because the
studies and plots show them apart.

Two states carry this: the simulation's own (centre of mass ``x``), and a
recorded :class:`~refsim.dynamics.trajectory.Trajectory`, whose ``position``
is the mesh's origin: its centre of mass is ``position + R c`` with ``c`` the
centre of mass in the mesh's frame (:func:`trajectory_energy`).

Cost: O(B) per state; O(F B) for a trajectory of F frames.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from refsim.dynamics.loads import field_potential

if TYPE_CHECKING:
    from refsim.dynamics.simulation import Simulation


@dataclass(frozen=True)
class EnergyParts:
    """The three parts of the mechanical energy, each of shape (..., B) in J:
    ``kinetic`` (translational, of the centre of mass), ``rotational`` and
    ``potential`` (from the floor)."""

    kinetic: np.ndarray
    rotational: np.ndarray
    potential: np.ndarray

    @property
    def total(self) -> np.ndarray:
        return self.kinetic + self.rotational + self.potential


def mechanical_energy(mass, inertia, gravity: float, floor: float, center_of_mass,
                      orientation, velocity, angular_velocity) -> EnergyParts:
    """The energy of bodies in any number of states (module docstring).

    Parameters
    ----------
    mass : array_like
        (B,) kg.
    inertia : array_like
        (B, 3, 3) inertia tensors about the centre of mass, in the body's
        frame, kg m^2.
    gravity : float
        m/s^2, acting along -y.
    floor : float
        The height of zero potential energy (the world cube's floor, ``-H``).
    center_of_mass, velocity, angular_velocity : array_like
        (..., B, 3): world positions of the centres of mass, their
        velocities, angular velocities (rad/s).
    orientation : array_like
        (..., B, 3, 3) rotations from the body's frame to the world's.
    """
    mass = np.asarray(mass, dtype=np.float64)
    v = np.asarray(velocity, dtype=np.float64)
    w = np.asarray(angular_velocity, dtype=np.float64)
    w_body = np.einsum("...ji,...j->...i", orientation, w)             # R^T w
    rotational = 0.5 * np.einsum("...i,...ij,...j->...", w_body, np.asarray(inertia), w_body)
    kinetic = 0.5 * mass * np.einsum("...i,...i->...", v, v)
    height = np.asarray(center_of_mass, dtype=np.float64)[..., 1] - floor
    return EnergyParts(kinetic=kinetic, rotational=rotational,
                       potential=mass * gravity * height)


def body_energy(sim: Simulation, center_of_mass, orientation, velocity,
                angular_velocity) -> EnergyParts:
    """The energy parts of ``sim``'s bodies in states of any leading shape
    (..., B, ...): :func:`refsim.dynamics.energy.mechanical_energy` with the
    seed's gravity, else with each body's field (:mod:`refsim.dynamics.loads`)."""
    world = sim.scene.world
    if sim.loads.uniform:
        return mechanical_energy(sim.mass, sim.I_body, world.gravity, -world.half_size,
                                 center_of_mass, orientation, velocity, angular_velocity)
    parts = mechanical_energy(sim.mass, sim.I_body, 0.0, -world.half_size, center_of_mass,
                              orientation, velocity, angular_velocity)
    return EnergyParts(kinetic=parts.kinetic, rotational=parts.rotational,
                       potential=field_potential(sim.mass, sim.loads.accel, center_of_mass,
                                                 world.half_size))


def trajectory_energy(scene, trajectory) -> EnergyParts:
    """The energy of every frame and body of ``trajectory``, a run of
    ``scene`` (refsim's or another engine's, in refsim's frame layout), each
    part of shape (F, B).

    The bodies' masses, inertias and centres are those a
    :class:`refsim.Simulation` of the scene uses (the centre depends on the
    rotation model: seed S9's vertex average or the solid's centre of mass);
    the recorded velocity is the centre of mass's, as
    :meth:`refsim.Simulation.record` writes it.
    """
    from refsim.dynamics.simulation import Simulation  # it imports this module

    sim = Simulation(scene)
    R = np.asarray(trajectory.orientation, dtype=np.float64)
    center_of_mass = (np.asarray(trajectory.position, dtype=np.float64)
                      + np.einsum("fbij,bj->fbi", R, sim.center))
    return body_energy(sim, center_of_mass, R, trajectory.velocity,
                       trajectory.angular_velocity)
