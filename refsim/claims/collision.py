"""Claims C3 and C4, and the hierarchy's speed against FCL (seed S4).

C3: "the hierarchy trades accuracy for speed; coarse levels are
conservative", judged on :func:`refsim.studies.levels.measure_levels`.
C4: near-parallel edges and planes "did not seem to be a problem", judged on
:func:`refsim.studies.triangles.measure_c4` and
:func:`~refsim.studies.triangles.measure_c4_sweep`.
:func:`speed_findings` reads :func:`refsim.studies.levels.measure_hierarchy_speed`.
"""

from __future__ import annotations

import sys

from refsim.claims.result import ClaimResult, by_timed_parts, comparison
from refsim.studies.levels import HierarchySpeed, LevelsResult
from refsim.studies.triangles import C4Result, C4Sweep

#: A tilt within this many double-precision epsilons is at the rounding of
#: the coordinates (C4: "as large as the tilt").
ROUNDING_TILT = 1e3

#: The C4 configurations whose triangles cross or miss (a transversal answer,
#: decided by the tilt alone), and those that touch along a line (an exact
#: contact); refsim.studies.triangles.C4_CONFIGS defines them.
C4_TRANSVERSAL = ("overlap", "miss")
C4_TOUCHING = ("touch", "shared-edge")

#: Slowest configurations of the exact level that C3's sentence names.
C3_SLOWEST_SHOWN = 2


#: A coarser level's median time over a finer one's: at most this, the
#: coarser level is no slower.
PARITY_TIME = 1.0


def c3(levels: LevelsResult) -> ClaimResult:
    """C3 from the measured levels (``levels.levels``, coarsest first). Its
    two halves: accuracy (no level misses a contact, and false positives do
    not fall from a finer to a coarser level) and speed (median times do not
    fall from a coarser to a finer level: coarser is faster). Confirmed when
    both hold, partly when one does, refuted when neither. The speed half is
    a timing: each coarser/finer time ratio is compared with
    :data:`PARITY_TIME` against the spread of its per-repeat ratios
    (:func:`refsim.claims.result.comparison`); the half is open when a ratio
    lies within it and none is clearly above, and the verdict then
    "undecided" (:func:`refsim.claims.result.by_timed_parts`)."""
    order = tuple(levels.levels)
    summary = {s.level: s for s in levels.summary}
    fp = {lv: summary[lv].false_positive_rate for lv in order}
    median = {lv: summary[lv].median_seconds for lv in order}
    pairs = list(zip(order, order[1:], strict=False))
    fp_ordered = all(fp[a] >= fp[b] for a, b in pairs)
    speed = {f"{a} / {b}": comparison(
        median[a] / median[b], PARITY_TIME,
        [x / y for x, y in zip(summary[a].seconds_by_repeat, summary[b].seconds_by_repeat,
                               strict=True)]) for a, b in pairs}
    sides = [c["side"] for c in speed.values()]
    speed_ordered = all(side in ("below", "at") for side in sides)
    speed_open = not speed_ordered and "above" not in sides
    conservative = levels.false_negatives == 0
    missed = [f"{c.name} ({lv})" for c in levels.configurations for lv in order
              if c.false_negative(lv)]
    missed += [f"{r.model_a} / {r.model_b} random poses ({lv}: {k})"
               for r in levels.random for lv, k in r.false_negatives.items() if k]
    slowest = sorted(levels.configurations, key=lambda c: c.seconds["exact"],
                     reverse=True)[:C3_SLOWEST_SHOWN]
    coarse, box = order[0], order[1]
    return ClaimResult("C3", by_timed_parts((conservative and fp_ordered) + speed_ordered,
                                            speed_open, 2), {
        "levels": list(order),
        "configurations": len(levels.configurations),
        "random_poses": sum(r.n for r in levels.random),
        "false_negatives": levels.false_negatives,
        "conservative": conservative,
        "missed": missed,
        "negative_queries": summary["exact"].negatives,
        "false_positive_rate": fp,
        "false_positives_ordered": fp_ordered,
        "median_seconds": median,
        "speed_ordered": speed_ordered,
        "speed_open": speed_open,
        "speed_against_parity": speed,
        "exact_over_box": median["exact"] / median[box],
        "exact_over_coarsest": median["exact"] / median[coarse],
        "slowest_exact": [{"name": c.name, "kind": c.kind, "seconds": c.seconds["exact"]}
                          for c in slowest],
        "slowest_all_touching": all(c.kind == "touching" for c in slowest),
        "coarsest_only": [c.name for c in levels.configurations
                          if c.answers[coarse] and not c.answers[box]],
        "box_only": [c.name for c in levels.configurations
                     if c.answers[box] and not c.answers[coarse]],
    }, timing=True)


def _largest_wrong(thetas, counts) -> float | None:
    """The largest angle at which any frame's answer was wrong, or None."""
    wrong = [theta for theta, k in zip(thetas, counts, strict=True) if k]
    return max(wrong) if wrong else None


def c4(c4_result: C4Result, sweep: C4Sweep) -> ClaimResult:
    """C4 from the measured flips: the largest angle at which the plain-float
    test (the seed's arithmetic) differs from the exact answer, per kind of
    configuration. Confirmed when the float test is never wrong, crossing
    or touching; partly otherwise (near-parallel planes are a problem, but
    only within the rounding of the coordinates or at exact contacts, which
    the facts tell apart). The claim is never refuted outright: the seed's
    "did not seem to be" is about what one sees, and a wrong answer only at
    some angles is a partial problem."""
    eps = sys.float_info.epsilon
    transversal = {c: _largest_wrong(sweep.thetas, sweep.float_wrong[c]) for c in C4_TRANSVERSAL}
    oracle = ({c: _largest_wrong(sweep.thetas, sweep.oracle_wrong[c]) for c in C4_TRANSVERSAL}
              if sweep.oracle_wrong else {})
    touching = {c: _largest_wrong(sweep.thetas, sweep.float_wrong[c]) for c in C4_TOUCHING}
    worst = [t for t in transversal.values() if t is not None]
    oracle_worst = [t for t in oracle.values() if t is not None]
    touch_worst = [t for t in touching.values() if t is not None]
    largest = max(worst) if worst else None
    verdict = "partly" if worst or any(touching.values()) else "confirmed"
    return ClaimResult("C4", verdict, {
        "frames": sweep.frames,
        "largest_angle": max(sweep.thetas),
        "float_wrong_from": transversal,
        "float_worst": largest,
        "float_worst_over_eps": None if largest is None else largest / eps,
        "at_rounding": largest is not None and largest <= ROUNDING_TILT * eps,
        "oracle_measured": bool(oracle),
        "oracle_wrong_from": oracle,
        "oracle_worst": max(oracle_worst) if oracle_worst else None,
        "touching_wrong_from": touching,
        "touching_worst": max(touch_worst) if touch_worst else None,
        "touching_wrong_at_largest_angle": bool(touch_worst)
                                           and max(touch_worst) >= max(sweep.thetas),
        "axis_aligned_never_wrong": all(s.float_wrong == 0 for s in c4_result.series
                                        if s.frame == "axis-aligned"),
    })


#: refsim's time equal to FCL's: a ratio above it means refsim is slower.
PARITY = 1.0

#: The speed configuration where the bodies are apart but their boxes
#: overlap: all node tests, no exact pair to report.
APART_KIND = "separated-boxes-overlap"


def speed_findings(speed: HierarchySpeed) -> dict:
    """The speed table's findings (timings): refsim's time over FCL's where
    the bodies are apart but their boxes overlap, and where they meet;
    whether refsim is slower than FCL where they are apart, and whether it
    compares best where there are pairs to report. Empty without FCL."""
    apart = [c for c in speed.cases if c.kind == APART_KIND and c.pairs_ratio is not None]
    if not apart:
        return {}
    meet = [c for c in speed.cases if c.kind != APART_KIND and c.pairs_ratio is not None]
    return {
        "apart": [{"model": c.model, "pairs_ratio": c.pairs_ratio,
                   "boolean_ratio": c.boolean_ratio} for c in apart],
        "apart_slower": any(c.pairs_ratio > PARITY for c in apart),
        "meet": [{"model": c.model, "kind": c.kind, "pairs_ratio": c.pairs_ratio}
                 for c in meet],
        "best_with_pairs": bool(meet) and (max(c.pairs_ratio for c in meet)
                                           < min(c.pairs_ratio for c in apart)),
    }
