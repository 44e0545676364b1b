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
from refsim.studies.bounce import ApexRow, CostStudy, StepCost
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


def apex_findings(rows: Sequence[ApexRow], target: float, rounding: float) -> dict:
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


def rounding_series(cost: CostStudy, rounding: float) -> list[str]:
    """The series of the error-against-cost chart whose errors stay at or
    below ``rounding`` at every step size (finite errors only)."""
    return [solver for solver in dict.fromkeys(p.solver for p in cost.points)
            if all(p.error <= rounding for p in cost.points
                   if p.solver == solver and math.isfinite(p.error))]


def step_cost_findings(rows: Sequence[StepCost]) -> dict:
    """The step-cost table's findings (timings), over the rows timed after
    the shortest warm-up: refsim / pybullet by body count, whether the mean
    ratio falls as bodies are added (None when fewer than two counts or a
    ratio is not finite), and at the largest body count whether each ratio
    is within :data:`STEP_COST_TARGET`."""
    early = [r for r in rows if r.warmup == min(x.warmup for x in rows)]
    counts = sorted(dict.fromkeys(r.bodies for r in early))
    ratios = {c: [r.ratio for r in early if r.bodies == c] for c in counts}
    means = [float(np.mean(ratios[c])) for c in counts]
    falling = None
    if len(means) > 1 and all(math.isfinite(m) for m in means):
        falling = all(b < a for a, b in zip(means, means[1:], strict=False))
    biggest = max(r.bodies for r in rows)
    return {
        "ratios": ratios,
        "ratio_falls": falling,
        "target": STEP_COST_TARGET,
        "largest_bodies": biggest,
        "at_largest": [{"rotation": r.rotation, "warmup": r.warmup, "ratio": r.ratio,
                        "within_target": r.ratio <= STEP_COST_TARGET}
                       for r in rows if r.bodies == biggest],
    }
