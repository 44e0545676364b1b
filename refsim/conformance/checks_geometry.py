"""Checks of the geometric capabilities: triangles, pairs, collide, aabb.

One function per property, ``check_xxx(engine, cases) -> CheckResult``
(:mod:`refsim.conformance.results`), each comparing the engine's answer
with the exact one on every case and classifying every disagreement:

- triangle pairs (:func:`classify_triangles`): the classification of
  :func:`refsim.studies.triangles.classify_disagreement` (coplanar,
  touching, near-degenerate "tolerance", else bug; it first confirms the
  ground truth against refsim's own exact test, so a wrong truth shows as a
  bug, never as the engine's fault);
- mesh pairs: each face pair the engine adds or misses is a triangle pair of
  the world triangles (refsim's transform arithmetic, as the truth used),
  classified as above; a case takes its most serious class
  (:func:`refsim.conformance.results.worst_class`). Two reasons a float
  engine's *world* differs from refsim's are recognised first: the answer
  it gives is the exact answer for the poses rounded to float32 (an engine
  that transforms in single precision), or the grazing case's gap is within
  :data:`POSE_TOLERANCE` (engines that decide by a distance and stop at a
  tolerance, as GJK does): "tolerance". A body entirely inside the other,
  reported as a collision, is "known-divergence" (a solid engine; refsim's
  surfaces do not meet);
- boxes: the per-axis rounding bound of :mod:`refsim.conformance.cases_boxes`
  (a side beyond it by no more than the float32 bound is "tolerance").

Where a check fails, Hypothesis searches the same families for a failing
case and shrinks it (:mod:`refsim.conformance.shrink`); it goes first in
``examples``.

Cost: one engine call per case, plus, per failing case, a classification
(O(1) exact predicates per disagreeing triangle pair), plus one Hypothesis
search per failing check.
"""

from __future__ import annotations

import math
import time
from fractions import Fraction

import numpy as np

from refsim.conformance.results import CLASSES, CheckResult, tally, worst_class
from refsim.conformance.shrink import minimal_failure

#: Seeded failing cases kept in ``examples`` per class (after the shrunk one).
EXAMPLES_PER_CLASS = 2

#: A grazing pose whose gap (or overlap) is at most this, relative to the
#: bodies' size (about 1 m here), may go either way in an engine that decides
#: by a distance with a tolerance: FCL's GJK stops at 1e-6 by default (its
#: ``gjk_tolerance``), and trimesh's CollisionManager tests convex meshes as
#: GJK solids.
POSE_TOLERANCE = 1e-6

#: trimesh treats a pose within this of the identity (every entry of the
#: 4x4) as the identity and returns the untransformed box
#: (:data:`refsim.oracles.trimesh_adapter.TRIMESH_IDENTITY_ATOL`): a box that
#: is exactly the untransformed one, for such a pose, is "tolerance".
IDENTITY_TOLERANCE = 1e-8

#: The float32 unit roundoff: a box side beyond the float64 bound by no more
#: than ``FLOAT32_ROUNDOFF`` times the sum the bound is made of (each of its
#: four terms rounded once in single precision) is "tolerance".
FLOAT32_ROUNDOFF = 2.0 ** -24


def _keep(found: list, example: dict) -> None:
    """Keep ``example`` if its class has fewer than EXAMPLES_PER_CLASS so far
    (every class that occurs gets its examples, however rare)."""
    if sum(e["class"] == example["class"] for e in found) < EXAMPLES_PER_CLASS:
        found.append(example)


def _examples(found, shrunk) -> list[dict]:
    """The shrunk case first, then the kept seeded ones, by class order."""
    from refsim.conformance.results import CLASSES

    return ([shrunk] if shrunk is not None else []) + sorted(
        found, key=lambda e: CLASSES.index(e["class"]))


def _shrunk(cases, fails, classify, describe):
    value = minimal_failure(cases.strategy(), fails, cases.seed)
    if value is None:
        return None
    return {"shrunk": True, "class": classify(value), **describe(value)}


# -- triangles ---------------------------------------------------------------------------


def classify_triangles(a, b) -> str:
    """The class of a disagreement on the triangle pair ``(a, b)``."""
    from refsim.studies.triangles import classify_disagreement

    return classify_disagreement(a, b)


def _triangle_check(name: str, answer, cases) -> CheckResult:
    start = time.perf_counter()
    outcomes: list[str | None] = []  # per case: None (passed) or its class
    found: list[dict] = []
    for index, pair in enumerate(cases.pairs):
        got = bool(answer(pair.a, pair.b))
        if got == pair.truth:
            outcomes.append(None)
            continue
        kind = classify_triangles(pair.a, pair.b)
        outcomes.append(kind)
        _keep(found, {"case": index, "class": kind, "answer": got, **pair.to_dict()})
    shrunk = None
    if any(outcomes):
        def fails(p):
            return bool(answer(p.a, p.b)) != p.truth

        shrunk = _shrunk(cases, fails, lambda p: classify_triangles(p.a, p.b),
                         lambda p: {"answer": not p.truth, **p.to_dict()})
    by_family: dict[str, int] = {}
    for pair, outcome in zip(cases.pairs, outcomes, strict=True):
        if outcome is not None:
            by_family[pair.family] = by_family.get(pair.family, 0) + 1
    return tally("triangles", name, outcomes, examples=_examples(found, shrunk),
                 measured={"failed_by_family": by_family},
                 seconds=time.perf_counter() - start)


def check_triangles_agreement(engine, cases) -> CheckResult:
    """``triangles.agreement``: the engine's ``triangles_intersect(a, b)`` is
    the exact answer (closed triangles, touching counts) on every pair."""
    return _triangle_check("agreement", engine.triangles_intersect, cases)


def check_triangles_reference(engine, cases) -> CheckResult:
    """``triangles.reference``: refsim's own edge-triangle test agrees with
    the rational separating-axis test on the same pairs. It does not call the
    engine: it checks the ground truth every other check of this engine
    leans on (the mesh-pair answers come from refsim's test) with a second,
    independent exact algorithm, in every report."""
    from refsim.collision.triangle import triangles_intersect

    return _triangle_check("reference", triangles_intersect, cases)


# -- mesh pairs and bodies ------------------------------------------------------------------


def _call(engine, method: str, case):
    a, b = case.mesh_a, case.mesh_b
    return getattr(engine, method)(a.vertices, a.faces, case.pose_a, b.vertices, b.faces,
                                   case.pose_b)


def _pair_set(pairs) -> set[tuple[int, int]]:
    return {(int(i), int(j)) for i, j in np.asarray(pairs, dtype=np.int64).reshape(-1, 2)}


def _float32_pose(pose):
    rotation, translation = pose
    return (np.asarray(rotation, np.float32).astype(np.float64),
            np.asarray(translation, np.float32).astype(np.float64))


def _exact_for_float32_poses(case) -> np.ndarray:
    from refsim.collision.bodies import intersecting_pairs

    return intersecting_pairs(case.mesh_a, _float32_pose(case.pose_a), case.mesh_b,
                              _float32_pose(case.pose_b), level="exact", method="bvh")


def _within_pose_tolerance(case) -> bool:
    return case.gap is not None and abs(case.gap) <= POSE_TOLERANCE


def _classify_face_pairs(case, differing) -> str:
    from refsim.types import transform_points

    world_a = transform_points(case.mesh_a.vertices, case.pose_a)
    world_b = transform_points(case.mesh_b.vertices, case.pose_b)
    fa, fb = case.mesh_a.faces, case.mesh_b.faces
    return worst_class(classify_triangles(world_a[fa[i]], world_b[fb[j]]) for i, j in differing)


def classify_pairs(case, got) -> str:
    """The class of an engine's face pairs ``got`` that differ from the truth."""
    truth, answer = _pair_set(case.truth), _pair_set(got)
    if _pair_set(_exact_for_float32_poses(case)) == answer or _within_pose_tolerance(case):
        return "tolerance"
    return _classify_face_pairs(case, sorted(truth ^ answer))


def _inside(point, mesh, pose) -> bool:
    """Whether ``point`` (world) is inside the closed mesh under ``pose``: the
    parity of crossings of a ray in a fixed, generic direction (float64; for
    classifying a disagreement only, never for a ground truth)."""
    from refsim.types import transform_points

    world = transform_points(mesh.vertices, pose)
    tri = world[mesh.faces]                                   # (m, 3, 3)
    direction = np.array([0.5773502691896258, 0.5773502691896257, 0.5773502691896259])
    e1, e2 = tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    p = np.cross(direction, e2)
    det = (e1 * p).sum(axis=1)
    ok = np.abs(det) > 1e-300
    s = point - tri[:, 0]
    inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
    u = (s * p).sum(axis=1) * inv
    q = np.cross(s, e1)
    v = (q * direction).sum(axis=1) * inv
    t = (q * e2).sum(axis=1) * inv
    hits = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 0)
    return bool(hits.sum() % 2)


def _near_pairs(case, margin: float) -> list[tuple[int, int]]:
    """Face pairs whose world boxes (refsim's transform) overlap when each
    is widened by ``margin``: the pairs a false "collide" may rest on."""
    from refsim.types import transform_points

    ta = transform_points(case.mesh_a.vertices, case.pose_a)[case.mesh_a.faces]
    tb = transform_points(case.mesh_b.vertices, case.pose_b)[case.mesh_b.faces]
    lo_a, hi_a = ta.min(axis=1) - margin, ta.max(axis=1) + margin
    lo_b, hi_b = tb.min(axis=1), tb.max(axis=1)
    overlap = ((lo_a[:, None, :] <= hi_b[None, :, :])
               & (lo_b[None, :, :] <= hi_a[:, None, :])).all(axis=2)
    return [(int(i), int(j)) for i, j in zip(*np.nonzero(overlap), strict=True)]


def classify_collide(case, got: bool) -> str:
    """The class of an engine's boolean answer that differs from the truth.

    A false "apart" takes the most serious class of the exact pairs it
    missed. A false "collide" is "known-divergence" when one body's centroid
    is inside the other (a solid engine), else the least serious class of
    the triangle pairs within :data:`POSE_TOLERANCE` of each other (some
    pair near touching explains it; none is a bug)."""
    truth = len(case.truth) > 0
    if not truth and got:
        centroid_a = np.asarray(case.pose_a[0]) @ case.mesh_a.vertices.mean(axis=0) \
            + case.pose_a[1]
        centroid_b = np.asarray(case.pose_b[0]) @ case.mesh_b.vertices.mean(axis=0) \
            + case.pose_b[1]
        if (_inside(centroid_b, case.mesh_a, case.pose_a)
                or _inside(centroid_a, case.mesh_b, case.pose_b)):
            return "known-divergence"
    if (len(_exact_for_float32_poses(case)) > 0) == got or _within_pose_tolerance(case):
        return "tolerance"
    if truth:
        # every exact pair is missed: the class of the pairs it rests on
        return _classify_face_pairs(case, [tuple(p) for p in np.asarray(case.truth)])
    scale = max(1.0, float(np.abs(case.pose_a[1]).max()), float(np.abs(case.pose_b[1]).max()))
    near = _near_pairs(case, POSE_TOLERANCE * scale)
    if not near:
        return "bug"
    from refsim.types import transform_points

    world_a = transform_points(case.mesh_a.vertices, case.pose_a)
    world_b = transform_points(case.mesh_b.vertices, case.pose_b)
    fa, fb = case.mesh_a.faces, case.mesh_b.faces
    kinds = {classify_triangles(world_a[fa[i]], world_b[fb[j]]) for i, j in near}
    return max(kinds, key=CLASSES.index)          # the least serious


def check_pairs_agreement(engine, cases) -> CheckResult:
    """``pairs.agreement``: the engine's ``intersecting_pairs`` is the exact
    set of intersecting face pairs on every pose (as a set: order and
    duplicates do not matter)."""
    start = time.perf_counter()
    outcomes: list[str | None] = []  # per case: None (passed) or its class
    found: list[dict] = []
    extra = missing = 0
    for index, case in enumerate(cases.cases):
        got = _call(engine, "intersecting_pairs", case)
        truth, answer = _pair_set(case.truth), _pair_set(got)
        if truth == answer:
            outcomes.append(None)
            continue
        extra += len(answer - truth)
        missing += len(truth - answer)
        kind = classify_pairs(case, got)
        outcomes.append(kind)
        _keep(found, {"case": index, "class": kind,
                      "extra_pairs": sorted(answer - truth)[:10],
                      "missing_pairs": sorted(truth - answer)[:10], **case.to_dict()})
    shrunk = None
    if any(outcomes):
        def fails(c):
            return _pair_set(_call(engine, "intersecting_pairs", c)) != _pair_set(c.truth)

        shrunk = _shrunk(cases, fails,
                         lambda c: classify_pairs(c, _call(engine, "intersecting_pairs", c)),
                         lambda c: c.to_dict())
    return tally("pairs", "agreement", outcomes, examples=_examples(found, shrunk),
                 measured={"extra_face_pairs": extra, "missing_face_pairs": missing},
                 seconds=time.perf_counter() - start)


def check_collide_agreement(engine, cases) -> CheckResult:
    """``collide.agreement``: the engine's ``bodies_collide`` is true exactly
    when some triangle of one surface meets a triangle of the other."""
    start = time.perf_counter()
    outcomes: list[str | None] = []  # per case: None (passed) or its class
    found: list[dict] = []
    for index, case in enumerate(cases.cases):
        got = bool(_call(engine, "bodies_collide", case))
        if got == (len(case.truth) > 0):
            outcomes.append(None)
            continue
        kind = classify_collide(case, got)
        outcomes.append(kind)
        _keep(found, {"case": index, "class": kind, "answer": got, **case.to_dict()})
    shrunk = None
    if any(outcomes):
        def fails(c):
            return bool(_call(engine, "bodies_collide", c)) != (len(c.truth) > 0)

        shrunk = _shrunk(cases, fails,
                         lambda c: classify_collide(c, bool(_call(engine, "bodies_collide", c))),
                         lambda c: {"answer": not len(c.truth), **c.to_dict()})
    return tally("collide", "agreement", outcomes, examples=_examples(found, shrunk),
                 seconds=time.perf_counter() - start)


# -- boxes ---------------------------------------------------------------------------------


def _box(engine, case):
    lo, hi = engine.aabb(case.vertices, case.pose)
    return (np.asarray(lo, dtype=np.float64).reshape(3),
            np.asarray(hi, dtype=np.float64).reshape(3))


def box_excess(case, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """Per axis, how far the engine's box is *inside* the exact box
    (``short``: it misses transformed points) and *outside* it (``wide``),
    in units of the case's rounding bound (exact rationals, then a float)."""
    short = np.zeros(3)
    wide = np.zeros(3)
    for i in range(3):
        bound = float(case.bound[i])
        d_lo = Fraction(float(lo[i])) - case.exact[0][i]       # > 0: misses points
        d_hi = case.exact[1][i] - Fraction(float(hi[i]))       # > 0: misses points
        if not (math.isfinite(lo[i]) and math.isfinite(hi[i])):
            short[i] = wide[i] = math.inf
            continue
        short[i] = float(max(d_lo, d_hi, Fraction(0))) / bound
        wide[i] = float(max(-d_lo, -d_hi, Fraction(0))) / bound
    return short, wide


def _classify_box(case, excess: float, lo, hi) -> str:
    """"tolerance" for an untransformed box of a pose within
    IDENTITY_TOLERANCE of the identity, or a side off by no more than
    float32 rounding (the float32 bound is ``4 u32 / gamma_4`` times the
    float64 one); else "bug"."""
    from refsim.conformance.cases_boxes import GAMMA_4

    rotation, translation = case.pose
    near_identity = max(float(np.abs(rotation - np.eye(3)).max()),
                        float(np.abs(translation).max())) <= IDENTITY_TOLERANCE
    if near_identity and np.array_equal(lo, case.vertices.min(axis=0)) \
            and np.array_equal(hi, case.vertices.max(axis=0)):
        return "tolerance"
    return "tolerance" if excess <= 4 * FLOAT32_ROUNDOFF / GAMMA_4 else "bug"


def _box_check(name: str, engine, cases, side: int) -> CheckResult:
    start = time.perf_counter()
    outcomes: list[str | None] = []  # per case: None (passed) or its class
    found: list[dict] = []
    worst = 0.0
    for index, case in enumerate(cases.cases):
        lo, hi = _box(engine, case)
        excess = float(box_excess(case, lo, hi)[side].max())
        worst = max(worst, excess)
        if excess <= 1.0:
            outcomes.append(None)
            continue
        kind = _classify_box(case, excess, lo, hi)
        outcomes.append(kind)
        _keep(found, {"case": index, "class": kind, "excess_in_bounds": excess,
                      "lo": lo.tolist(), "hi": hi.tolist(), **case.to_dict()})
    shrunk = None
    if any(outcomes):
        def excess_of(c):
            lo, hi = _box(engine, c)
            return float(box_excess(c, lo, hi)[side].max())

        shrunk = _shrunk(cases, lambda c: excess_of(c) > 1.0,
                         lambda c: _classify_box(c, excess_of(c), *_box(engine, c)),
                         lambda c: {"excess_in_bounds": excess_of(c),
                                    "lo": _box(engine, c)[0].tolist(),
                                    "hi": _box(engine, c)[1].tolist(), **c.to_dict()})
    return tally("aabb", name, outcomes, examples=_examples(found, shrunk),
                 measured={"largest_excess_in_bounds": worst},
                 seconds=time.perf_counter() - start)


def check_aabb_encloses(engine, cases) -> CheckResult:
    """``aabb.encloses``: the engine's box contains every exactly transformed
    vertex, up to the rounding bound of a float64 evaluation of ``R p + t``
    (each side at most ``bound_i`` inside the exact box)."""
    return _box_check("encloses", engine, cases, 0)


def check_aabb_tight(engine, cases) -> CheckResult:
    """``aabb.tight``: the engine's box is no larger than the exact box by
    more than the same bound (each side at most ``bound_i`` outside it): the
    box of the vertices, not of a padded or coarser shape."""
    return _box_check("tight", engine, cases, 1)


__all__ = ["check_triangles_agreement", "check_triangles_reference", "check_pairs_agreement",
           "check_collide_agreement", "check_aabb_encloses", "check_aabb_tight",
           "CheckResult"]
