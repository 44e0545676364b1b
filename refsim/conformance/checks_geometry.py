"""Checks of the geometric capabilities: triangles, pairs, collide, aabb.

One function per property, ``check_xxx(engine, cases) -> CheckResult``
(:mod:`refsim.conformance.results`), each comparing the engine's answer
with the exact one on every case and classifying every disagreement by a
length in metres, compared with the rounding bound and with what the engine
declares (:func:`refsim.engines.declarations`):

- triangle pairs (:func:`classify_triangles`): the ground truth first
  confirmed against refsim's own exact test (a wrong truth is a "bug",
  never the engine's fault); then "coplanar" and "touching" by exact
  predicates; otherwise the pair's gap (:mod:`refsim.conformance.gaps`:
  distance apart, minus the depth of a crossing) within the rounding bound
  or the engine's ``distance_tolerance`` is "tolerance", beyond both "bug";
- mesh pairs: each face pair the engine adds or misses is a triangle pair of
  the world triangles (refsim's transform arithmetic, as the truth used),
  classified as above; a case takes its most serious class
  (:func:`refsim.conformance.results.worst_class`) and reports its largest
  gap. A false "collide" is "known-divergence" when one body's centroid is
  inside the other (a solid engine; refsim's surfaces do not meet), else
  classed by the smallest gap between the surfaces;
- boxes: per side, how far the box stands inside the exact one (``aabb.encloses``)
  or outside it (``aabb.tight``), in metres; within the rounding bound of
  :mod:`refsim.conformance.cases_boxes` it passes, within the declared
  ``distance_tolerance`` it is "tolerance", a box that encloses and is wider
  by no more than the declared ``box_slack`` is "loose", beyond is "bug".

An exception on a case is that case's "crash" (its input and the
traceback's last line). Where a check fails, Hypothesis searches the same
families for a failing case and shrinks it (:mod:`refsim.conformance.shrink`);
it goes first in ``examples``.

Cost: one engine call per case, plus, per failing case, a classification
(O(1) exact predicates and a gap per disagreeing triangle pair), plus one
Hypothesis search per failing check.
"""

from __future__ import annotations

import math
import time
from fractions import Fraction

import numpy as np

from refsim.conformance.gaps import face_box_distances, rounding_bound, signed_gap
from refsim.conformance.results import CheckResult, Crash, attempt, tally, worst_class
from refsim.conformance.shrink import minimal_failure

#: Seeded failing cases kept in ``examples`` per class (after the shrunk one).
EXAMPLES_PER_CLASS = 2

#: Face pairs whose triangle distances are computed, at most, to measure the
#: gap of a false "collide" (the pairs whose boxes are nearest); beyond it
#: the gap reported is the boxes' lower bound (``gap_is_lower_bound``).
GAP_PAIRS = 500


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
    return {"shrunk": True, **classify(value), **describe(value)}


def _distance_tolerance(engine) -> float:
    from refsim.engines import declarations

    return declarations(engine).distance_tolerance


def _verdict(kind: str, gap: float, bound: float, tolerance: float) -> dict:
    """A classified disagreement as example fields, units in the names."""
    return {"class": kind, "gap_metres": gap, "rounding_bound_metres": bound,
            "distance_tolerance_metres": tolerance}


# -- triangles ---------------------------------------------------------------------------


def classify_triangles(a, b, distance_tolerance: float = 0.0) -> dict:
    """The class of a disagreement on the triangle pair ``(a, b)`` with its
    gap, the rounding bound and the tolerance (module docstring), as
    example fields."""
    from refsim.collision.sat_exact import triangles_intersect_sat
    from refsim.collision.triangle import triangles_intersect
    from refsim.studies.triangles import _points_coplanar, _strict_crossing

    t1 = tuple(map(tuple, np.asarray(a, np.float64).tolist()))
    t2 = tuple(map(tuple, np.asarray(b, np.float64).tolist()))
    refsim = triangles_intersect(t1, t2)
    truth = triangles_intersect_sat(t1, t2)
    bound = rounding_bound(a, b)
    gap = signed_gap(a, b, refsim if truth is None else truth)
    if truth is not None and truth != refsim:
        kind = "bug"                       # the ground truth itself is wrong
    elif _points_coplanar(t1 + t2):
        kind = "coplanar"
    elif refsim and not _strict_crossing(t1, t2):
        kind, gap = "touching", 0.0
    else:
        kind = "tolerance" if abs(gap) <= max(bound, distance_tolerance) else "bug"
    return _verdict(kind, gap, bound, distance_tolerance)


def _triangle_check(name: str, answer, cases, tolerance: float) -> CheckResult:
    start = time.perf_counter()
    outcomes: list[str | None] = []  # per case: None (passed) or its class
    misses: list[float | None] = []
    found: list[dict] = []
    for index, pair in enumerate(cases.pairs):
        got = attempt(lambda p: bool(answer(p.a, p.b)), pair)
        if isinstance(got, Crash):
            outcomes.append("crash")
            misses.append(None)
            _keep(found, got.example(case=index, **pair.to_dict()))
            continue
        if got == pair.truth:
            outcomes.append(None)
            misses.append(None)
            continue
        verdict = classify_triangles(pair.a, pair.b, tolerance)
        outcomes.append(verdict["class"])
        misses.append(verdict["gap_metres"])
        _keep(found, {"case": index, **verdict, "answer": got, **pair.to_dict()})
    shrunk = None
    if any(outcomes):
        def fails(p):
            return bool(answer(p.a, p.b)) != p.truth

        shrunk = _shrunk(cases, fails, lambda p: classify_triangles(p.a, p.b, tolerance),
                         lambda p: {"answer": not p.truth, **p.to_dict()})
    by_family: dict[str, int] = {}
    for pair, outcome in zip(cases.pairs, outcomes, strict=True):
        if outcome is not None:
            by_family[pair.family] = by_family.get(pair.family, 0) + 1
    return tally("triangles", name, outcomes, examples=_examples(found, shrunk),
                 measured={"failed_by_family": by_family}, misses=misses,
                 seconds=time.perf_counter() - start)


def check_triangles_agreement(engine, cases) -> CheckResult:
    """``triangles.agreement``: the engine's ``triangles_intersect(a, b)`` is
    the exact answer (closed triangles, touching counts) on every pair."""
    return _triangle_check("agreement", engine.triangles_intersect, cases,
                           _distance_tolerance(engine))


def check_triangles_reference(engine, cases) -> CheckResult:
    """``triangles.reference``: refsim's own edge-triangle test agrees with
    the rational separating-axis test on the same pairs. It does not call the
    engine (its result is the same for every engine): it checks the ground
    truth every other check of this engine leans on (the mesh-pair answers
    come from refsim's test) with a second, independent exact algorithm, in
    every report."""
    from refsim.collision.triangle import triangles_intersect

    return _triangle_check("reference", triangles_intersect, cases, 0.0)


# -- mesh pairs and bodies ------------------------------------------------------------------


def _call(engine, method: str, case):
    a, b = case.mesh_a, case.mesh_b
    return getattr(engine, method)(a.vertices, a.faces, case.pose_a, b.vertices, b.faces,
                                   case.pose_b)


def _pair_set(pairs) -> set[tuple[int, int]]:
    return {(int(i), int(j)) for i, j in np.asarray(pairs, dtype=np.int64).reshape(-1, 2)}


def _world(case):
    from refsim.types import transform_points

    return (transform_points(case.mesh_a.vertices, case.pose_a),
            transform_points(case.mesh_b.vertices, case.pose_b))


def _classify_face_pairs(case, differing, tolerance: float) -> dict:
    """The most serious class of the face pairs ``differing``, with the gap
    of the pair farthest from touching."""
    world_a, world_b = _world(case)
    fa, fb = case.mesh_a.faces, case.mesh_b.faces
    verdicts = [classify_triangles(world_a[fa[i]], world_b[fb[j]], tolerance)
                for i, j in differing]
    kind = worst_class(v["class"] for v in verdicts)
    widest = max(verdicts, key=lambda v: abs(v["gap_metres"]))
    return {**widest, "class": kind}


def classify_pairs(case, got, tolerance: float = 0.0) -> dict:
    """The class of an engine's face pairs ``got`` that differ from the
    truth, with the largest gap among them (module docstring)."""
    truth, answer = _pair_set(case.truth), _pair_set(got)
    return _classify_face_pairs(case, sorted(truth ^ answer), tolerance)


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


def _surface_gap(case, tolerance: float) -> dict:
    """The class of a false "collide" between surfaces that do not meet, by
    their smallest distance: the triangle distances of the face pairs whose
    boxes are within reach (at most :data:`GAP_PAIRS`, nearest first)."""
    world_a, world_b = _world(case)
    fa, fb = case.mesh_a.faces, case.mesh_b.faces
    boxes = face_box_distances(world_a, fa, world_b, fb)
    order = np.argsort(boxes, axis=None, kind="stable")[:GAP_PAIRS]
    pairs = [np.unravel_index(k, boxes.shape) for k in order]
    gaps = [signed_gap(world_a[fa[i]], world_b[fb[j]], False) for i, j in pairs]
    gap = min(gaps)
    # exact when no pair left out could be nearer: its box is at least as far
    lower_bound = len(order) < boxes.size and float(boxes.flat[order[-1]]) < gap
    if lower_bound:
        gap = float(boxes.flat[order[-1]])
    bound = max(rounding_bound(world_a), rounding_bound(world_b))
    kind = "tolerance" if gap <= max(bound, tolerance) and not lower_bound else "bug"
    return {**_verdict(kind, gap, bound, tolerance), "gap_is_lower_bound": lower_bound}


def classify_collide(case, got: bool, tolerance: float = 0.0) -> dict:
    """The class of an engine's boolean answer that differs from the truth
    (module docstring): a false "apart" takes the most serious class of the
    exact pairs it missed (the deepest gap); a false "collide" is
    "known-divergence" when one body's centroid is inside the other, else
    classed by the surfaces' distance."""
    if len(case.truth) > 0:
        return _classify_face_pairs(case, [tuple(p) for p in np.asarray(case.truth)], tolerance)
    centroid_a = np.asarray(case.pose_a[0]) @ case.mesh_a.vertices.mean(axis=0) + case.pose_a[1]
    centroid_b = np.asarray(case.pose_b[0]) @ case.mesh_b.vertices.mean(axis=0) + case.pose_b[1]
    if (_inside(centroid_b, case.mesh_a, case.pose_a)
            or _inside(centroid_a, case.mesh_b, case.pose_b)):
        return {"class": "known-divergence", "contained": True}
    return _surface_gap(case, tolerance)


def _mesh_check(name: str, engine, cases, agrees, classify, describe) -> CheckResult:
    """The loop of ``pairs.agreement`` and ``collide.agreement``: per case the
    engine's answer (``agrees(case, got)``), a crash, or a classified
    disagreement (``classify(case, got, tolerance)``, ``describe(case, got)``
    the answer's fields)."""
    start = time.perf_counter()
    method = "intersecting_pairs" if name == "pairs" else "bodies_collide"
    tolerance = _distance_tolerance(engine)
    outcomes: list[str | None] = []  # per case: None (passed) or its class
    misses: list[float | None] = []
    found: list[dict] = []
    counts: dict[str, int] = {}        # the answers' *_count fields, summed
    for index, case in enumerate(cases.cases):
        got = attempt(_call, engine, method, case)
        if isinstance(got, Crash):
            outcomes.append("crash")
            misses.append(None)
            _keep(found, got.example(case=index, **case.to_dict()))
            continue
        if agrees(case, got):
            outcomes.append(None)
            misses.append(None)
            continue
        verdict, answer = classify(case, got, tolerance), describe(case, got)
        outcomes.append(verdict["class"])
        misses.append(verdict.get("gap_metres"))
        for key, value in answer.items():
            if key.endswith("_count"):
                counts[key] = counts.get(key, 0) + value
        _keep(found, {"case": index, **verdict, **answer, **case.to_dict()})
    shrunk = None
    if any(outcomes):
        def fails(c):
            return not agrees(c, _call(engine, method, c))

        def classified(c):
            got = _call(engine, method, c)
            return {**classify(c, got, tolerance), **describe(c, got)}

        shrunk = _shrunk(cases, fails, classified, lambda c: c.to_dict())
    return tally(name, "agreement", outcomes, examples=_examples(found, shrunk), misses=misses,
                 measured=counts, seconds=time.perf_counter() - start)


def _pairs_answer(case, got) -> dict:
    """What the engine answered: the face pairs it added and missed (the first
    ten of each) and how many."""
    truth, answer = _pair_set(case.truth), _pair_set(got)
    return {"extra_pairs": sorted(answer - truth)[:10],
            "missing_pairs": sorted(truth - answer)[:10],
            "extra_pair_count": len(answer - truth), "missing_pair_count": len(truth - answer)}


def check_pairs_agreement(engine, cases) -> CheckResult:
    """``pairs.agreement``: the engine's ``intersecting_pairs`` is the exact
    set of intersecting face pairs on every pose (as a set: order and
    duplicates do not matter)."""
    return _mesh_check("pairs", engine, cases,
                       lambda c, got: _pair_set(got) == _pair_set(c.truth),
                       classify_pairs, _pairs_answer)


def check_collide_agreement(engine, cases) -> CheckResult:
    """``collide.agreement``: the engine's ``bodies_collide`` is true exactly
    when some triangle of one surface meets a triangle of the other."""
    return _mesh_check("collide", engine, cases,
                       lambda c, got: bool(got) == (len(c.truth) > 0),
                       lambda c, got, tol: classify_collide(c, bool(got), tol),
                       lambda c, got: {"answer": bool(got)})


# -- boxes ---------------------------------------------------------------------------------


def _box(engine, case):
    lo, hi = engine.aabb(case.vertices, case.pose)
    return (np.asarray(lo, dtype=np.float64).reshape(3),
            np.asarray(hi, dtype=np.float64).reshape(3))


def box_excess(case, lo, hi) -> tuple[np.ndarray, np.ndarray]:
    """Per axis, in metres, how far the engine's box is *inside* the exact
    box (``short``: it misses transformed points) and *outside* it
    (``wide``): exact rationals, then a float (inf for a side that is not
    finite)."""
    short = np.zeros(3)
    wide = np.zeros(3)
    for i in range(3):
        if not (math.isfinite(lo[i]) and math.isfinite(hi[i])):
            short[i] = wide[i] = math.inf
            continue
        d_lo = Fraction(float(lo[i])) - case.exact[0][i]       # > 0: misses points
        d_hi = case.exact[1][i] - Fraction(float(hi[i]))       # > 0: misses points
        short[i] = float(max(d_lo, d_hi, Fraction(0)))
        wide[i] = float(max(-d_lo, -d_hi, Fraction(0)))
    return short, wide


def classify_box(case, lo, hi, side: int, declared) -> dict | None:
    """None when side ``side`` of the box (0: ``short``, the enclosing check;
    1: ``wide``, the tight one) is within the rounding bound on every axis;
    else its class (module docstring) and its excess, in metres and in
    rounding bounds (``declared``: :class:`refsim.engines.Declarations`)."""
    excess = box_excess(case, lo, hi)
    with np.errstate(over="ignore", divide="ignore"):    # a bound of a few subnormals
        ratio = excess[side] / case.bound
    if not (ratio > 1.0).any():
        return None
    axis = int(np.argmax(ratio))
    metres = float(excess[side][axis])
    encloses = not (excess[0] > np.maximum(case.bound, declared.distance_tolerance)).any()
    if metres <= declared.distance_tolerance:
        kind = "tolerance"
    elif side == 1 and encloses and metres <= declared.box_slack:
        kind = "loose"
    else:
        kind = "bug"
    return {"class": kind, "excess_metres": metres,
            "excess_rounding_bounds": float(ratio[axis]), "axis": axis,
            "distance_tolerance_metres": declared.distance_tolerance,
            "box_slack_metres": declared.box_slack}


def _box_check(name: str, engine, cases, side: int) -> CheckResult:
    from refsim.engines import declarations

    start = time.perf_counter()
    declared = declarations(engine)
    outcomes: list[str | None] = []  # per case: None (passed) or its class
    misses: list[float | None] = []
    found: list[dict] = []
    worst, worst_ratio = 0.0, 0.0
    for index, case in enumerate(cases.cases):
        box = attempt(_box, engine, case)
        if isinstance(box, Crash):
            outcomes.append("crash")
            misses.append(None)
            _keep(found, box.example(case=index, **case.to_dict()))
            continue
        lo, hi = box
        verdict = classify_box(case, lo, hi, side, declared)
        if verdict is None:
            outcomes.append(None)
            misses.append(None)
            continue
        worst = max(worst, verdict["excess_metres"])
        worst_ratio = max(worst_ratio, verdict["excess_rounding_bounds"])
        outcomes.append(verdict["class"])
        misses.append(verdict["excess_metres"])
        _keep(found, {"case": index, **verdict, "lo": lo.tolist(), "hi": hi.tolist(),
                      **case.to_dict()})
    shrunk = None
    if any(outcomes):
        def classified(c):
            lo, hi = _box(engine, c)
            return {**(classify_box(c, lo, hi, side, declared) or {}),
                    "lo": lo.tolist(), "hi": hi.tolist()}

        def fails(c):
            lo, hi = _box(engine, c)
            return classify_box(c, lo, hi, side, declared) is not None

        shrunk = _shrunk(cases, fails, classified, lambda c: c.to_dict())
    return tally("aabb", name, outcomes, examples=_examples(found, shrunk), misses=misses,
                 measured={"largest_excess_metres": worst,
                           "largest_excess_rounding_bounds": worst_ratio},
                 seconds=time.perf_counter() - start)


def check_aabb_encloses(engine, cases) -> CheckResult:
    """``aabb.encloses``: the engine's box contains every exactly transformed
    vertex, up to the rounding bound of a float64 evaluation of ``R p + t``
    (each side at most ``bound_i`` inside the exact box)."""
    return _box_check("encloses", engine, cases, 0)


def check_aabb_tight(engine, cases) -> CheckResult:
    """``aabb.tight``: the engine's box is no larger than the exact box by
    more than the same bound (each side at most ``bound_i`` outside it): the
    box of the vertices, not of a padded or coarser shape (a padded box the
    engine declares, ``box_slack``, is "loose")."""
    return _box_check("tight", engine, cases, 1)


__all__ = ["check_triangles_agreement", "check_triangles_reference", "check_pairs_agreement",
           "check_collide_agreement", "check_aabb_encloses", "check_aabb_tight",
           "CheckResult"]
