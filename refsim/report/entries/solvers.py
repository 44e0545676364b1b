"""The report's ODE solver entries (seed S6, claims C7 and C10).

Observed orders of convergence beside what each tableau gives (C10), the
seed's literal RK4 weights, stability limits with each method's R(z) and
|R| on a grid, energy per period, and work-precision on Kepler (timed).
``solvers-alike`` gathers C7's measurements from these and from the
resting-contact entry of :mod:`refsim.report.entries.particles`. A quick
run drops Kepler from the order study and caps the step counts.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from refsim.report.run import Run

#: |R(z)| is drawn on this grid of z = h lambda.
STABILITY_GRID_RE, STABILITY_GRID_IM, STABILITY_GRID_N = (-5.5, 1.5), (-3.5, 3.5), 281
STABILITY_GRID = {"re": STABILITY_GRID_RE, "im": STABILITY_GRID_IM, "n": STABILITY_GRID_N}


@dataclass(frozen=True)
class OrderRun:
    """Observed orders, with what the tableaux say of each method."""

    convergence: dict           # (problem, method) -> refsim.studies.solvers.Convergence
    derived: dict               # method -> order derived from its tableau
    stated: dict                # method -> order the seed states
    failing: dict               # method -> order conditions (up to the stated order) it fails


@dataclass(frozen=True)
class SeedLiteral:
    problem: str
    result: Any                 # refsim.studies.solvers.SeedLiteralRK4


@dataclass(frozen=True)
class StabilityRun:
    """Stability limits, each method's R(z), and |R| on a grid of the complex plane."""

    limits: list                # refsim.studies.solvers.StabilityLimit
    polynomials: dict           # method -> coefficients of R(z) (Fractions), lowest first
    grid: dict                  # {"re": (lo, hi), "im": (lo, hi), "n": points per axis}
    x: Any                      # (n,) real parts
    y: Any                      # (n,) imaginary parts
    regions: list               # (label, |R| (n, n)) per distinct R(z)


@dataclass(frozen=True)
class WorkPrecisionRun:
    points: list                # refsim.studies.solvers.WorkPoint
    repeats: int                # wall time: best of this many runs
    count: int = 0              # particles (0: not a particle system)
    orders: dict = field(default_factory=dict)   # method -> observed order


@dataclass(frozen=True)
class AlikeRun:
    """C7's measurements: orders, stability limits, resting hops, and R(z)."""

    orders: dict
    limits: list
    jitter: list
    polynomials: dict


def solvers_orders(run: Run):
    from refsim.solvers.methods import SOLVERS
    from refsim.studies import solvers as sm

    problems = sm.standard_problems()
    if run.quick:
        # Kepler needs 10^5-step Euler runs: the full report only. The others
        # stop at a quarter of STEP_RANGE's most steps, which still leaves each
        # solver three points inside the fitted error window.
        del problems["kepler"]
        convergence = {}
        for name, problem in problems.items():
            lo, hi = sm.STEP_RANGE[name]
            steps = [lo * 2**k for k in range(int(math.log2(hi // lo)) - 1)]
            y_ref = sm.reference_at_t1(problem, run.engine("scipy"))
            for method in SOLVERS:
                convergence[(name, method)] = sm.measure_convergence(problem, method, steps,
                                                                     y_ref=y_ref)
    else:
        convergence = sm.measure_orders(problems, oracle=run.engine("scipy"))
    return OrderRun(convergence, {k: s.order for k, s in SOLVERS.items()},
                    {k: s.seed_order for k, s in SOLVERS.items()},
                    {k: sm.failing_order_conditions(s) for k, s in SOLVERS.items()})


def solvers_seed_literal(run: Run):
    from refsim.solvers.problems import exponential_decay, harmonic_oscillator, kepler_orbit
    from refsim.studies import solvers as sm

    problems = ([harmonic_oscillator()] if run.quick
                else [exponential_decay(), harmonic_oscillator(), kepler_orbit()])
    return [SeedLiteral(p.name, sm.measure_seed_literal_rk4(p, oracle=run.engine("scipy")))
            for p in problems]


def solvers_stability(run: Run):
    from refsim.studies import solvers as sm

    limits = sm.measure_stability()
    polynomials, x, y, regions = sm.stability_regions(STABILITY_GRID_RE, STABILITY_GRID_IM,
                                                      STABILITY_GRID_N)
    return StabilityRun(limits, polynomials, STABILITY_GRID, x, y, regions)


def solvers_energy(run: Run):
    from refsim.studies import solvers as sm

    return sm.measure_oscillator_energy()


def wall_time_repeats(run: Run) -> int:
    """Wall times: best of this many runs."""
    return run.size(2, 3)


def solvers_work_precision(run: Run):
    from refsim.studies import solvers as sm

    repeats = wall_time_repeats(run)
    if run.quick:
        lo, _ = sm.STEP_RANGE["kepler"]
        points = sm.measure_work_precision(steps=[lo * 2**k for k in range(8)],
                                           tolerances=sm.SCIPY_TOLERANCES[:8], repeats=repeats,
                                           oracle=run.engine("scipy"))
    else:
        points = sm.measure_work_precision(repeats=repeats, oracle=run.engine("scipy"))
    return WorkPrecisionRun(points, repeats)


def solvers_alike(run: Run):
    return AlikeRun(run.get("solvers-orders").convergence, run.get("solvers-stability").limits,
                    run.get("particles-jitter").undamped,
                    run.get("solvers-stability").polynomials)
