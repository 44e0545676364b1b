"""Why two answers may differ, on a triangle pair or on two whole bodies:
refsim's one classifier of disagreements.

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

Two bodies (:func:`classify_bodies`): an engine's boolean answer on two
posed closed meshes. The class is one of the conformance kit's
(:data:`BODY_CLASSES`, a subset of
:data:`refsim.conformance.results.CLASSES`), with a finer **reason**
(:data:`BODY_REASONS`) and the gap in metres: the deepest exact pair's
depth when refsim finds the surfaces meeting, their distance when it does
not. Exact explanations come first (refsim's own pair answer against the
rational test; a contact resting on exact zeros; the engine's declared
``pose_used``; a body inside one the engine tests as a solid), then the
measured gap against the rounding bound and the engine's declared
``distance_tolerance``; "bug" only when none holds.

Both the studies' comparison with oracles (:mod:`refsim.studies.triangles`,
:mod:`refsim.studies.levels`) and the conformance kit
(:mod:`refsim.conformance.checks_geometry`) classify with these, so that one
pair, or one pose of two bodies, gets one class wherever it is met.

Cost: O(1) orientation predicates per pair (filtered, exact where the
filter cannot decide), plus one rational separating-axis test. Two bodies:
one triangle pair's cost per exact pair, or O(m_a m_b) face boxes and at
most :data:`GAP_PAIRS` triangle distances for surfaces apart, plus one
winding number per connected part of each body against the other's faces
and, with ``pose_used``, one exact query.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from refsim.collision.boxes import world_vertices
from refsim.collision.containment import contains_part
from refsim.collision.gaps import face_box_distances, rounding_bound, signed_gap
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


# -- whole bodies ------------------------------------------------------------------------

#: Face pairs whose triangle distances are computed, at most, to measure the
#: gap of bodies whose surfaces do not meet (the pairs whose boxes are
#: nearest); beyond it the gap is the boxes' lower bound (``gap_is_lower_bound``).
GAP_PAIRS = 500

#: The classes of a triangle pair's verdict, most serious first (the
#: conformance kit's order, :data:`refsim.conformance.results.CLASSES`): a
#: set of pairs takes the first that any of them has.
PAIR_SEVERITY = ("bug", "tolerance", "touching", "coplanar")

#: Why a body-level answer differs from refsim's exact one: each reason, the
#: class it falls in (one of the conformance kit's classes,
#: :data:`refsim.conformance.results.CLASSES`) and what it means; the rules
#: that decide it are :func:`classify_bodies`'.
BODY_REASONS: dict[str, tuple[str, str]] = {
    "refsim against the exact test": (
        "bug", "refsim's own answer on an intersecting triangle pair differs from the "
        "rational separating-axis test: refsim is wrong, whatever the engine does"),
    "containment without solid": (
        "bug", "one body lies inside the other and their surfaces do not meet; the engine "
        "says they collide but does not declare that it tests the container as a solid"),
    "gap beyond tolerance": (
        "bug", "a well-conditioned answer differs: the gap (distance apart, or depth of the "
        "deepest crossing pair) is beyond the rounding bound and the declared "
        "distance_tolerance"),
    "containment": (
        "known-divergence", "one body lies inside the other, which the engine declares it "
        "tests as a solid (solid, or is_solid of that mesh): volumes meet, surfaces do not"),
    "float32 transform": (
        "tolerance", "refsim on the poses the engine declares it applies (pose_used, e.g. "
        "rounded to float32) gives the engine's answer: the engine rounded its input"),
    "gap within tolerance": (
        "tolerance", "the gap (distance apart, or depth of the deepest crossing pair) is "
        "within the rounding bound (scaled to the engine's unit roundoff) or the declared "
        "distance_tolerance"),
    "touching": (
        "touching", "the bodies meet only where an orientation is exactly zero (a shared "
        "face, edge or corner, nothing crossing transversally): gap exactly 0"),
    "coplanar": (
        "coplanar", "every triangle pair the bodies meet in lies on one plane, exactly"),
}

#: The classes :func:`classify_bodies` can give, in the kit's order.
BODY_CLASSES = ("bug", "known-divergence", "tolerance", "touching", "coplanar")


@dataclass(frozen=True)
class BodyVerdict:
    """A classified disagreement on two posed bodies: its ``kind`` (one of
    :data:`BODY_CLASSES`), its ``reason`` (a key of :data:`BODY_REASONS`),
    the ``gap`` in metres (negative: the depth of the deepest crossing
    pair; positive: the distance between surfaces that do not meet), the
    rounding bound in metres it was compared with (scaled by the engine's
    unit roundoff), ``gap_is_lower_bound`` (only the :data:`GAP_PAIRS`
    nearest face pairs were measured and a farther one could be nearer),
    ``contained`` (one body lies inside the other) and ``solid`` (the
    engine tests the container as a solid; False when nothing is
    contained)."""

    kind: str
    reason: str
    gap: float
    bound: float
    gap_is_lower_bound: bool = False
    contained: bool = False
    solid: bool = False


def worst_pair(world_a, faces_a, world_b, faces_b, pairs, distance_tolerance: float = 0.0,
               roundoff: float = 1.0) -> tuple[str, TriangleVerdict]:
    """The most serious class (:data:`PAIR_SEVERITY`) of the face pairs
    ``pairs`` (``(i, j)``, face ``i`` of A and ``j`` of B, world vertices
    given), each classified by :func:`classify_triangle_pair`, and the
    verdict of the pair farthest from touching (largest ``|gap|``, the
    first in ``pairs`` order among equals)."""
    verdicts = [classify_triangle_pair(world_a[faces_a[i]], world_b[faces_b[j]],
                                       distance_tolerance, roundoff) for i, j in pairs]
    found = {v.kind for v in verdicts}
    kind = next(k for k in PAIR_SEVERITY if k in found)
    return kind, max(verdicts, key=lambda v: abs(v.gap))


def surface_gap(world_a, faces_a, world_b, faces_b) -> tuple[float, bool]:
    """The smallest distance between two surfaces that do not meet, in
    metres, and whether it is only a lower bound: the triangle distances
    (:func:`refsim.collision.gaps.triangle_distance`) of the face pairs whose
    boxes are nearest (at most :data:`GAP_PAIRS`); exact when no pair left
    out could be nearer (its box is at least as far as the gap found), else
    the farthest measured box distance, a lower bound."""
    boxes = face_box_distances(world_a, faces_a, world_b, faces_b)
    order = np.argsort(boxes, axis=None, kind="stable")[:GAP_PAIRS]
    pairs = [np.unravel_index(k, boxes.shape) for k in order]
    gap = min(signed_gap(world_a[faces_a[i]], world_b[faces_b[j]], False) for i, j in pairs)
    lower_bound = bool(len(order) < boxes.size and float(boxes.flat[order[-1]]) < gap)
    return (float(boxes.flat[order[-1]]) if lower_bound else gap), lower_bound


def classify_bodies(mesh_a, pose_a, mesh_b, pose_b, answer: bool, *, exact_pairs=None,
                    distance_tolerance: float = 0.0, roundoff: float = 1.0,
                    solid: bool = False, is_solid=None, pose_used=None,
                    kernel: str | None = None) -> BodyVerdict:
    """Why an engine's boolean ``answer`` on two posed bodies differs from
    refsim's exact one: the class and reason of :data:`BODY_REASONS`, and
    the gap in metres. The one classifier of the conformance kit's
    ``collide.agreement`` and of the level study's comparison with oracles.

    The engine's declarations (:func:`refsim.engines.body_conventions`):
    ``distance_tolerance`` (metres), ``roundoff`` (its unit roundoff over
    float64's: the factor on every rounding bound), ``solid`` (it tests
    closed meshes as solids), ``is_solid(vertices, faces)`` (per mesh, which
    it tests as a solid; overrides ``solid``), ``pose_used(pose)`` (the pose
    it really applies). ``exact_pairs``: refsim's exact intersecting face
    pairs, when the caller has them (else computed with ``kernel``).

    Rules, the first that holds (exact explanations before measured ones,
    "bug" only when none holds):

    refsim says the surfaces meet, the engine says apart. Every exact pair
    is classified (:func:`worst_pair`); the gap is the deepest pair's
    (minus its penetration depth: to separate the bodies every pair must
    separate, so the bodies' depth is at least the deepest pair's).

    1. a pair on which refsim's answer differs from the rational
       separating-axis test: "bug", "refsim against the exact test";
    2. every pair touching or coplanar (exact predicates): "touching" (or
       "coplanar" when all are): the contact rests on exact zeros, gap 0;
    3. refsim on ``pose_used`` poses says apart: "tolerance", "float32
       transform";
    4. the deepest pair within the rounding bound or the declared
       tolerance: "tolerance", "gap within tolerance"; else "bug", "gap
       beyond tolerance".

    refsim says apart, the engine says they collide. The gap is the
    surfaces' distance (:func:`surface_gap`).

    1. refsim on ``pose_used`` poses says collide: "tolerance", "float32
       transform";
    2. a part of one body inside the other (:func:`contains_part`), and the
       engine tests that container as a solid: "known-divergence",
       "containment" (volumes meet where surfaces do not);
    3. the gap within the rounding bound (of the world coordinates, scaled
       by ``roundoff``) or the declared tolerance, and exact (not a lower
       bound): "tolerance", "gap within tolerance";
    4. contained, the container not declared solid: "bug", "containment
       without solid"; else "bug", "gap beyond tolerance".

    Call it only where ``answer`` differs from refsim's exact answer
    (ValueError otherwise).
    """
    from refsim.collision.bodies import bodies_collide, intersecting_pairs

    if exact_pairs is None:
        exact_pairs = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, kernel=kernel)
    pairs = [(int(i), int(j)) for i, j in np.asarray(exact_pairs, np.int64).reshape(-1, 2)]
    if bool(answer) == bool(pairs):
        raise ValueError(f"answer {answer!r} is refsim's exact answer: no disagreement to "
                         "classify")
    world_a, world_b = world_vertices(mesh_a, pose_a), world_vertices(mesh_b, pose_b)
    fa, fb = mesh_a.faces, mesh_b.faces

    def rounded_poses_agree() -> bool:
        return pose_used is not None and bool(bodies_collide(
            mesh_a, pose_used(pose_a), mesh_b, pose_used(pose_b), kernel=kernel)) == bool(answer)

    if pairs:
        kind, widest = worst_pair(world_a, fa, world_b, fb, pairs, distance_tolerance,
                                  roundoff)
        gap, bound = widest.gap, widest.bound
        if kind == "bug" and any(
                exact_class(tuple(map(tuple, world_a[fa[i]].tolist())),
                            tuple(map(tuple, world_b[fb[j]].tolist()))) == "bug"
                for i, j in pairs):
            return BodyVerdict("bug", "refsim against the exact test", gap, bound)
        if kind in ("touching", "coplanar"):
            return BodyVerdict(kind, kind, 0.0, bound)      # not -0.0: no depth at all
        if rounded_poses_agree():
            return BodyVerdict("tolerance", "float32 transform", gap, bound)
        reason = "gap within tolerance" if kind == "tolerance" else "gap beyond tolerance"
        return BodyVerdict(BODY_REASONS[reason][0], reason, gap, bound)

    gap, lower_bound = surface_gap(world_a, fa, world_b, fb)
    bound = max(rounding_bound(world_a), rounding_bound(world_b)) * roundoff

    def verdict(reason: str, contained: bool = False, is_solid_container: bool = False):
        return BodyVerdict(BODY_REASONS[reason][0], reason, gap, bound, lower_bound,
                           contained, is_solid_container)

    if rounded_poses_agree():
        return verdict("float32 transform")
    containers = [container for container, pc, inner, pi in (
        (mesh_a, pose_a, mesh_b, pose_b), (mesh_b, pose_b, mesh_a, pose_a))
        if contains_part(container, pc, inner, pi)]
    solid_container = any(
        is_solid(c.vertices, c.faces) if is_solid is not None else solid for c in containers)
    if solid_container:
        return verdict("containment", True, True)
    if gap <= max(bound, distance_tolerance) and not lower_bound:
        return verdict("gap within tolerance", bool(containers))
    if containers:
        return verdict("containment without solid", True)
    return verdict("gap beyond tolerance")
