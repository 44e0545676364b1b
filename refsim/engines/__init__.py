"""Engines: what refsim checks, one small protocol per capability.

An *engine* is any object with a ``name`` and any subset of the capabilities
below; refsim's seed model and corrected model are engines
(:mod:`refsim.engines.refsim_engines`), so is every adapter in
:mod:`refsim.oracles`, and so is any user's own code. Studies and the
conformance kit receive engines as arguments; only a composition root (the
command line, the report build, a test fixture) chooses them (docs/design.md,
Architecture).

The contract uses plain float64 and int64 arrays, so that an engine needs
nothing of refsim but, for ``simulate``, the :class:`refsim.Scene` it is
given. The arrays the kit hands over may be read-only (a mesh case's
vertices and faces are shared by every case): an engine that writes to its
input, or a library that needs writable buffers, copies them first.

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

What an engine declares about itself, as attributes (each optional, with
the default shown; :func:`declarations` reads and validates them), decides
how the conformance kit classes its misses:

=======================  ==================================================
attribute                meaning
=======================  ==================================================
``distance_tolerance``   metres (the scene's length unit; 0.0): the engine
                         may call sets this far apart touching, and miss an
                         overlap this deep (GJK and EPA stop at a
                         tolerance: FCL's ``gjk_tolerance`` is 1e-6). A
                         triangle, mesh or box answer wrong by no more is
                         class "tolerance"; beyond it and the rounding
                         bound, "bug".
``box_slack``            metres (0.0): each side of the engine's ``aabb``
                         may stand this far outside the tight box (a
                         fattened box: Bullet's collision margin, Box2D's
                         AABB margin). A box that encloses and is wider by
                         no more is class "loose".
``unit_roundoff``        ``2**-53`` (the default, float64): the unit
                         roundoff of the arithmetic the engine computes in
                         (``2**-24`` for float32 coordinates, as MeshLib
                         stores them). Every rounding bound the kit compares
                         a geometric miss with is float64's scaled by
                         ``unit_roundoff / 2**-53``: a miss within the
                         engine's own rounding is "tolerance", not "bug".
``solid``                ``False`` (the default): ``bodies_collide`` tests
                         surfaces, as the contract asks. ``True`` declares
                         that the engine tests closed meshes as solids
                         (GJK on convex shapes does): a body wholly inside
                         the other collides, class "known-divergence";
                         undeclared, that answer is a "bug".
``is_solid``             optional method ``is_solid(vertices, faces) ->
                         bool``: per mesh, whether ``bodies_collide``
                         tests it as a solid (trimesh's CollisionManager:
                         a convex mesh only); where given it decides, not
                         ``solid``.
``pose_used``            optional method ``pose_used(pose) -> pose``: the
                         pose the engine really applies (trimesh rounds
                         it to float32). refsim's answer on those poses
                         equal to the engine's is class "tolerance".
``integrator_order``     ``None`` (the default): the order of the rigid
                         engine's time step (1 for semi-implicit Euler, as
                         Bullet, MuJoCo's "Euler" and Drake's discrete
                         solvers take). Declared, a free body's energy and
                         momentum drift beyond ``rigid.free_rotation``'s
                         tolerance is run again at half the step: falling
                         at the declared order (within 0.3) and within 10 %,
                         it is the integrator's truncation error, class
                         "tolerance"; otherwise, or undeclared, "bug".
``contact_law``          ``"restitution"`` (the default): a coefficient of
                         restitution ``e`` sets the bounce, the law the
                         apex-ratio and oblique-bounce checks assume. Any
                         other name (``"hunt-crossley"``, ``"soft"``,
                         ``"hydroelastic"``) declares another law: those
                         checks' misses are class "law", naming it.
=======================  ==================================================
"""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from refsim.errors import ArgumentTypeError, OptionError

Pose = tuple[np.ndarray, np.ndarray]


@runtime_checkable
class TriangleTest(Protocol):
    """``triangles``: ``triangles_intersect(a, b) -> bool``.

    ``a``, ``b``: (3, 3) float64, one vertex a row, in any one frame and
    length unit. True when the closed triangles share at least one point
    (a touching pair intersects). Checked by ``triangles.agreement`` against
    the separating-axis test in rational arithmetic; a miss is measured by
    the pair's gap in the same unit."""

    name: str

    def triangles_intersect(self, a: np.ndarray, b: np.ndarray) -> bool: ...


@runtime_checkable
class MeshPairs(Protocol):
    """``pairs``: ``intersecting_pairs(vertices_a, faces_a, pose_a,
    vertices_b, faces_b, pose_b) -> (k, 2) int array``.

    ``vertices`` (n, 3) float64 in the body frame (metres), ``faces`` (m, 3)
    int vertex indices, a pose ``(R (3, 3), t (3,))`` placing the body at
    ``R p + t`` in the world. Every face pair ``(i, j)`` (``i`` of a, ``j``
    of b) whose closed triangles meet in the world, each once, in any order.
    The meshes are refsim's bundled models (``refsim.bundled.model_path``
    locates the files the examples name)."""

    name: str

    def intersecting_pairs(self, vertices_a: np.ndarray, faces_a: np.ndarray, pose_a: Pose,
                           vertices_b: np.ndarray, faces_b: np.ndarray,
                           pose_b: Pose) -> np.ndarray: ...


@runtime_checkable
class BodyCollision(Protocol):
    """``collide``: ``bodies_collide(...) -> bool`` with the arguments of
    :class:`MeshPairs`: whether the two *surfaces* meet. One body wholly
    inside the other does not meet it (a solid engine answering True there
    is classed "known-divergence" when the engine declares ``solid = True``,
    else "bug")."""

    name: str

    def bodies_collide(self, vertices_a: np.ndarray, faces_a: np.ndarray, pose_a: Pose,
                       vertices_b: np.ndarray, faces_b: np.ndarray, pose_b: Pose) -> bool: ...


@runtime_checkable
class BoundingBox(Protocol):
    """``aabb``: ``aabb(vertices, pose) -> (lo, hi)``, each (3,) float64: the
    smallest axis-aligned box of ``R p + t`` over the (n, 3) ``vertices``
    (metres, world frame). Held to the float64 rounding bound of ``R p + t``
    on each side; a fattened box declares its ``box_slack``."""

    name: str

    def aabb(self, vertices: np.ndarray, pose: Pose) -> tuple[np.ndarray, np.ndarray]: ...


@runtime_checkable
class OdeStepper(Protocol):
    """``ode``: ``ode_step(f, t, y, h) -> y_next``, one step of size ``h`` of
    ``y' = f(t, y)`` from ``(t, y)``; ``y`` a float64 array (d,), ``f``
    returning one. ``ode_order``: the order the engine claims (observed
    order checked on problems with exact solutions). Optional:
    ``ode_stability(z) -> complex``, the method's R(z) (checked against one
    step of ``y' = z y``), and ``ode_evaluations``, the calls of ``f`` per
    step it claims (else at least the order's minimum is required)."""

    name: str
    ode_order: int

    def ode_step(self, f, t: float, y: np.ndarray, h: float) -> np.ndarray: ...


@runtime_checkable
class RigidBodyWorld(Protocol):
    """``rigid``: ``simulate(scene) -> trajectory``.

    ``scene`` is a :class:`refsim.Scene` (:mod:`refsim.scenes.schema`);
    ``docs/design.md`` lists every key with its unit and default. SI units
    throughout. What the kit's scenes use:

    - ``scene.world``: ``gravity`` (m/s^2) along ``gravity_direction`` (a
      unit vector, default -y), the ``walls`` present (``"y-"`` is the floor;
      the world cube has half-size ``half_size``), ``restitution`` e and
      Coulomb's ``coulomb_mu`` at every contact; ``scene.integration.step``
      h (s) and ``duration`` (s).
    - each ``scene.bodies[i]``: ``model`` (a bundled model's file name:
      ``refsim.bundled.model_path(name)``; ``scene.mesh(body)`` is its
      loaded mesh) at ``scale``; ``mass`` (kg, a uniform solid);
      ``position``: the mesh origin in the world frame; ``orientation``:
      R, whose columns are the body's axes in the world; ``velocity``: the
      centre of mass's (not the origin's); ``angular_velocity``: rad/s,
      world frame; ``restitution``, ``mu``, ``fixed``, ``force``,
      ``torque`` where set (see :meth:`refsim.Scene.coefficients`).

    The trajectory has ``t`` (F,), the frames' times in seconds from the
    initial state (``t[0] = 0``, F >= 2, each frame at a whole step). The
    checks read times from ``t``, never frame counts, and apexes, impacts
    and rest from the frames: keep one frame a step (refsim keeps one every
    ``ceil(steps / 1000)``: every step in all but the long drops and the free
    brick), and per frame and body, in the scene's
    body order: ``position`` (F, B, 3) the mesh origin, ``velocity`` (F, B,
    3) the centre of mass's, ``angular_velocity`` (F, B, 3) world frame,
    ``orientation`` (F, B, 3, 3) with the body's axes as columns (as
    :class:`refsim.Trajectory` holds them). An engine that cannot pose a
    key the scene uses raises :class:`refsim.errors.UnposableKey` naming it
    (:func:`refsim.scenes.support.refuse_unhonoured` does it from
    ``honoured_keys``): that check is ``n/a``, not failed."""

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


#: The contact law the rigid checks' analytic answers assume.
RESTITUTION = "restitution"


@dataclass(frozen=True)
class Declarations:
    """What an engine declares about itself (module docstring): lengths in
    metres, the contact law by name."""

    distance_tolerance: float = 0.0
    box_slack: float = 0.0
    contact_law: str = RESTITUTION
    solid: bool = False
    integrator_order: int | None = None
    unit_roundoff: float = 2.0 ** -53


def body_conventions(engine) -> dict:
    """What :func:`refsim.collision.disagreement.classify_bodies` needs of a
    ``collide`` engine, as its keyword arguments: the declared
    ``distance_tolerance``, ``roundoff`` (``unit_roundoff`` over float64's),
    ``solid``, and the optional ``is_solid`` and ``pose_used`` methods (None
    where the engine has none). The kit and the studies both read an
    engine's conventions here, so that one answer gets one class."""
    declared = declarations(engine)
    return {"distance_tolerance": declared.distance_tolerance,
            "roundoff": declared.unit_roundoff / 2.0 ** -53, "solid": declared.solid,
            "is_solid": getattr(engine, "is_solid", None),
            "pose_used": getattr(engine, "pose_used", None)}


def declarations(engine) -> Declarations:
    """The engine's :class:`Declarations`, defaults where it declares none;
    :class:`OptionError` naming the engine and the attribute for a value that
    is not a finite length >= 0 or a non-empty law name."""
    found = {}
    for name in ("distance_tolerance", "box_slack"):
        value = getattr(engine, name, 0.0)
        try:
            length = float(value)
        except (TypeError, ValueError):
            length = math.nan
        if isinstance(value, bool) or not (math.isfinite(length) and length >= 0.0):
            raise OptionError(f"engine {getattr(engine, 'name', '?')!r}: {name} must be a "
                              f"finite number of metres >= 0, got {value!r}")
        found[name] = length
    law = getattr(engine, "contact_law", RESTITUTION)
    if not isinstance(law, str) or not law.strip():
        raise OptionError(f"engine {getattr(engine, 'name', '?')!r}: contact_law must be a "
                          f"non-empty name, e.g. 'restitution' or 'hunt-crossley', "
                          f"got {law!r}")
    roundoff = getattr(engine, "unit_roundoff", 2.0 ** -53)
    try:
        roundoff_value = float(roundoff)
    except (TypeError, ValueError):
        roundoff_value = math.nan
    if isinstance(roundoff, bool) or not (2.0 ** -53 <= roundoff_value < 1.0):
        raise OptionError(f"engine {getattr(engine, 'name', '?')!r}: unit_roundoff must be a "
                          f"number in [2**-53, 1), e.g. 2**-24 for float32, got {roundoff!r}")
    found["unit_roundoff"] = roundoff_value
    solid = getattr(engine, "solid", False)
    if not isinstance(solid, bool):
        raise OptionError(f"engine {getattr(engine, 'name', '?')!r}: solid must be True or "
                          f"False, got {solid!r}")
    order = getattr(engine, "integrator_order", None)
    if order is not None and (isinstance(order, bool) or not isinstance(order, int)
                              or order < 1):
        raise OptionError(f"engine {getattr(engine, 'name', '?')!r}: integrator_order must "
                          f"be a whole number >= 1 or None, got {order!r}")
    return Declarations(contact_law=law.strip(), solid=solid, integrator_order=order,
                        **found)


def engine_name(engine) -> str:
    """The engine's ``name``; :class:`ArgumentTypeError` when it has none."""
    name = getattr(engine, "name", None)
    if not isinstance(name, str) or not name:
        raise ArgumentTypeError(f"an engine needs a non-empty string attribute 'name', "
                                f"got {name!r} on {type(engine).__name__}")
    return name


def resolve_factory(spec: str):
    """The callable ``module:factory`` names, imported from ``module``.

    Raises
    ------
    OptionError
        The spec is not ``module:factory``, or the module or the factory
        cannot be found; the message names the spec, and a module whose own
        import fails is reported with that failure's one line.
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
    return factory


def load_engine(spec: str, **kwargs):
    """The engine ``module:factory`` names: ``factory(**kwargs)`` imported from
    ``module`` (:func:`resolve_factory`).

    Raises
    ------
    OptionError
        The spec is not ``module:factory``, the module or the factory cannot
        be found, or the factory's result has no name or no capability. The
        message names the spec; an engine whose own import fails is reported
        with that failure's one line.
    """
    engine = resolve_factory(spec)(**kwargs)
    try:
        engine_name(engine)
    except ArgumentTypeError as exc:
        raise OptionError(f"engine {spec!r}: {exc}") from None
    if not capabilities(engine):
        methods = ", ".join(method for method, _ in CAPABILITIES.values())
        raise OptionError(f"engine {spec!r} ({engine.name}) provides none of: {methods}")
    return engine
