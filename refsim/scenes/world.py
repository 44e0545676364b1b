"""The world and the integration settings of a scene (S5, S6, S11), with
their defaults: the one place they are written, shared by the scene schema
(:mod:`refsim.scenes.schema`) and the particle system's configuration
(:mod:`refsim.particles.config`).
"""

from __future__ import annotations

from dataclasses import dataclass

from refsim.solvers.integrate import whole_steps


@dataclass(frozen=True)
class WorldConfig:
    """``[world]``: the cube, the forces (S5) and the wall law (S7).

    ``wall_speed``: the normal speed a wall bounce flips, "wall" (the speed at
    the wall, energy-consistent: :mod:`refsim.dynamics.walls`, DEVIATION D1)
    or "seed" (the seed's literal speed at the penetrated position); for
    rigid bodies and particles alike.
    """

    half_size: float = 5.0
    gravity: float = 9.81
    drag: float = 0.0
    drag_model: str = "linear"
    restitution: float = 0.8
    friction: float = 0.0
    wall_speed: str = "wall"


@dataclass(frozen=True)
class IntegrationConfig:
    """``[integration]``: the solver (S6), its step and the duration."""

    solver: str = "rk4"
    step: float = 0.001
    duration: float = 5.0

    @property
    def n_steps(self) -> int:
        """The whole number of steps in ``duration`` (the loader checks it is one)."""
        return whole_steps(self.duration, self.step)
