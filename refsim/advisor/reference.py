"""The advisor's reference run, and whether a run meets TOL against it.

:func:`find_reference` halves the step of the finest setting (rk4, level
"exact", linear boxes) until the run and its check, the same at twice the
step, agree well within TOL, stop getting closer, or would exceed the step
budget. It returns a :class:`Reference`: the run, how far it can be trusted
(its horizon, when it did not converge) and what a candidate is allowed to
differ from it by. :func:`judge` measures one candidate against it. Both
follow docs/advisor.md, "The reference" and "Meeting TOL".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from refsim.advisor import metrics
from refsim.advisor.records import ReferenceRow
from refsim.advisor.runner import Runner, Setting
from refsim.errors import OptionError

#: The reference's first step is the scene's divided by this (the scene's
#: step is what its author found good enough; the reference must be better).
REFERENCE_START = 4

#: Halve the reference's step until it and its check agree within this
#: fraction of TOL (docs/advisor.md, The reference).
REFERENCE_SHARE = 0.25

#: A halving of the reference's step that shrinks its difference with the
#: check by less than this factor is not converging (a first-order error
#: halves; a chaotic run's difference stays about the same).
REDUCTION_MIN = 1.5

#: Past the horizon a candidate may differ from the reference by this many
#: times the spread (end energy, impact counts). The spread is the largest
#: of one or two draws of how far equally fine runs of an unpredictable
#: scene end apart; allowing only that would fail a run as good as the
#: check by the luck of the draw (runs of solvers that are all exact for
#: constant gravity differ by rounding alone, and land on either side of it).
SPREAD_FACTOR = 2.0

#: Default most steps of one reference run: 5 s of simulated time at a step
#: of 1e-5 s; the cap keeps a reference for a fine tolerance finite.
MAX_REFERENCE_STEPS = 2**19

REFERENCE_SOLVER, REFERENCE_LEVEL, REFERENCE_AABB = "rk4", "exact", "linear"

#: Stop reasons of the reference's halving.
CONVERGED, NOT_CONVERGING, BUDGET = "converged", "not converging", "budget"


@dataclass(frozen=True)
class Reference:
    """The reference, its check and what the comparison of the two allows."""

    run: metrics.Run
    setting: Setting
    check: Setting
    row: ReferenceRow
    scale: float
    energy_allowance: float
    count_allowance: dict


def find_reference(runner: Runner, tolerance: float, max_steps: int,
                   first: list[tuple[Setting, str]], aim: float) -> Reference:
    """Halve the reference's step until it converges, stops converging or
    reaches the budget at the tolerance ``aim`` (docs/advisor.md, The
    reference). The
    horizon and the allowances past it are ``aim``'s; only the energy
    allowance grows with ``tolerance`` (>= ``aim``: advice at several
    tolerances shares the reference of the strictest). ``first``: runs to
    make along with the first pair (the search's first round), so that one
    sweep runs them all."""
    ladder = runner.ladder
    m = ladder.divisions * REFERENCE_START
    if ladder.n_steps(2 * m) > max_steps:
        m = max_steps // (2 * ladder.samples)
        if m < 1:
            raise OptionError(f"max_reference_steps = {max_steps} is too few: the reference "
                              f"needs at least {2 * ladder.samples} steps "
                              f"({ladder.samples} samples of the run)")

    def ref(k: int) -> Setting:
        return Setting(REFERENCE_SOLVER, k, REFERENCE_LEVEL, REFERENCE_AABB)

    runner.run([(ref(m), "reference ladder"), (ref(2 * m), "reference ladder"), *first],
               once={ref(m), ref(2 * m)})
    halvings = []
    H = float(runner.data["world"]["half_size"])
    end = runner.duration                   # (a reference that diverged ends before it)

    def gaps(fine: metrics.Run, coarse: metrics.Run, h: float, scale: float, tol: float):
        horizon = metrics.agreement_horizon(fine, coarse, tol)
        position_gap = float(metrics.distances(fine, coarse).max())
        events = metrics.compare_events(fine, coarse, tol, end)
        event_gap = events.error if events.paired else math.inf
        fastest = max((e.speed for e in metrics.impacts(fine) if e.time <= horizon), default=0.0)
        resolution = fastest * h
        energy_gap = metrics.energy_drift(coarse, scale) - metrics.energy_drift(fine, scale)
        # all four as distances: the energy's by its allowance TOL / H (metrics)
        uncertainty = max(position_gap, event_gap, resolution, abs(energy_gap) * H)
        return horizon, position_gap, event_gap, resolution, energy_gap, uncertainty

    while True:
        fine, coarse = runner.runs[ref(2 * m)], runner.runs[ref(m)]
        h = ladder.step(2 * m)
        scale = metrics.energy_scale(fine)
        horizon, position_gap, event_gap, resolution, energy_gap, uncertainty = gaps(
            fine, coarse, h, scale, aim)
        halvings.append((h, uncertainty, horizon))
        if uncertainty <= REFERENCE_SHARE * aim and horizon >= end * (1 - 1e-12):
            stop = CONVERGED
            break
        # halving did not help: the difference shrank by less than REDUCTION_MIN,
        # or the impacts still do not pair (an infinite difference)
        if len(halvings) > 1 and (math.isinf(uncertainty)
                                  or uncertainty * REDUCTION_MIN > halvings[-2][1]):
            stop = NOT_CONVERGING
            break
        if ladder.n_steps(4 * m) > max_steps:
            stop = BUDGET
            break
        m *= 2
        runner.run([(ref(2 * m), "reference ladder")], once={ref(2 * m)})

    reference, check = ref(2 * m), ref(m)
    runner.roles[reference] = ["reference"]
    runner.roles[check] = ["check"]
    converged = horizon >= end * (1 - 1e-12) and uncertainty <= aim
    ours, theirs = metrics.impact_counts(fine), metrics.impact_counts(coarse)
    count_gap = {k: theirs[k] - ours[k] for k in metrics.KINDS}
    # The spread past the horizon: how far the runs of the last comparison
    # (the check, and the run at twice its step when there was one) end from
    # the reference (docs/advisor.md, The reference).
    drawn = [coarse] + ([runner.runs[ref(m // 2)]] if len(halvings) > 1 else [])
    energy_spread = max(abs(metrics.energy_drift(r, scale) - metrics.energy_drift(fine, scale))
                        for r in drawn)
    count_spread = {k: max(abs(metrics.impact_counts(r)[k] - ours[k]) for r in drawn)
                    for k in metrics.KINDS}
    if converged:
        count_allowance = dict.fromkeys(metrics.KINDS, 0)
        energy_allowance = tolerance / H
    else:
        count_allowance = {k: max(math.ceil(SPREAD_FACTOR * count_spread[k]),
                                  math.ceil(math.sqrt(ours[k])))
                           for k in metrics.KINDS}
        energy_allowance = max(tolerance / H, SPREAD_FACTOR * energy_spread)
    row = ReferenceRow(
        solver=REFERENCE_SOLVER, step=h, check_step=ladder.step(m), level=REFERENCE_LEVEL,
        aabb=REFERENCE_AABB, converged=converged, stop=stop,
        horizon=horizon, uncertainty=uncertainty, position_gap=position_gap,
        event_gap=event_gap, resolution=resolution, energy_gap=energy_gap,
        count_gap=count_gap, energy_spread=energy_spread, count_spread=count_spread,
        impacts=ours, halvings=tuple(halvings), aim=aim)
    return Reference(run=fine, setting=reference, check=check, row=row, scale=scale,
                     energy_allowance=energy_allowance, count_allowance=count_allowance)


@dataclass(frozen=True)
class Verdict:
    """One run measured against the reference: the comparison, the error
    ratio the search's error model fits, and whether the run meets TOL."""

    comparison: metrics.Comparison
    ratio: float          # what the error model fits; inf when impacts do not pair
    meets: bool


def judge(run: metrics.Run, ref: Reference, tolerance: float) -> Verdict:
    """Measure ``run`` against the reference (docs/advisor.md, Meeting TOL)."""
    c = metrics.compare(ref.run, run, tolerance, ref.row.horizon, ref.scale)
    ratio = max(c.position_error / tolerance, c.events.error / tolerance,
                abs(c.energy_gap) / ref.energy_allowance)
    if run.diverged is not None or not c.events.paired:
        ratio = math.inf
    # counts matter past the horizon only: before it the impacts are paired one by one
    counts_ok = ref.row.converged or all(abs(c.count_gap[k]) <= ref.count_allowance[k]
                                         for k in metrics.KINDS)
    meets = (run.diverged is None and c.events.agree and counts_ok
             and c.position_error <= tolerance and c.events.error <= tolerance
             and abs(c.energy_gap) <= ref.energy_allowance)
    return Verdict(c, ratio, meets)
