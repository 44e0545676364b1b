"""Claims C5..C10: the ODE solvers (S6), drag (S5) and the particle system (S10).

Each function reads the records of :mod:`refsim.studies.solvers` and
:mod:`refsim.studies.particles`:

- C5 "quadratic drag is not worth its cost": :class:`DragComparison`;
- C6 "Euler jitters in resting contact without damping": :class:`Jitter`;
- C7 "the other four solvers behave alike in stability and accuracy":
  observed orders (:class:`Convergence`), stability limits
  (:class:`StabilityLimit`) and resting hops;
- C8 "RK4 is not worth its cost in a particle system" and C9 "backwards
  Euler is the best general choice": :class:`SolverChoice` rows, and for C8
  the frame-step differences (:class:`FrameStepDifference`) and the observed
  orders with walls;
- C10 "the stated global error orders": observed orders against the orders
  the seed states.

What is a property of a solver's tableau, not a measurement (its derived
order, the order the seed states, the order conditions it fails, its
stability polynomial), the caller passes as a plain mapping from method name.
Methods are taken in the order of the records given.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from refsim.claims.result import (
    ClaimResult,
    by_parts,
    by_timed_parts,
    comparison,
    lower,
    rank,
    relative_difference,
    tied,
)
from refsim.studies.particles import DragComparison, FrameStepDifference, Jitter, SolverChoice
from refsim.studies.solvers import Convergence, OscillatorEnergy, StabilityLimit

#: An observed order counts as the stated one when it is this close: the
#: fitted slopes of the five solvers sit within 0.05 of an integer (the next
#: error term's share over a factor 4 in h), and integers are 1 apart.
ORDER_MATCH_TOL = 0.25

#: The step whose resting hop the verdicts quote (s), as
#: refsim.studies.particles.measure_solver_choice measures it.
JITTER_QUOTED_STEP = 1 / 100

#: Two steps are the same step when they differ by less than this (s): the
#: steps are written as fractions (1/30, 1/100, ...) and computed the same way
#: wherever they are used, so equal steps are equal floats; the tolerance only
#: keeps a step written as 0.01 from missing 1/100.
SAME_STEP = 1e-12

#: Euler's hop must exceed the others' by this factor to count as the jitter
#: C6 describes (measured: about 44 times; a factor 10 is "clearly more", far
#: from both the measured value and from "alike").
JITTER_FACTOR = 10.0

#: C6: the hop "scales as h^2" when hop / (g h^2) of every method that hops
#: varies by less than this, relative, over the steps measured. A hop
#: proportional to h instead would change hop / (g h^2) by the ratio of the
#: steps (3.3 from 1/30 to 1/100 s), so a tenth tells h^2 from h with a wide
#: margin while allowing the estimate's own slack at coarse steps.
HOP_SCALING_RTOL = 0.1

#: C7: two solvers behave alike in a measured stability limit or resting hop
#: when the values differ by less than this, relative (in order: when every
#: observed order differs by at most ORDER_MATCH_TOL, i.e. the same integer
#: order). A tenth is far above the measurements' own spread (limits bisected
#: to 1e-9, hops reproduced to FORMULA_AGREE_RTOL) and well below a factor 2,
#: one halving of the step, the smallest change a user would make to stay
#: stable or to halve a hop.
ALIKE_RTOL = 0.1

#: C8/C9: two costs (evaluations to reach a target error) or two errors at a
#: budget of evaluations are tied when they differ by less than this,
#: relative. Both are interpolated log-log between runs whose steps halve; a
#: difference of a tenth is small against that factor 2 and is not one a
#: choice of solver would turn on. "Better" means better by more than this.
COST_TIE_RTOL = 0.1

#: C8: a position difference at the frame step is visible when it exceeds
#: this fraction of the cube's edge: one pixel when the cube fills a
#: 1000-pixel view (4 mm for the 4 m cube).
VISIBLE_FRACTION = 1e-3

#: C5: the quadratic-drag path differs significantly from the linear-drag one
#: when their largest distance exceeds this fraction of the distance
#: travelled: 1% of the path is a centimetre per metre thrown, as much as a
#: body's own size in most scenes and more than a viewer forgives in a
#: trajectory they can compare (a reticle, a goal).
DRAG_SIGNIFICANT_FRACTION = 0.01

#: C5: quadratic drag has an extra cost when its step takes more than this
#: times as long as a linear-drag step. Best-of-several wall times still
#: vary by up to ~10% from run to run, so a ratio below 1.2 cannot be told
#: from noise; 20% more time per step is a cost worth weighing.
DRAG_EXTRA_COST_RATIO = 1.2

#: A stable step predicted from R(z) and one found by simulation agree when
#: they differ by less than this, relative: the simulation bisects to 1e-9
#: and calls growth of 1e-13 per step over 400 steps unstable, which moves
#: the boundary by ~1e-9 (measured: at most 6e-10).
STABILITY_AGREE_RTOL = 1e-8

#: Measured and predicted energy per period (and resting hops) agree when
#: they differ by less than this, relative: both are the same polynomial
#: evaluated two ways, a few hundred steps of rounding apart (measured: ~1e-12
#: for the energy; the hop of a 1/30 s step sits 3e-7 above 7/18 g h^2, its
#: push-back rounding).
FORMULA_AGREE_RTOL = 1e-6

#: The method C6 is about, and the method C8 and C9 are about.
EULER = "euler"
RK4 = "rk4"
BACKWARDS_EULER = "backwards-euler"

#: C7's "other four solvers": every method but Euler.
OTHER_FOUR = ("averaged-euler", "backwards-euler", "midpoint", "rk4")

#: The methods of order 2 or more by their tableaux: exact for constant
#: gravity, so their resting hop has a closed form (the seed's
#: backwards-euler is order 1 and never rises).
EXACT_FOR_GRAVITY = ("averaged-euler", "midpoint", "rk4")


def _observed(orders: Mapping[tuple[str, str], Convergence]) -> dict[str, dict[str, float]]:
    """method -> problem -> observed order, in the order of ``orders``."""
    observed: dict[str, dict[str, float]] = {}
    for (problem, method), c in orders.items():
        observed.setdefault(method, {})[problem] = c.order
    return observed


def _quoted(jitter: Sequence[Jitter]) -> dict[str, Jitter]:
    """The rows of :data:`JITTER_QUOTED_STEP`, by method."""
    return {j.method: j for j in jitter if abs(j.h - JITTER_QUOTED_STEP) < SAME_STEP}


def c5(drag: DragComparison) -> ClaimResult:
    """C5 from the drag comparison. Its two parts: quadratic drag changes the
    path insignificantly (at most :data:`DRAG_SIGNIFICANT_FRACTION` of the
    distance, at the same terminal speed), and it costs more (a step more
    than :data:`DRAG_EXTRA_COST_RATIO` times as long). The cost part is a
    timing: it is open when the ratio lies within the spread of its repeats
    of the threshold, and the verdict then "undecided"
    (:func:`refsim.claims.result.by_timed_parts`)."""
    significant = (drag.same_terminal_difference
                   > DRAG_SIGNIFICANT_FRACTION * drag.same_terminal_distance)
    cost = comparison(drag.cost_ratio, DRAG_EXTRA_COST_RATIO, drag.cost_ratios)
    extra = cost["side"] == "above"
    open_cost = cost["side"] == "within spread"
    return ClaimResult("C5", by_timed_parts((not significant) + extra, open_cost, 2), {
        "terminal_speed": drag.terminal_speed,
        "same_terminal_difference": drag.same_terminal_difference,
        "same_terminal_distance": drag.same_terminal_distance,
        "same_k_difference": drag.same_k_difference,
        "significant_fraction": DRAG_SIGNIFICANT_FRACTION,
        "significant": significant,
        "cost_ratio": drag.cost_ratio,
        "extra_cost_ratio": DRAG_EXTRA_COST_RATIO,
        "extra_cost": extra,
        "cost_against_threshold": cost,
    }, timing=True)


def c6(jitter: Sequence[Jitter], damped: Sequence[Jitter]) -> ClaimResult:
    """C6 from the resting-contact runs without drag (``jitter``) and with
    strong drag (``damped``). Confirmed when Euler's hop at
    :data:`JITTER_QUOTED_STEP` exceeds every other method's by more than
    :data:`JITTER_FACTOR`, refuted otherwise. Whether the hop scales as h^2
    (bounded jitter, not a growing instability) is a fact beside it."""
    quoted, quoted_damped = _quoted(jitter), _quoted(damped)
    euler, euler_damped = quoted[EULER], quoted_damped[EULER]
    others = {k: j.max_height_gh2 for k, j in quoted.items() if k != EULER}
    hops: dict[str, dict[float, float]] = {}
    for j in jitter:
        hops.setdefault(j.method, {})[j.h] = j.max_height_gh2
    steps = sorted({j.h for j in jitter}, reverse=True)
    hopping = {k: v for k, v in hops.items() if all(x > 0 for x in v.values())}
    measured_scaling = len(steps) > 1 and bool(hopping)
    return ClaimResult(
        "C6", "confirmed" if euler.max_height_gh2 > JITTER_FACTOR * max(others.values())
        else "refuted", {
            "step": JITTER_QUOTED_STEP,
            "euler_hop": euler.max_height,
            "euler_hop_gh2": euler.max_height_gh2,
            "euler_damped_hop_gh2": euler_damped.max_height_gh2,
            "damped_drag": euler_damped.drag,
            "others_hop_gh2": others,
            "factor": JITTER_FACTOR,
            "steps": steps,
            "euler_hop_gh2_by_step": [hops[EULER][s] for s in steps],
            "scaling_measured": measured_scaling,
            "scales_as_h2": measured_scaling and all(
                tied(min(v.values()), max(v.values()), HOP_SCALING_RTOL)
                for v in hopping.values()),
            "scaling_rtol": HOP_SCALING_RTOL,
        })


def c7(orders: Mapping[tuple[str, str], Convergence], limits: Sequence[StabilityLimit],
       jitter: Sequence[Jitter], polynomials: Mapping[str, tuple]) -> ClaimResult:
    """C7 over :data:`OTHER_FOUR`, pair by pair: alike in order (every
    observed order within :data:`ORDER_MATCH_TOL`), in stability (both
    measured limits within :data:`ALIKE_RTOL`) and in resting hop (within
    ALIKE_RTOL). Confirmed when every pair is alike in all three, refuted when
    the four differ in both order and stability, partly otherwise.
    ``polynomials``: each method's stability polynomial R(z), to say which
    alike pairs are the same method on linear problems."""
    observed = _observed(orders)
    by_limit = {s.method: s for s in limits}
    hop = {k: j.max_height_gh2 for k, j in _quoted(jitter).items()}
    four = OTHER_FOUR
    pairs = [(a, b) for i, a in enumerate(four) for b in four[i + 1:]]

    def order_alike(a, b):
        return all(abs(observed[a][p] - observed[b][p]) <= ORDER_MATCH_TOL for p in observed[a])

    def stability_alike(a, b):
        la, lb = by_limit[a], by_limit[b]
        return (tied(la.drag_measured, lb.drag_measured, ALIKE_RTOL)
                and tied(la.oscillator_measured, lb.oscillator_measured, ALIKE_RTOL))

    def hop_alike(a, b):
        return tied(hop[a], hop[b], ALIKE_RTOL)

    agree = {"order": all(order_alike(a, b) for a, b in pairs),
             "stability": all(stability_alike(a, b) for a, b in pairs),
             "resting hop": all(hop_alike(a, b) for a, b in pairs)}
    alike = [(a, b) for a, b in pairs
             if order_alike(a, b) and stability_alike(a, b) and hop_alike(a, b)]
    if all(agree.values()):
        verdict = "confirmed"
    elif not agree["order"] and not agree["stability"]:
        verdict = "refuted"
    else:
        verdict = "partly"
    return ClaimResult("C7", verdict, {
        "methods": list(four),
        "observed_orders": {k: observed[k] for k in four},
        "drag_limit": {k: by_limit[k].drag_measured for k in four},
        "oscillator_limit": {k: by_limit[k].oscillator_measured for k in four},
        "hop_gh2": {k: hop[k] for k in four},
        "agree": agree,
        "alike_pairs": [{"pair": [a, b], "same_polynomial": polynomials[a] == polynomials[b]}
                        for a, b in alike],
        "order_tol": ORDER_MATCH_TOL,
        "rtol": ALIKE_RTOL,
    })


def _best_other(values: Mapping[str, float], than: str) -> str | None:
    """The method with the lowest finite value, ``than`` left out."""
    finite = [k for k in values if k != than and not math.isnan(values[k])]
    return min(finite, key=lambda k: values[k]) if finite else None


def walls_first_order(wall_orders: Mapping[str, float]) -> bool:
    """Whether every observed order with walls is first order (within
    :data:`ORDER_MATCH_TOL` of 1): a contact between steps is caught up to a
    step late, whatever the method's own order."""
    return all(abs(o - 1) <= ORDER_MATCH_TOL for o in wall_orders.values())


def c8(choice: Sequence[SolverChoice], frame_free: FrameStepDifference,
       frame_walls: FrameStepDifference, wall_orders: Mapping[str, float]) -> ClaimResult:
    """C8 from the solver choice runs: is RK4 better than the best other
    method at equal cost, by more than :data:`COST_TIE_RTOL`? Without walls
    (fewer evaluations to reach the target) and with walls (a lower error at
    the budget). Refuted when it is better in both, confirmed in neither,
    partly in one. Beside it: the observed orders with walls
    (``wall_orders``, of the methods in ``choice``), and whether RK4 and the
    second-order methods end up visibly apart (:data:`VISIBLE_FRACTION` of
    the cube's edge) at the frame step."""
    by = {c.method: c for c in choice}
    walls_orders = {k: wall_orders[k] for k in by}
    nfev = {k: c.nfev_free for k, c in by.items()}
    errors = {k: c.error_walls_at_budget for k, c in by.items()}
    best_free, best_walls = _best_other(nfev, RK4), _best_other(errors, RK4)
    rk4_free = best_free is not None and lower(nfev[RK4], nfev[best_free], COST_TIE_RTOL)
    rk4_walls = best_walls is not None and lower(errors[RK4], errors[best_walls],
                                                 COST_TIE_RTOL)
    second = [k for k, c in by.items() if c.order == 2]
    edge = 2 * frame_free.half_size
    visible = VISIBLE_FRACTION * edge
    return ClaimResult("C8", "refuted" if rk4_free and rk4_walls
                       else "confirmed" if not (rk4_free or rk4_walls) else "partly", {
        "nfev_free": nfev,
        "error_walls": errors,
        "best_other_free": best_free,
        "best_other_walls": best_walls,
        "rk4_better_free": rk4_free,
        "rk4_better_walls": rk4_walls,
        "tie_rtol": COST_TIE_RTOL,
        "wall_orders": walls_orders,
        "walls_first_order": walls_first_order(walls_orders),
        "order_tol": ORDER_MATCH_TOL,
        "second_order": second,
        "frame_difference_free": {k: frame_free.difference[k] for k in second},
        "frame_difference_walls": {k: frame_walls.difference[k] for k in second},
        "cube_edge": edge,
        "visible": visible,
        "visible_free": any(frame_free.difference[k] > visible for k in second),
        "visible_walls": any(frame_walls.difference[k] > visible for k in second),
    })


def c9(choice: Sequence[SolverChoice]) -> ClaimResult:
    """C9 from the solver choice runs: is backwards-euler best or tied-best
    (within :data:`COST_TIE_RTOL`) on accuracy per cost, without walls and
    with walls? Confirmed when both, refuted when neither, partly when one.
    Beside it: its order against the methods of the same cost per step, and
    its rank (:func:`refsim.claims.result.rank`) in stability and resting
    hop (:data:`ALIKE_RTOL`) and in the error with walls."""
    by = {c.method: c for c in choice}
    be = by[BACKWARDS_EULER]
    others = [k for k in by if k != BACKWARDS_EULER]
    peers = [k for k in others if by[k].stages == be.stages]
    if all(be.order < by[k].order for k in peers):
        relation = "lower"
    elif all(be.order > by[k].order for k in peers):
        relation = "higher"
    elif all(be.order == by[k].order for k in peers):
        relation = "equal"
    else:
        relation = "mixed"
    nfev = {k: by[k].nfev_free for k in others}
    errors = {k: by[k].error_walls_at_budget for k in others}
    drag = {k: by[k].drag_limit for k in others}
    hop = {k: by[k].hop_height_gh2 for k in others}
    free_best = (all(not lower(nfev[k], be.nfev_free, COST_TIE_RTOL) for k in others)
                 and not math.isnan(be.nfev_free))
    walls_best = (all(not lower(errors[k], be.error_walls_at_budget, COST_TIE_RTOL)
                      for k in others) and not math.isnan(be.error_walls_at_budget))
    return ClaimResult("C9", by_parts(free_best + walls_best, 2), {
        "stages": be.stages,
        "order": be.order,
        "peers": {k: by[k].order for k in peers},
        "order_relation": relation,
        "drag_limit": be.drag_limit,
        "drag_others": drag,
        "drag_rank": rank(be.drag_limit, drag, ALIKE_RTOL),
        # A limit of 0 means the oscillation grows at every step tried.
        "oscillator_limit": be.oscillator_limit,
        "oscillator_stable": be.oscillator_limit > 0,
        "oscillator_stable_others": {k: by[k].oscillator_limit for k in others
                                     if by[k].oscillator_limit > 0},
        "hop_gh2": be.hop_height_gh2,
        "hop_others": hop,
        "hop_rank": rank(be.hop_height_gh2, hop, ALIKE_RTOL),
        "nfev_free": be.nfev_free,
        "nfev_others": nfev,
        "error_walls": be.error_walls_at_budget,
        "error_walls_others": errors,
        "walls_rank": rank(be.error_walls_at_budget, errors, COST_TIE_RTOL),
        "best_free": free_best,
        "best_walls": walls_best,
        "tie_rtol": COST_TIE_RTOL,
    })


def c10(orders: Mapping[tuple[str, str], Convergence], derived: Mapping[str, int],
        stated: Mapping[str, int]) -> ClaimResult:
    """C10 from the observed orders (:class:`Convergence`, keyed by
    ``(problem, method)``) against the orders the seed ``stated``. A method
    matches when every observed order is within :data:`ORDER_MATCH_TOL` of
    the stated one. Confirmed when all match, refuted when none does, partly
    otherwise. ``derived``: each method's order from its tableau; whether the
    observed orders match it is a fact beside the verdict."""
    observed = _observed(orders)

    def matches(method, order):
        return all(abs(o - order) <= ORDER_MATCH_TOL for o in observed[method].values())

    matches_stated = {k: matches(k, stated[k]) for k in observed}
    wrong = [k for k, ok in matches_stated.items() if not ok]
    right = [k for k, ok in matches_stated.items() if ok]
    return ClaimResult("C10", by_parts(len(right), len(observed)), {
        "problems": list(next(iter(observed.values()))),
        "observed_orders": observed,
        "derived_order": {k: derived[k] for k in observed},
        "stated_order": {k: stated[k] for k in observed},
        "matches_stated": matches_stated,
        "matches_derived": {k: matches(k, derived[k]) for k in observed},
        "wrong": wrong,
        "right": right,
        "order_tol": ORDER_MATCH_TOL,
    })


def oracle_agreement(orders: Mapping[tuple[str, str], Convergence], derived: Mapping[str, int],
                     limits: Sequence[StabilityLimit], energy: Sequence[OscillatorEnergy],
                     jitter: Sequence[Jitter], predicted_hop: Mapping[float, float]) -> dict:
    """The solvers' agreements with scipy and the analytic answers: observed
    orders within :data:`ORDER_MATCH_TOL` of the derived ones, stable steps
    predicted from R(z) within :data:`STABILITY_AGREE_RTOL` of the simulated
    ones, energy per period and the resting hops of
    :data:`EXACT_FOR_GRAVITY` (``predicted_hop``: step -> hop) within
    :data:`FORMULA_AGREE_RTOL` of their formulas. Counts, totals and the
    worst relative differences."""
    observed = [(o, derived[k]) for k, by_problem in _observed(orders).items()
                for o in by_problem.values()]
    limit_pairs = ([(s.drag_predicted, s.drag_measured) for s in limits]
                   + [(s.oscillator_predicted, s.oscillator_measured) for s in limits])
    limit_diff = [relative_difference(p, q) for p, q in limit_pairs]
    energy_diff = [relative_difference(e.predicted, e.measured) for e in energy]
    hop_diff = [relative_difference(j.max_height, predicted_hop[j.h]) for j in jitter
                if j.method in EXACT_FOR_GRAVITY]
    return {
        "orders_within": sum(abs(o - d) <= ORDER_MATCH_TOL for o, d in observed),
        "orders_total": len(observed),
        "order_tol": ORDER_MATCH_TOL,
        "limits_within": sum(d <= STABILITY_AGREE_RTOL for d in limit_diff),
        "limits_total": len(limit_diff),
        "limits_worst": max(limit_diff),
        "limits_rtol": STABILITY_AGREE_RTOL,
        "energy_within": sum(d <= FORMULA_AGREE_RTOL for d in energy_diff),
        "energy_total": len(energy_diff),
        "energy_worst": max(energy_diff),
        "hops_within": sum(d <= FORMULA_AGREE_RTOL for d in hop_diff),
        "hops_total": len(hop_diff),
        "hops_worst": max(hop_diff),
        "formula_rtol": FORMULA_AGREE_RTOL,
    }
