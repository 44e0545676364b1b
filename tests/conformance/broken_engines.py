"""Deliberately broken engines: each must be caught by exactly the checks it
should fail (tests/conformance/test_broken_engines.py).

- :func:`float_triangles`: the seed's edge-triangle test with plain float
  orientation signs, no filter and no exact fallback (what a 1997
  implementation computes: :func:`refsim.collision.triangle.triangles_intersect_float`).
- :func:`rk4_seed_literal`: RK4 with the seed's literal weights 1/6, 2/3,
  2/3, 1/6 (``refsim.SEED_LITERAL_VARIANTS["rk4-seed-literal"]``), declared
  as order 4.
- :func:`box_ignores_translation`: the box of ``R p``, the translation
  forgotten; :class:`BoxIgnoresRotation`, the box of ``p + t``.
- :class:`PaddedBox`: the tight box padded by ``pad`` on every side,
  declaring ``box_slack`` (a fattened box: "loose" within it).
- :class:`GjkLikeCollide`: bodies whose boxes are within ``reach`` collide
  (as GJK stopping at a tolerance calls near bodies touching; on the
  axis-aligned cubes of the tests the boxes' gap is the bodies' gap),
  declaring ``distance_tolerance``.
- :func:`crashing_triangles`: raises on every pair whose first vertex has
  x > 0 (a crash, never hidden by a declaration of "bug").
- :class:`RigidStub`: ``simulate`` from a function of the scene (a crash,
  an answer of the wrong shape, a bounce that stops, another contact law).
"""

from __future__ import annotations

import numpy as np

from refsim.collision.triangle import triangles_intersect_float
from refsim.solvers.methods import SEED_LITERAL_VARIANTS
from refsim.types import transform_points


class FloatTriangles:
    name = "broken-float-triangles"

    def triangles_intersect(self, a, b) -> bool:
        return triangles_intersect_float(a, b)


class SeedLiteralRK4:
    name = "broken-rk4-seed-literal"
    ode_order = 4

    def __init__(self):
        self.method = SEED_LITERAL_VARIANTS["rk4-seed-literal"]

    def ode_step(self, f, t, y, h):
        return self.method.step(f, t, np.asarray(y, dtype=np.float64), h)


class BoxIgnoresTranslation:
    name = "broken-box-ignores-translation"

    def aabb(self, vertices, pose):
        rotation, _ = pose
        world = transform_points(np.asarray(vertices, dtype=np.float64),
                                 (np.asarray(rotation, dtype=np.float64), np.zeros(3)))
        return world.min(axis=0), world.max(axis=0)


class BoxIgnoresRotation:
    name = "broken-box-ignores-rotation"

    def aabb(self, vertices, pose):
        world = np.asarray(vertices, dtype=np.float64) + np.asarray(pose[1], dtype=np.float64)
        return world.min(axis=0), world.max(axis=0)


class PaddedBox:
    name = "padded-box"

    def __init__(self, pad: float, box_slack: float):
        self.pad = pad
        self.box_slack = box_slack

    def aabb(self, vertices, pose):
        world = transform_points(np.asarray(vertices, dtype=np.float64), pose)
        return world.min(axis=0) - self.pad, world.max(axis=0) + self.pad


class GjkLikeCollide:
    name = "gjk-like"

    def __init__(self, reach: float, distance_tolerance: float):
        self.reach = reach
        self.distance_tolerance = distance_tolerance

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b, pose_b) -> bool:
        a = transform_points(np.asarray(vertices_a, dtype=np.float64), pose_a)
        b = transform_points(np.asarray(vertices_b, dtype=np.float64), pose_b)
        apart = np.maximum(b.min(axis=0) - a.max(axis=0), a.min(axis=0) - b.max(axis=0))
        return bool(np.sqrt((np.maximum(apart, 0.0) ** 2).sum()) <= self.reach)


class CrashingTriangles:
    name = "broken-crashing-triangles"

    def triangles_intersect(self, a, b) -> bool:
        if a[0][0] > 0.0:
            raise ZeroDivisionError("degenerate edge in my_engine.clip()")
        return triangles_intersect_float(a, b)


class RigidStub:
    """``simulate(scene)`` is ``answer(rigid_scene)``: a stand-in for a
    rigid-body engine whose trajectories the tests construct."""

    def __init__(self, name: str, answer, contact_law: str = "restitution"):
        self.name = name
        self.answer = answer
        self.contact_law = contact_law

    def simulate(self, scene):
        return self.answer(scene)


class SeveralFlaws:
    """Float triangles, a collide that reaches 1 mm, a box padded by 1e-9 m
    and the seed's RK4: failures in every check that judges cases one by one
    and in one of the fixed ODE checks (the sharding tests)."""

    name = "several-flaws"
    ode_order = 4

    def __init__(self):
        self._collide = GjkLikeCollide(1e-3, 0.0)
        self._box = PaddedBox(1e-9, 0.0)
        self._ode = SeedLiteralRK4()

    def triangles_intersect(self, a, b) -> bool:
        return triangles_intersect_float(a, b)

    def bodies_collide(self, *args) -> bool:
        return self._collide.bodies_collide(*args)

    def aabb(self, vertices, pose):
        return self._box.aabb(vertices, pose)

    def ode_step(self, f, t, y, h):
        return self._ode.ode_step(f, t, y, h)


def several_flaws() -> SeveralFlaws:
    return SeveralFlaws()


def crashing_triangles() -> CrashingTriangles:
    return CrashingTriangles()


def float_triangles() -> FloatTriangles:
    return FloatTriangles()


def rk4_seed_literal() -> SeedLiteralRK4:
    return SeedLiteralRK4()


def box_ignores_translation() -> BoxIgnoresTranslation:
    return BoxIgnoresTranslation()


def missing():
    """An engine whose package is not installed (as an adapter reports it)."""
    from refsim.oracles import OracleUnavailable

    raise OracleUnavailable("oracle engine 'nothing-here' is not installed")
