"""Report section: the ODE solvers (S6) and the particle system (S10).

Claims C5-C10. Every number comes from the plan's records of
:mod:`refsim.studies.solvers` and :mod:`refsim.studies.particles` (and the
stability polynomials the plan reads off each tableau), every verdict and
agreement count from :mod:`refsim.claims.solvers`; this module only
arranges them into charts, tables and sentences (``docs/design.md``, Views).

The full report runs each measurement with the parameters of its command
(``refsim study solvers-orders``, ``refsim study particles-jitter``, ...), so
each table can be checked with the command named under it. A quick run
drops the Kepler problem from the order study, caps step counts and shrinks
the particle systems (:mod:`refsim.report.entries.solvers`,
:mod:`refsim.report.entries.particles`): the section then takes seconds, not
a minute, and its numbers differ from the full run's where its captions say
so.

The measurement functions seed their own random states (the particle
systems' ``seed``); none depends on the report's seed, so their figures are
the same bytes on every run. Only wall times vary: the study records mark
them (``wall_time``, ``cost_ratio``), and the one verdict that quotes a
timing (C5, the cost ratio of quadratic drag) is marked ``timing=True``.
"""

from __future__ import annotations

import math

from refsim.claims.solvers import oracle_agreement
from refsim.report.charts import Series, contour_chart, line_chart
from refsim.report.plan import claim_command, command
from refsim.report.section import Agreement, Figure, Section, Table, Verdict
from refsim.report.words import against_spread, listing

METHODS = ("euler", "averaged-euler", "backwards-euler", "midpoint", "rk4")
SCIPY = ("scipy-RK45", "scipy-DOP853")

#: matplotlib styles: a marker shape per method, so that methods whose points
#: coincide (averaged-euler and midpoint on linear problems: the same R(z))
#: stay visible on top of each other; scipy's adaptive runs dashed.
STYLES = {"euler": "o-", "averaged-euler": "s--", "backwards-euler": "^-",
          "midpoint": "x:", "rk4": "D-", "scipy-RK45": "v--", "scipy-DOP853": "*--"}

#: Chart size in inches (the page is about 11 inches wide).
CHART_SIZE = (7.0, 4.2)

PROBLEM_TITLES = {
    "exponential-decay": "exponential decay y' = -y",
    "harmonic-oscillator": "harmonic oscillator, one period",
    "projectile-linear-drag": "projectile with linear drag",
    "kepler": "Kepler orbit, e = 0.5, one period",
    "particles": "20 particles, quadratic drag, no walls",
}

CMD_ORDERS = command("solvers-orders")
CMD_SEED_LITERAL = command("solvers-seed-literal")
CMD_STABILITY = command("solvers-stability")
CMD_ENERGY = command("solvers-energy")
CMD_WORK_PRECISION = command("solvers-work-precision")
CMD_PARTICLES_WP = command("particles-work-precision")
CMD_PARTICLES_WP_WALLS = command("particles-work-precision-walls")
CMD_JITTER = command("particles-jitter")
CMD_DRAG = command("particles-drag")
CMD_FRAME = command("particles-frame")
CMD_CHOICE = command("particles-choice")


# -- formatting helpers (no arithmetic on the measurements) --------------------------


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


# -- the records, gathered from the plan ------------------------------------------------


def _measure(run) -> dict:
    """Every record of the section, by the keys the building blocks use."""
    m = {}
    orders = run.get("solvers-orders")
    m["orders"] = orders.convergence
    m["seed_literal"] = [(s.problem, s.result) for s in run.get("solvers-seed-literal")]
    m["stability_run"] = run.get("solvers-stability")
    m["stability"] = m["stability_run"].limits
    m["energy"] = run.get("solvers-energy")
    kepler = run.get("solvers-work-precision")
    m["repeats"], m["wp_kepler"] = kepler.repeats, kepler.points
    free = run.get("particles-work-precision")
    walls = run.get("particles-work-precision-walls")
    m["particle_count"] = free.count
    m["wp_free"], m["free_orders"] = free.points, free.orders
    m["wp_walls"], m["wall_orders"] = walls.points, walls.orders
    jitter = run.get("particles-jitter")
    m["jitter"], m["jitter_damped"] = jitter.undamped, jitter.damped
    m["jitter_damped_drag"], m["jitter_predicted"] = jitter.damped_drag, jitter.predicted
    m["drag"] = run.get("particles-drag")
    frame = run.get("particles-frame")
    m["frame_free"], m["frame_walls"] = frame.free, frame.walls
    choice = run.get("particles-choice")
    m["choice"], m["choice_count"], m["choice_max_steps"] = (choice.rows, choice.count,
                                                             choice.max_steps)
    m["target_free"], m["budget_walls"] = choice.target_free, choice.budget_walls
    m["claims"] = {claim: run.claim(claim) for claim in ("C10", "C6", "C7", "C8", "C9", "C5")}
    m["agreement"] = oracle_agreement(
        orders.convergence, orders.derived, m["stability"], m["energy"], m["jitter"],
        {h: p["order-2-or-more"] for h, p in m["jitter_predicted"].items()})
    m["failing"] = orders.failing
    return m


# -- building blocks --------------------------------------------------------------


def _convergence(m):
    from refsim.studies.solvers import ERROR_CEILING_REL, ERROR_FLOOR_REL, FIT_POINTS

    c10 = m["claims"]["C10"].facts
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
                     f"Reproduce: {CMD_ORDERS}")))

    rows = []
    summary = []
    for method in METHODS:
        observed = c10["observed_orders"][method]
        agrees = c10["matches_stated"][method]
        derived, stated = c10["derived_order"][method], c10["stated_order"][method]
        rows.append((method, *(_order(observed[p]) for p in problems), derived, stated,
                     "yes" if agrees else "no"))
        summary.append({"method": method, "derived_order": derived,
                        "seed_order": stated, "observed": observed,
                        "observed_matches_seed": agrees,
                        "observed_matches_derived": c10["matches_derived"][method]})
    table = Table(
        id="solvers-orders", title="Observed, derived and stated orders (C10)",
        columns=("method", *(f"observed: {p}" for p in problems), "derived (tableau)",
                 "seed states", "seed right"),
        rows=tuple(rows),
        caption=("Observed: the fitted slopes of the convergence charts. Derived: the "
                 "largest p whose order conditions hold exactly in rational arithmetic. "
                 f"'seed right' when every observed order is within {c10['order_tol']} of "
                 "the seed's. The seed's 'backwards Euler' uses only the second slope, "
                 "k2 at t + h: sum b_i c_i = 1, not 1/2, so it is first order. "
                 f"Reproduce: {CMD_ORDERS}"))
    results = {
        "problems": problems,
        "convergence": {p: {meth: {"h": c.h, "error": c.error, "nfev": c.nfev,
                                   "fitted": c.fitted, "order": c.order}
                            for (q, meth), c in m["orders"].items() if q == p}
                        for p in problems},
        "summary": summary,
    }
    return figures, table, results


def _seed_literal(m):
    rows = []
    results = []
    for name, r in m["seed_literal"]:
        true = r.against_true
        rows.append((name, _g(true.h[-1], 3), _g(true.error[-1], 4), _g(r.limit_error, 4),
                     _g(r.against_scaled.order, 3)))
        results.append({"problem": name, "smallest_h": true.h[-1],
                        "error_vs_true_at_smallest_h": true.error[-1],
                        "limit_error": r.limit_error,
                        "order_vs_scaled": r.against_scaled.order,
                        "against_true": {"h": true.h, "error": true.error},
                        "against_scaled": {"h": r.against_scaled.h,
                                           "error": r.against_scaled.error}})
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
                 f"refsim/solvers/methods.py). Reproduce: {CMD_SEED_LITERAL}"))
    return table, results


def _stability(m):
    st = m["stability_run"]
    polys = {name: st.polynomials[name] for name in METHODS}
    figure = Figure(
        id="solvers-stability-regions", title="Stability regions |R(z)| = 1",
        svg=contour_chart(st.x, st.y, st.regions, 1.0, xlabel="Re z = Re(h lambda)",
                          ylabel="Im z = Im(h lambda)", size=(6.5, 5.6)),
        caption=("Each curve bounds the set of z = h lambda where one step of y' = lambda y "
                 "does not grow; the stable set is the inside of the curve. Stiff drag lies on the "
                 "negative real axis (z = -h k/m), an undamped oscillation on the imaginary "
                 "axis (z = i h omega). Euler, averaged-euler and midpoint only touch the "
                 "imaginary axis at 0, so they amplify every oscillation; rk4 and the "
                 "seed's backwards-euler (R = 1 + z + z^2) contain a piece of it. "
                 f"Reproduce: {CMD_STABILITY}"))

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
                 f"{CMD_STABILITY}"))

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
                 f"Reproduce: {CMD_ENERGY}"))
    results = {
        "stability_polynomials": {name: [str(c) for c in p] for name, p in polys.items()},
        "stability_grid": st.grid,
        "limits": m["stability"],
        "oscillator_energy": m["energy"],
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
         "relative error at t1", CMD_WORK_PRECISION),
        ("particles-free", m["wp_free"],
         f"{m['particle_count']} particles, quadratic drag, no walls",
         "max position error at t1 (m)", CMD_PARTICLES_WP),
        ("particles-walls", m["wp_walls"],
         f"{m['particle_count']} particles, quadratic drag, in the cube",
         "max position error at t1 (m)", CMD_PARTICLES_WP_WALLS),
    )
    figures = []
    for key, points, title, ylabel, cmd in cases:
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
                         + f" Reproduce: {cmd}")))
    results = {
        "kepler": m["wp_kepler"],
        "particles_free": m["wp_free"],
        "particles_walls": m["wp_walls"],
        "particle_count": m["particle_count"],
        "observed_orders_free": m["free_orders"],
        "observed_orders_walls": m["wall_orders"],
    }
    return figures, results


def _jitter(m):
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
    table = Table(
        id="solvers-jitter", title="Resting contact: how far a particle at rest hops (C6, C7)",
        columns=("method", "h (s)", "hop (m)", "hop / (g h^2)", "predicted hop (m)",
                 "rms vertical v (m/s)", "bounces/s", f"hop / (g h^2), drag k = "
                 f"{m['jitter_damped_drag']:g}"),
        rows=tuple(rows),
        caption=("One particle placed at rest on the floor (restitution 0.8, no friction), "
                 "5 s simulated, measured over the last second. Predicted: Euler gains "
                 "g^2 h^2 / 2 of energy every step in free fall, which the bounces balance "
                 "at a hop of about 2 g h^2 / (1 - e^2)^2; methods of order 2 or more are "
                 "exact for constant gravity and settle into a two-step cycle of height "
                 "(3e - 1) / (2 (1 + e)) g h^2 = 7/18 g h^2; backwards-euler sinks each step, "
                 "is pushed back, and never rises. The last column repeats the run with "
                 "strong linear drag (k/m = 1/s): it does not stop Euler's hop. "
                 f"Reproduce: {CMD_JITTER}"))
    results = {"undamped": m["jitter"], "damped": m["jitter_damped"],
               "damped_drag": m["jitter_damped_drag"],
               "predicted": [{"h": h, **p} for h, p in m["jitter_predicted"].items()]}
    return table, results


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
                 f"table). Reproduce: {CMD_DRAG}"))
    return table, d


def _listing(values: dict, fmt) -> str:
    return ", ".join(f"{k} {fmt(v)}" for k, v in values.items())


def _wall_orders_clause(c8) -> str:
    """A clause on the observed orders with walls (C8's facts)."""
    listed = _listing({k: c8["wall_orders"][k] for k in METHODS}, lambda o: f"{o:.2f}")
    if c8["walls_first_order"]:
        return f"with walls every method is first order (observed {listed})"
    return (f"with walls the observed orders are {listed}, not all within "
            f"{c8['order_tol']} of 1")


def _c8_c9(m):
    choice = {c.method: c for c in m["choice"]}
    ff, fw = m["frame_free"], m["frame_walls"]
    c8 = m["claims"]["C8"].facts
    walls_clause = _wall_orders_clause(c8)
    target, budget = m["target_free"], m["budget_walls"]
    rows = []
    for method in METHODS:
        c = choice[method]
        rows.append((method, c.stages, c.order, _order(m["free_orders"].get(method)),
                     _order(m["wall_orders"].get(method)), _g(c.nfev_free, 4),
                     _g(c.error_walls_at_budget, 3), _g(ff.difference[method], 3),
                     _g(fw.difference[method], 3)))
    c8_table = Table(
        id="solvers-c8", title="Is RK4 worth its cost in a particle system? (C8)",
        columns=("method", "evaluations / step", "order (tableau)", "observed order, free",
                 "observed order, walls", f"evaluations to {target:g} m, free",
                 f"error (m) at {budget} evaluations, walls",
                 "difference from rk4 at h = 1/60 (m), free", "same, walls"),
        rows=tuple(rows),
        caption=("Particle systems with quadratic drag (speeds 1-5 m/s, cube of half size "
                 "2 m, e = 0.8, friction 0.1), 1 s simulated. Observed orders from the "
                 f"work-precision runs ({m['particle_count']} particles); evaluations and "
                 f"errors at a budget from {m['choice_count']} particles, interpolated "
                 "log-log between runs ('never': not reached with up to "
                 f"{m['choice_max_steps']} steps). "
                 + walls_clause[0].upper() + walls_clause[1:]
                 + (": a contact between steps is caught up to a step late"
                    if c8["walls_first_order"] else "")
                 + f". Reproduce: {CMD_CHOICE}; {CMD_FRAME}"))
    rows = []
    for method in METHODS:
        c = choice[method]
        rows.append((method, c.stages, c.order, _g(c.drag_limit, 4),
                     _g(c.oscillator_limit, 4), _g(c.nfev_free, 4),
                     _g(c.error_walls_at_budget, 3), _g(c.hop_height_gh2, 4)))
    c9_table = Table(
        id="solvers-c9", title="Which solver in general? (C9)",
        columns=("method", "evaluations / step", "order", "stable drag h k/m",
                 "stable oscillator h omega", f"evaluations to {target:g} m, free",
                 f"error (m) at {budget} evaluations, walls",
                 "resting hop / (g h^2), h = 0.01"),
        rows=tuple(rows),
        caption=("The facts the seed's choice rests on, side by side: cost per step, "
                 "accuracy without and with walls, stability for stiff drag and for "
                 "oscillation, and resting contact. Reproduce: "
                 f"{CMD_CHOICE}"))
    results = {"choice": m["choice"], "choice_count": m["choice_count"],
               "frame_free": ff, "frame_walls": fw,
               "target_free": target, "budget_walls": budget,
               "choice_max_steps": m["choice_max_steps"]}
    return c8_table, c9_table, results


# -- verdicts: sentences from the facts of refsim.claims.solvers ------------------------


def _rank(rank: dict) -> str:
    """:func:`refsim.claims.result.rank` in words."""
    if rank["position"] == "all tied":
        return "the same as all the others"
    tied = f"tied with {', '.join(rank['tied_with'])} for " if rank["tied_with"] else ""
    if rank["position"] in ("lowest", "highest"):
        return f"{tied}the {rank['position']}"
    return "between the others"


def _span(values) -> str:
    """The range of a method's observed orders, to two decimals."""
    lo, hi = min(values), max(values)
    return f"{lo:.2f}" if f"{lo:.2f}" == f"{hi:.2f}" else f"{lo:.2f}-{hi:.2f}"


def _c10(result, failing) -> Verdict:
    f = result.facts

    def why(method):
        """The order conditions (up to the stated order) the tableau fails."""
        if failing[method]:
            return "; ".join(failing[method])
        return (f"it meets every condition of order {f['stated_order'][method]}; the fitted "
                "slopes miss it")

    observed = f["observed_orders"]
    wrong, right = f["wrong"], f["right"]
    return Verdict(
        claim="C10",
        measured=("Observed orders on {n} problems: {orders}; {wrong}".format(
            n=len(f["problems"]),
            orders=", ".join(f"{k} {_span(observed[k].values())}" for k in observed),
            wrong=("; ".join(f"{w} is order {f['derived_order'][w]} by its tableau "
                             f"({why(w)}), not {f['stated_order'][w]} as stated"
                             for w in wrong)
                   + ("; the others match." if right else ".")) if wrong
            else "all as stated.")),
        verdict=result.verdict, evidence="solvers-orders", command=claim_command("C10"),
        timing=result.timing,
        summary=("; ".join(f"{w[0].upper()}{w[1:]} is order {f['derived_order'][w]}, not "
                           f"{f['stated_order'][w]} as stated" for w in wrong)
                 + ("; the others match." if right else ".") if wrong
                 else "Every solver has the order the seed states."))


def _c6(result) -> Verdict:
    f = result.facts
    h = f["step"]
    if f["scaling_measured"]:
        spread = ("Euler's hop / (g h^2) is "
                  + ", ".join(f"{hop:.3g} at h = 1/{round(1 / s)}"
                              for s, hop in zip(f["steps"], f["euler_hop_gh2_by_step"],
                                                strict=True)))
        scaling = (f" {spread}: the jitter is bounded (for every method that hops, a hop "
                   f"that scales as h^2 to within {f['scaling_rtol']:.0%}), not a growing "
                   "instability." if f["scales_as_h2"] else
                   f" {spread}: the hop does not scale as h^2 (to within "
                   f"{f['scaling_rtol']:.0%}) for every method that hops.")
    else:
        scaling = ""
    return Verdict(
        claim="C6",
        measured=(f"A particle at rest on the floor (e = 0.8, h = 1/{round(1 / h)} s) hops "
                  f"{f['euler_hop']:.3g} m = {f['euler_hop_gh2']:.3g} g h^2 with Euler "
                  f"(still {f['euler_damped_hop_gh2']:.3g} g h^2 with drag k/m = "
                  f"{f['damped_drag']:g}/s) against "
                  + ", ".join(f"{v:.3g} g h^2 for {k}" for k, v in f["others_hop_gh2"].items())
                  + " (Euler gains g^2 h^2/2 of energy a step in flight)." + scaling),
        verdict=result.verdict, evidence="solvers-jitter", command=claim_command("C6"),
        timing=result.timing,
        summary=(f"At rest on the floor Euler hops {f['euler_hop_gh2']:.3g} g h^2, "
                 + ("far more than" if result.verdict == "confirmed" else "not far more than")
                 + " the other solvers"
                 + (" (a bounded jitter that shrinks as h^2)." if f["scales_as_h2"] else ".")))


def _c7(result) -> Verdict:
    f = result.facts
    four = f["methods"]
    pairs_text = ("; ".join(f"{p['pair'][0]} and {p['pair'][1]}"
                            + (" (the same R(z))" if p["same_polynomial"] else "")
                            for p in f["alike_pairs"]) if f["alike_pairs"] else "none")
    return Verdict(
        claim="C7",
        measured=("Observed orders {orders}; stable drag step h k/m up to {drag}; "
                  "undamped oscillation stable for h omega up to {osc} (0: amplified at "
                  "every step); resting hop {hop} g h^2. The four {o} in order, {s} in "
                  "stability and {r} in resting hop (alike: orders within {otol}, limits "
                  "and hops within {rtol:.0%}). Pairs alike in all of these: {pairs}.").format(
                      orders=", ".join(f"{k} {_span(f['observed_orders'][k].values())}"
                                       for k in four),
                      drag=", ".join(f"{k} {f['drag_limit'][k]:.3g}" for k in four),
                      osc=", ".join(f"{k} {f['oscillator_limit'][k]:.3g}" for k in four),
                      hop=", ".join(f"{k} {f['hop_gh2'][k]:.3g}" for k in four),
                      o="agree" if f["agree"]["order"] else "differ",
                      s="agree" if f["agree"]["stability"] else "differ",
                      r="agree" if f["agree"]["resting hop"] else "differ",
                      otol=f["order_tol"], rtol=f["rtol"], pairs=pairs_text),
        verdict=result.verdict, evidence="solvers-stability", command=claim_command("C7"),
        timing=result.timing, summary=_c7_summary(f["agree"]))


def _c7_summary(agree: dict) -> str:
    """C7 in a sentence: in which respects the four solvers agree."""
    same = [k for k, v in agree.items() if v]
    differ = [k for k, v in agree.items() if not v]
    if not differ:
        return "The four solvers agree in order, stability and resting hop."
    return (f"The four solvers differ in {listing(differ)}"
            + (f"; they agree in {listing(same)}." if same else "."))



def _c8(result, m) -> Verdict:
    f = result.facts
    target, budget = m["target_free"], m["budget_walls"]
    nfev, errors = f["nfev_free"], f["error_walls"]
    rest = [k for k in METHODS if k != "rk4"]
    walls_clause = _wall_orders_clause(f)
    second = f["second_order"]
    ff, fw = f["frame_difference_free"], f["frame_difference_walls"]
    return Verdict(
        claim="C8",
        measured=(f"Without walls rk4 reaches {target:g} m with "
                  f"{_evaluations(nfev['rk4'])} force evaluations against "
                  + ", ".join(f"{_evaluations(nfev[k])} for {k}" for k in rest)
                  + f" (never: not within {m['choice_max_steps']} steps): "
                  + ("fewer than" if f["rk4_better_free"] else "not fewer than")
                  + f" the best of the others ({f['best_other_free']}). "
                  + walls_clause[0].upper() + walls_clause[1:]
                  + f", and at {budget} evaluations rk4's error is "
                  f"{errors['rk4']:.3g} m against "
                  + ", ".join(f"{_g(errors[k])} m for {k}" for k in rest)
                  + (": lower than" if f["rk4_better_walls"] else ": not lower than")
                  + f" the best of the others ({f['best_other_walls']}). At a 1/60 s frame "
                    "step rk4 and the second-order methods ("
                  + ", ".join(second) + ") end up "
                  + ", ".join(f"{ff[k]:.2g}" for k in second)
                  + f" m apart without walls, {'above' if f['visible_free'] else 'below'} "
                    f"the {f['visible']:.2g} m a viewer "
                    f"could see (one pixel of a 1000-pixel view of the {f['cube_edge']:g} m "
                    "cube), and "
                  + ", ".join(f"{fw[k]:.2g}" for k in second)
                  + f" m with walls, {'above' if f['visible_walls'] else 'below'} it. Better "
                    f"than every other method at equal cost (by more than "
                    f"{f['tie_rtol']:.0%}): "
                  + ("yes" if f["rk4_better_free"] else "no") + " without walls, "
                  + ("yes" if f["rk4_better_walls"] else "no") + " with walls."),
        verdict=result.verdict, evidence="solvers-c8", command=claim_command("C8"),
        timing=result.timing,
        summary=("RK4 is " + ("" if f["rk4_better_free"] else "not ")
                 + "better than the other solvers at equal cost without walls, and "
                 + ("" if f["rk4_better_walls"] else "not ") + "with walls"
                 + (" (where every method is first order)." if f["walls_first_order"]
                    else ".")))


#: C9's words for how backwards-euler's order compares with its peers'.
ORDER_RELATION = {"lower": "lower than", "higher": "higher than", "equal": "equal to",
                  "mixed": "against"}


def _c9(result, m) -> Verdict:
    f = result.facts
    target, budget = m["target_free"], m["budget_walls"]

    def reaches(nfev: float) -> str:
        if math.isinf(nfev):
            return f"never reaches {target:g} m within {m['choice_max_steps']} steps"
        return f"reaches {target:g} m after {nfev:.3g} evaluations"

    peers = f["peers"]
    osc_text = (f"it is stable for oscillation up to h omega = {f['oscillator_limit']:.3g}"
                if f["oscillator_stable"] else "it amplifies every oscillation")
    stable = f["oscillator_stable_others"]
    osc_text += ("; of the others only " + ", ".join(f"{k} ({v:.3g})" for k, v in stable.items())
                 + " is" if stable else "; none of the others is")
    return Verdict(
        claim="C9",
        measured=(f"Backwards-euler costs {f['stages']} evaluations a step like "
                  + " and ".join(peers)
                  + f" and is order {f['order']}, {ORDER_RELATION[f['order_relation']]} "
                  f"theirs ({', '.join(f'{k} {v}' for k, v in peers.items())}); its stable "
                  f"drag step h k/m <= {f['drag_limit']:.3g} is {_rank(f['drag_rank'])} "
                  f"(others {_listing(f['drag_others'], lambda v: f'{v:.3g}')}); {osc_text}; "
                  f"its resting hop {f['hop_gh2']:.3g} g h^2 is {_rank(f['hop_rank'])} "
                  f"(others {_listing(f['hop_others'], lambda v: f'{v:.3g}')}). Without "
                  f"walls it {reaches(f['nfev_free'])} ("
                  + ", ".join(f"{k} {_evaluations(v)}" for k, v in f["nfev_others"].items())
                  + f" evaluations); with walls its error at {budget} evaluations is "
                  f"{_g(f['error_walls'])} m, "
                  f"{_rank(f['walls_rank'])} (others {_listing(f['error_walls_others'], _g)} "
                  f"m). Best or tied-best (within {f['tie_rtol']:.0%}) on accuracy per cost: "
                  + ("yes" if f["best_free"] else "no") + " without walls, "
                  + ("yes" if f["best_walls"] else "no") + " with walls."),
        verdict=result.verdict, evidence="solvers-c9", command=claim_command("C9"),
        timing=result.timing,
        summary=(f"Backwards Euler is order {f['order']}, "
                 f"{ORDER_RELATION[f['order_relation']]} the methods of its cost, and "
                 + {(True, True): "best or tied-best on accuracy per cost with and without "
                                  "walls.",
                    (True, False): "best or tied-best on accuracy per cost only without walls.",
                    (False, True): "best or tied-best on accuracy per cost only with walls.",
                    (False, False): "not the best on accuracy per cost, with or without "
                                    "walls."}[(f["best_free"], f["best_walls"])]))


def _c5(result) -> Verdict:
    f = result.facts
    significant, extra = f["significant"], f["extra_cost"]
    return Verdict(
        claim="C5",
        measured=(f"With the same terminal speed ({f['terminal_speed']:g} m/s) a projectile "
                  f"under quadratic drag ends up to {f['same_terminal_difference']:.3g} m from "
                  f"the linear-drag path over {f['same_terminal_distance']:.3g} m travelled "
                  f"({f['same_k_difference']:.3g} m with the same k): "
                  + ("more" if significant else "not more")
                  + f" than {f['significant_fraction']:.0%} of the distance, "
                  + ("a significant" if significant else "an insignificant")
                  + f" difference. A quadratic-drag step took {f['cost_ratio']:.2g} times as "
                    "long as a linear one in this run: "
                  + ("more" if extra else "not more")
                  + f" than {f['extra_cost_ratio']:g} times, "
                  + ("an extra cost" if extra else "no extra cost")
                  + f" (per-repeat ratios: {against_spread(f['cost_against_threshold'])})."),
        verdict=result.verdict, evidence="solvers-drag", command=claim_command("C5"),
        timing=result.timing,
        summary=("Quadratic drag changes the path by "
                 + ("more" if significant else "less")
                 + f" than {f['significant_fraction']:.0%} of the distance travelled, at "
                 + ("a step cost too close to call against the threshold in this run."
                    if f["cost_against_threshold"]["side"] == "within spread" else
                    f"{f['cost_ratio']:.2g} times the cost of a linear-drag step.")))


def _verdicts(m) -> list[Verdict]:
    claims = m["claims"]
    return [_c10(claims["C10"], m["failing"]), _c6(claims["C6"]), _c7(claims["C7"]),
            _c8(claims["C8"], m), _c9(claims["C9"], m), _c5(claims["C5"])]


# -- agreement with the oracles (the page's summary) -------------------------------------


def _agreements(m) -> list[Agreement]:
    a = m["agreement"]
    return [
        Agreement("scipy solve_ivp (DOP853)",
                  "observed order of convergence of each solver against the order derived "
                  "from its tableau",
                  f"{a['orders_within']} / {a['orders_total']} (solver, problem) pairs within "
                  f"{a['order_tol']}", CMD_ORDERS),
        Agreement("analytic",
                  "largest stable step predicted from R(z) against simulation (drag, "
                  "oscillator)",
                  f"{a['limits_within']} / {a['limits_total']} "
                  f"within {a['limits_rtol']:g} relative (worst {a['limits_worst']:.1g})",
                  CMD_STABILITY),
        Agreement("analytic",
                  "energy per period of an undamped oscillator against |R(i h omega)|^(2T/h)",
                  f"{a['energy_within']} / {a['energy_total']} "
                  f"within {a['formula_rtol']:g} relative (worst {a['energy_worst']:.1g})",
                  CMD_ENERGY),
        Agreement("analytic",
                  "resting hop of averaged-euler, midpoint and rk4 against "
                  "(3e - 1) / (2 (1 + e)) g h^2",
                  f"{a['hops_within']} / {a['hops_total']} "
                  f"within {a['formula_rtol']:g} relative (worst {a['hops_worst']:.1g})",
                  CMD_JITTER),
    ]


# -- the section --------------------------------------------------------------------


def build(ctx) -> Section:
    m = _measure(ctx.run)
    ctx.progress.announce("solvers: charts")
    conv_figures, orders_table, orders_results = _convergence(m)
    literal_table, literal_results = _seed_literal(m)
    region, stability_table, energy_table, stability_results = _stability(m)
    wp_figures, wp_results = _work_precision(m)
    jitter_table, jitter_results = _jitter(m)
    drag_table, drag_results = _drag(m)
    c8_table, c9_table, choice_results = _c8_c9(m)

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
        verdicts=_verdicts(m),
        agreements=_agreements(m),
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
