"""Triangle pairs whose answer is known exactly (seed S4, level 3).

What: ``n`` pairs of closed, non-degenerate triangles, cycling through six
families, each pair's answer given by the separating-axis test in rational
arithmetic (:func:`refsim.collision.sat_exact.triangles_intersect_sat`), an
algorithm independent of refsim's edge-triangle test and of every float
engine:

================  =========================================================
family            construction
================  =========================================================
random            six vertices uniform in [-1, 1]^3 (mostly clear answers)
vertex-on-face    a vertex of B at a float point of A's face (rounded:
                  within an ulp of the plane, either side)
edge-on-edge      an edge of B through a float point of an edge of A
near-parallel     B in A's plane, each vertex lifted by 1e-17 .. 1e-9
                  along the normal (planes within 1e-9 of parallel)
touching-exact    small-integer A; B's first vertex exactly on A's plane
                  (at a vertex, an edge point or a face point of A, exact in
                  binary, or just beyond a vertex on an edge's extension),
                  B's other vertices strictly on one side: the triangles
                  touch at one point, or miss by construction, exactly
coplanar-exact    both triangles in one plane with integer coordinates
                  (z = c, or x + y + z = c, with the axes permuted):
                  overlapping, sharing edges and vertices, or apart
================  =========================================================

The families are builders of a :class:`refsim.conformance.draw.Draw`, so
the same constructions give the seeded set (numpy) and the Hypothesis search
that shrinks a failure (:func:`pair_strategy`). A degenerate triangle (zero
area, where the separating-axis set is incomplete) is never a case: the
builder draws again.

References: the near-degenerate families follow J. R. Shewchuk, "Adaptive
Precision Floating-Point Arithmetic and Fast Robust Geometric Predicates",
Discrete Comput. Geom. 18, 1997 (inputs within rounding of a plane), and the
C4 study (:mod:`refsim.studies.triangles`).

Cost: O(1) per pair to build; the truth (rational arithmetic) is the
dominant cost, O(1) per pair but large: size ``n`` accordingly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from refsim.collision.sat_exact import triangles_intersect_sat
from refsim.conformance.draw import Draw, dot3, seeded_range, signed_permutations, strategy

FAMILIES = ("random", "vertex-on-face", "edge-on-edge", "near-parallel", "touching-exact",
            "coplanar-exact")

def _random(draw):
    a = np.array(draw.uniform(-1.0, 1.0, 9)).reshape(3, 3)
    b = np.array(draw.uniform(-1.0, 1.0, 9)).reshape(3, 3)
    return a, b


def _barycentric(draw):
    u, v = draw.uniform(0.0, 1.0, 2)
    if u + v > 1.0:
        u, v = 1.0 - u, 1.0 - v
    return u, v


def _vertex_on_face(draw):
    a, b = _random(draw)
    u, v = _barycentric(draw)
    b[0] = a[0] + u * (a[1] - a[0]) + v * (a[2] - a[0])
    return a, b


def _edge_on_edge(draw):
    a, b = _random(draw)
    u = draw.uniform(0.0, 1.0)[0]
    p = a[0] + u * (a[1] - a[0])
    w = np.array(draw.uniform(-1.0, 1.0, 3))
    s = draw.uniform(0.1, 2.0)[0]
    b[0] = p + w
    b[1] = p - s * w
    return a, b


def _near_parallel(draw):
    a = np.array(draw.uniform(-1.0, 1.0, 9)).reshape(3, 3)
    e1, e2 = a[1] - a[0], a[2] - a[0]
    n = np.cross(e1, e2)
    length = math.sqrt(dot3(n, n))
    n = n / length if length > 0 else n
    b = np.empty((3, 3))
    for j in range(3):
        s, t = draw.uniform(-0.5, 1.2, 2)
        lift = draw.log_uniform(-17.0, -9.0) * draw.choice((-1.0, 1.0))
        b[j] = a[0] + s * e1 + t * e2 + lift * n
    return a, b


def _touching_exact(draw):
    a = np.array(draw.integers(-4, 4, 9), dtype=np.float64).reshape(3, 3)
    i, j = draw.integers(0, 2, 2)
    where = draw.choice(("vertex", "edge", "face", "beyond"))
    if where == "vertex":
        p = a[i]
    elif where == "face":
        k1, k2 = draw.integers(0, 4, 2)
        if k1 + k2 > 4:
            k1, k2 = 4 - k1, 4 - k2
        p = a[0] + (k1 / 4.0) * (a[1] - a[0]) + (k2 / 4.0) * (a[2] - a[0])
    else:
        # on the line through two vertices: k/4 along the edge (on it), or
        # 5/4 or 6/4 (past a vertex, outside the triangle, in its plane)
        k = draw.integers(0, 4)[0] if where == "edge" else draw.integers(5, 6)[0]
        p = a[i] + (k / 4.0) * (a[(i + 1 + j % 2) % 3] - a[i])
    # A's integer normal; B's other vertices strictly above the plane
    n = np.cross(a[1] - a[0], a[2] - a[0])
    b = np.empty((3, 3))
    b[0] = p
    for m in (1, 2):
        d = np.array(draw.integers(-3, 3, 3), dtype=np.float64)
        side = dot3(n, d)                        # integers: exact
        if side == 0.0:
            d, side = n, dot3(n, n)              # in the plane: go along the normal
        b[m] = p + (d if side > 0 else -d)
    return a, b


def _coplanar_exact(draw):
    plane = draw.choice(("axis", "diagonal"))
    c = float(draw.integers(-2, 2)[0])
    pts = np.array(draw.integers(-3, 3, 12), dtype=np.float64).reshape(6, 2)
    if plane == "axis":
        xyz = np.column_stack([pts, np.full(6, c)])
    else:
        xyz = np.column_stack([pts, c - pts[:, 0] - pts[:, 1]])
    rotation = draw.choice(signed_permutations())
    xyz = np.array([[dot3(rotation[i], p) for i in range(3)] for p in xyz])  # exact: 0, +-1
    return xyz[:3].copy(), xyz[3:].copy()


BUILDERS = {
    "random": _random,
    "vertex-on-face": _vertex_on_face,
    "edge-on-edge": _edge_on_edge,
    "near-parallel": _near_parallel,
    "touching-exact": _touching_exact,
    "coplanar-exact": _coplanar_exact,
}


@dataclass(frozen=True)
class TrianglePair:
    """One case: triangles ``a``, ``b`` (3, 3), its family, its exact answer."""

    a: np.ndarray
    b: np.ndarray
    family: str
    truth: bool

    def to_dict(self) -> dict:
        return {"family": self.family, "a": self.a.tolist(), "b": self.b.tolist(),
                "truth": self.truth}


def build_pair(draw: Draw, family: str) -> TrianglePair:
    """A non-degenerate pair of ``family`` with its exact answer (draws
    again while a triangle is degenerate, up to ``draw.retries`` times: the
    integer families are degenerate about one time in five)."""
    for _ in range(draw.retries):
        a, b = BUILDERS[family](draw)
        truth = triangles_intersect_sat(a, b)
        if truth is not None:
            return TrianglePair(a, b, family, bool(truth))
    draw.reject()


def _any_pair(draw) -> TrianglePair:
    return build_pair(draw, draw.choice(FAMILIES))


def pair_strategy():
    """Hypothesis strategy of :class:`TrianglePair` over every family (the
    family is drawn first, so a failure shrinks towards ``random``, the
    first, where it can)."""
    return strategy(_any_pair)


@dataclass(frozen=True)
class TriangleCases:
    """``n`` seeded pairs, family ``i % 6`` for pair ``i``."""

    pairs: tuple
    seed: int

    def __len__(self) -> int:
        return len(self.pairs)

    def strategy(self):
        return pair_strategy()


def triangle_cases(n: int, seed: int = 0, start: int = 0, stop: int | None = None
                   ) -> TriangleCases:
    """The seeded set of ``n`` pairs (module docstring), or its pairs
    ``start`` to ``stop - 1`` (a shard: :func:`refsim.conformance.draw.seeded_range`).
    Cost: O(n), the exact answers in rational arithmetic."""
    pairs = seeded_range(lambda draw, i: build_pair(draw, FAMILIES[i % len(FAMILIES)]),
                         seed, 0x7219, start, n if stop is None else stop)
    return TriangleCases(pairs=pairs, seed=seed)
