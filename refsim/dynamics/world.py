"""The world and the integration settings of a scene (S5, S6, S11), with
their defaults: the one place they are written, shared by the scene schema
(:mod:`refsim.scenes.schema`) and the particle system's configuration
(:mod:`refsim.particles.config`). They live with the dynamics, below both.
"""

from __future__ import annotations

from dataclasses import dataclass

from refsim.dynamics.impulse import RESTITUTION_THRESHOLD
from refsim.solvers.integrate import whole_steps

#: The six walls of the world cube by name: the axis and the side, "y-" the
#: floor (y is up), "y+" the ceiling.
WALL_NAMES = ("x-", "x+", "y-", "y+", "z-", "z+")
#: Gravity's direction when the scene gives none: down, -y.
DOWN = (0.0, -1.0, 0.0)


@dataclass(frozen=True)
class WorldConfig:
    """``[world]``: the cube, the forces (S5) and the wall law (S7).

    ``wall_speed``: the normal speed a wall bounce flips, "wall" (the speed at
    the wall, energy-consistent: :mod:`refsim.dynamics.walls`, DEVIATION D1)
    or "seed" (the seed's literal speed at the penetrated position); for
    rigid bodies and particles alike.

    Keys the corrected model reads for textbook problems (the rigid bodies
    only; a particle system refuses a value other than the default):

    - ``gravity_direction``: a non-zero vector, normalised; ``gravity`` is
      the magnitude along it (an incline is a tilted gravity over a floor).
    - ``walls``: which of the cube's walls exist (:data:`WALL_NAMES`); a
      body may leave the cube through a missing one.
    - ``mu``: Coulomb's friction coefficient (>= 0, may exceed 1) of the
      corrected contact impulses, named apart from ``friction``, the seed's
      fraction of lateral speed a wall bounce removes. Unset: the corrected
      model reads ``friction`` as mu.
    - ``restitution_threshold``: m/s; a contact approaching slower gets no
      restitution (DEVIATION D6).
    """

    half_size: float = 5.0
    gravity: float = 9.81
    drag: float = 0.0
    drag_model: str = "linear"
    restitution: float = 0.8
    friction: float = 0.0
    wall_speed: str = "wall"
    gravity_direction: tuple[float, float, float] = DOWN
    walls: tuple[str, ...] = WALL_NAMES
    mu: float | None = None
    restitution_threshold: float = RESTITUTION_THRESHOLD

    @property
    def coulomb_mu(self) -> float:
        """The Coulomb coefficient of the corrected responses: ``mu`` when
        the scene sets it, else ``friction`` (read as mu, DEVIATION D5)."""
        return self.friction if self.mu is None else self.mu

    @property
    def gravity_vector(self) -> tuple[float, float, float]:
        """Gravity's acceleration (m/s^2, world frame): ``gravity`` along
        the unit ``gravity_direction``."""
        d = self.gravity_direction
        if d == DOWN:
            return (0.0, -self.gravity, 0.0)
        norm = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) ** 0.5
        return (self.gravity * d[0] / norm, self.gravity * d[1] / norm,
                self.gravity * d[2] / norm)


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
