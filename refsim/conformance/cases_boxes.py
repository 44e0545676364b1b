"""Boxes of transformed vertices, known exactly (seed S2, capability ``aabb``).

What: ``n`` cases of vertices (n, 3) and a pose ``(R, t)``; the answer is the
box of the points ``R p + t`` computed in rational arithmetic
(``fractions.Fraction`` of every float, so every product and sum is exact):
``lo_i = min_p (R p + t)_i``, ``hi_i = max_p (R p + t)_i``. No float engine,
refsim's included, takes part in it.

A float engine cannot return that box: its coordinates are rounded. What it
can promise is the rounding bound of any float64 evaluation of ``R p + t``:
coordinate ``i`` is a sum of four terms (three products and ``t_i``), and
by the standard bound for a dot product of length 4 (N. J. Higham,
*Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM 2002,
section 3.1, eq. (3.5)), in any order, with or without fused multiply-adds,

    |fl((R p + t)_i) - (R p + t)_i| <= gamma_4 (|R_i0 x| + |R_i1 y| + |R_i2 z| + |t_i|),
    gamma_4 = 4 u / (1 - 4 u),  u = 2^-53,

plus ``4 * 2^-1074`` for products that underflow. The minimum over the
points moves by no more than the largest such bound, so per axis
``bound_i = gamma_4 max_p (sum_j |R_ij p_j| + |t_i|) + 4 * 2^-1074``
(:func:`rounding_bound`). The checks (:mod:`refsim.conformance.checks_geometry`)
accept an engine's box when each side is within ``bound_i`` of the exact
one: it encloses every exactly transformed point up to rounding
(``aabb.encloses``) and is no larger than the exact box by more than that
(``aabb.tight``).

==============  ============================================================
family          construction
==============  ============================================================
random          1 .. 12 points uniform in [-1, 1]^3 times 10^(-3 .. 3), a
                random rotation, a translation up to 10 times 10^(-3 .. 3)
bundled         a bundled model's vertices, a random pose
far             a translation of 10^6 .. 10^9 (the rounding of t dominates)
exact           axes permuted with signs and a translation on a 1/8 grid:
                the float box is the exact box
near-identity   the identity rotation and a translation of 10^-12 .. 10^-8
                (an engine that skips a transform "close to the identity"
                returns the untransformed box)
tiny            points of size 10^-12 .. 10^-9 moved by a unit translation
==============  ============================================================

Cost: O(n) float operations per case, and exact integer arithmetic on the
few vertices that can be extreme (:func:`exact_box`).
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from refsim.conformance.cases_meshes import bundled_mesh
from refsim.conformance.draw import (
    seeded_range,
    signed_permutations,
    strategy,
    unit_quaternion_rotation,
)

FAMILIES = ("random", "bundled", "far", "exact", "near-identity", "tiny")

#: Bundled models whose vertices the "bundled" family uses (up to 1002
#: vertices: the sphere-2k is the largest, as the truth's rational
#: arithmetic costs O(vertices) per case).
BOX_MODELS = ("cube.ac", "icosahedron.ac", "l-beam.ac", "star.ac", "sphere-2k.ac")

#: The unit roundoff of float64 and gamma_4 = 4u / (1 - 4u) (module docstring).
UNIT_ROUNDOFF = 2.0 ** -53
GAMMA_4 = 4 * UNIT_ROUNDOFF / (1 - 4 * UNIT_ROUNDOFF)
#: Four products may each underflow by at most half the smallest subnormal.
UNDERFLOW = 4 * 2.0 ** -1074


def exact_box(vertices, pose) -> tuple[tuple[Fraction, ...], tuple[Fraction, ...]]:
    """The box of ``R p + t`` over the rows ``p`` of ``vertices``, exactly.

    Each coordinate's extremes are found among its candidates: the vertices
    whose float value (:func:`_float_coordinates`) lies within four times
    :func:`rounding_bound` of the float extreme. The float value of every
    vertex is within one bound of its exact value, so the exact extreme is
    always among them (the margin is four bounds where two would do). The
    candidates are then evaluated exactly, in integers: every float is a
    rational with a power-of-two denominator, so scaled by the largest
    such denominator ``D`` of ``R``, ``t`` and the points, ``R p`` is an
    integer over ``D^2`` and ``t`` one over ``D``. The float values only
    choose which vertices to evaluate; the answer is exact.
    """
    rotation, translation = pose
    V = np.asarray(vertices, dtype=np.float64)
    R = np.asarray(rotation, dtype=np.float64)
    t = np.asarray(translation, dtype=np.float64)
    approx = _float_coordinates(V, R, t)
    margin = 4.0 * rounding_bound(V, (R, t))
    ratios = {}

    def ratio(x: float) -> tuple[int, int]:
        if x not in ratios:
            ratios[x] = float(x).as_integer_ratio()
        return ratios[x]

    lo: list = [None, None, None]
    hi: list = [None, None, None]
    for i in range(3):
        column = approx[:, i]
        low = np.flatnonzero(column <= column.min() + margin[i])
        high = np.flatnonzero(column >= column.max() - margin[i])
        rows = sorted(set(low.tolist()) | set(high.tolist()))
        terms = [ratio(x) for x in R[i].tolist()] + [ratio(float(t[i]))]
        points = [[ratio(x) for x in V[r].tolist()] for r in rows]
        D = max(d for _, d in terms + [c for p in points for c in p])
        r_int = [n * (D // d) for n, d in terms[:3]]
        t_int = terms[3][0] * (D // terms[3][1]) * D            # over D^2
        values = {r: sum(r_int[j] * (p[j][0] * (D // p[j][1])) for j in range(3)) + t_int
                  for r, p in zip(rows, points, strict=True)}
        lo[i] = Fraction(min(values[r] for r in low.tolist()), D * D)
        hi[i] = Fraction(max(values[r] for r in high.tolist()), D * D)
    return tuple(lo), tuple(hi)


def _float_coordinates(V: np.ndarray, R: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(n, 3) ``R p + t`` of the rows of ``V`` in float64, element by element
    (no matrix product, so no BLAS kernel chooses the order)."""
    return np.stack([((R[i, 0] * V[:, 0] + R[i, 1] * V[:, 1]) + R[i, 2] * V[:, 2]) + t[i]
                     for i in range(3)], axis=1)


def rounding_bound(vertices, pose) -> np.ndarray:
    """(3,) ``bound_i`` of the module docstring (rounded up: computed in
    floats, then enlarged by a relative 1e-15, far above the few roundings of
    the bound itself)."""
    rotation, translation = pose
    v = np.abs(np.asarray(vertices, dtype=np.float64))
    R = np.abs(np.asarray(rotation, dtype=np.float64))
    sums = (R[:, 0] * v[:, 0:1] + R[:, 1] * v[:, 1:2] + R[:, 2] * v[:, 2:3]
            + np.abs(np.asarray(translation, dtype=np.float64)))
    return sums.max(axis=0) * GAMMA_4 * (1.0 + 1e-15) + UNDERFLOW


def _points(draw, count: int, size: float) -> np.ndarray:
    return np.array(draw.uniform(-1.0, 1.0, 3 * count)).reshape(count, 3) * size


def _box_case(draw, family: str):
    if family == "exact":
        rotation = draw.choice(signed_permutations())
        translation = np.array(draw.integers(-80, 80, 3), dtype=np.float64) / 8.0
        vertices = np.array(draw.integers(-16, 16, 3 * draw.integers(1, 8)[0]),
                            dtype=np.float64).reshape(-1, 3) / 4.0
    elif family == "near-identity":
        rotation = np.eye(3)
        translation = np.array(draw.uniform(-1.0, 1.0, 3)) * draw.log_uniform(-12.0, -8.0)
        vertices = _points(draw, draw.integers(1, 8)[0], 1.0)
    elif family == "bundled":
        rotation = unit_quaternion_rotation(draw)
        translation = np.array(draw.uniform(-10.0, 10.0, 3))
        vertices = np.array(bundled_mesh(draw.choice(BOX_MODELS)).vertices)
    else:
        rotation = unit_quaternion_rotation(draw)
        count = draw.integers(1, 12)[0]
        if family == "far":
            vertices = _points(draw, count, 1.0)
            translation = np.array(draw.uniform(-1.0, 1.0, 3)) * draw.log_uniform(6.0, 9.0)
        elif family == "tiny":
            vertices = _points(draw, count, draw.log_uniform(-12.0, -9.0))
            translation = np.array(draw.uniform(-1.0, 1.0, 3))
        else:
            vertices = _points(draw, count, draw.log_uniform(-3.0, 3.0))
            translation = np.array(draw.uniform(-10.0, 10.0, 3)) * draw.log_uniform(-3.0, 3.0)
    pose = (np.asarray(rotation, dtype=np.float64), translation)
    return BoxCase(vertices=vertices, pose=pose, family=family, exact=exact_box(vertices, pose),
                   bound=rounding_bound(vertices, pose))


@dataclass(frozen=True)
class BoxCase:
    """Vertices (n, 3), a pose, the family, the exact box (two triples of
    Fractions) and the per-axis rounding bound (3,)."""

    vertices: np.ndarray
    pose: tuple
    family: str
    exact: tuple
    bound: np.ndarray

    def to_dict(self) -> dict:
        return {"family": self.family, "vertices": self.vertices.tolist(),
                "R": self.pose[0].tolist(), "t": self.pose[1].tolist(),
                "exact_lo": [float(x) for x in self.exact[0]],
                "exact_hi": [float(x) for x in self.exact[1]],
                "bound": self.bound.tolist()}


def _any_box(draw) -> BoxCase:
    return _box_case(draw, draw.choice(FAMILIES))


def box_strategy():
    """Hypothesis strategy of :class:`BoxCase` over every family."""
    return strategy(_any_box)


@dataclass(frozen=True)
class BoxCases:
    cases: tuple
    seed: int

    def __len__(self) -> int:
        return len(self.cases)

    def strategy(self):
        return box_strategy()


def box_cases(n: int, seed: int = 0, start: int = 0, stop: int | None = None) -> BoxCases:
    """The seeded set of ``n`` box cases, family ``i % 6``, or its cases
    ``start`` to ``stop - 1`` (a shard)."""
    cases = seeded_range(lambda draw, i: _box_case(draw, FAMILIES[i % len(FAMILIES)]),
                         seed, 0xB0C5, start, n if stop is None else stop)
    return BoxCases(cases=cases, seed=seed)
