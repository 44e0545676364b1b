"""Checks of the geometric capabilities: triangles, pairs, collide, aabb.

One function per property, ``check_xxx(engine, cases) -> CheckResult``
(:mod:`refsim.conformance.results`), each comparing the engine's answer
with the exact one on every case and classifying every disagreement by a
length in metres, compared with the rounding bound and with what the engine
declares (:func:`refsim.engines.declarations`):

- triangle pairs (:func:`classify_triangles`): the ground truth first
  confirmed against refsim's own exact test (a wrong truth is a "bug",
  never the engine's fault); then "coplanar" and "touching" by exact
  predicates; otherwise the pair's gap (:mod:`refsim.collision.gaps`:
  distance apart, minus the depth of a crossing) within the rounding bound
  (float64's, scaled by the engine's declared ``unit_roundoff``) or the
  engine's ``distance_tolerance`` is "tolerance", beyond both "bug";
- mesh pairs: each face pair the engine adds or misses is a triangle pair of
  the world triangles (refsim's transform arithmetic, as the truth used),
  classified as above; a case takes its most serious class
  (:func:`refsim.conformance.results.worst_class`) and reports its largest
  gap;
- bodies (``collide``): :func:`refsim.collision.disagreement.classify_bodies`,
  the classifier the studies use too, with the engine's conventions
  (:func:`refsim.engines.body_conventions`): a class and a finer ``reason``
  (a false "apart" by the exact pairs it missed; a false "collide" with one
  body inside the other is "known-divergence" for an engine that tests that
  body as a solid and "bug" for any other, refsim's surfaces not meeting;
  otherwise by the gap between the surfaces, or by the engine's declared
  ``pose_used``);
- boxes: per side, how far the box stands inside the exact one (``aabb.encloses``)
  or outside it (``aabb.tight``), in metres; within the rounding bound of
  :mod:`refsim.conformance.cases_boxes` it passes, within the declared
  ``distance_tolerance`` it is "tolerance", a box that encloses and is wider
  by no more than the declared ``box_slack`` is "loose", beyond is "bug".

An exception on a case is that case's "crash" (its input and the
traceback's last line). Where a check fails, Hypothesis searches the same
families for a case failing in the most serious class the seeded cases met
and shrinks it (:mod:`refsim.conformance.shrink`); it goes first in
``examples``.

Cost: one engine call per case, plus, per failing case, a classification
(O(1) exact predicates and a gap per disagreeing triangle pair), plus one
Hypothesis search per failing check.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from refsim.collision.disagreement import classify_bodies, worst_pair
from refsim.collision.gaps import UNIT_ROUNDOFF
from refsim.conformance.results import CheckResult, Crash, attempt, tally, worst_class
from refsim.conformance.shrink import minimal_failure

#: Seeded failing cases kept in ``examples`` per class (after the shrunk one).
EXAMPLES_PER_CLASS = 2


@dataclass(frozen=True)
class CaseCheck:
    """A check that judges every case of a generated set on its own, so that
    a set may be split into shards run anywhere (:mod:`refsim.conformance.shards`)
    and the result put together from their failures is the one a single run
    gives.

    ``prepare(engine)`` is what the others need of the engine, read once per
    run (the method to call, the declared tolerances); ``ask(prepared,
    case)`` is the engine's answer, read into plain values (an exception
    there is the engine's: class "crash"); ``judge(prepared, case, answer)``
    is None when the answer is right, else the failure's fields: its class,
    the gap or excess, the answer (the case's input and truth are added from
    ``case.to_dict()``). An exception in ``judge`` is the kit's own and stops
    the check (it is not blamed on the engine). ``measure(failures)``
    gives the check's ``measured`` numbers from the failure records alone
    (so that shards' records give the same numbers), and ``miss`` names the
    field holding a failure's length in metres.
    """

    capability: str
    name: str
    prepare: Callable
    ask: Callable
    judge: Callable
    measure: Callable
    miss: str

    @property
    def key(self) -> str:
        return f"{self.capability}.{self.name}"

    def failures(self, engine, items, first: int = 0) -> list[dict]:
        """The failure record of every failing case of ``items`` (cases
        ``first``, ``first + 1``, ...), in case order; a crash is recorded
        with the traceback's last line."""
        prepared = self.prepare(engine)
        found: list[dict] = []
        for index, case in enumerate(items, start=first):
            answer = attempt(self.ask, prepared, case)
            if isinstance(answer, Crash):
                found.append(answer.example(case=index, **case.to_dict()))
                continue
            verdict = self.judge(prepared, case, answer)
            if verdict is not None:
                found.append({"case": index, **verdict, **case.to_dict()})
        return found

    def result(self, engine, cases, failures: list[dict], count: int,
               seconds: float) -> CheckResult:
        """The check's result from every failure of its ``count`` cases (from
        one run or from shards, in case order), with the minimal failing case
        Hypothesis finds when there is a failure."""
        outcomes: list[str | None] = [None] * count
        misses: list[float | None] = [None] * count
        for failure in failures:
            outcomes[failure["case"]] = failure["class"]
            misses[failure["case"]] = failure.get(self.miss)
        shrunk = None
        if failures:
            start = time.perf_counter()
            shrunk = self._shrunk(engine, cases, worst_class(f["class"] for f in failures))
            seconds += time.perf_counter() - start
        return tally(self.capability, self.name, outcomes, examples=_examples(failures, shrunk),
                     measured=self.measure(failures), misses=misses, failures=failures,
                     seconds=seconds)

    def _shrunk(self, engine, cases, target: str) -> dict | None:
        """The minimal case Hypothesis finds in the set's families that fails
        in class ``target`` (the most serious class among the seeded
        failures, so that the shrunk example is one of the classes counted),
        as an example record marked ``"shrunk": true``; None if none is found."""
        prepared = self.prepare(engine)

        def verdict(case):
            answer = attempt(self.ask, prepared, case)
            if isinstance(answer, Crash):
                return answer.example()
            return self.judge(prepared, case, answer)

        def fails(case) -> bool:
            answer = verdict(case)
            return answer is not None and answer["class"] == target

        value = minimal_failure(cases.strategy(), fails, cases.seed)
        answer = None if value is None else verdict(value)
        if answer is None or answer["class"] != target:
            return None
        return {"shrunk": True, **answer, **value.to_dict()}

    def run(self, engine, cases) -> CheckResult:
        """The check on every case of ``cases`` in this process."""
        start = time.perf_counter()
        items = _items(cases)
        failures = self.failures(engine, items)
        return self.result(engine, cases, failures, len(items), time.perf_counter() - start)


def _items(cases) -> tuple:
    """The cases of a generated set (triangle pairs, or poses and boxes)."""
    return cases.pairs if hasattr(cases, "pairs") else cases.cases


def _examples(failures: list[dict], shrunk) -> list[dict]:
    """The shrunk case first, then the first EXAMPLES_PER_CLASS failures of
    each class in case order (every class that occurs gets its examples,
    however rare), by class order."""
    from refsim.conformance.results import CLASSES

    kept: list[dict] = []
    for failure in failures:
        if sum(e["class"] == failure["class"] for e in kept) < EXAMPLES_PER_CLASS:
            kept.append(failure)
    return ([shrunk] if shrunk is not None else []) + sorted(
        kept, key=lambda e: CLASSES.index(e["class"]))


def _roundoff(declared) -> float:
    """The engine's declared unit roundoff (:class:`refsim.engines.Declarations`)
    over float64's: the factor on every rounding bound (1 for a float64
    engine, 2^29 for float32)."""
    return declared.unit_roundoff / UNIT_ROUNDOFF


def _verdict(kind: str, gap: float, bound: float, tolerance: float,
             roundoff: float = 1.0) -> dict:
    """A classified disagreement as example fields, units in the names (the
    engine's unit roundoff too, where it declared one other than float64's)."""
    fields = {"class": kind, "gap_metres": gap, "rounding_bound_metres": bound,
              "distance_tolerance_metres": tolerance}
    if roundoff != 1.0:
        fields["unit_roundoff"] = roundoff * UNIT_ROUNDOFF
    return fields


# -- triangles ---------------------------------------------------------------------------


def classify_triangles(a, b, distance_tolerance: float = 0.0, roundoff: float = 1.0) -> dict:
    """The class of a disagreement on the triangle pair ``(a, b)`` with its
    gap, the rounding bound and the tolerance (module docstring), as
    example fields. ``roundoff``: the engine's declared unit roundoff over
    float64's (:func:`_roundoff`), which scales the rounding bound."""
    from refsim.collision.disagreement import classify_triangle_pair

    verdict = classify_triangle_pair(a, b, distance_tolerance, roundoff)
    return _verdict(verdict.kind, verdict.gap, verdict.bound, distance_tolerance, roundoff)


def _ask_triangles(prepared, pair) -> bool:
    return bool(prepared[0](pair.a, pair.b))


def _judge_triangles(prepared, pair, got: bool) -> dict | None:
    _, tolerance, roundoff = prepared
    if got == pair.truth:
        return None
    return {**classify_triangles(pair.a, pair.b, tolerance, roundoff), "answer": got}


def _by_family(failures: list[dict]) -> dict:
    counts: dict[str, int] = {}
    for failure in failures:
        counts[failure["family"]] = counts.get(failure["family"], 0) + 1
    return {"failed_by_family": counts}


def _engine_triangles(engine):
    from refsim.engines import declarations

    declared = declarations(engine)
    return engine.triangles_intersect, declared.distance_tolerance, _roundoff(declared)


def _refsim_triangles(engine):
    from refsim.collision.triangle import triangles_intersect

    return triangles_intersect, 0.0, 1.0


TRIANGLES_AGREEMENT = CaseCheck("triangles", "agreement", _engine_triangles, _ask_triangles,
                                _judge_triangles, _by_family, "gap_metres")
TRIANGLES_REFERENCE = CaseCheck("triangles", "reference", _refsim_triangles, _ask_triangles,
                                _judge_triangles, _by_family, "gap_metres")


def check_triangles_agreement(engine, cases) -> CheckResult:
    """``triangles.agreement``: the engine's ``triangles_intersect(a, b)`` is
    the exact answer (closed triangles, touching counts) on every pair."""
    return TRIANGLES_AGREEMENT.run(engine, cases)


def check_triangles_reference(engine, cases) -> CheckResult:
    """``triangles.reference``: refsim's own edge-triangle test agrees with
    the rational separating-axis test on the same pairs. It does not call the
    engine (its result is the same for every engine): it checks the ground
    truth every other check of this engine leans on (the mesh-pair answers
    come from refsim's test) with a second, independent exact algorithm, in
    every report."""
    return TRIANGLES_REFERENCE.run(engine, cases)


# -- mesh pairs and bodies ------------------------------------------------------------------


def _call(engine, method: str, case):
    a, b = case.mesh_a, case.mesh_b
    return getattr(engine, method)(a.vertices, a.faces, case.pose_a, b.vertices, b.faces,
                                   case.pose_b)


def _pair_set(pairs) -> set[tuple[int, int]]:
    """Face pairs as a set of ``(i, j)`` (an array, a list, or a set already)."""
    if isinstance(pairs, set):
        return pairs
    return {(int(i), int(j)) for i, j in np.asarray(pairs, dtype=np.int64).reshape(-1, 2)}


def _world(case):
    from refsim.types import transform_points

    return (transform_points(case.mesh_a.vertices, case.pose_a),
            transform_points(case.mesh_b.vertices, case.pose_b))


def _classify_face_pairs(case, differing, tolerance: float, roundoff: float = 1.0) -> dict:
    """The most serious class of the face pairs ``differing``, with the gap
    of the pair farthest from touching."""
    world_a, world_b = _world(case)
    kind, widest = worst_pair(world_a, case.mesh_a.faces, world_b, case.mesh_b.faces, differing,
                              tolerance, roundoff)
    return _verdict(kind, widest.gap, widest.bound, tolerance, roundoff)


def classify_pairs(case, got, tolerance: float = 0.0, roundoff: float = 1.0) -> dict:
    """The class of an engine's face pairs ``got`` that differ from the
    truth, with the largest gap among them (module docstring)."""
    truth, answer = _pair_set(case.truth), _pair_set(got)
    return _classify_face_pairs(case, sorted(truth ^ answer), tolerance, roundoff)


def classify_collide(case, got: bool, tolerance: float = 0.0, solid: bool = False,
                     roundoff: float = 1.0, *, is_solid=None, pose_used=None) -> dict:
    """The class of an engine's boolean answer that differs from the truth,
    with its reason and gap, as example fields: the verdict of
    :func:`refsim.collision.disagreement.classify_bodies` on the case's
    exact pairs (its rules), with the engine's declared ``tolerance``
    (metres), ``solid``, ``roundoff`` (over float64's) and, where it has
    them, its ``is_solid`` and ``pose_used`` methods. A false "collide"
    also gives ``gap_is_lower_bound``, and one body inside the other
    ``contained`` and ``solid_declared`` (whether the engine tests that
    container as a solid)."""
    verdict = classify_bodies(case.mesh_a, case.pose_a, case.mesh_b, case.pose_b, got,
                              exact_pairs=case.truth, distance_tolerance=tolerance,
                              roundoff=roundoff, solid=solid, is_solid=is_solid,
                              pose_used=pose_used)
    fields = {**_verdict(verdict.kind, verdict.gap, verdict.bound, tolerance, roundoff),
              "reason": verdict.reason}
    if len(case.truth) == 0:
        fields["gap_is_lower_bound"] = verdict.gap_is_lower_bound
    if verdict.contained:
        fields.update(contained=True, solid_declared=verdict.solid)
    return fields


def _answer_counts(failures: list[dict]) -> dict:
    """The failures' ``*_count`` fields (pairs added and missed), summed."""
    counts: dict[str, int] = {}
    for failure in failures:
        for key, value in failure.items():
            if key.endswith("_count"):
                counts[key] = counts.get(key, 0) + value
    return counts


def _ask_pairs(prepared, case) -> set:
    return _pair_set(_call(prepared[0], "intersecting_pairs", case))


def _judge_pairs(prepared, case, got: set) -> dict | None:
    _, declared = prepared
    if got == _pair_set(case.truth):
        return None
    return {**classify_pairs(case, got, declared.distance_tolerance, _roundoff(declared)),
            **_pairs_answer(case, got)}


def _ask_collide(prepared, case) -> bool:
    return bool(_call(prepared[0], "bodies_collide", case))


def _judge_collide(prepared, case, got: bool) -> dict | None:
    _, conventions = prepared
    if got == (len(case.truth) > 0):
        return None
    return {**classify_collide(case, got, conventions["distance_tolerance"],
                               conventions["solid"], conventions["roundoff"],
                               is_solid=conventions["is_solid"],
                               pose_used=conventions["pose_used"]),
            "answer": got}


def _pairs_answer(case, got) -> dict:
    """What the engine answered: the face pairs it added and missed (the first
    ten of each) and how many."""
    truth, answer = _pair_set(case.truth), _pair_set(got)
    return {"extra_pairs": sorted(answer - truth)[:10],
            "missing_pairs": sorted(truth - answer)[:10],
            "extra_pair_count": len(answer - truth), "missing_pair_count": len(truth - answer)}


def _with_declarations(engine):
    from refsim.engines import declarations

    return engine, declarations(engine)


PAIRS_AGREEMENT = CaseCheck("pairs", "agreement", _with_declarations, _ask_pairs, _judge_pairs,
                            _answer_counts, "gap_metres")
def _with_conventions(engine):
    from refsim.engines import body_conventions

    return engine, body_conventions(engine)


COLLIDE_AGREEMENT = CaseCheck("collide", "agreement", _with_conventions, _ask_collide,
                              _judge_collide, lambda failures: {}, "gap_metres")


def check_pairs_agreement(engine, cases) -> CheckResult:
    """``pairs.agreement``: the engine's ``intersecting_pairs`` is the exact
    set of intersecting face pairs on every pose (as a set: order and
    duplicates do not matter)."""
    return PAIRS_AGREEMENT.run(engine, cases)


def check_collide_agreement(engine, cases) -> CheckResult:
    """``collide.agreement``: the engine's ``bodies_collide`` is true exactly
    when some triangle of one surface meets a triangle of the other."""
    return COLLIDE_AGREEMENT.run(engine, cases)


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
    engine_bound = case.bound * _roundoff(declared)           # the engine's own rounding
    encloses = not (excess[0] > np.maximum(engine_bound, declared.distance_tolerance)).any()
    if metres <= max(declared.distance_tolerance, float(engine_bound[axis])):
        kind = "tolerance"
    elif side == 1 and encloses and metres <= declared.box_slack:
        kind = "loose"
    else:
        kind = "bug"
    return {"class": kind, "excess_metres": metres,
            "excess_rounding_bounds": float(ratio[axis]), "axis": axis,
            "engine_rounding_bound_metres": float(engine_bound[axis]),
            "distance_tolerance_metres": declared.distance_tolerance,
            "box_slack_metres": declared.box_slack}


def _ask_box(prepared, case):
    return _box(prepared[0], case)


def _box_judge(side: int):
    def judge(prepared, case, box) -> dict | None:
        _, declared = prepared
        lo, hi = box
        verdict = classify_box(case, lo, hi, side, declared)
        return None if verdict is None else {**verdict, "lo": lo.tolist(), "hi": hi.tolist()}
    return judge


def _largest_excess(failures: list[dict]) -> dict:
    return {"largest_excess_metres": max((f.get("excess_metres", 0.0) for f in failures),
                                         default=0.0),
            "largest_excess_rounding_bounds": max(
                (f.get("excess_rounding_bounds", 0.0) for f in failures), default=0.0)}


AABB_ENCLOSES = CaseCheck("aabb", "encloses", _with_declarations, _ask_box, _box_judge(0),
                          _largest_excess, "excess_metres")
AABB_TIGHT = CaseCheck("aabb", "tight", _with_declarations, _ask_box, _box_judge(1),
                       _largest_excess, "excess_metres")


def check_aabb_encloses(engine, cases) -> CheckResult:
    """``aabb.encloses``: the engine's box contains every exactly transformed
    vertex, up to the rounding bound of a float64 evaluation of ``R p + t``
    (each side at most ``bound_i`` inside the exact box)."""
    return AABB_ENCLOSES.run(engine, cases)


def check_aabb_tight(engine, cases) -> CheckResult:
    """``aabb.tight``: the engine's box is no larger than the exact box by
    more than the same bound (each side at most ``bound_i`` outside it): the
    box of the vertices, not of a padded or coarser shape (a padded box the
    engine declares, ``box_slack``, is "loose")."""
    return AABB_TIGHT.run(engine, cases)


#: The checks that judge each case alone, by key: the ones a run may shard.
CASE_CHECKS = {c.key: c for c in (TRIANGLES_REFERENCE, TRIANGLES_AGREEMENT, PAIRS_AGREEMENT,
                                  COLLIDE_AGREEMENT, AABB_ENCLOSES, AABB_TIGHT)}

__all__ = ["check_triangles_agreement", "check_triangles_reference", "check_pairs_agreement",
           "check_collide_agreement", "check_aabb_encloses", "check_aabb_tight",
           "CASE_CHECKS", "CaseCheck", "CheckResult"]
