"""Claims C11 and C12, the seed's own "Existing Problems", and the findings
of the bounce studies (S5, S7, S8, S9).

C11: "the body-body response lets slow or same-direction bodies
interpenetrate", judged on :func:`refsim.studies.dynamics.measure_interpenetration`.
C12: "the angular velocity does not damp to rest", judged on
:func:`refsim.studies.dynamics.measure_spin`. The findings read the records
of :mod:`refsim.studies.bounce` (long-form: one row per case and engine):
how close the apex ratios come to e^2, which error series stay at rounding,
how refsim's step cost compares with the oracle's (:data:`ORACLE`), and when
a cube counts as tipping.
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

#: The engine the bounce findings set beside refsim: the records hold any
#: engine's rows under its name; the findings and divergences speak of this one.
ORACLE = "pybullet"

#: The cube of the bounce studies (refsim.studies.bounce_scenes.CUBE).
CUBE = "cube.ac"

#: refsim's accuracy target for the bounce: with rotation off, at the
#: reference step and solver (refsim.studies.bounce_scenes.STEP, SOLVER), each apex
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
    """C12 from the spin runs: refsim's (engine "refsim", models "seed" and
    "impulse") and optionally the oracle's (:data:`ORACLE`). Confirmed when
    the seed's model is not at rest at the end and the corrected one is;
    partly when neither is; refuted when the seed's model comes to rest."""
    ours = {s.model: s for s in spin if s.engine == bounce.REFSIM}
    if not {"seed", "impulse"} <= set(ours):
        raise ValueError(f"C12 needs refsim's seed and impulse spin series; the runs hold "
                         f"{sorted({(s.engine, s.model) for s in spin})}")
    seed, corrected = ours["seed"], ours["impulse"]
    theirs = next((s for s in spin if s.engine == ORACLE), None)
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


def _of(rows, engine: str) -> list:
    return [r for r in rows if r.engine == engine]


def apex_findings(rows: Sequence[ApexRow], target: float = APEX_RATIO_TARGET,
                  rounding: float = ROUNDING_ERROR) -> dict:
    """The apex table's findings: refsim's largest error from e^2 with
    rotation off (at ``rounding``? within the apex-ratio ``target``?), that
    of the seed's literal wall speed, of the cube face down; the cube with
    the seed's rotation (its spin, its error, how often above e^2); and
    whether the oracle's cube tips (a spin above :data:`NOTICEABLE_SPIN`)."""
    found: dict = {"target": target, "rounding": rounding}
    ours = _of(rows, bounce.REFSIM)
    off = [r for r in ours if r.rotation == "off"]
    if off:
        worst = max(r.error for r in off)
        found |= {"off_worst": worst, "off_at_rounding": worst <= rounding,
                  "off_within_target": worst <= target}
    literal = [r.error for r in _of(rows, bounce.SEED_WALL_SPEED) if r.rotation == "off"]
    if literal:
        found |= {"literal_worst": max(literal), "literal_within_target": max(literal) <= target}
    cubes_off = [r for r in off if r.body == CUBE]
    if cubes_off:
        found["cube_off_worst"] = max(r.error for r in cubes_off)
    # the cube's drops with the seed's rotation, refsim's row beside the analytic one
    seeded = [(d[bounce.REFSIM], d[bounce.ANALYTIC])
              for d in bounce.by_case(rows, bounce.APEX_CASE).values()
              if bounce.REFSIM in d and bounce.ANALYTIC in d
              and d[bounce.REFSIM].body == CUBE and d[bounce.REFSIM].rotation == "seed"]
    if seeded:
        found |= {"seeded_drops": len(seeded),
                  "seeded_above_e2": sum(r.ratio > closed.ratio for r, closed in seeded),
                  "seeded_max_spin": max(r.max_spin for r, _ in seeded),
                  "seeded_worst": max(r.error for r, _ in seeded)}
    cube_spins = _finite(r.max_spin for r in _of(rows, ORACLE) if r.body == CUBE)
    if cube_spins:
        found |= {"pybullet_cube_spin": max(cube_spins),
                  "pybullet_cube_tips": max(cube_spins) > NOTICEABLE_SPIN,
                  "noticeable_spin": NOTICEABLE_SPIN}
    return found


def tipping_spin(rows: Sequence[ApexRow]) -> float | None:
    """The largest spin of the oracle's cube over the drops where it tips
    (above :data:`NOTICEABLE_SPIN`), or None when it never does."""
    spins = [r.max_spin for r in _of(rows, ORACLE) if r.body.startswith("cube")
             and r.max_spin > NOTICEABLE_SPIN]
    return max(spins) if spins else None


def rounding_series(cost: CostStudy, rounding: float = ROUNDING_ERROR) -> list[str]:
    """The series of the error-against-cost chart whose errors stay at or
    below ``rounding`` at every step size (finite errors only)."""
    return [solver for solver in dict.fromkeys(p.solver for p in cost.points)
            if all(p.error <= rounding for p in cost.points
                   if p.solver == solver and math.isfinite(p.error))]


def step_cost_pairs(rows: Sequence[StepCost]) -> list[dict]:
    """refsim's time per step beside the oracle's for each timed scene
    (refsim's order): the scene (:data:`refsim.studies.bounce.STEP_CASE`),
    ``refsim_seconds``, ``pybullet_seconds`` (nan when the oracle did not
    run), ``ratio`` (refsim / oracle) and refsim's ``stage_seconds``."""
    pairs = []
    for case, by_engine in bounce.by_case(rows, bounce.STEP_CASE).items():
        ours = by_engine.get(bounce.REFSIM)
        if ours is None:
            continue
        theirs = by_engine[ORACLE].seconds if ORACLE in by_engine else math.nan
        pairs.append({**dict(zip(bounce.STEP_CASE, case, strict=True)),
                      "refsim_seconds": ours.seconds, "pybullet_seconds": theirs,
                      "ratio": ours.seconds / theirs, "stage_seconds": ours.stage_seconds})
    return pairs


def step_cost_findings(rows: Sequence[StepCost]) -> dict:
    """The step-cost table's findings (timings), over the scenes timed after
    the shortest warm-up (:func:`step_cost_pairs`): the scenes of the fewest
    bodies (refsim's and the oracle's time per step) and the largest stage
    of refsim's step in the first of them that was timed by stage (its share
    of the step); the scenes timed after a longer warm-up (the cubes
    settled); refsim / oracle by body count, whether the mean ratio falls as
    bodies are added (None when fewer than two counts or a ratio is not
    finite), and at the largest body count whether each ratio is within
    :data:`STEP_COST_TARGET`."""
    pairs = step_cost_pairs(rows)
    first = min(p["warmup"] for p in pairs)
    early = [p for p in pairs if p["warmup"] == first]
    counts = sorted(dict.fromkeys(p["bodies"] for p in early))
    ratios = {c: [p["ratio"] for p in early if p["bodies"] == c] for c in counts}
    means = [float(np.mean(ratios[c])) for c in counts]
    falling = None
    if len(means) > 1 and all(math.isfinite(m) for m in means):
        falling = all(b < a for a, b in zip(means, means[1:], strict=False))
    biggest = max(p["bodies"] for p in pairs)
    single = [p for p in early if p["bodies"] == min(counts)]
    largest_stage = None
    for p in single:
        stages = p["stage_seconds"]
        if stages:
            top = max(stages, key=stages.__getitem__)
            largest_stage = {"rotation": p["rotation"], "stage": top,
                             "fraction": stages[top] / p["refsim_seconds"]}
            break
    return {
        "single": [{"bodies": p["bodies"], "rotation": p["rotation"],
                    "refsim_seconds": p["refsim_seconds"],
                    "pybullet_seconds": p["pybullet_seconds"]} for p in single],
        "largest_stage": largest_stage,
        "settled": [{"warmup": p["warmup"], "refsim_seconds": p["refsim_seconds"],
                     "pybullet_seconds": p["pybullet_seconds"]}
                    for p in pairs if p["warmup"] > first],
        "ratios": ratios,
        "ratio_falls": falling,
        "target": STEP_COST_TARGET,
        "largest_bodies": biggest,
        "at_largest": [{"rotation": p["rotation"], "warmup": p["warmup"], "ratio": p["ratio"],
                        "within_target": p["ratio"] <= STEP_COST_TARGET}
                       for p in pairs if p["bodies"] == biggest],
    }


def _max_gap(a, b) -> float:
    """Largest |a - b| over the pairs where both are finite (nan if none)."""
    gaps = _finite(abs(x - y) for x, y in zip(a, b, strict=False)
                   if x is not None and y is not None)
    return max(gaps) if gaps else math.nan


def height_gaps(series: Sequence[DropEnergy], rows: Sequence[ApexRow]) -> dict:
    """The heights chart's findings: the largest height difference (m) of
    refsim and of the oracle from the analytic curve (nan for an engine that
    did not run) and, from the apex rows of the same drop with rotation off,
    the largest difference of their apex times from the analytic ones (ms)
    over the bounces measured."""
    curves = {s.engine: s for s in series}
    closed = curves[bounce.ANALYTIC]

    def height_gap(engine):
        return _max_gap(curves[engine].height, closed.height) if engine in curves else math.nan

    found: dict = {"refsim_height": height_gap(bounce.REFSIM),
                   "pybullet_height": height_gap(ORACLE)}
    drop = next((d for d in bounce.by_case(rows, bounce.APEX_CASE).values()
                 if bounce.ANALYTIC in d and d[bounce.ANALYTIC].body == closed.body
                 and d[bounce.ANALYTIC].e == closed.e
                 and d[bounce.ANALYTIC].rotation == "off"), None)
    if drop is not None:
        times = drop[bounce.ANALYTIC].times

        def apex_gap(engine):
            return 1e3 * _max_gap(drop[engine].times, times) if engine in drop else math.nan

        found |= {"bounces": len(times) - 1, "refsim_apex_ms": apex_gap(bounce.REFSIM),
                  "pybullet_apex_ms": apex_gap(ORACLE)}
    return found


def rest_findings(rows: Sequence[RestRow]) -> list[dict]:
    """The time-to-rest table's findings, one per drop: the bounce after
    which each engine settles, refsim's settling time less the analytic one
    (ms; when refsim ran) and, when the oracle settles, its bounces after
    (+) or before (-) the analytic bounce."""
    found = []
    for drop in bounce.by_case(rows, bounce.REST_CASE).values():
        closed, ours = drop[bounce.ANALYTIC], drop.get(bounce.REFSIM)
        item = {"e": closed.e, "analytic_bounces": closed.bounces}
        if ours is not None:
            item |= {"refsim_bounces": ours.bounces,
                     "refsim_offset_ms": 1e3 * (ours.settle - closed.settle)}
        theirs = drop.get(ORACLE)
        if theirs is not None and theirs.bounces:
            item |= {"pybullet_bounces": theirs.bounces,
                     "pybullet_bounces_late": theirs.bounces - closed.bounces}
        found.append(item)
    return found


def agreement_findings(apex: Sequence[ApexRow], oblique: Sequence[ObliqueRow]) -> dict:
    """The summary's agreement figures: over the drops with rotation off, the
    largest apex-ratio error of refsim (against :data:`APEX_RATIO_TARGET`) and
    of the oracle; over the spheres' oblique bounces the oracle ran, its
    largest relative difference from Coulomb's lateral speed for a ball."""
    found: dict = {"target": APEX_RATIO_TARGET, "step": bounce.STEP}
    off = [r for r in _of(apex, bounce.REFSIM) if r.rotation == "off"]
    if off:
        found |= {"restitutions": list(dict.fromkeys(r.e for r in off)),
                  "refsim_worst": max(r.error for r in off), "drops": len(off)}
    measured = [r for r in _of(apex, ORACLE) if r.rotation == "off"]
    if measured:
        found |= {"pybullet_worst": max(r.error for r in measured),
                  "pybullet_drops": len(measured)}
    sliding = [r for r in _of(oblique, ORACLE) if r.body.startswith("sphere")]
    if sliding:
        found |= {"coulomb_worst": max(abs(r.lateral - r.coulomb_ball) / r.coulomb_ball
                                       for r in sliding),
                  "coulomb_bounces": len(sliding)}
    return found


def divergences(apex: Sequence[ApexRow], oblique: Sequence[ObliqueRow]) -> list[dict]:
    """Where the oracle or the seed's literal words part from the analytic
    answers, each with its key, its class (:data:`DIVERGENCE_CLASSES`) and
    its figures: the oracle's worst apex ratio (rotation off, beside
    refsim's error on the same drop), the seed's literal wall flip's worst,
    the spheres' lateral speed after an oblique bounce, and the oracle's
    cube tipping (:func:`tipping_spin`)."""
    found = []

    def add(key: str, **facts) -> None:
        found.append({"key": key, "class": DIVERGENCE_CLASSES[key], **facts})

    drops = bounce.by_case(apex, bounce.APEX_CASE)
    rounds = [d for d in drops.values() if ORACLE in d and d[ORACLE].rotation == "off"]
    if rounds:
        worst = max(rounds, key=lambda d: abs(d[ORACLE].error))
        ours = worst.get(bounce.REFSIM)
        add("pybullet-apex", body=worst[ORACLE].body, e=worst[ORACLE].e,
            pybullet_error=worst[ORACLE].error,
            refsim_error=math.nan if ours is None else ours.error)
    literal = [r for r in _of(apex, bounce.SEED_WALL_SPEED) if r.rotation == "off"]
    if literal:
        worst_row = max(literal, key=lambda r: abs(r.error))
        add("literal-wall-flip", body=worst_row.body, e=worst_row.e,
            seed_speed_error=worst_row.error)
    bounces = bounce.by_case(oblique, bounce.OBLIQUE_CASE)
    slides = [b for b in bounces.values() if ORACLE in b and b[ORACLE].body.startswith("sphere")]
    if slides:
        add("lateral-friction", bounces=[
            {"v_t": b[ORACLE].v_t,
             "refsim": b[bounce.REFSIM].lateral if bounce.REFSIM in b else math.nan,
             "pybullet": b[ORACLE].lateral, "coulomb": b[ORACLE].coulomb_ball}
            for b in slides])
    spin = tipping_spin(apex)
    if spin is not None:
        add("pybullet-tips", spin=spin)
    return found
