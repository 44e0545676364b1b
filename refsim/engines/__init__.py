"""Engines: what refsim checks, one small protocol per capability.

An *engine* is any object with a ``name`` and any subset of the capabilities
below; refsim's seed model and corrected model are engines
(:mod:`refsim.engines.refsim_engines`), so is every adapter in
:mod:`refsim.oracles`, and so is any user's own code. Studies and the
conformance kit receive engines as arguments; only a composition root (the
command line, the report build, a test fixture) chooses them (DESIGN.md,
Architecture).

The contract uses plain arrays, so that an engine needs nothing of refsim
but, for ``simulate``, the :class:`refsim.Scene` it is given:

=================  =========================================================
capability         method
=================  =========================================================
``triangles``      ``triangles_intersect(a, b) -> bool``: ``a``, ``b`` (3, 3)
                   float64 vertex rows; closed triangles, touching counts.
``pairs``          ``intersecting_pairs(vertices_a, faces_a, pose_a,
                   vertices_b, faces_b, pose_b) -> (k, 2) int array`` of
                   face-index pairs (i of a, j of b) whose triangles
                   intersect; a pose is ``(R (3, 3), t (3,))``, the world
                   point ``R p + t``.
``collide``        ``bodies_collide(vertices_a, faces_a, pose_a, vertices_b,
                   faces_b, pose_b) -> bool``: whether the two surfaces meet.
``aabb``           ``aabb(vertices, pose) -> (lo, hi)``, each (3,): the
                   world box of the transformed vertices.
``ode``            ``ode_step(f, t, y, h) -> y_next`` for ``f(t, y) ->
                   dy/dt``, with an attribute ``ode_order`` (the order the
                   engine declares) and optionally ``ode_stability(z) ->
                   complex``, its stability function R(z).
``rigid``          ``simulate(scene) -> trajectory`` with arrays ``t`` (F,),
                   ``position``, ``velocity``, ``angular_velocity`` (F, B, 3)
                   and ``orientation`` (F, B, 3, 3), as
                   :class:`refsim.Trajectory` holds them.
=================  =========================================================

An engine is named on the command line and in pytest as ``module:factory``,
a callable returning the engine (:func:`load_engine`).
"""

from __future__ import annotations

import importlib
from typing import Any, Protocol, runtime_checkable

import numpy as np

from refsim.errors import ArgumentTypeError, OptionError

Pose = tuple[np.ndarray, np.ndarray]


@runtime_checkable
class TriangleTest(Protocol):
    name: str

    def triangles_intersect(self, a: np.ndarray, b: np.ndarray) -> bool: ...


@runtime_checkable
class MeshPairs(Protocol):
    name: str

    def intersecting_pairs(self, vertices_a: np.ndarray, faces_a: np.ndarray, pose_a: Pose,
                           vertices_b: np.ndarray, faces_b: np.ndarray,
                           pose_b: Pose) -> np.ndarray: ...


@runtime_checkable
class BodyCollision(Protocol):
    name: str

    def bodies_collide(self, vertices_a: np.ndarray, faces_a: np.ndarray, pose_a: Pose,
                       vertices_b: np.ndarray, faces_b: np.ndarray, pose_b: Pose) -> bool: ...


@runtime_checkable
class BoundingBox(Protocol):
    name: str

    def aabb(self, vertices: np.ndarray, pose: Pose) -> tuple[np.ndarray, np.ndarray]: ...


@runtime_checkable
class OdeStepper(Protocol):
    name: str
    ode_order: int

    def ode_step(self, f, t: float, y: np.ndarray, h: float) -> np.ndarray: ...


@runtime_checkable
class RigidBodyWorld(Protocol):
    name: str

    def simulate(self, scene) -> Any: ...


@runtime_checkable
class ReferenceSolver(Protocol):
    """Not a checked capability but the role the solver studies give an ODE
    oracle: a tight reference solution of ``y' = f(t, y)`` (``solution``
    returning ``t`` (n,) and ``y`` (n, d) at ``t_eval``, default ``[t1]``),
    the same with terminal events (``solve_with_events``, scipy's result
    conventions), and adaptive runs at a tolerance to compare the fixed-step
    solvers with (``adaptive_run``, returning ``y1``, ``nfev``,
    ``wall_time``). ``refsim.oracles.scipy_ivp.ScipyReference`` is one."""

    name: str
    tolerance: float

    def solution(self, f, y0, t0: float, t1: float, t_eval=None) -> Any: ...

    def solve_with_events(self, f, y0, t0: float, t1: float, events) -> Any: ...

    def adaptive_run(self, f, y0, t0: float, t1: float, method: str, tol: float) -> Any: ...


#: Each capability, the method that provides it and its protocol.
CAPABILITIES: dict[str, tuple[str, type]] = {
    "triangles": ("triangles_intersect", TriangleTest),
    "pairs": ("intersecting_pairs", MeshPairs),
    "collide": ("bodies_collide", BodyCollision),
    "aabb": ("aabb", BoundingBox),
    "ode": ("ode_step", OdeStepper),
    "rigid": ("simulate", RigidBodyWorld),
}


def capabilities(engine) -> tuple[str, ...]:
    """The capabilities ``engine`` provides, in :data:`CAPABILITIES` order."""
    return tuple(key for key, (_, protocol) in CAPABILITIES.items()
                 if isinstance(engine, protocol))


def engine_name(engine) -> str:
    """The engine's ``name``; :class:`ArgumentTypeError` when it has none."""
    name = getattr(engine, "name", None)
    if not isinstance(name, str) or not name:
        raise ArgumentTypeError(f"an engine needs a non-empty string attribute 'name', "
                                f"got {name!r} on {type(engine).__name__}")
    return name


def load_engine(spec: str, **kwargs):
    """The engine ``module:factory`` names: ``factory(**kwargs)`` imported from
    ``module``.

    Raises
    ------
    OptionError
        The spec is not ``module:factory``, the module or the factory cannot
        be found, or the factory's result has no name or no capability. The
        message names the spec; an engine whose own import fails is reported
        with that failure's one line.
    """
    if not isinstance(spec, str) or spec.count(":") != 1 or not all(spec.split(":")):
        raise OptionError(f"engine {spec!r}: expected 'module:factory', e.g. "
                          "'refsim.engines.refsim_engines:corrected'")
    module_name, factory_name = spec.split(":")
    try:
        module = importlib.import_module(module_name)
    except ImportError as exc:
        raise OptionError(f"engine {spec!r}: cannot import {module_name!r}: {exc}") from None
    factory = getattr(module, factory_name, None)
    if not callable(factory):
        raise OptionError(f"engine {spec!r}: {module_name} has no callable {factory_name!r}")
    engine = factory(**kwargs)
    try:
        engine_name(engine)
    except ArgumentTypeError as exc:
        raise OptionError(f"engine {spec!r}: {exc}") from None
    if not capabilities(engine):
        methods = ", ".join(method for method, _ in CAPABILITIES.values())
        raise OptionError(f"engine {spec!r} ({engine.name}) provides none of: {methods}")
    return engine
