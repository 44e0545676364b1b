"""The scene file schema (seed S11: "fully configurable simulation script files").

A scene is a TOML file with the tables ``[world]``, ``[integration]``,
``[collision]``, ``[dynamics]``, an array ``[[body]]`` (docs/design.md, Scene
files) and an optional ``[particles]`` table (S10); it needs at least one
body or the particles table. This module declares every key once: its type, default and allowed
range, as :class:`Field` rows. :mod:`refsim.scenes.loader` walks a parsed file
against these rows; an unknown key, a wrong type or a value out of range is a
:class:`~refsim.errors.SceneError` naming the file and the key path.

The configuration objects are frozen dataclasses, so a loaded scene cannot
change under a running simulation.

Particles. A particle system is configured by
:class:`refsim.particles.config.ParticleConfig`, and each of its fields is set
in exactly one table, never two: the forces and the cube come from
``[world]`` (:data:`PARTICLE_FIELDS_FROM`: gravity, drag, drag_model,
restitution, friction, half_size), the solver and step from ``[integration]``
(solver, step; ``duration`` is how long ``refsim run`` simulates), and the
rest from ``[particles]`` (:data:`PARTICLE_KEYS`: count, seed, box_lo, box_hi,
speed_min, speed_max, mass, walls). So bodies and particles in one scene
share one world and one solver. The values of ``[particles]`` are checked by
``ParticleConfig`` itself, which names the key ``particles.<field>``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from refsim.dynamics import plan
from refsim.dynamics.forces import DRAG_MODELS
from refsim.dynamics.walls import SPEEDS
from refsim.dynamics.world import WALL_NAMES, IntegrationConfig, WorldConfig
from refsim.limits import MIN_POSITIVE
from refsim.particles.config import ParticleConfig

SOLVER_NAMES = ("euler", "averaged-euler", "backwards-euler", "midpoint", "rk4")
COLLISION_LEVELS = plan.COLLISION_LEVELS
AABB_MODES = ("linear", "incremental", "auto")
# the dynamics choices' values, where the stages read them
ROTATION_MODELS, RESPONSE_MODELS, WALL_RESPONSES = (plan.ROTATION_MODELS, plan.RESPONSE_MODELS,
                                                    plan.WALL_RESPONSES)
WALL_SPEEDS = SPEEDS
#: ``[[body]] shape``: a model file (""), or a shape built from its keys.
SHAPES = ("", "box", "sphere")

#: A body's starting box may stick out of the world cube by this fraction of
#: the cube's half size: the rounding of a position written as
#: ``-half_size + half the body's height``, never a real overlap.
START_INSIDE_RTOL = 1e-9


# -- the configuration objects -------------------------------------------------


@dataclass(frozen=True)
class CollisionConfig:
    level: str = "exact"
    aabb: str = "auto"


@dataclass(frozen=True)
class DynamicsConfig:
    rotation: str = "seed"
    body_response: str = "seed"
    wall_response: str = "auto"


@dataclass(frozen=True)
class BodyConfig:
    """One ``[[body]]`` entry; ``model`` is resolved to an existing file, or,
    for a ``shape``, is the shape's name (``<box 1 x 0.6 x 0.3>``), the key
    of its generated mesh in :attr:`Scene.meshes`.

    ``shape``: "" (the mesh of the file ``model``), "box" (edges ``size``,
    centred) or "sphere" (a geodesic sphere of ``radius`` with ``20
    frequency^2`` triangles, its vertices on the sphere). ``fixed``: the
    body never moves (infinite mass; the corrected body response only).
    ``force``, ``torque``: constant, world frame, N and N m; the force acts
    at the centre of mass. ``restitution``, ``mu``: this body's
    coefficients at its contacts (None: the world's), see
    :meth:`Scene.coefficients`.
    """

    name: str
    model: Path
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    angular_velocity: tuple[float, float, float] = (0.0, 0.0, 0.0)
    orientation: tuple[tuple[float, ...], ...] = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0),
                                                  (0.0, 0.0, 1.0))
    mass: float = 1.0
    scale: float = 1.0
    shape: str = ""
    size: tuple[float, float, float] = (1.0, 1.0, 1.0)
    radius: float = 0.5
    frequency: int = 8
    fixed: bool = False
    force: tuple[float, float, float] = (0.0, 0.0, 0.0)
    torque: tuple[float, float, float] = (0.0, 0.0, 0.0)
    restitution: float | None = None
    mu: float | None = None


@dataclass(frozen=True)
class PairConfig:
    """One ``[[pair]]`` entry: the coefficients at the contacts of two named
    bodies (None: as :meth:`Scene.coefficients` resolves them without it)."""

    bodies: tuple[str, str]
    restitution: float | None = None
    mu: float | None = None


@dataclass(frozen=True)
class Scene:
    """A validated scene. ``meshes`` maps each model path to its loaded mesh.

    ``particles`` is the complete particle configuration (``[particles]``
    with ``[world]`` and ``[integration]`` filled in), or None when the scene
    has no ``[particles]`` table.
    """

    path: Path | None
    world: WorldConfig = field(default_factory=WorldConfig)
    integration: IntegrationConfig = field(default_factory=IntegrationConfig)
    collision: CollisionConfig = field(default_factory=CollisionConfig)
    dynamics: DynamicsConfig = field(default_factory=DynamicsConfig)
    bodies: tuple[BodyConfig, ...] = ()
    meshes: dict = field(default_factory=dict, compare=False, repr=False)
    particles: ParticleConfig | None = None
    pairs: tuple[PairConfig, ...] = ()

    def mesh(self, body: BodyConfig):
        """The loaded mesh of ``body`` (shared between bodies of one model)."""
        return self.meshes[body.model]

    def coefficients(self, a: BodyConfig, b: BodyConfig | None = None) -> tuple[float, float]:
        """Restitution e and Coulomb's mu at the contacts of body ``a`` with
        body ``b``, or with a wall (``b`` None), for the corrected responses.

        With a wall: the body's own values, else the world's (``restitution``,
        :attr:`WorldConfig.coulomb_mu`). Between two bodies: a ``[[pair]]``
        entry naming both; else the value the two bodies give (one of them,
        or both alike); else the world's. Two bodies that give different
        values and no ``[[pair]]`` are refused by the loader: no combination
        rule is guessed (engines differ on it; Bullet multiplies).
        """
        world = self.world
        if b is None:
            return (world.restitution if a.restitution is None else a.restitution,
                    world.coulomb_mu if a.mu is None else a.mu)
        pair = next((p for p in self.pairs if set(p.bodies) == {a.name, b.name}), None)
        values = []
        for key, default in (("restitution", world.restitution), ("mu", world.coulomb_mu)):
            given = getattr(pair, key) if pair is not None else None
            if given is None:
                given = next((getattr(c, key) for c in (a, b) if getattr(c, key) is not None),
                             default)
            values.append(given)
        return values[0], values[1]


plan.register_scene_type(Scene)       # the loop's check of its argument (it cannot import this)


# -- the schema rows -------------------------------------------------------------

Check = Callable[[Any], str | None]


@dataclass(frozen=True)
class Field:
    """One key: its kind ("float", "str", "vec3", "mat3") and check. Its
    default is the configuration dataclass's (one place for every default).

    ``check`` returns None when the (already type-checked) value is allowed,
    or a phrase saying what is required.
    """

    name: str
    kind: str
    check: Check | None = None
    required: bool = False


def positive(value) -> str | None:
    if not value > 0:
        return "must be > 0"
    return None if value >= MIN_POSITIVE else f"must be at least {MIN_POSITIVE:g}"


def non_negative(value) -> str | None:
    return None if value >= 0 else "must be >= 0"


def unit_interval(value) -> str | None:
    return None if 0.0 <= value <= 1.0 else "must be in [0, 1]"


def nonzero(value) -> str | None:
    return None if any(value) else "must not be the zero vector"


def at_least(low: int) -> Check:
    def check(value):
        return None if value >= low else f"must be at least {low}"
    return check


def wall_names(value) -> str | None:
    unknown = [w for w in value if w not in WALL_NAMES]
    if unknown:
        return f"names {unknown[0]!r}: walls are " + ", ".join(repr(w) for w in WALL_NAMES)
    if len(set(value)) != len(value):
        return "names a wall twice"
    return None


def positive_vec3(value) -> str | None:
    return None if all(x > 0 for x in value) else "must have every component > 0"


def one_of(*choices: str) -> Check:
    def check(value):
        return None if value in choices else "must be one of " + ", ".join(
            repr(c) for c in choices)
    return check


def orthonormal(value) -> str | None:
    from refsim.types import ORTHONORMAL_TOL

    r = np.asarray(value, dtype=np.float64)
    if np.abs(r.T @ r - np.eye(3)).max() > ORTHONORMAL_TOL:
        return "must be an orthonormal 3x3 matrix (its columns are the body's axes)"
    if np.linalg.det(r) < 0:
        return "must be a rotation (determinant +1), not a reflection"
    return None


TABLES: dict[str, tuple[type, tuple[Field, ...]]] = {
    "world": (WorldConfig, (
        Field("half_size", "float", positive),
        Field("gravity", "float", non_negative),
        Field("drag", "float", non_negative),
        Field("drag_model", "str", one_of(*DRAG_MODELS)),
        Field("restitution", "float", unit_interval),
        Field("friction", "float", unit_interval),
        Field("wall_speed", "str", one_of(*WALL_SPEEDS)),
        Field("gravity_direction", "vec3", nonzero),
        Field("walls", "walls", wall_names),
        Field("mu", "float", non_negative),
        Field("restitution_threshold", "float", non_negative),
    )),
    "integration": (IntegrationConfig, (
        Field("solver", "str", one_of(*SOLVER_NAMES)),
        Field("step", "float", positive),
        Field("duration", "float", positive),
    )),
    "collision": (CollisionConfig, (
        Field("level", "str", one_of(*COLLISION_LEVELS)),
        Field("aabb", "str", one_of(*AABB_MODES)),
    )),
    "dynamics": (DynamicsConfig, (
        Field("rotation", "str", one_of(*ROTATION_MODELS)),
        Field("body_response", "str", one_of(*RESPONSE_MODELS)),
        Field("wall_response", "str", one_of(*WALL_RESPONSES)),
    )),
}

BODY_FIELDS: tuple[Field, ...] = (
    Field("name", "str"),
    Field("model", "str"),
    Field("position", "vec3"),
    Field("velocity", "vec3"),
    Field("angular_velocity", "vec3"),
    Field("orientation", "mat3", orthonormal),
    Field("mass", "float", positive),
    Field("scale", "float", positive),
    Field("shape", "str", one_of(*SHAPES[1:])),
    Field("size", "vec3", positive_vec3),
    Field("radius", "float", positive),
    Field("frequency", "int", at_least(1)),
    Field("fixed", "bool"),
    Field("force", "vec3"),
    Field("torque", "vec3"),
    Field("restitution", "float", unit_interval),
    Field("mu", "float", non_negative),
)

PAIR_FIELDS: tuple[Field, ...] = (
    Field("bodies", "names2", required=True),
    Field("restitution", "float", unit_interval),
    Field("mu", "float", non_negative),
)

#: ParticleConfig fields that other tables set, and the scene key of each.
#: A particle system lives in the scene's world and uses the scene's solver.
PARTICLE_FIELDS_FROM: dict[str, str] = {
    "gravity": "world.gravity",
    "drag": "world.drag",
    "drag_model": "world.drag_model",
    "restitution": "world.restitution",
    "friction": "world.friction",
    "wall_speed": "world.wall_speed",
    "half_size": "world.half_size",
    "solver": "integration.solver",
    "step": "integration.step",
}

#: The keys of ``[particles]``: every other ParticleConfig field, with its
#: default from ParticleConfig.
PARTICLE_KEYS: tuple[str, ...] = tuple(
    name for name in ParticleConfig.field_names() if name not in PARTICLE_FIELDS_FROM)
