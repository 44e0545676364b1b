"""Claims C11 and C12, the seed's own "Existing Problems", and the findings
of the bounce studies (S5, S7, S8, S9).

C11: "the body-body response lets slow or same-direction bodies
interpenetrate", judged on :func:`refsim.studies.dynamics.measure_interpenetration`.
C12: "the angular velocity does not damp to rest", judged on
:func:`refsim.studies.dynamics.measure_spin`. The findings read the records
of :mod:`refsim.studies.bounce`: how close the apex ratios come to e^2, which
error series stay at rounding, how refsim's step cost compares with
pybullet's, and when a cube counts as tipping.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from refsim.claims.result import ClaimResult
from refsim.studies import bounce
from refsim.studies.bounce import ApexRow, CostStudy, DropEnergy, ObliqueRow, RestRow, StepCost
from refsim.studies.dynamics import InterpenetrationRow, SpinSeries

#: The C11 cases where bodies meet slowly or moving the same way (the claim's
#: "slow or same-direction"; refsim.studies.dynamics.c11_scene): the chase,
#: the slow head-on approach and the body dropped onto another. "glancing"
#: (an offset pass at 1 m/s) is neither.
C11_CLAIM_CASES = ("chase", "slow", "stack")

#: A frame of overlap is what any discrete detection sees first (the contact
#: is found after the step that made it); the claim is about overlap that
#: persists, so a case counts when its longest run of interpenetrating frames
#: is longer than this.
DETECTION_FRAMES = 1

#: A spin the catalogue reports as the cube tipping (rad/s): a face-down drop
#: starts with none, and rounding alone leaves pybullet's cube below 1e-4.
NOTICEABLE_SPIN = 0.01

#: refsim's step-cost target: at most this many times pybullet's time per
#: step at the largest body count.
STEP_COST_TARGET = 2.0

#: The cube of the bounce studies (refsim.studies.bounce.CUBE).
CUBE = "cube.ac"

#: refsim's accuracy target for the bounce: with rotation off, at the
#: reference step and solver (refsim.studies.bounce.STEP, SOLVER), each apex
#: ratio within this relative error of e^2.
APEX_RATIO_TARGET = 0.005

#: Relative apex-ratio errors at or below this are rounding: the floor below
#: which the bounce study leaves errors out of its fitted orders
#: (refsim.studies.bounce.ROUNDING_ERROR), so that the findings and the fit
#: call the same errors rounding.
ROUNDING_ERROR = bounce.ROUNDING_ERROR

#: The class of each divergence of refsim's seed model or pybullet from the
#: analytic answers (:func:`divergences`), by the divergence's key.
DIVERGENCE_CLASSES = {
    "pybullet-apex": "oracle: contact model",
    "literal-wall-flip": "seed ambiguity, resolved (D1)",
    "lateral-friction": "model difference (seed against pybullet)",
    "pybullet-tips": "oracle: contact model",
}


def c11(rows: Sequence[InterpenetrationRow]) -> ClaimResult:
    """C11 from the measured frames. Confirmed when the seed's response lets
    overlap persist (a run longer than :data:`DETECTION_FRAMES`) in every
    slow or same-direction case measured (:data:`C11_CLAIM_CASES`), partly
    when in some, refuted when in none."""
    seed = {r.case: r for r in rows if r.response == "seed"}
    impulse = {r.case: r for r in rows if r.response == "impulse"}
    persistent = [c for c, r in seed.items() if r.longest_run > DETECTION_FRAMES]
    claim_cases = [c for c in C11_CLAIM_CASES if c in seed]
    hit = [c for c in claim_cases if c in persistent]
    if claim_cases and len(hit) == len(claim_cases):
        verdict = "confirmed"
    elif hit:
        verdict = "partly"
    else:
        verdict = "refuted"
    return ClaimResult("C11", verdict, {
        "seed": {c: {"interpenetrating": r.interpenetrating, "frames": r.frames,
                     "longest_run": r.longest_run} for c, r in seed.items()},
        "impulse": {c: {"interpenetrating": r.interpenetrating, "frames": r.frames,
                        "longest_run": r.longest_run} for c, r in impulse.items()},
        "persistent": persistent,
        "detection_only": [c for c, r in seed.items()
                           if 0 < r.longest_run <= DETECTION_FRAMES],
        "never": [c for c, r in seed.items() if r.longest_run == 0],
        "impulse_persistent": [c for c, r in impulse.items()
                               if r.longest_run > DETECTION_FRAMES],
        "claim_cases": claim_cases,
        "claim_cases_persistent": hit,
    })


def c12(spin: Sequence[SpinSeries]) -> ClaimResult:
    """C12 from the spin runs (models "seed", "impulse" and optionally an
    external engine, "pybullet"). Confirmed when the seed's model is not at
    rest at the end and the corrected one is; partly when neither is;
    refuted when the seed's model comes to rest."""
    by = {s.model: s for s in spin}
    seed, corrected, theirs = by["seed"], by["impulse"], by.get("pybullet")
    if not seed.at_rest and corrected.at_rest:
        verdict = "confirmed"
    elif not seed.at_rest:
        verdict = "partly"
    else:
        verdict = "refuted"
    return ClaimResult("C12", verdict, {
        "seed_final_spin": seed.final_spin,
        "seed_at_rest": seed.at_rest,
        "seed_vertical_spin_start": float(seed.spin_normal[0]),
        "seed_vertical_spin_end": float(seed.spin_normal[-1]),
        "corrected_final_spin": corrected.final_spin,
        "corrected_at_rest": corrected.at_rest,
        "pybullet_final_spin": None if theirs is None else theirs.final_spin,
    })


def _finite(values) -> list[float]:
    return [float(v) for v in values if v is not None and math.isfinite(v)]


def apex_findings(rows: Sequence[ApexRow], target: float = APEX_RATIO_TARGET,
                  rounding: float = ROUNDING_ERROR) -> dict:
    """The apex table's findings: the largest error from e^2 with rotation
    off (at ``rounding``? within the apex-ratio ``target``?), of the seed's
    literal wall speed, of the cube face down; the cube with the seed's
    rotation (its spin, its error, how often above e^2); and whether
    pybullet's cube tips (a spin above :data:`NOTICEABLE_SPIN`)."""
    found: dict = {"target": target, "rounding": rounding}
    off = [r for r in rows if r.rotation == "off"]
    if off:
        worst = max(r.refsim_error for r in off)
        literal = max(r.seed_speed_error for r in off)
        found |= {"off_worst": worst, "off_at_rounding": worst <= rounding,
                  "off_within_target": worst <= target, "literal_worst": literal,
                  "literal_within_target": literal <= target}
    cubes_off = [r for r in off if r.body == CUBE]
    if cubes_off:
        found["cube_off_worst"] = max(r.refsim_error for r in cubes_off)
    seeded = [r for r in rows if r.body == CUBE and r.rotation == "seed"]
    if seeded:
        found |= {"seeded_drops": len(seeded),
                  "seeded_above_e2": sum(r.refsim_ratio > r.analytic_ratio for r in seeded),
                  "seeded_max_spin": max(r.refsim_max_spin for r in seeded),
                  "seeded_worst": max(r.refsim_error for r in seeded)}
    cube_spins = _finite(r.pybullet_max_spin for r in rows if r.body == CUBE)
    if cube_spins:
        found |= {"pybullet_cube_spin": max(cube_spins),
                  "pybullet_cube_tips": max(cube_spins) > NOTICEABLE_SPIN,
                  "noticeable_spin": NOTICEABLE_SPIN}
    return found


def tipping_spin(rows: Sequence[ApexRow]) -> float | None:
    """The largest spin of pybullet's cube over the drops where it tips
    (above :data:`NOTICEABLE_SPIN`), or None when it never does."""
    spins = [r.pybullet_max_spin for r in rows if r.body.startswith("cube")
             and r.pybullet_max_spin and r.pybullet_max_spin > NOTICEABLE_SPIN]
    return max(spins) if spins else None


def rounding_series(cost: CostStudy, rounding: float = ROUNDING_ERROR) -> list[str]:
    """The series of the error-against-cost chart whose errors stay at or
    below ``rounding`` at every step size (finite errors only)."""
    return [solver for solver in dict.fromkeys(p.solver for p in cost.points)
            if all(p.error <= rounding for p in cost.points
                   if p.solver == solver and math.isfinite(p.error))]


def step_cost_findings(rows: Sequence[StepCost]) -> dict:
    """The step-cost table's findings (timings), over the rows timed after
    the shortest warm-up: the rows of the fewest bodies (refsim's and
    pybullet's time per step) and the largest stage of refsim's step in the
    first of them that was timed by stage (its share of the step); the rows
    timed after a longer warm-up (the cubes settled); refsim / pybullet by
    body count, whether the mean ratio falls as bodies are added (None when
    fewer than two counts or a ratio is not finite), and at the largest body
    count whether each ratio is within :data:`STEP_COST_TARGET`."""
    early = [r for r in rows if r.warmup == min(x.warmup for x in rows)]
    counts = sorted(dict.fromkeys(r.bodies for r in early))
    ratios = {c: [r.ratio for r in early if r.bodies == c] for c in counts}
    means = [float(np.mean(ratios[c])) for c in counts]
    falling = None
    if len(means) > 1 and all(math.isfinite(m) for m in means):
        falling = all(b < a for a, b in zip(means, means[1:], strict=False))
    biggest = max(r.bodies for r in rows)
    single = [r for r in early if r.bodies == min(x.bodies for x in early)]
    largest_stage = None
    for r in single:
        stages = r.refsim_stage_seconds
        if stages:
            top = max(stages, key=stages.__getitem__)
            largest_stage = {"rotation": r.rotation, "stage": top,
                             "fraction": stages[top] / r.refsim_seconds}
            break
    late = [r for r in rows if r.warmup > min(x.warmup for x in rows)]
    return {
        "single": [{"bodies": r.bodies, "rotation": r.rotation,
                    "refsim_seconds": r.refsim_seconds, "pybullet_seconds": r.pybullet_seconds}
                   for r in single],
        "largest_stage": largest_stage,
        "settled": [{"warmup": r.warmup, "refsim_seconds": r.refsim_seconds,
                     "pybullet_seconds": r.pybullet_seconds} for r in late],
        "ratios": ratios,
        "ratio_falls": falling,
        "target": STEP_COST_TARGET,
        "largest_bodies": biggest,
        "at_largest": [{"rotation": r.rotation, "warmup": r.warmup, "ratio": r.ratio,
                        "within_target": r.ratio <= STEP_COST_TARGET}
                       for r in rows if r.bodies == biggest],
    }


def _max_gap(a, b) -> float:
    """Largest |a - b| over the pairs where both are finite (nan if none)."""
    gaps = _finite(abs(x - y) for x, y in zip(a, b, strict=False)
                   if x is not None and y is not None)
    return max(gaps) if gaps else math.nan


def height_gaps(series: DropEnergy, rows: Sequence[ApexRow]) -> dict:
    """The heights chart's findings: the largest height difference (m) of
    refsim and of pybullet from the analytic curve and, from the apex row of
    the same drop with rotation off, the largest difference of their apex
    times from the analytic ones (ms) over the bounces measured."""
    found: dict = {"refsim_height": _max_gap(series.refsim_height, series.analytic_height),
                   "pybullet_height": _max_gap(series.pybullet_height, series.analytic_height)}
    row = next((r for r in rows if r.body == series.body and r.e == series.e
                and r.rotation == "off"), None)
    if row is not None:
        found |= {"bounces": len(row.analytic_times) - 1,
                  "refsim_apex_ms": 1e3 * _max_gap(row.refsim_times, row.analytic_times),
                  "pybullet_apex_ms": 1e3 * _max_gap(row.pybullet_times, row.analytic_times)}
    return found


def rest_findings(rows: Sequence[RestRow]) -> list[dict]:
    """The time-to-rest table's findings, one per row: the bounce after which
    each engine settles, refsim's settling time less the analytic one (ms)
    and, when pybullet settles, its bounces after (+) or before (-) the
    analytic bounce."""
    found = []
    for r in rows:
        item = {"e": r.e, "analytic_bounces": r.analytic_bounces,
                "refsim_bounces": r.refsim_bounces,
                "refsim_offset_ms": 1e3 * (r.refsim_settle - r.analytic_settle)}
        if r.pybullet_bounces:
            item |= {"pybullet_bounces": r.pybullet_bounces,
                     "pybullet_bounces_late": r.pybullet_bounces - r.analytic_bounces}
        found.append(item)
    return found


def agreement_findings(apex: Sequence[ApexRow], oblique: Sequence[ObliqueRow]) -> dict:
    """The summary's agreement figures: over the drops with rotation off, the
    largest apex-ratio error of refsim (against :data:`APEX_RATIO_TARGET`) and
    of pybullet; over the spheres' oblique bounces pybullet measured, its
    largest relative difference from Coulomb's lateral speed for a ball."""
    found: dict = {"target": APEX_RATIO_TARGET, "step": bounce.STEP}
    off = [r for r in apex if r.rotation == "off"]
    if off:
        found |= {"restitutions": list(dict.fromkeys(r.e for r in off)),
                  "refsim_worst": max(r.refsim_error for r in off), "drops": len(off)}
        measured = [r for r in off if r.pybullet_error is not None]
        if measured:
            found |= {"pybullet_worst": max(r.pybullet_error for r in measured),
                      "pybullet_drops": len(measured)}
    sliding = [r for r in oblique if r.body.startswith("sphere") and r.pybullet is not None]
    if sliding:
        found |= {"coulomb_worst": max(abs(r.pybullet - r.coulomb_ball) / r.coulomb_ball
                                       for r in sliding),
                  "coulomb_bounces": len(sliding)}
    return found


def divergences(apex: Sequence[ApexRow], oblique: Sequence[ObliqueRow]) -> list[dict]:
    """Where pybullet or the seed's literal words part from the analytic
    answers, each with its key, its class (:data:`DIVERGENCE_CLASSES`) and
    its figures: pybullet's worst apex ratio (rotation off), the seed's
    literal wall flip's worst, the spheres' lateral speed after an oblique
    bounce, and pybullet's cube tipping (:func:`tipping_spin`)."""
    found = []

    def add(key: str, **facts) -> None:
        found.append({"key": key, "class": DIVERGENCE_CLASSES[key], **facts})

    rounds = [r for r in apex if r.rotation == "off" and r.pybullet_error is not None]
    if rounds:
        worst = max(rounds, key=lambda r: abs(r.pybullet_error))
        add("pybullet-apex", body=worst.body, e=worst.e, pybullet_error=worst.pybullet_error,
            refsim_error=worst.refsim_error)
    literal = [r for r in apex if r.seed_speed_error is not None and r.rotation == "off"]
    if literal:
        worst = max(literal, key=lambda r: abs(r.seed_speed_error))
        add("literal-wall-flip", body=worst.body, e=worst.e,
            seed_speed_error=worst.seed_speed_error)
    slides = [r for r in oblique if r.body.startswith("sphere") and r.pybullet is not None]
    if slides:
        add("lateral-friction", bounces=[{"v_t": r.v_t, "refsim": r.refsim,
                                          "pybullet": r.pybullet, "coulomb": r.coulomb_ball}
                                         for r in slides])
    spin = tipping_spin(apex)
    if spin is not None:
        add("pybullet-tips", spin=spin)
    return found
