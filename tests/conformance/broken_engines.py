"""Deliberately broken engines: each must be caught by exactly the checks it
should fail (tests/conformance/test_broken_engines.py).

- :func:`float_triangles`: the seed's edge-triangle test with plain float
  orientation signs, no filter and no exact fallback (what a 1997
  implementation computes: :func:`refsim.collision.triangle.triangles_intersect_float`).
- :func:`rk4_seed_literal`: RK4 with the seed's literal weights 1/6, 2/3,
  2/3, 1/6 (``refsim.SEED_LITERAL_VARIANTS["rk4-seed-literal"]``), declared
  as order 4.
- :func:`box_ignores_translation`: the box of ``R p``, the translation
  forgotten.
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
