"""Why two answers on a triangle pair may differ: the classes exact
predicates decide.

When another engine's answer on two closed triangles differs from refsim's
exact one (:func:`refsim.collision.triangle.triangles_intersect`), some
disagreements are settled by exact predicates alone, before any tolerance
is asked about (:func:`exact_class`):

- ``"bug"``: refsim's own answer differs from an independent exact ground
  truth, the separating-axis test in rational arithmetic
  (:mod:`refsim.collision.sat_exact`): refsim is wrong, whatever else holds;
- ``"coplanar"``: all six vertices lie on one plane, exactly
  (:func:`points_coplanar`), where engines part by convention (many treat
  coplanar triangles as not intersecting);
- ``"touching"``: refsim finds a common point, but no edge of one triangle
  crosses the other's open interior with all signs strict
  (:func:`strict_crossing`): the contact rests on an exact zero orientation
  and the exact minimum distance is 0.

Where none of them holds, :func:`classify_triangle_pair` measures the pair's
**gap** in metres (:mod:`refsim.collision.gaps`: distance apart, minus the
depth of a crossing) and calls the disagreement ``"tolerance"`` when the gap
lies within the rounding bound (float64's, scaled by the engine's unit
roundoff) or the engine's declared distance tolerance, ``"bug"`` beyond
both: one vocabulary (:data:`CLASSES`) and one tolerance measure.

Both the studies' comparison with oracles (:mod:`refsim.studies.triangles`,
:mod:`refsim.studies.levels`) and the conformance kit
(:mod:`refsim.conformance.checks_geometry`) classify with these, so that one
pair gets one class wherever it is met.

Cost: O(1) orientation predicates per pair (filtered, exact where the
filter cannot decide), plus one rational separating-axis test.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from refsim.collision.gaps import rounding_bound, signed_gap
from refsim.collision.predicates import FILTERED, orient3d
from refsim.collision.sat_exact import triangles_intersect_sat
from refsim.collision.triangle import normal_signs, triangles_intersect

#: The classes :func:`exact_class` can return.
EXACT_CLASSES = ("bug", "coplanar", "touching")

#: The classes :func:`classify_triangle_pair` can return, in the order the
#: studies tabulate them.
CLASSES = ("coplanar", "touching", "tolerance", "bug")


def points_coplanar(points) -> bool:
    """All points (tuples of float coordinates) on one plane, exactly (true
    for collinear or equal points): the first three points that span a plane
    decide it, and every point's orientation against them is zero."""
    m = len(points)
    for i in range(m):
        for j in range(i + 1, m):
            for k in range(j + 1, m):
                a, b, c = points[i], points[j], points[k]
                if any(normal_signs(a, b, c, FILTERED)):
                    return all(orient3d(a, b, c, d) == 0 for d in points)
    return True


def strict_crossing(t1, t2) -> bool:
    """Some edge of one triangle crosses the other's OPEN interior
    transversally, decided with strict signs only (no zero involved): the
    edge's ends lie strictly on both sides of the plane and the three line
    orientations of the edge against the triangle's edges share one strict
    sign (Guigue and Devillers 2003's edge-triangle test without its
    boundary cases)."""
    for e, t in ((t1, t2), (t2, t1)):
        a, b, c = t
        for i in range(3):
            p, q = e[i], e[(i + 1) % 3]
            sp, sq = orient3d(a, b, c, p), orient3d(a, b, c, q)
            if sp * sq >= 0:
                continue
            signs = {orient3d(p, q, a, b), orient3d(p, q, b, c), orient3d(p, q, c, a)}
            if signs in ({1}, {-1}):
                return True
    return False


def exact_class(t1, t2, answers: tuple[bool, bool | None] | None = None) -> str | None:
    """The class of a disagreement on the triangle pair ``(t1, t2)`` (tuples
    of float coordinates) that exact predicates decide (module docstring),
    or None when none does and the class turns on a tolerance. ``"bug"``
    is never given for a degenerate triangle, where the separating-axis
    test does not apply.

    ``answers``: ``(refsim, truth)`` when the caller has them already:
    :func:`refsim.collision.triangle.triangles_intersect` and
    :func:`refsim.collision.sat_exact.triangles_intersect_sat` on the pair.
    """
    refsim, truth = answers if answers is not None else (
        triangles_intersect(t1, t2), triangles_intersect_sat(t1, t2))
    if truth is not None and truth != refsim:
        return "bug"
    if points_coplanar(t1 + t2):
        return "coplanar"
    if refsim and not strict_crossing(t1, t2):
        return "touching"
    return None


@dataclass(frozen=True)
class TriangleVerdict:
    """A classified disagreement on a triangle pair: its class (one of
    :data:`CLASSES`), its gap in metres (0 for "touching"), and the rounding
    bound in metres it was compared with (already scaled by the roundoff)."""

    kind: str
    gap: float
    bound: float


def classify_triangle_pair(a, b, distance_tolerance: float = 0.0,
                           roundoff: float = 1.0) -> TriangleVerdict:
    """Why an engine's answer may differ from refsim's exact one on the
    triangle pair ``(a, b)`` ((3, 3) arrays or nested sequences).

    First the classes exact predicates decide (:func:`exact_class`): "bug"
    when refsim's answer differs from the rational separating-axis truth,
    then "coplanar" and "touching". Otherwise the pair's gap
    (:func:`refsim.collision.gaps.signed_gap`, against the exact answer)
    decides: "tolerance" when ``|gap|`` is within the rounding bound
    (:func:`refsim.collision.gaps.rounding_bound` times ``roundoff``, the
    engine's unit roundoff over float64's) or ``distance_tolerance`` (what
    the engine declares, metres), else "bug": a well-conditioned pair
    answered differently, which rounding does not explain.

    Call it only for pairs where the answers differ; it does not look at
    the engine's answer.
    """
    t1 = tuple(map(tuple, np.asarray(a, np.float64).tolist()))
    t2 = tuple(map(tuple, np.asarray(b, np.float64).tolist()))
    refsim = triangles_intersect(t1, t2)
    truth = triangles_intersect_sat(t1, t2)
    bound = rounding_bound(t1, t2) * roundoff
    gap = signed_gap(t1, t2, refsim if truth is None else truth)
    kind = exact_class(t1, t2, (refsim, truth))
    if kind == "touching":
        gap = 0.0
    elif kind is None:
        kind = "tolerance" if abs(gap) <= max(bound, distance_tolerance) else "bug"
    return TriangleVerdict(kind, gap, bound)
