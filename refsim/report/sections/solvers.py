"""Report section: the ODE solvers (S6) and the particle system (S10).

Claims C5-C10. Every number comes from a ``measure_*`` function of
:mod:`refsim.studies.solvers` or :mod:`refsim.studies.particles` (or from the
stability polynomial of :mod:`refsim.solvers.stability`); this module only
arranges them into charts, tables and verdicts (STYLE.md, rule 9).

The full report runs each measurement with the parameters of its command
line (``python -m refsim.studies.solvers ...``,
``python -m refsim.studies.particles ...``), so each table can be checked
with the command named under it. ``ctx.quick`` drops the Kepler problem from
the order study, caps step counts and shrinks the particle systems: the
section then takes seconds, not a minute, and its numbers differ from the
full run's where its captions say so.

The measurement functions seed their own random states (the particle
systems' ``seed``); none depends on ``ctx.seed``, so their figures are the
same bytes on every run. Only wall times vary, and they sit under keys that
name them (``wall_time``, ``cost_ratio``, ``..._time``); the one verdict that
quotes a timing (C5, the cost ratio of quadratic drag) is marked
``timing=True``.
"""

from __future__ import annotations

import math
from dataclasses import asdict

import numpy as np

from refsim.report.charts import Series, contour_chart, line_chart
from refsim.report.section import Agreement, Figure, Section, Table, Verdict

METHODS = ("euler", "averaged-euler", "backwards-euler", "midpoint", "rk4")
SCIPY = ("scipy-RK45", "scipy-DOP853")

#: matplotlib styles: a marker shape per method, so that methods whose points
#: coincide (averaged-euler and midpoint on linear problems: the same R(z))
#: stay visible on top of each other; scipy's adaptive runs dashed.
STYLES = {"euler": "o-", "averaged-euler": "s--", "backwards-euler": "^-",
          "midpoint": "x:", "rk4": "D-", "scipy-RK45": "v--", "scipy-DOP853": "*--"}

#: Chart size in inches (the page is about 11 inches wide).
CHART_SIZE = (7.0, 4.2)

#: An observed order counts as the stated one when it is this close: the
#: fitted slopes of the five solvers sit within 0.05 of an integer (the next
#: error term's share over a factor 4 in h), and integers are 1 apart.
ORDER_MATCH_TOL = 0.25

#: Steps of the resting-contact (jitter) study; the quick run leaves out 1 ms
#: (5000 steps a solver), which only confirms that the hop scales as h^2.
JITTER_STEPS_FULL = (1 / 30, 1 / 100, 1 / 1000)
JITTER_STEPS_QUICK = (1 / 30, 1 / 100)

#: The step whose hop the verdicts quote (as measure_solver_choice does).
JITTER_QUOTED_STEP = 1 / 100

#: Drag coefficient of the "damped" jitter runs: k/m = 1/s, a strong drag
#: (terminal speed 9.8 m/s) that still does not stop Euler's hop.
JITTER_DAMPED_DRAG = 1.0

#: Euler's hop must exceed the others' by this factor to count as the jitter
#: C6 describes (measured: about 44 times; a factor 10 is "clearly more", far
#: from both the measured value and from "alike").
JITTER_FACTOR = 10.0

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

#: C8/C9 budget and target, the defaults of measure_solver_choice.
TARGET_FREE = 1e-4
BUDGET_WALLS = 512

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

#: C8/C9: two costs (evaluations to reach TARGET_FREE) or two errors at
#: BUDGET_WALLS evaluations are tied when they differ by less than this,
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

PROBLEM_TITLES = {
    "exponential-decay": "exponential decay y' = -y",
    "harmonic-oscillator": "harmonic oscillator, one period",
    "projectile-linear-drag": "projectile with linear drag",
    "kepler": "Kepler orbit, e = 0.5, one period",
    "particles": "20 particles, quadratic drag, no walls",
}

CMD_SOLVERS = "python -m refsim.studies.solvers"
CMD_PARTICLES = "python -m refsim.studies.particles"


# -- formatting helpers (no arithmetic on the measurements) --------------------------


def _jsonable(value):
    """Dataclasses, numpy values and non-finite floats as plain JSON values.

    ``inf`` ("never reached", "no limit") and ``nan`` ("not defined") become
    None, so that results.json is strict JSON; the tables print them.
    """
    if hasattr(value, "__dataclass_fields__"):
        value = asdict(value)
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def _g(x, digits: int = 3) -> str:
    """A number for a table cell; inf and nan in words."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    if isinstance(x, float) and math.isinf(x):
        return "never" if x > 0 else "-inf"
    return f"{x:.{digits}g}"


def _order(x) -> str:
    """An observed order (a fitted slope), to the 0.001 it is meaningful to."""
    return "n/a" if x is None or math.isnan(x) else f"{x:.3f}"


def _evaluations(x: float) -> str:
    """Evaluations to reach a target; inf is "never" (not within the runs)."""
    return "never" if math.isinf(x) else f"{x:.3g}"


# -- the measurements, with the quick/full parameters ----------------------------------


def _measure(ctx) -> dict:
    """Run every measurement of the section; returns the raw objects."""
    from refsim.solvers.problems import exponential_decay, harmonic_oscillator, kepler_orbit
    from refsim.studies import particles as pm
    from refsim.studies import solvers as sm

    quick = ctx.quick
    say = ctx.progress.announce
    m = {}

    say("solvers: orders of convergence")
    problems = sm.standard_problems()
    if quick:
        # Kepler needs 10^5-step Euler runs: the full report only. The others
        # stop at a quarter of STEP_RANGE's most steps, which still leaves each
        # solver three points inside the fitted error window.
        del problems["kepler"]
        m["orders"] = {}
        for name, problem in problems.items():
            lo, hi = sm.STEP_RANGE[name]
            steps = [lo * 2**k for k in range(int(math.log2(hi // lo)) - 1)]
            y_ref = sm.reference_at_t1(problem)
            for method in METHODS:
                m["orders"][(name, method)] = sm.measure_convergence(problem, method, steps,
                                                                     y_ref=y_ref)
    else:
        m["orders"] = sm.measure_orders(problems)

    say("solvers: the seed's literal RK4 weights")
    literal_problems = ([harmonic_oscillator()] if quick
                        else [exponential_decay(), harmonic_oscillator(), kepler_orbit()])
    m["seed_literal"] = [(p.name, sm.measure_seed_literal_rk4(p)) for p in literal_problems]

    say("solvers: stability limits")
    m["stability"] = sm.measure_stability()
    m["energy"] = sm.measure_oscillator_energy()

    say("solvers: work-precision, Kepler")
    repeats = 2 if quick else 3
    m["repeats"] = repeats
    if quick:
        lo, _ = sm.STEP_RANGE["kepler"]
        m["wp_kepler"] = sm.measure_work_precision(
            steps=[lo * 2**k for k in range(8)], tolerances=sm.SCIPY_TOLERANCES[:8],
            repeats=repeats)
    else:
        m["wp_kepler"] = sm.measure_work_precision(repeats=repeats)

    say("solvers: work-precision, particle system")
    count = 50 if quick else 200
    m["particle_count"] = count
    free_config = pm.particle_test_config(count=count)
    walls_config = pm.particle_test_config(count=count, walls=True)
    m["wp_free"] = pm.measure_particle_work_precision(free_config, repeats=repeats)
    say("solvers: work-precision, particle system with walls")
    wall_steps = pm.PARTICLE_STEPS if quick else pm.PARTICLE_STEPS + (2048, 4096)
    m["wp_walls"] = pm.measure_particle_work_precision(walls_config, steps=wall_steps,
                                                       repeats=repeats)
    m["wall_orders"] = pm.observed_orders(m["wp_walls"])
    m["free_orders"] = pm.observed_orders(m["wp_free"])

    say("solvers: resting contact")
    steps = JITTER_STEPS_QUICK if quick else JITTER_STEPS_FULL
    m["jitter"] = pm.measure_jitter_table(steps=steps)
    m["jitter_damped"] = pm.measure_jitter_table(steps=steps, drag=JITTER_DAMPED_DRAG)
    m["jitter_predicted"] = {
        h: {"euler": pm.euler_jitter_estimate(h, 0.8),
            "order-2-or-more": pm.exact_integrator_hop(h, 0.8)} for h in steps}

    say("solvers: drag models")
    m["drag"] = (pm.measure_drag_models(count=20_000, repeats=3) if quick
                 else pm.measure_drag_models())

    say("solvers: frame-step differences")
    m["frame_free"] = pm.measure_frame_step_difference(free_config)
    m["frame_walls"] = pm.measure_frame_step_difference(walls_config)

    say("solvers: which solver (C9)")
    if quick:
        # measure_solver_choice runs its own work-precision study (up to 16384
        # steps per solver, ~5 s whatever the particle count); the quick report
        # reads the same facts off the runs above with the same helpers.
        m["choice_count"] = count
        m["choice_max_steps"] = max(pm.PARTICLE_STEPS)
        m["choice"] = _quick_choice(m)
    else:
        m["choice_count"] = 50
        m["choice_max_steps"] = 8 * 2**11        # measure_solver_choice's largest run
        m["choice"] = pm.measure_solver_choice(target_free=TARGET_FREE,
                                               budget_walls=BUDGET_WALLS,
                                               count=m["choice_count"])
    return m


def _quick_choice(m) -> list:
    """:class:`refsim.studies.particles.SolverChoice` rows from the quick
    run's measurements, by the helpers measure_solver_choice itself uses."""
    from refsim.solvers.methods import SOLVERS
    from refsim.studies.particles import SolverChoice
    from refsim.studies.solvers import cost_for_error, error_at_cost

    limits = {s.method: s for s in m["stability"]}
    hop = {j.method: j.max_height_gh2 for j in m["jitter"]
           if abs(j.h - JITTER_QUOTED_STEP) < 1e-12}
    return [SolverChoice(name, method.order, method.stages, limits[name].drag_predicted,
                         limits[name].oscillator_predicted,
                         cost_for_error(m["wp_free"], name, TARGET_FREE),
                         error_at_cost(m["wp_walls"], name, BUDGET_WALLS), hop[name])
            for name, method in SOLVERS.items()]


# -- building blocks --------------------------------------------------------------


def _convergence(m):
    from refsim.solvers.methods import SOLVERS
    from refsim.studies.solvers import ERROR_CEILING_REL, ERROR_FLOOR_REL, FIT_POINTS

    problems = list(dict.fromkeys(p for p, _ in m["orders"]))
    figures = []
    for problem in problems:
        series = []
        for method in METHODS:
            c = m["orders"][(problem, method)]
            series.append(Series(f"{method} (slope {_order(c.order)})", c.h, c.error,
                                 STYLES[method]))
        figures.append(Figure(
            id=f"solvers-convergence-{problem}",
            title=f"Convergence: {PROBLEM_TITLES.get(problem, problem)}",
            svg=line_chart(series, xlabel="step h", ylabel="max error at t1 / scale",
                           logx=True, logy=True, size=CHART_SIZE),
            caption=(f"Error at the end time against a DOP853 reference (rtol = atol = "
                     f"1e-13). The slope in the legend is the least-squares fit of log "
                     f"error on log h over the {FIT_POINTS} smallest steps with error in "
                     f"({ERROR_FLOOR_REL:g}, {ERROR_CEILING_REL:g}). Averaged-euler and "
                     f"midpoint coincide where f is linear (the same R(z)); euler and "
                     f"backwards-euler have errors of the same size and opposite sign. "
                     f"Reproduce: {CMD_SOLVERS} orders")))

    rows = []
    summary = []
    for method in METHODS:
        solver = SOLVERS[method]
        observed = {p: m["orders"][(p, method)].order for p in problems}
        agrees = all(abs(o - solver.seed_order) <= ORDER_MATCH_TOL for o in observed.values())
        derived_ok = all(abs(o - solver.order) <= ORDER_MATCH_TOL for o in observed.values())
        rows.append((method, *(_order(observed[p]) for p in problems), solver.order,
                     solver.seed_order, "yes" if agrees else "no"))
        summary.append({"method": method, "derived_order": solver.order,
                        "seed_order": solver.seed_order, "observed": observed,
                        "observed_matches_seed": agrees,
                        "observed_matches_derived": derived_ok})
    table = Table(
        id="solvers-orders", title="Observed, derived and stated orders (C10)",
        columns=("method", *(f"observed: {p}" for p in problems), "derived (tableau)",
                 "seed states", "seed right"),
        rows=tuple(rows),
        caption=("Observed: the fitted slopes of the convergence charts. Derived: the "
                 "largest p whose order conditions hold exactly in rational arithmetic. "
                 f"'seed right' when every observed order is within {ORDER_MATCH_TOL} of "
                 "the seed's. The seed's 'backwards Euler' uses only the second slope, "
                 "k2 at t + h: sum b_i c_i = 1, not 1/2, so it is first order. "
                 f"Reproduce: {CMD_SOLVERS} orders"))
    results = {
        "problems": problems,
        "convergence": {p: {meth: _jsonable({"h": c.h, "error": c.error, "nfev": c.nfev,
                                             "fitted": c.fitted, "order": c.order})
                            for (q, meth), c in m["orders"].items() if q == p}
                        for p in problems},
        "summary": _jsonable(summary),
    }
    return figures, table, results, summary


def _seed_literal(m):
    rows = []
    results = []
    for name, r in m["seed_literal"]:
        true = r.against_true
        rows.append((name, _g(true.h[-1], 3), _g(true.error[-1], 4), _g(r.limit_error, 4),
                     _g(r.against_scaled.order, 3)))
        results.append(_jsonable({"problem": name, "smallest_h": true.h[-1],
                                  "error_vs_true_at_smallest_h": true.error[-1],
                                  "limit_error": r.limit_error,
                                  "order_vs_scaled": r.against_scaled.order,
                                  "against_true": {"h": true.h, "error": true.error},
                                  "against_scaled": {"h": r.against_scaled.h,
                                                     "error": r.against_scaled.error}}))
    table = Table(
        id="solvers-seed-literal", title="The seed's RK4 weights read literally",
        columns=("problem", "smallest h", "error vs y' = f", "|y_(5/3 f) - y_f| at t1",
                 "order vs y' = (5/3) f"),
        rows=tuple(rows),
        caption=("The seed's RK4 combines its four slopes as 1/6, 2/3, 2/3, 1/6, which sum "
                 "to 5/3, not 1: a typo for 1/6, 1/3, 1/3, 1/6. Read literally, the method "
                 "converges to the solution of y' = (5/3) f (first order), and its error "
                 "against y' = f stays at the gap between the two solutions however small "
                 "h is. refsim's rk4 uses the classical weights (marked DEVIATION in "
                 f"refsim/solvers/methods.py). Reproduce: {CMD_SOLVERS} seed-literal"))
    return table, results


def _stability(m):
    from refsim.solvers.methods import SOLVERS
    from refsim.solvers.stability import stability_grid, stability_polynomial

    grid = {"re": (-5.5, 1.5), "im": (-3.5, 3.5), "n": 281}
    polys = {name: stability_polynomial(SOLVERS[name]) for name in METHODS}
    # Methods with the same R(z) share one curve (averaged-euler and midpoint).
    groups: dict[tuple, list[str]] = {}
    for name in METHODS:
        groups.setdefault(polys[name], []).append(name)
    fields = []
    x = y = None
    for names in groups.values():
        x, y, absR = stability_grid(SOLVERS[names[0]], re=grid["re"], im=grid["im"],
                                    n=grid["n"])
        label = " = ".join(names) + (" (same R)" if len(names) > 1 else "")
        fields.append((label, absR))
    figure = Figure(
        id="solvers-stability-regions", title="Stability regions |R(z)| = 1",
        svg=contour_chart(x, y, fields, 1.0, xlabel="Re z = Re(h lambda)",
                          ylabel="Im z = Im(h lambda)", size=(6.5, 5.6)),
        caption=("Each curve bounds the set of z = h lambda where one step of y' = lambda y "
                 "does not grow; the stable set is the inside of the curve. Stiff drag lies on the "
                 "negative real axis (z = -h k/m), an undamped oscillation on the imaginary "
                 "axis (z = i h omega). Euler, averaged-euler and midpoint only touch the "
                 "imaginary axis at 0, so they amplify every oscillation; rk4 and the "
                 "seed's backwards-euler (R = 1 + z + z^2) contain a piece of it. "
                 f"Reproduce: {CMD_SOLVERS} stability"))

    rows = []
    for s in m["stability"]:
        coeffs = " + ".join(
            "1" if j == 0 else ("" if c == 1 else f"{c} ") + "z" + (f"^{j}" if j > 1 else "")
            for j, c in enumerate(polys[s.method]))
        rows.append((s.method, coeffs, _g(s.drag_predicted, 6), _g(s.drag_measured, 6),
                     _g(s.oscillator_predicted, 6), _g(s.oscillator_measured, 6)))
    table = Table(
        id="solvers-stability", title="Largest stable step: predicted and measured",
        columns=("method", "R(z)", "drag h k/m: predicted", "measured",
                 "oscillator h omega: predicted", "measured"),
        rows=tuple(rows),
        caption=("Predicted: where |R|^2 - 1 first turns positive along the axis (exact "
                 "polynomial, bisection). Measured: the largest step at which 400 steps do "
                 "not grow the state: for drag, one particle of the particle system with "
                 "k = 1 (no gravity, no walls); for the oscillator, x'' = -x. 0 means it "
                 "grows at every step tried. Reproduce: "
                 f"{CMD_SOLVERS} stability"))

    omegas = list(dict.fromkeys(e.omega_h for e in m["energy"]))
    energy_rows = []
    for method in METHODS:
        cells = {e.omega_h: e for e in m["energy"] if e.method == method}
        energy_rows.append((method, *(f"{cells[w].measured:.6g} ({cells[w].predicted:.6g})"
                                      for w in omegas)))
    energy = Table(
        id="solvers-energy", title="Energy per period of an undamped oscillator",
        columns=("method", *(f"h omega = {w:g}" for w in omegas)),
        rows=tuple(energy_rows),
        caption=("E(T)/E(0) per period T = 2 pi of x'' = -x, measured over 10 periods "
                 "(predicted |R(i h omega)|^(2T/h) in brackets). Above 1 the motion gains "
                 "energy every period: the seed's bodies swing ever wider with euler, "
                 "averaged-euler and midpoint; backwards-euler damps. "
                 f"Reproduce: {CMD_SOLVERS} energy"))
    results = {
        "stability_polynomials": {name: [str(c) for c in p] for name, p in polys.items()},
        "stability_grid": _jsonable(grid),
        "limits": _jsonable(m["stability"]),
        "oscillator_energy": _jsonable(m["energy"]),
    }
    return figure, table, energy, results


def _wp_series(points, cost):
    series = []
    for method in (*METHODS, *SCIPY):
        pts = [p for p in points if p.method == method]
        if not pts:
            continue
        # In the order of the runs (rising cost in evaluations) on both charts,
        # so that timing noise shows as a wiggle along x, not as a zigzag.
        pts.sort(key=lambda p: p.nfev)
        series.append(Series(method, [getattr(p, cost) for p in pts],
                             [p.error for p in pts], STYLES[method]))
    return series


def _work_precision(m):
    cases = (
        ("kepler", m["wp_kepler"], "Kepler orbit (e = 0.5, one period)",
         "relative error at t1", f"{CMD_SOLVERS} work-precision"),
        ("particles-free", m["wp_free"],
         f"{m['particle_count']} particles, quadratic drag, no walls",
         "max position error at t1 (m)", f"{CMD_PARTICLES} work-precision"),
        ("particles-walls", m["wp_walls"],
         f"{m['particle_count']} particles, quadratic drag, in the cube",
         "max position error at t1 (m)", f"{CMD_PARTICLES} work-precision-walls"),
    )
    figures = []
    for key, points, title, ylabel, command in cases:
        for cost, xlabel in (("nfev", "evaluations of f (whole system)"),
                             ("wall_time", "wall time (s)")):
            if key == "particles-walls":
                runs = ("Fixed-step solvers over halving steps. scipy's methods are not "
                        "shown: without event location they step through the walls (the "
                        "reference here is DOP853 stopped at each contact, tolerance "
                        "1e-13).")
            else:
                runs = ("Fixed-step solvers over halving steps (solid), scipy's adaptive "
                        "RK45 and DOP853 with rtol = atol from 1e-3 down (dashed).")
            figures.append(Figure(
                id=f"solvers-wp-{key}-{'nfev' if cost == 'nfev' else 'time'}",
                title=f"Work-precision, {title}: error against "
                      f"{'evaluations' if cost == 'nfev' else 'wall time'}",
                svg=line_chart(_wp_series(points, cost), xlabel=xlabel, ylabel=ylabel,
                               logx=True, logy=True, size=CHART_SIZE),
                caption=(runs
                         + f" Wall time: best of {m['repeats']} runs."
                         + f" Reproduce: {command}")))
    results = {
        "kepler": _jsonable(m["wp_kepler"]),
        "particles_free": _jsonable(m["wp_free"]),
        "particles_walls": _jsonable(m["wp_walls"]),
        "particle_count": m["particle_count"],
        "observed_orders_free": _jsonable(m["free_orders"]),
        "observed_orders_walls": _jsonable(m["wall_orders"]),
    }
    return figures, results


def _jitter(m):
    quoted = {}
    rows = []
    for j, d in zip(m["jitter"], m["jitter_damped"], strict=True):
        pred = m["jitter_predicted"][j.h]
        if j.method == "euler":
            predicted = f"~{pred['euler']:.3g} (estimate)"
        elif j.method == "backwards-euler":
            predicted = "0"
        else:
            predicted = f"{pred['order-2-or-more']:.4g}"
        rows.append((j.method, f"1/{round(1 / j.h)}", f"{j.max_height:.3g}",
                     f"{j.max_height_gh2:.4g}", predicted, f"{j.rms_velocity:.3g}",
                     f"{j.bounces_per_second:g}", f"{d.max_height_gh2:.4g}"))
        if abs(j.h - JITTER_QUOTED_STEP) < 1e-12:
            quoted[j.method] = (j, d)
    table = Table(
        id="solvers-jitter", title="Resting contact: how far a particle at rest hops (C6, C7)",
        columns=("method", "h (s)", "hop (m)", "hop / (g h^2)", "predicted hop (m)",
                 "rms vertical v (m/s)", "bounces/s", f"hop / (g h^2), drag k = "
                 f"{JITTER_DAMPED_DRAG:g}"),
        rows=tuple(rows),
        caption=("One particle placed at rest on the floor (restitution 0.8, no friction), "
                 "5 s simulated, measured over the last second. Predicted: Euler gains "
                 "g^2 h^2 / 2 of energy every step in free fall, which the bounces balance "
                 "at a hop of about 2 g h^2 / (1 - e^2)^2; methods of order 2 or more are "
                 "exact for constant gravity and settle into a two-step cycle of height "
                 "(3e - 1) / (2 (1 + e)) g h^2 = 7/18 g h^2; backwards-euler sinks each step, "
                 "is pushed back, and never rises. The last column repeats the run with "
                 "strong linear drag (k/m = 1/s): it does not stop Euler's hop. "
                 f"Reproduce: {CMD_PARTICLES} jitter"))
    results = {"undamped": _jsonable(m["jitter"]), "damped": _jsonable(m["jitter_damped"]),
               "damped_drag": JITTER_DAMPED_DRAG,
               "predicted": _jsonable([{"h": h, **p} for h, p in
                                       m["jitter_predicted"].items()])}
    return table, results, quoted


def _drag(m):
    d = m["drag"]
    table = Table(
        id="solvers-drag", title="Quadratic against linear drag (C5)",
        columns=("quantity", "value"),
        rows=(("common terminal speed v_T (m/s)", _g(d.terminal_speed)),
              ("k linear = m g / v_T", _g(d.k_linear, 4)),
              ("k quadratic = m g / v_T^2", _g(d.k_quadratic, 4)),
              ("largest distance between the paths, same v_T (m)",
               _g(d.same_terminal_difference, 4)),
              ("path length, linear drag (m)", _g(d.same_terminal_distance, 4)),
              ("largest distance, same k (m)", _g(d.same_k_difference, 4))),
        caption=("A projectile launched at 15 m/s, 45 degrees, for 2 s; both paths by the "
                 "DOP853 reference, so the difference is the force law's, not a solver's. "
                 f"Cost: in this run a quadratic-drag Euler step of a free particle system "
                 f"took {d.cost_ratio:.2g} times as long as a linear-drag one (best of "
                 "several; wall time varies from run to run, so it is kept out of the "
                 f"table). Reproduce: {CMD_PARTICLES} drag"))
    return table, _jsonable(d)


def _c8_c9(m):
    choice = {c.method: c for c in m["choice"]}
    ff, fw = m["frame_free"], m["frame_walls"]
    first_order, walls_clause = _wall_orders_clause(m)
    rows = []
    for method in METHODS:
        c = choice[method]
        rows.append((method, c.stages, c.order, _order(m["free_orders"].get(method)),
                     _order(m["wall_orders"].get(method)), _g(c.nfev_free, 4),
                     _g(c.error_walls_at_budget, 3), _g(ff.difference[method], 3),
                     _g(fw.difference[method], 3)))
    c8 = Table(
        id="solvers-c8", title="Is RK4 worth its cost in a particle system? (C8)",
        columns=("method", "evaluations / step", "order (tableau)", "observed order, free",
                 "observed order, walls", f"evaluations to {TARGET_FREE:g} m, free",
                 f"error (m) at {BUDGET_WALLS} evaluations, walls",
                 "difference from rk4 at h = 1/60 (m), free", "same, walls"),
        rows=tuple(rows),
        caption=("Particle systems with quadratic drag (speeds 1-5 m/s, cube of half size "
                 "2 m, e = 0.8, friction 0.1), 1 s simulated. Observed orders from the "
                 f"work-precision runs ({m['particle_count']} particles); evaluations and "
                 f"errors at a budget from {m['choice_count']} particles, interpolated "
                 "log-log between runs ('never': not reached with up to "
                 f"{m['choice_max_steps']} steps). "
                 + walls_clause[0].upper() + walls_clause[1:]
                 + (": a contact between steps is caught up to a step late" if first_order
                    else "")
                 + f". Reproduce: {CMD_PARTICLES} choice; {CMD_PARTICLES} frame"))
    rows = []
    for method in METHODS:
        c = choice[method]
        rows.append((method, c.stages, c.order, _g(c.drag_limit, 4),
                     _g(c.oscillator_limit, 4), _g(c.nfev_free, 4),
                     _g(c.error_walls_at_budget, 3), _g(c.hop_height_gh2, 4)))
    c9 = Table(
        id="solvers-c9", title="Which solver in general? (C9)",
        columns=("method", "evaluations / step", "order", "stable drag h k/m",
                 "stable oscillator h omega", f"evaluations to {TARGET_FREE:g} m, free",
                 f"error (m) at {BUDGET_WALLS} evaluations, walls",
                 "resting hop / (g h^2), h = 0.01"),
        rows=tuple(rows),
        caption=("The facts the seed's choice rests on, side by side: cost per step, "
                 "accuracy without and with walls, stability for stiff drag and for "
                 "oscillation, and resting contact. Reproduce: "
                 f"{CMD_PARTICLES} choice"))
    results = {"choice": _jsonable(m["choice"]), "choice_count": m["choice_count"],
               "frame_free": _jsonable(ff), "frame_walls": _jsonable(fw),
               "target_free": TARGET_FREE, "budget_walls": BUDGET_WALLS,
               "choice_max_steps": m["choice_max_steps"]}
    return c8, c9, results, choice


# -- verdicts ----------------------------------------------------------------------


def _tied(a: float, b: float, rtol: float) -> bool:
    """Two measured values within ``rtol`` of each other, relative; inf ties
    only with inf, nan with nothing."""
    if math.isnan(a) or math.isnan(b):
        return False
    if math.isinf(a) or math.isinf(b):
        return a == b
    return _relative_difference(a, b) <= rtol


def _lower(a: float, b: float, rtol: float) -> bool:
    """``a`` below ``b`` by more than a tie (nan is never lower)."""
    return a < b and not _tied(a, b, rtol)


def _rank(value: float, others: dict, rtol: float) -> str:
    """Where ``value`` stands among ``others`` (method -> value): "the lowest",
    "the highest", "tied lowest with ...", "tied highest with ..." or "between
    the others"."""
    ties = [k for k, v in others.items() if _tied(value, v, rtol)]
    rest = [v for k, v in others.items() if k not in ties]
    lowest = all(_lower(value, v, rtol) for v in rest)
    highest = all(_lower(v, value, rtol) for v in rest)
    if ties and len(ties) == len(others):
        return "the same as all the others"
    tied = f"tied with {', '.join(ties)} for " if ties else ""
    if lowest:
        return f"{tied}the lowest"
    if highest:
        return f"{tied}the highest"
    return "between the others"


def _listing(values: dict, fmt) -> str:
    return ", ".join(f"{k} {fmt(v)}" for k, v in values.items())


def _wall_orders_clause(m) -> tuple[bool, str]:
    """Whether every observed order with walls is first order (within
    ORDER_MATCH_TOL of 1), and a clause saying so with the orders."""
    orders = {k: m["wall_orders"][k] for k in METHODS}
    first = all(abs(o - 1) <= ORDER_MATCH_TOL for o in orders.values())
    listed = _listing(orders, lambda o: f"{o:.2f}")
    if first:
        return True, f"with walls every method is first order (observed {listed})"
    return False, (f"with walls the observed orders are {listed}, not all within "
                   f"{ORDER_MATCH_TOL} of 1")


def _verdicts(m, summary, quoted, choice):
    from refsim.solvers.methods import SOLVERS
    from refsim.solvers.stability import stability_polynomial

    verdicts = []
    by = {s["method"]: s for s in summary}

    def span(method):
        values = list(by[method]["observed"].values())
        lo, hi = min(values), max(values)
        return f"{lo:.2f}" if f"{lo:.2f}" == f"{hi:.2f}" else f"{lo:.2f}-{hi:.2f}"

    def why(method):
        """The order conditions (up to the stated order) the tableau fails."""
        solver = SOLVERS[method]
        if solver.row_sums() != solver.c:
            return "c_i != sum_j a_ij"
        failing = [f"{name.split(' = ')[0]} = {value}, not {want}"
                   for p, name, value, want in solver.order_conditions()
                   if p <= solver.seed_order and value != want]
        if failing:
            return "; ".join(failing)
        return (f"it meets every condition of order {solver.seed_order}; the fitted slopes "
                "miss it")

    wrong = [s["method"] for s in summary if not s["observed_matches_seed"]]
    right = [s["method"] for s in summary if s["observed_matches_seed"]]
    c10 = "confirmed" if not wrong else ("refuted" if not right else "partly")
    verdicts.append(Verdict(
        claim="C10",
        measured=("Observed orders on {n} problems: {orders}; {wrong}".format(
            n=len(next(iter(summary))["observed"]),
            orders=", ".join(f"{s['method']} {span(s['method'])}" for s in summary),
            wrong=("; ".join(f"{w} is order {SOLVERS[w].order} by its tableau ({why(w)}), "
                             f"not {SOLVERS[w].seed_order} as stated" for w in wrong)
                   + ("; the others match." if right else ".")) if wrong
            else "all as stated.")),
        verdict=c10, evidence="solvers-orders", command=f"{CMD_SOLVERS} orders"))

    h = JITTER_QUOTED_STEP
    ej, ed = quoted["euler"]
    others = {k: v[0].max_height_gh2 for k, v in quoted.items() if k != "euler"}
    c6 = "confirmed" if ej.max_height_gh2 > JITTER_FACTOR * max(others.values()) else "refuted"
    hops_by_h: dict[str, dict[float, float]] = {}
    for j in m["jitter"]:
        hops_by_h.setdefault(j.method, {})[j.h] = j.max_height_gh2
    steps = sorted({j.h for j in m["jitter"]}, reverse=True)
    hopping = {k: v for k, v in hops_by_h.items() if all(x > 0 for x in v.values())}
    if len(steps) > 1 and hopping:
        scales = all(_tied(min(v.values()), max(v.values()), HOP_SCALING_RTOL)
                     for v in hopping.values())
        spread = ("Euler's hop / (g h^2) is "
                  + ", ".join(f"{hops_by_h['euler'][s]:.3g} at h = 1/{round(1 / s)}"
                              for s in steps))
        scaling = (f" {spread}: the jitter is bounded (for every method that hops, a hop "
                   f"that scales as h^2 to within {HOP_SCALING_RTOL:.0%}), not a growing "
                   "instability." if scales else
                   f" {spread}: the hop does not scale as h^2 (to within "
                   f"{HOP_SCALING_RTOL:.0%}) for every method that hops.")
    else:
        scaling = ""
    verdicts.append(Verdict(
        claim="C6",
        measured=(f"A particle at rest on the floor (e = 0.8, h = 1/{round(1 / h)} s) hops "
                  f"{ej.max_height:.3g} m = {ej.max_height_gh2:.3g} g h^2 with Euler "
                  f"(still {ed.max_height_gh2:.3g} g h^2 with drag k/m = "
                  f"{JITTER_DAMPED_DRAG:g}/s) against "
                  + ", ".join(f"{v:.3g} g h^2 for {k}" for k, v in others.items())
                  + " (Euler gains g^2 h^2/2 of energy a step in flight)." + scaling),
        verdict=c6, evidence="solvers-jitter", command=f"{CMD_PARTICLES} jitter"))

    limits = {s.method: s for s in m["stability"]}
    four = ("averaged-euler", "backwards-euler", "midpoint", "rk4")
    hop4 = {k: quoted[k][0].max_height_gh2 for k in four}
    pairs = [(a, b) for i, a in enumerate(four) for b in four[i + 1:]]

    def order_alike(a, b):
        oa, ob = by[a]["observed"], by[b]["observed"]
        return all(abs(oa[p] - ob[p]) <= ORDER_MATCH_TOL for p in oa)

    def stability_alike(a, b):
        la, lb = limits[a], limits[b]
        return (_tied(la.drag_measured, lb.drag_measured, ALIKE_RTOL)
                and _tied(la.oscillator_measured, lb.oscillator_measured, ALIKE_RTOL))

    def hop_alike(a, b):
        return _tied(hop4[a], hop4[b], ALIKE_RTOL)

    agree = {"order": all(order_alike(a, b) for a, b in pairs),
             "stability": all(stability_alike(a, b) for a, b in pairs),
             "resting hop": all(hop_alike(a, b) for a, b in pairs)}
    alike = [(a, b) for a, b in pairs
             if order_alike(a, b) and stability_alike(a, b) and hop_alike(a, b)]
    if all(agree.values()):
        c7 = "confirmed"
    elif not agree["order"] and not agree["stability"]:
        c7 = "refuted"
    else:
        c7 = "partly"
    same_r = {pair: stability_polynomial(SOLVERS[pair[0]]) == stability_polynomial(
        SOLVERS[pair[1]]) for pair in alike}
    pairs_text = ("; ".join(f"{a} and {b}" + (" (the same R(z))" if same_r[(a, b)] else "")
                            for a, b in alike) if alike else "none")
    verdicts.append(Verdict(
        claim="C7",
        measured=("Observed orders {orders}; stable drag step h k/m up to {drag}; "
                  "undamped oscillation stable for h omega up to {osc} (0: amplified at "
                  "every step); resting hop {hop} g h^2. The four {o} in order, {s} in "
                  "stability and {r} in resting hop (alike: orders within {otol}, limits "
                  "and hops within {rtol:.0%}). Pairs alike in all of these: {pairs}.").format(
                      orders=", ".join(f"{k} {span(k)}" for k in four),
                      drag=", ".join(f"{k} {limits[k].drag_measured:.3g}" for k in four),
                      osc=", ".join(f"{k} {limits[k].oscillator_measured:.3g}" for k in four),
                      hop=", ".join(f"{k} {hop4[k]:.3g}" for k in four),
                      o="agree" if agree["order"] else "differ",
                      s="agree" if agree["stability"] else "differ",
                      r="agree" if agree["resting hop"] else "differ",
                      otol=ORDER_MATCH_TOL, rtol=ALIKE_RTOL, pairs=pairs_text),
        verdict=c7, evidence="solvers-stability", command=f"{CMD_SOLVERS} stability"))

    # C8: is rk4 better than the best of the others at equal cost?
    nfev_free = {k: c.nfev_free for k, c in choice.items()}
    wall_errors = {k: c.error_walls_at_budget for k, c in choice.items()}
    rest = [k for k in METHODS if k != "rk4"]

    def best_of(values):
        finite = [k for k in rest if not math.isnan(values[k])]
        return min(finite, key=lambda k: values[k]) if finite else None

    best_free, best_walls = best_of(nfev_free), best_of(wall_errors)
    rk4_free = best_free is not None and _lower(nfev_free["rk4"], nfev_free[best_free],
                                                COST_TIE_RTOL)
    rk4_walls = best_walls is not None and _lower(wall_errors["rk4"], wall_errors[best_walls],
                                                  COST_TIE_RTOL)
    c8 = ("refuted" if rk4_free and rk4_walls
          else "confirmed" if not (rk4_free or rk4_walls) else "partly")
    _, walls_clause = _wall_orders_clause(m)
    second = [k for k in METHODS if choice[k].order == 2]
    ff, fw = m["frame_free"], m["frame_walls"]
    edge = 2 * ff.half_size
    visible = VISIBLE_FRACTION * edge

    def seen(frame):
        return ("above" if any(frame.difference[k] > visible for k in second)
                else "below")

    verdicts.append(Verdict(
        claim="C8",
        measured=(f"Without walls rk4 reaches {TARGET_FREE:g} m with "
                  f"{_evaluations(nfev_free['rk4'])} force evaluations against "
                  + ", ".join(f"{_evaluations(nfev_free[k])} for {k}" for k in rest)
                  + f" (never: not within {m['choice_max_steps']} steps): "
                  + ("fewer than" if rk4_free else "not fewer than")
                  + f" the best of the others ({best_free}). "
                  + walls_clause[0].upper() + walls_clause[1:]
                  + f", and at {BUDGET_WALLS} evaluations rk4's error is "
                  f"{wall_errors['rk4']:.3g} m against "
                  + ", ".join(f"{_g(wall_errors[k])} m for {k}" for k in rest)
                  + (": lower than" if rk4_walls else ": not lower than")
                  + f" the best of the others ({best_walls}). At a 1/60 s frame step rk4 "
                    "and the second-order methods ("
                  + ", ".join(second) + ") end up "
                  + ", ".join(f"{ff.difference[k]:.2g}" for k in second)
                  + f" m apart without walls, {seen(ff)} the {visible:.2g} m a viewer "
                    f"could see (one pixel of a 1000-pixel view of the {edge:g} m cube), and "
                  + ", ".join(f"{fw.difference[k]:.2g}" for k in second)
                  + f" m with walls, {seen(fw)} it. Better than every other method at equal "
                    f"cost (by more than {COST_TIE_RTOL:.0%}): "
                  + ("yes" if rk4_free else "no") + " without walls, "
                  + ("yes" if rk4_walls else "no") + " with walls."),
        verdict=c8, evidence="solvers-c8", command=f"{CMD_PARTICLES} choice"))

    def _reaches(nfev: float) -> str:
        if math.isinf(nfev):
            return f"never reaches {TARGET_FREE:g} m within {m['choice_max_steps']} steps"
        return f"reaches {TARGET_FREE:g} m after {nfev:.3g} evaluations"

    name = "backwards-euler"
    be = choice[name]
    peers = [k for k in METHODS if k != name and choice[k].stages == be.stages]
    others9 = [k for k in METHODS if k != name]
    peer_orders = ", ".join(f"{k} {choice[k].order}" for k in peers)
    relation = ("lower than" if all(be.order < choice[k].order for k in peers)
                else "higher than" if all(be.order > choice[k].order for k in peers)
                else "equal to" if all(be.order == choice[k].order for k in peers)
                else "against")
    drag9 = {k: choice[k].drag_limit for k in others9}
    osc_stable = [k for k in others9 if choice[k].oscillator_limit > 0]
    hop9 = {k: choice[k].hop_height_gh2 for k in others9}
    free_best = all(not _lower(nfev_free[k], be.nfev_free, COST_TIE_RTOL) for k in others9)
    walls_best = all(not _lower(wall_errors[k], be.error_walls_at_budget, COST_TIE_RTOL)
                     for k in others9) and not math.isnan(be.error_walls_at_budget)
    free_best = free_best and not math.isnan(be.nfev_free)
    walls9 = {k: wall_errors[k] for k in others9}
    drag_rank = _rank(be.drag_limit, drag9, ALIKE_RTOL)
    hop_rank = _rank(be.hop_height_gh2, hop9, ALIKE_RTOL)
    walls_rank = _rank(be.error_walls_at_budget, walls9, COST_TIE_RTOL)
    c9 = ("confirmed" if free_best and walls_best
          else "refuted" if not (free_best or walls_best) else "partly")
    osc_text = (f"it is stable for oscillation up to h omega = {be.oscillator_limit:.3g}"
                if be.oscillator_limit > 0 else "it amplifies every oscillation")
    osc_text += ("; of the others only " + ", ".join(
        f"{k} ({choice[k].oscillator_limit:.3g})" for k in osc_stable) + " is"
        if osc_stable else "; none of the others is")
    verdicts.append(Verdict(
        claim="C9",
        measured=(f"Backwards-euler costs {be.stages} evaluations a step like "
                  + " and ".join(peers)
                  + f" and is order {be.order}, {relation} theirs ({peer_orders}); its stable "
                  f"drag step h k/m <= {be.drag_limit:.3g} is {drag_rank} "
                  f"(others {_listing(drag9, lambda v: f'{v:.3g}')}); {osc_text}; its resting "
                  f"hop {be.hop_height_gh2:.3g} g h^2 is {hop_rank} "
                  f"(others {_listing(hop9, lambda v: f'{v:.3g}')}). Without walls it "
                  f"{_reaches(be.nfev_free)} ("
                  + ", ".join(f"{k} {_evaluations(nfev_free[k])}" for k in others9)
                  + f" evaluations); with walls its error at {BUDGET_WALLS} evaluations is "
                  f"{_g(be.error_walls_at_budget)} m, "
                  f"{walls_rank} (others {_listing(walls9, _g)} m). Best or "
                  f"tied-best (within {COST_TIE_RTOL:.0%}) on accuracy per cost: "
                  + ("yes" if free_best else "no") + " without walls, "
                  + ("yes" if walls_best else "no") + " with walls."),
        verdict=c9, evidence="solvers-c9", command=f"{CMD_PARTICLES} choice"))

    d = m["drag"]
    significant = d.same_terminal_difference > DRAG_SIGNIFICANT_FRACTION * d.same_terminal_distance
    extra = d.cost_ratio > DRAG_EXTRA_COST_RATIO
    c5 = ("confirmed" if not significant and extra
          else "refuted" if significant and not extra else "partly")
    verdicts.append(Verdict(
        claim="C5",
        measured=(f"With the same terminal speed ({d.terminal_speed:g} m/s) a projectile "
                  f"under quadratic drag ends up to {d.same_terminal_difference:.3g} m from "
                  f"the linear-drag path over {d.same_terminal_distance:.3g} m travelled "
                  f"({d.same_k_difference:.3g} m with the same k): "
                  + ("more" if significant else "not more")
                  + f" than {DRAG_SIGNIFICANT_FRACTION:.0%} of the distance, "
                  + ("a significant" if significant else "an insignificant")
                  + f" difference. A quadratic-drag step took {d.cost_ratio:.2g} times as "
                    "long as a linear one in this run: "
                  + ("more" if extra else "not more")
                  + f" than {DRAG_EXTRA_COST_RATIO:g} times, "
                  + ("an extra cost." if extra else "no extra cost.")),
        verdict=c5, evidence="solvers-drag", command=f"{CMD_PARTICLES} drag", timing=True))
    return verdicts


# -- agreement with the oracles (the page's summary) -------------------------------------


def _relative_difference(a: float, b: float) -> float:
    return 0.0 if a == b else abs(a - b) / max(abs(a), abs(b))


def _agreements(m, summary) -> list[Agreement]:
    pairs = [(s["method"], p) for s in summary for p in s["observed"]]
    orders_ok = sum(abs(s["observed"][p] - s["derived_order"]) <= ORDER_MATCH_TOL
                    for s in summary for p in s["observed"])
    limits = [(s.drag_predicted, s.drag_measured) for s in m["stability"]] + \
             [(s.oscillator_predicted, s.oscillator_measured) for s in m["stability"]]
    limits_diff = [_relative_difference(p, q) for p, q in limits]
    energy_diff = [_relative_difference(e.predicted, e.measured) for e in m["energy"]]
    hops = [(j.max_height, m["jitter_predicted"][j.h]["order-2-or-more"]) for j in m["jitter"]
            if j.method in ("averaged-euler", "midpoint", "rk4")]
    hop_diff = [_relative_difference(a, b) for a, b in hops]
    return [
        Agreement("scipy solve_ivp (DOP853)",
                  "observed order of convergence of each solver against the order derived "
                  "from its tableau",
                  f"{orders_ok} / {len(pairs)} (solver, problem) pairs within "
                  f"{ORDER_MATCH_TOL}", f"{CMD_SOLVERS} orders"),
        Agreement("analytic",
                  "largest stable step predicted from R(z) against simulation (drag, "
                  "oscillator)",
                  f"{sum(d <= STABILITY_AGREE_RTOL for d in limits_diff)} / {len(limits)} "
                  f"within {STABILITY_AGREE_RTOL:g} relative (worst {max(limits_diff):.1g})",
                  f"{CMD_SOLVERS} stability"),
        Agreement("analytic",
                  "energy per period of an undamped oscillator against |R(i h omega)|^(2T/h)",
                  f"{sum(d <= FORMULA_AGREE_RTOL for d in energy_diff)} / {len(energy_diff)} "
                  f"within {FORMULA_AGREE_RTOL:g} relative (worst {max(energy_diff):.1g})",
                  f"{CMD_SOLVERS} energy"),
        Agreement("analytic",
                  "resting hop of averaged-euler, midpoint and rk4 against "
                  "(3e - 1) / (2 (1 + e)) g h^2",
                  f"{sum(d <= FORMULA_AGREE_RTOL for d in hop_diff)} / {len(hop_diff)} "
                  f"within {FORMULA_AGREE_RTOL:g} relative (worst {max(hop_diff):.1g})",
                  f"{CMD_PARTICLES} jitter"),
    ]


# -- the section --------------------------------------------------------------------


def build(ctx) -> Section:
    m = _measure(ctx)
    ctx.progress.announce("solvers: charts")
    conv_figures, orders_table, orders_results, summary = _convergence(m)
    literal_table, literal_results = _seed_literal(m)
    region, stability_table, energy_table, stability_results = _stability(m)
    wp_figures, wp_results = _work_precision(m)
    jitter_table, jitter_results, quoted = _jitter(m)
    drag_table, drag_results = _drag(m)
    c8_table, c9_table, choice_results, choice = _c8_c9(m)
    verdicts = _verdicts(m, summary, quoted, choice)
    agreements = _agreements(m, summary)

    intro = ("The seed's five solvers (S6) as Butcher tableaux, measured against scipy's "
             "DOP853 at tight tolerance: their order of convergence (C10), where each is "
             "stable, what a step costs against the accuracy it buys (with scipy's adaptive "
             "RK45 and DOP853 as anchors), how each behaves in resting contact (C6, C7), "
             "and in the particle system (S10) with and without walls (C8, C9), and what "
             "quadratic drag changes (C5).")
    if ctx.quick:
        intro += (" Quick run: the Kepler problem is left out of the order study, step "
                  "counts are capped, particle systems are smaller and wall times are from "
                  "one run; the full report uses the parameters of the commands named under "
                  "each table.")
    return Section(
        key="solvers", title="ODE solvers and the particle system",
        intro=intro,
        figures=[*conv_figures, region, *wp_figures],
        tables=[orders_table, literal_table, stability_table, energy_table, jitter_table,
                drag_table, c8_table, c9_table],
        verdicts=verdicts,
        agreements=agreements,
        results={
            "quick": ctx.quick,
            "non_finite_note": "null stands for inf (never reached, no limit) or nan "
                               "(too few points to fit)",
            "orders": orders_results,
            "seed_literal_rk4": literal_results,
            "stability": stability_results,
            "work_precision": wp_results,
            "jitter": jitter_results,
            "drag_models": drag_results,
            "solver_choice": choice_results,
        })
