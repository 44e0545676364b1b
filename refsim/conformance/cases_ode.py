"""ODE problems with exact solutions, and the sample points of the stability
check (seed S6, capability ``ode``).

What: the problems of :mod:`refsim.solvers.problems` that have a closed-form
solution and are smooth over the interval (exponential decay, the harmonic
oscillator, the projectile with linear drag), and two more that a linear
problem cannot stand in for:

- ``logistic``: ``y' = y (1 - y)``, ``y(0) = 1/10``, exact
  ``y(t) = 1 / (1 + 9 e^-t)``. Nonlinear: a method whose tableau satisfies
  only the linear order conditions (its R(z) matches e^z further than its
  order) shows its true order here.
- ``time-dependent``: ``y' = cos(t) y``, ``y(0) = 1``, exact
  ``y(t) = exp(sin t)``. The right-hand side depends on t, so the stage
  times ``c_i`` are exercised: evaluating a stage at the wrong time costs
  order.

Each problem is integrated over its interval with ``STEP_COUNTS`` equal
steps; the observed order is the least-squares slope of log(error) against
log(h) (errors at the end point, relative to the problem's scale) over the
step counts whose error is above ``ERROR_FLOOR``.

Stability: ``y' = lambda y`` from ``y = 1`` with ``h = 1`` and
``lambda = z`` gives ``R(z)`` in one step; the points are ``z = -k/8`` for
k = 0 .. 40 (the negative real axis to -5, past every explicit method of at
most four stages' stable interval: RK4's ends at -2.785).

References: E. Hairer, S. P. Norsett, G. Wanner, *Solving Ordinary
Differential Equations I*, 2nd ed., Springer 1993, section II.1 (observed
order from a sequence of step sizes) and II.2 (order conditions); the
logistic equation, ibid. section I.3.

Cost: sum over problems of ``STEP_COUNTS`` steps, ``s`` evaluations each:
about 2,500 steps in all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from refsim.solvers import problems

#: Equal steps per interval: h falls by a factor 8 over the fit; RK4's errors
#: stay above ERROR_FLOOR at 128 steps on every problem here, Euler's stay in
#: the asymptotic regime at 32.
STEP_COUNTS = (32, 64, 128, 256)

#: Where a method of high order is exact to rounding at STEP_COUNTS (fewer
#: than three errors above ERROR_FLOOR: Tsit5 and Dopri5 on most of the five
#: problems), the same factor-8 range of h is tried at twice the step, then
#: four times, ...: the order is measured at the finest steps where the
#: truncation error shows (:func:`fitted_order` there). Never coarser once
#: three errors show: coarser steps are further from the asymptotic regime,
#: and a slope that looks steady there can be the next term's (Tsit5 on
#: y' = cos(t) y shows 5.97 at 2 to 16 steps, 5.57 at 16 to 64).
COARSER_STEP_COUNTS = ((16, 32, 64, 128), (8, 16, 32, 64), (4, 8, 16, 32), (2, 4, 8, 16))

#: Errors (relative to the problem's scale) below this are rounding, not
#: truncation: at most 256 steps, each rounding ~1.1e-16 relative, add up to
#: 2.8e-14 if every rounding fell the same way; 1e-13 is above that and
#: lets Tsit5 and Dopri5 show their order where 1e-11 left them two points
#: or fewer. Left out of the fit.
ERROR_FLOOR = 1e-13


#: The stability sample points z = -k / 8, k = 0 .. 40.
STABILITY_POINTS = tuple(-k / 8.0 for k in range(41))

#: Steps whose evaluations of f are counted (each must take the same number).
COUNTED_STEPS = 5


def logistic() -> problems.Problem:
    """``y' = y (1 - y)``, ``y(0) = 0.1`` on [0, 2]; ``y = 1 / (1 + 9 e^-t)``."""
    return problems.Problem(
        "logistic", lambda t, y: y * (1.0 - y), np.array([0.1]), 0.0, 2.0,
        lambda t: np.array([1.0 / (1.0 + 9.0 * math.exp(-t))]), 1.0)


def time_dependent() -> problems.Problem:
    """``y' = cos(t) y``, ``y(0) = 1`` on [0, 2]; ``y = exp(sin t)``."""
    return problems.Problem(
        "time-dependent", lambda t, y: math.cos(t) * y, np.array([1.0]), 0.0, 2.0,
        lambda t: np.array([math.exp(math.sin(t))]), math.e)


def order_problems() -> tuple[problems.Problem, ...]:
    """The problems of the order check (module docstring)."""
    return (problems.exponential_decay(), problems.harmonic_oscillator(),
            problems.projectile_linear_drag(), logistic(), time_dependent())


@dataclass(frozen=True)
class OdeCases:
    """The ODE case set: problems, step counts and stability points. It does
    not grow with ``--cases``: each problem is one case of the order check."""

    problems: tuple
    step_counts: tuple = STEP_COUNTS
    coarser_step_counts: tuple = COARSER_STEP_COUNTS
    stability_points: tuple = STABILITY_POINTS
    counted_steps: int = COUNTED_STEPS
    seed: int = 0

    def __len__(self) -> int:
        return len(self.problems)


def ode_cases(seed: int = 0) -> OdeCases:
    return OdeCases(problems=order_problems(), seed=seed)


def end_error(step, problem: problems.Problem, n: int) -> float:
    """Relative error at ``t1`` after ``n`` equal steps of ``step(f, t, y, h)``.

    Raises
    ------
    ValueError
        ``problem`` has no exact solution to compare with.
    """
    if problem.exact is None:
        raise ValueError(f"problem {problem.name!r} has no exact solution: "
                         "its end error cannot be measured")
    h = (problem.t1 - problem.t0) / n
    y = np.array(problem.y0, dtype=np.float64)
    for k in range(n):
        y = np.asarray(step(problem.f, problem.t0 + k * h, y, h), dtype=np.float64)
    error = y - problem.exact(problem.t1)
    return float(np.abs(error).max() / problem.scale)


def fitted_order(steps, errors, floor: float = ERROR_FLOOR) -> float | None:
    """Least-squares slope of log(error) on log(h) over the points with an
    error above ``floor``; None when fewer than two are (the engine is exact
    to rounding on the problem); NaN when any error is not finite (NaN
    included: it is never "below the floor")."""
    if not all(math.isfinite(e) for e in errors):
        return math.nan
    pts = [(h, e) for h, e in zip(steps, errors, strict=True) if e > floor]
    if len(pts) < 2:
        return None
    x = np.log([h for h, _ in pts])
    y = np.log([e for _, e in pts])
    x0, y0 = x.mean(), y.mean()
    return float(((x - x0) * (y - y0)).sum() / ((x - x0) ** 2).sum())
