"""Checks of the ``ode`` capability: order, stability function, cost per step.

- ``ode.order``: on each problem of :mod:`refsim.conformance.cases_ode` the
  observed order (the fitted slope of log error against log h, at the
  finest step sizes where three errors stand above rounding) is within
  :data:`ORDER_TOL` of the engine's declared ``ode_order``; a problem where
  no order shows is "unmeasurable", one with a non-finite error a "bug".
- ``ode.stability``: on the negative real axis, one step of ``y' = lambda
  y`` from ``y = 1`` with ``h = 1`` multiplies ``y`` by ``R(lambda)``; the
  engine's step must give the ``R(z)`` its ``ode_stability(z)`` declares,
  within :data:`STABILITY_RTOL`. Not applicable without ``ode_stability``.
- ``ode.evaluations``: the number of calls of ``f`` in each of a few steps
  is the same every step; it equals the engine's ``ode_evaluations`` when
  declared, and is otherwise at least the fewest stages an explicit
  Runge-Kutta method of the declared order needs (Butcher's bounds:
  :data:`MIN_STAGES`). The count is reported either way.

A failure within twice its tolerance is "tolerance"; beyond, "bug"
(:data:`refsim.conformance.results.MARGINAL_FACTOR`). The
RK4 with the seed's literal weights (1/6, 2/3, 2/3, 1/6; they sum to 5/3)
declared as order 4 fails ``ode.order`` on every problem: its error does not
fall with h at all (observed order ~0).

References: Hairer, Norsett, Wanner, *Solving ODEs I*, II.1-II.2 (order),
Hairer and Wanner, *Solving ODEs II*, IV.2 (stability function); J. C.
Butcher, *Numerical Methods for Ordinary Differential Equations*, 3rd ed.,
Wiley 2016, section 32 (attainable order: s stages give order s only up to
s = 4; order 5 needs 6 stages, 6 needs 7, 7 needs 9, 8 needs 11).

Cost: about 2,500 steps for the order check, 41 single steps for the
stability check, a handful for the count.
"""

from __future__ import annotations

import math
import time

import numpy as np

from refsim.conformance.cases_ode import ERROR_FLOOR, end_error, fitted_order
from refsim.conformance.results import (
    CheckResult,
    Crash,
    attempt,
    classify_miss,
    not_applicable,
    tally,
)

#: Observed and declared order may differ by this much. The fits of refsim's
#: five methods on these problems land within 0.15 of their orders (the
#: pre-asymptotic terms of a factor-8 range of h; measured in
#: tests/conformance); 0.3 is twice that and still tells order p from p +- 1
#: with room on both sides.
ORDER_TOL = 0.3

#: ``|R_measured(z) - R_declared(z)| <= STABILITY_RTOL * max(1, |R(z)|)``:
#: one step of at most four stages on |z| <= 5 rounds each of a dozen
#: operations once, some 1e-15 of the largest term; 1e-12 leaves a factor
#: 1000 and is still far below any difference in a coefficient (the smallest
#: coefficient of a four-stage R(z), 1/24, moves R(-1) by 4e-2).
STABILITY_RTOL = 1e-12

#: Fewest stages of an explicit Runge-Kutta method of order p (Butcher 2016,
#: section 32; the counts above 8 are open, so higher orders are not checked).
MIN_STAGES = {1: 1, 2: 2, 3: 3, 4: 4, 5: 6, 6: 7, 7: 9, 8: 11}


def _measured_order(engine, problem, cases) -> tuple[float | None, list, list]:
    """The observed order on ``problem`` (:func:`fitted_order`) with its step
    sizes and end errors, at the finest step counts where three errors stand
    above rounding (the step counts, else the first of
    :data:`refsim.conformance.cases_ode.COARSER_STEP_COUNTS`), or where an
    error is not finite (the order is then NaN); None when no step counts
    show three."""
    for counts in (cases.step_counts, *cases.coarser_step_counts):
        steps = [(problem.t1 - problem.t0) / n for n in counts]
        errors = [end_error(engine.ode_step, problem, n) for n in counts]
        if sum(e > ERROR_FLOOR for e in errors) >= 3 or not all(map(math.isfinite, errors)):
            return fitted_order(steps, errors), steps, errors
    return None, steps, errors


def check_ode_order(engine, cases) -> CheckResult:
    """``ode.order``: observed order within ORDER_TOL of ``ode_order`` on
    every problem (module docstring), measured at the finest steps where the
    truncation error stands above rounding; a non-finite error is a "bug". A
    problem the engine solves to rounding at every step tried is
    "unmeasurable": it shows no order at all."""
    start = time.perf_counter()
    declared = float(engine.ode_order)
    outcomes: list[str | None] = []
    examples: list[dict] = []
    orders: dict = {}
    for problem in cases.problems:
        measured = attempt(_measured_order, engine, problem, cases)
        if isinstance(measured, Crash):
            outcomes.append("crash")
            examples.append(measured.example(problem=problem.name))
            continue
        observed, steps, errors = measured
        orders[problem.name] = observed
        if observed is None:
            outcomes.append("unmeasurable")
            examples.append({"class": "unmeasurable", "problem": problem.name,
                             "reason": "no step sizes tried give three end errors above "
                                       f"rounding ({ERROR_FLOOR:g}): the order does not show",
                             "declared_order": declared, "steps": steps, "errors": errors})
            continue
        miss = math.inf if math.isnan(observed) else abs(observed - declared)
        outcome = classify_miss(miss, ORDER_TOL)
        outcomes.append(outcome)
        if outcome is not None:
            examples.append({"class": outcome, "problem": problem.name,
                             "declared_order": declared, "observed_order": observed,
                             "steps": steps, "errors": errors})
    return tally("ode", "order", outcomes, examples=examples,
                 measured={"declared_order": declared, "observed_orders": orders},
                 seconds=time.perf_counter() - start)


def _amplification(engine, z: float) -> float:
    y = engine.ode_step(lambda t, y: z * y, 0.0, np.array([1.0]), 1.0)
    return float(np.asarray(y, dtype=np.float64).reshape(-1)[0])


def real_axis_limit(values, points) -> float:
    """The largest ``x`` of the sample points with ``|R(-x')| <= 1`` at every
    sample point ``x' <= x`` (the measured stable interval, to the grid)."""
    limit = 0.0
    for z, r in sorted(zip(points, values, strict=True), key=lambda p: -p[0]):
        if abs(r) > 1.0 + STABILITY_RTOL:
            break
        limit = -z
    return limit


def check_ode_stability(engine, cases) -> CheckResult:
    """``ode.stability``: the engine's step realises its declared R(z) on the
    negative real axis (module docstring); ``n/a`` without ``ode_stability``."""
    if not callable(getattr(engine, "ode_stability", None)):
        return not_applicable("ode", "stability",
                              "the engine gives no ode_stability(z) to compare with")
    start = time.perf_counter()
    outcomes: list[str | None] = []      # per point: None (passed) or its class
    failures: list[dict] = []            # every failing point (the first 5 are examples)
    measured: list[float] = []           # R(z) realised by one step, per point
    for z in cases.stability_points:
        answer = attempt(lambda x: (_amplification(engine, x), complex(engine.ode_stability(x))),
                         z)
        if isinstance(answer, Crash):
            outcomes.append("crash")
            measured.append(math.inf)            # the stable interval ends before it
            failures.append(answer.example(z=z))
            continue
        got, declared = answer
        miss = abs(got - declared) / max(1.0, abs(declared)) if math.isfinite(got) else math.inf
        outcome = classify_miss(miss, STABILITY_RTOL)
        outcomes.append(outcome)
        measured.append(got)
        if outcome is not None:
            failures.append({"class": outcome, "z": z, "measured_R": got,
                             "declared_R": [declared.real, declared.imag]})
    return tally("ode", "stability", outcomes, examples=failures[:5], failures=failures,
                 measured={"real_axis_limit": real_axis_limit(measured,
                                                              cases.stability_points)},
                 seconds=time.perf_counter() - start)


def check_ode_evaluations(engine, cases) -> CheckResult:
    """``ode.evaluations``: evaluations of f per step, the same each step;
    equal to ``ode_evaluations`` if declared, else at least ``MIN_STAGES``
    of the declared order (module docstring)."""
    start = time.perf_counter()
    problem = cases.problems[0]
    calls = 0

    def f(t, y):
        nonlocal calls
        calls += 1
        return problem.f(t, y)

    counts = []
    y = np.array(problem.y0, dtype=np.float64)
    h = (problem.t1 - problem.t0) / cases.step_counts[0]
    for k in range(cases.counted_steps):
        calls = 0
        y = np.asarray(engine.ode_step(f, problem.t0 + k * h, y, h), dtype=np.float64)
        counts.append(calls)
    declared = getattr(engine, "ode_evaluations", None)
    order = int(engine.ode_order)
    if declared is not None:
        expected, rule = int(declared), "ode_evaluations"
    else:
        expected, rule = MIN_STAGES.get(order, 1), f"at least MIN_STAGES[{order}]"
    outcomes, examples = [], []
    for k, count in enumerate(counts):
        bad = (count != counts[0] or (count != expected if declared is not None
                                      else count < expected))
        outcomes.append("bug" if bad else None)
        if bad:
            examples.append({"class": "bug", "step": k, "evaluations": count,
                             "expected": expected, "rule": rule})
    return tally("ode", "evaluations", outcomes, examples=examples,
                 measured={"evaluations_per_step": counts[0], "declared": declared,
                           "rule": rule},
                 seconds=time.perf_counter() - start)
