"""Configuration of a particle system (S10), validated.

What: the frozen dataclass :class:`ParticleConfig` holding everything a run
of :class:`refsim.particles.system.ParticleSystem` needs: how many particles
and where they start, the forces (S5), the wall response (S7) and the solver
(S6). Bad values raise :class:`refsim.errors.SceneError` naming the key
``particles.<field>``, so that a scene file's ``[particles]`` table can be
passed straight through.

Seed section: S10 ("a full particle simulation for further analysis of ODE
solvers and the force approximations"), with the forces of S5 and walls of S7.

Cost: O(1) to validate; :meth:`ParticleConfig.initial_state` is O(N).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from refsim.dynamics.forces import DRAG_MODELS
from refsim.dynamics.walls import SPEEDS
from refsim.dynamics.world import IntegrationConfig, WorldConfig
from refsim.errors import SceneError
from refsim.limits import MAX_MAGNITUDE, MAX_PARTICLES, MIN_POSITIVE


@dataclass(frozen=True)
class ParticleConfig:
    """A particle system's parameters (units SI-like, y up).

    Attributes
    ----------
    count : int
        N, the number of particles (>= 1).
    seed : int
        Seed of the random initial state (numpy ``default_rng``).
    box_lo, box_hi : tuple of 3 floats
        Initial positions are uniform in this box, inside the world cube.
    speed_min, speed_max : float
        Initial speeds are uniform in ``[speed_min, speed_max]``, directions
        uniform on the sphere.
    gravity : float
        Magnitude ``g`` of gravity, which is ``(0, -g, 0)``.
    drag : float
        Drag coefficient ``k``.
    drag_model : {"linear", "quadratic"}
        ``F = -k v`` or ``F = -k |v| v`` (seed S5: linear is the seed's
        choice, quadratic the variant it tried).
    mass : float
        Mass of every particle.
    restitution : float
        ``e``: the normal velocity component after a wall bounce is ``-e``
        times the one before.
    friction : float
        Fraction of the lateral velocity removed at a bounce; the seed's
        ``kFriction = 1 - friction``.
    half_size : float
        The world cube spans ``[-half_size, half_size]`` on each axis.
    wall_speed : {"wall", "seed"}
        The normal speed a bounce flips: at the wall (energy-consistent,
        DEVIATION D1) or the seed's literal one
        (:mod:`refsim.dynamics.walls`, the same law as the bodies').
    walls : bool
        False turns the wall response off (a free particle system, used to
        measure the solvers alone).
    solver : str
        A key of ``refsim.SOLVERS``.
    step : float
        The step ``h``.
    """

    count: int = 1000
    seed: int = 0
    box_lo: tuple = (-1.0, -1.0, -1.0)
    box_hi: tuple = (1.0, 1.0, 1.0)
    speed_min: float = 0.0
    speed_max: float = 5.0
    # the world's and the integration's, with their defaults (refsim.dynamics.world)
    gravity: float = WorldConfig.gravity
    drag: float = WorldConfig.drag
    drag_model: str = WorldConfig.drag_model
    mass: float = 1.0
    restitution: float = WorldConfig.restitution
    friction: float = WorldConfig.friction
    half_size: float = WorldConfig.half_size
    wall_speed: str = WorldConfig.wall_speed
    walls: bool = True
    solver: str = IntegrationConfig.solver
    step: float = IntegrationConfig.step

    def __post_init__(self):
        def bad(field, message):
            raise SceneError(message, key=f"particles.{field}")

        def number(field, lo=-math.inf, hi=math.inf, lo_open=False):
            value = getattr(self, field)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                bad(field, f"expected a number, got {value!r}")
            if not math.isfinite(value):
                bad(field, f"must be finite, got {value!r}")
            if abs(value) > MAX_MAGNITUDE:
                bad(field, f"must be at most {MAX_MAGNITUDE:g} in magnitude, got {value!r}")
            if lo_open and lo == 0.0 and 0.0 < value < MIN_POSITIVE:
                bad(field, f"must be at least {MIN_POSITIVE:g}, got {value!r}")
            if value < lo or (lo_open and value == lo) or value > hi:
                low = "(" if lo_open else "["
                bad(field, f"must be in {low}{lo}, {hi}], got {value!r}")
            object.__setattr__(self, field, float(value))

        for field in ("count", "seed"):
            value = getattr(self, field)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
                bad(field, f"expected an integer, got {value!r}")
        if not 1 <= self.count <= MAX_PARTICLES:
            bad("count", f"must be in [1, {MAX_PARTICLES}], got {self.count!r} (at most "
                f"{MAX_PARTICLES:.0e} particles: refsim.limits.MAX_PARTICLES)")
        if self.seed < 0:
            bad("seed", f"must be non-negative, got {self.seed!r}")
        number("half_size", lo=0.0, lo_open=True)
        for field in ("box_lo", "box_hi"):
            value = getattr(self, field)
            try:
                box = tuple(float(x) for x in value)
            except (TypeError, ValueError):
                bad(field, f"expected three numbers, got {value!r}")
            if len(box) != 3 or not all(math.isfinite(x) for x in box):
                bad(field, f"expected three finite numbers, got {value!r}")
            if any(abs(x) > self.half_size for x in box):
                bad(field, f"{box} is outside the world cube of half size {self.half_size}")
            object.__setattr__(self, field, box)
        if any(lo > hi for lo, hi in zip(self.box_lo, self.box_hi, strict=True)):
            bad("box_hi", f"box_hi {self.box_hi} is below box_lo {self.box_lo}")
        number("speed_min", lo=0.0)
        number("speed_max", lo=self.speed_min)
        number("gravity", lo=0.0)
        number("drag", lo=0.0)
        if self.drag_model not in DRAG_MODELS:
            bad("drag_model", f"expected one of {', '.join(DRAG_MODELS)}, "
                f"got {self.drag_model!r}")
        if self.wall_speed not in SPEEDS:
            bad("wall_speed", f"expected one of {', '.join(SPEEDS)}, "
                f"got {self.wall_speed!r}")
        number("mass", lo=0.0, lo_open=True)
        number("restitution", lo=0.0, hi=1.0)
        number("friction", lo=0.0, hi=1.0)
        if not isinstance(self.walls, bool):
            bad("walls", f"expected true or false, got {self.walls!r}")
        from refsim.solvers.methods import SEED_LITERAL_VARIANTS, SOLVERS
        if self.solver not in SOLVERS and self.solver not in SEED_LITERAL_VARIANTS:
            bad("solver", f"expected one of {', '.join(SOLVERS)}, got {self.solver!r}")
        number("step", lo=0.0, lo_open=True)

    @classmethod
    def field_names(cls) -> tuple[str, ...]:
        return tuple(f.name for f in fields(cls))

    def initial_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities, each (count, 3) float64, from ``seed``.

        Positions are uniform in the box; velocities have a uniform speed in
        ``[speed_min, speed_max]`` and a direction uniform on the unit sphere
        (a normalized Gaussian vector). The same config gives the same bytes.
        """
        rng = np.random.default_rng(self.seed)
        positions = rng.uniform(self.box_lo, self.box_hi, size=(self.count, 3))
        direction = rng.standard_normal((self.count, 3))
        norm = np.linalg.norm(direction, axis=1, keepdims=True)
        norm[norm == 0.0] = 1.0
        speed = rng.uniform(self.speed_min, self.speed_max, size=(self.count, 1))
        return positions, direction / norm * speed
