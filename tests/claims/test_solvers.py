"""C5..C10 and the solvers' oracle agreement (refsim.claims.solvers) at the
edges of their thresholds.

Every tolerance is met exactly once (the value on the threshold counts as
inside, as the claims' "<=" says) and missed once by a hair.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from refsim.claims.solvers import (
    ALIKE_RTOL,
    COST_TIE_RTOL,
    DRAG_EXTRA_COST_RATIO,
    DRAG_SIGNIFICANT_FRACTION,
    FORMULA_AGREE_RTOL,
    JITTER_FACTOR,
    JITTER_QUOTED_STEP,
    ORDER_MATCH_TOL,
    STABILITY_AGREE_RTOL,
    VISIBLE_FRACTION,
    c5,
    c6,
    c7,
    c8,
    c9,
    c10,
    oracle_agreement,
)
from refsim.studies.particles import DragComparison, FrameStepDifference, Jitter, SolverChoice
from refsim.studies.solvers import Convergence, OscillatorEnergy, StabilityLimit

METHODS = ("euler", "averaged-euler", "backwards-euler", "midpoint", "rk4")
HAIR = 1 + 1e-9        # a factor that moves a value just past a threshold


def drag(difference, cost_ratio, cost_ratios=()) -> DragComparison:
    return DragComparison(terminal_speed=10.0, k_linear=0.981, k_quadratic=0.0981,
                          same_terminal_difference=difference, same_terminal_distance=10.0,
                          same_k_difference=7.0, cost_ratio=cost_ratio,
                          cost_ratios=cost_ratios)


ON_EDGE = DRAG_SIGNIFICANT_FRACTION * 10.0       # the largest insignificant difference


@pytest.mark.parametrize(("difference", "cost_ratio", "verdict"), [
    (ON_EDGE, DRAG_EXTRA_COST_RATIO * HAIR, "confirmed"),
    (ON_EDGE * HAIR, DRAG_EXTRA_COST_RATIO * HAIR, "partly"),
    (ON_EDGE, DRAG_EXTRA_COST_RATIO, "partly"),
    (ON_EDGE * HAIR, DRAG_EXTRA_COST_RATIO, "refuted"),
])
def test_c5_verdict_at_its_thresholds(difference, cost_ratio, verdict):
    result = c5(drag(difference, cost_ratio))
    assert result.verdict == verdict and result.timing
    assert result.facts["significant"] is (difference > ON_EDGE)
    assert result.facts["cost_ratio"] == cost_ratio


@pytest.mark.parametrize(("cost_ratio", "repeats", "verdict", "side"), [
    # 1.25 against repeats spread over 0.1: within the spread of 1.2
    (1.25, (1.1, 1.15, 1.25, 1.25, 1.3), "undecided", "within spread"),
    # the same ratio with repeats that agree to 0.02: an extra cost
    (1.25, (1.23, 1.24, 1.25, 1.26, 1.27), "confirmed", "above"),
    # 1.0 against the same spread of 0.1: clearly no extra cost
    (1.0, (0.9, 0.95, 1.0, 1.05, 1.1), "partly", "below"),
])
def test_c5_cost_is_undecided_within_the_run_to_run_spread(cost_ratio, repeats, verdict,
                                                           side):
    result = c5(drag(ON_EDGE, cost_ratio, repeats))
    assert result.verdict == verdict
    assert result.facts["cost_against_threshold"]["side"] == side


def jitter(method, h, gh2, drag=0.0) -> Jitter:
    return Jitter(method=method, h=h, restitution=0.8, drag=drag,
                  max_height=gh2 * 9.81 * h * h, max_height_gh2=gh2, rms_velocity=0.1,
                  bounces_per_second=50.0)


def jitter_table(euler_gh2, others=0.39, steps=(1 / 30, JITTER_QUOTED_STEP), drag=0.0,
                 euler_at=None):
    """One row per (method, step); Euler's hop / (g h^2) is ``euler_gh2``
    (or ``euler_at[h]``), the others' ``others`` (backwards-euler's 0)."""
    rows = []
    for m in METHODS:
        for h in steps:
            gh2 = ((euler_at or {}).get(h, euler_gh2) if m == "euler"
                   else 0.0 if m == "backwards-euler" else others)
            rows.append(jitter(m, h, gh2, drag))
    return rows


@pytest.mark.parametrize(("euler", "verdict"), [
    (JITTER_FACTOR * 0.39, "refuted"),           # exactly the factor: not "clearly more"
    (JITTER_FACTOR * 0.39 * HAIR, "confirmed"),
])
def test_c6_verdict_at_its_factor(euler, verdict):
    result = c6(jitter_table(euler), jitter_table(euler, drag=1.0))
    assert result.verdict == verdict
    assert result.facts["others_hop_gh2"] == {"averaged-euler": 0.39, "backwards-euler": 0.0,
                                              "midpoint": 0.39, "rk4": 0.39}
    assert result.facts["damped_drag"] == 1.0


@pytest.mark.parametrize(("coarse", "scales"), [
    (20.0, True),                   # hop / (g h^2) 20 and 18: exactly 10% apart, relative
    (20.0 * HAIR, False),
])
def test_c6_h2_scaling(coarse, scales):
    table = jitter_table(18.0, euler_at={1 / 30: coarse})
    facts = c6(table, jitter_table(18.0, drag=1.0)).facts
    assert facts["scaling_measured"] is True
    assert facts["scales_as_h2"] is scales
    assert facts["euler_hop_gh2_by_step"] == [coarse, 18.0]


def test_c6_one_step_does_not_measure_scaling():
    table = jitter_table(17.0, steps=(JITTER_QUOTED_STEP,))
    facts = c6(table, table).facts
    assert facts["scaling_measured"] is False and facts["scales_as_h2"] is False


def convergence(method, problem, order) -> Convergence:
    h = np.array([0.1, 0.05])
    return Convergence(method, problem, h, h**order, np.array([10, 20]),
                       np.array([True, True]), order)


def orders(by_method: dict[str, float], problems=("decay", "oscillator")) -> dict:
    return {(p, m): convergence(m, p, o) for p in problems for m, o in by_method.items()}


def limits(drag_by_method, oscillator=2.0) -> list[StabilityLimit]:
    return [StabilityLimit(m, d, d, oscillator, oscillator) for m, d in drag_by_method.items()]


FOUR_ORDERS = {"euler": 1.0, "averaged-euler": 2.0, "backwards-euler": 2.0, "midpoint": 2.0,
               "rk4": 2.0}
FOUR_DRAG = dict.fromkeys(METHODS, 2.0)
POLYNOMIALS = {m: (1, 1) for m in METHODS}


@pytest.mark.parametrize(("changes", "verdict"), [
    ({}, "confirmed"),
    # rk4's order ORDER_MATCH_TOL away: still alike
    ({"order": 2.0 + ORDER_MATCH_TOL}, "confirmed"),
    ({"order": 2.0 + ORDER_MATCH_TOL * 1.001}, "partly"),
    # rk4's drag limit 10% lower: alike; just more: not (stability differs)
    ({"drag": 2.0 * (1 - ALIKE_RTOL)}, "confirmed"),
    ({"drag": 2.0 * (1 - ALIKE_RTOL * 1.001)}, "partly"),
    # order and stability both differ: refuted
    ({"order": 4.0, "drag": 2.8}, "refuted"),
    # only the resting hop differs: partly
    ({"hop": 0.0}, "partly"),
])
def test_c7_verdict_at_its_tolerances(changes, verdict):
    by_order = FOUR_ORDERS | {"rk4": changes.get("order", 2.0)}
    by_drag = FOUR_DRAG | {"rk4": changes.get("drag", 2.0)}
    table = [j if j.method != "rk4" else jitter("rk4", j.h, changes.get("hop", 0.39))
             for j in jitter_table(17.0, others=0.39)]
    # backwards-euler hops like the others here, so that hops alone decide
    table = [jitter(j.method, j.h, 0.39) if j.method == "backwards-euler" else j for j in table]
    result = c7(orders(by_order), limits(by_drag), table, POLYNOMIALS)
    assert result.verdict == verdict


def test_c7_facts_name_the_alike_pairs():
    polynomials = POLYNOMIALS | {"rk4": (1, 1, 1)}
    table = [jitter(j.method, j.h, 0.39) for j in jitter_table(17.0)]
    facts = c7(orders(FOUR_ORDERS), limits(FOUR_DRAG), table, polynomials).facts
    assert facts["agree"] == {"order": True, "stability": True, "resting hop": True}
    assert facts["alike_pairs"][0] == {"pair": ["averaged-euler", "backwards-euler"],
                                       "same_polynomial": True}
    assert facts["alike_pairs"][-1] == {"pair": ["midpoint", "rk4"], "same_polynomial": False}
    assert len(facts["alike_pairs"]) == 6


def choice(nfev, errors, orders=(1, 2, 1, 2, 4), stages=(1, 2, 2, 2, 4), drag=(2, 2, 1, 2, 2.8),
           oscillator=(0, 0, 1, 0, 2.8), hop=(17, 0.39, 0, 0.39, 0.39)) -> list[SolverChoice]:
    return [SolverChoice(m, *values) for m, *values in
            zip(METHODS, orders, stages, drag, oscillator, nfev, errors, hop, strict=True)]


def frame(difference) -> FrameStepDifference:
    return FrameStepDifference(1 / 60, dict(zip(METHODS, difference, strict=True)),
                               dict.fromkeys(METHODS, 0.0), half_size=2.0)


WALL_ORDERS = dict.fromkeys(METHODS, 1.0)
NEVER = math.inf


@pytest.mark.parametrize(("rk4_nfev", "rk4_error", "verdict"), [
    (90.0, 1e-3, "confirmed"),              # 10% fewer evaluations: a tie, not better
    (90.0 / HAIR, 1e-3, "partly"),          # just better without walls
    (90.0, 0.9e-3 / HAIR, "partly"),        # just better with walls
    (50.0, 1e-4, "refuted"),                # better in both
])
def test_c8_verdict_at_the_tie(rk4_nfev, rk4_error, verdict):
    rows = choice(nfev=(NEVER, 100.0, NEVER, 120.0, rk4_nfev),
                  errors=(5e-3, 1e-3, 2e-3, 1.1e-3, rk4_error))
    result = c8(rows, frame((0, 0, 0, 0, 0)), frame((0, 0, 0, 0, 0)), WALL_ORDERS)
    assert result.verdict == verdict
    assert result.facts["best_other_free"] == "averaged-euler"
    assert result.facts["best_other_walls"] == "averaged-euler"


@pytest.mark.parametrize(("difference", "visible"), [
    (VISIBLE_FRACTION * 4.0, False),        # exactly one pixel of the 4 m cube: not above it
    (VISIBLE_FRACTION * 4.0 * HAIR, True),
])
def test_c8_visibility(difference, visible):
    rows = choice(nfev=(NEVER, 100.0, NEVER, 120.0, 90.0), errors=(5, 1, 2, 1.1, 1))
    facts = c8(rows, frame((1.0, difference, 1.0, 0.0, 0.0)), frame((0,) * 5),
               WALL_ORDERS).facts
    assert facts["second_order"] == ["averaged-euler", "midpoint"]
    assert facts["visible"] == pytest.approx(4e-3)
    assert facts["visible_free"] is visible and facts["visible_walls"] is False


@pytest.mark.parametrize(("rk4_order", "first"), [(1 + ORDER_MATCH_TOL, True),
                                                   (1 + ORDER_MATCH_TOL * 1.001, False)])
def test_c8_wall_orders(rk4_order, first):
    rows = choice(nfev=(NEVER,) * 5, errors=(1,) * 5)
    facts = c8(rows, frame((0,) * 5), frame((0,) * 5),
               WALL_ORDERS | {"rk4": rk4_order, "scipy-RK45": 5.0}).facts
    assert facts["walls_first_order"] is first
    assert "scipy-RK45" not in facts["wall_orders"]


@pytest.mark.parametrize(("be_nfev", "be_error", "verdict"), [
    (110.0, 1.1e-3, "confirmed"),           # within 10% of the best: tied-best in both
    (100.0 / (1 - COST_TIE_RTOL) * HAIR, 1e-3, "partly"),   # just beaten without walls
    (100.0, 1e-3 / (1 - COST_TIE_RTOL) * HAIR, "partly"),   # just beaten with walls
    (NEVER, math.nan, "refuted"),           # never reaches the target; no error measured
])
def test_c9_verdict_at_the_tie(be_nfev, be_error, verdict):
    rows = choice(nfev=(NEVER, 100.0, be_nfev, 120.0, 100.0),
                  errors=(5e-3, 1e-3, be_error, 1.2e-3, 1e-3))
    result = c9(rows)
    assert result.verdict == verdict


def test_c9_facts_rank_backwards_euler():
    rows = choice(nfev=(NEVER, 100.0, 105.0, 120.0, 100.0), errors=(5, 1, 1, 1.2, 1))
    facts = c9(rows).facts
    assert facts["peers"] == {"averaged-euler": 2, "midpoint": 2}
    assert facts["order_relation"] == "lower"
    assert facts["drag_rank"] == {"position": "lowest", "tied_with": []}
    assert facts["hop_rank"] == {"position": "lowest", "tied_with": []}
    assert facts["oscillator_stable"] is True
    assert facts["oscillator_stable_others"] == {"rk4": 2.8}
    assert facts["walls_rank"] == {"position": "lowest", "tied_with": ["averaged-euler", "rk4"]}


STATED = {"euler": 1, "averaged-euler": 2, "backwards-euler": 2, "midpoint": 2, "rk4": 4}
DERIVED = STATED | {"backwards-euler": 1}


@pytest.mark.parametrize(("observed", "verdict"), [
    (STATED | {"rk4": 4 - ORDER_MATCH_TOL}, "confirmed"),
    (STATED | {"rk4": 4 - ORDER_MATCH_TOL * 1.001}, "partly"),
    ({m: 0.0 for m in STATED}, "refuted"),
])
def test_c10_verdict_at_its_tolerance(observed, verdict):
    result = c10(orders(observed), DERIVED, STATED)
    assert result.verdict == verdict


def test_c10_facts():
    facts = c10(orders(DERIVED), DERIVED, STATED).facts
    assert facts["wrong"] == ["backwards-euler"]
    assert facts["right"] == ["euler", "averaged-euler", "midpoint", "rk4"]
    assert facts["matches_derived"] == dict.fromkeys(STATED, True)
    assert facts["problems"] == ["decay", "oscillator"]


def inside(rtol: float) -> float:
    """A value just within ``rtol`` of 1, relative (and one just outside)."""
    return 1 - rtol * (1 - 1e-6)


def outside(rtol: float) -> float:
    return 1 - rtol * (1 + 1e-6)


def test_oracle_agreement_at_its_tolerances():
    limit_rows = [StabilityLimit("euler", 1.0, inside(STABILITY_AGREE_RTOL), 0.0, 0.0),
                  StabilityLimit("rk4", 1.0, outside(STABILITY_AGREE_RTOL), 2.8, 2.8)]
    energy = [OscillatorEnergy("euler", 0.1, inside(FORMULA_AGREE_RTOL), 1.0),
              OscillatorEnergy("rk4", 0.1, outside(FORMULA_AGREE_RTOL), 1.0)]
    h = JITTER_QUOTED_STEP
    hop = 7 / 18 * 9.81 * h * h
    table = [jitter("rk4", h, 7 / 18), jitter("euler", h, 17.0)]
    found = oracle_agreement(orders(DERIVED | {"rk4": 4 + ORDER_MATCH_TOL * 1.001}), DERIVED,
                             limit_rows, energy, table, {h: hop})
    assert (found["orders_within"], found["orders_total"]) == (8, 10)
    assert (found["limits_within"], found["limits_total"]) == (3, 4)
    assert found["limits_worst"] == pytest.approx(STABILITY_AGREE_RTOL, rel=1e-5)
    assert (found["energy_within"], found["energy_total"]) == (1, 2)
    assert (found["hops_within"], found["hops_total"]) == (1, 1)
    assert found["hops_worst"] == pytest.approx(0.0, abs=1e-15)
