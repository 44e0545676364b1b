"""Report section: rigid-body dynamics (S5, S7, S8, S9), claims C11 and C12.

Every number comes from the plan's records: the bounce studies of
:mod:`refsim.studies.bounce` (refsim against the analytic answers of
:mod:`refsim.dynamics.analytic` and the pybullet oracle), and the C11/C12
measurements of :mod:`refsim.studies.dynamics`; the verdicts, every finding
(worst cases, gaps, targets met) and the divergences with their classes come
from :mod:`refsim.claims.dynamics`. This module only words them
(``docs/design.md``, Views).

A quick run has fewer restitutions, step sizes and solvers, shorter C11 and
C12 runs and fewer timed steps (:mod:`refsim.report.entries.dynamics`); the
captions say what the quick run leaves out. Without pybullet the section
still measures refsim against the analytic answers and says that the
oracle's columns are missing. Everything is deterministic but the wall
times, which the study records mark (the step-cost table is marked
``timing``); no verdict sentence quotes a time.
"""

from __future__ import annotations

import math

from refsim.claims import dynamics as judged
from refsim.report.charts import Series, line_chart
from refsim.report.plan import command
from refsim.report.section import Agreement, Divergence, Figure, Replay, Section, Table, Verdict

CHART_SIZE = (7.0, 4.0)
CMD_APEX = command("dynamics-apex")
CMD_OBLIQUE = command("dynamics-oblique")
CMD_REST = command("dynamics-rest")
CMD_ENERGY = command("dynamics-energy")
CMD_COST = command("dynamics-cost")
CMD_SETTINGS = command("dynamics-pybullet-settings")
CMD_STEP_COST = command("dynamics-step-cost")
CMD_SPIN = command("dynamics-spin")
CMD_C11 = command("dynamics-interpenetration")
#: Errors below this are rounding (RK4 integrates the parabola of free
#: flight exactly; refsim's wall response is then exact too): the cost chart
#: draws them at this floor so that a log axis can show them.
ERROR_FLOOR = 1e-16

STYLES = {"euler": "o-", "averaged-euler": "s--", "backwards-euler": "^-", "midpoint": "x:",
          "rk4": "D-", "rk4, seed wall speed": "D--", "pybullet": "*-"}


def _f(x, digits: int = 5) -> str:
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    return f"{x:.{digits}g}"


def _pct(x) -> str:
    return "n/a" if x is None or not math.isfinite(x) else f"{100 * x:.3g}%"


def _oblique_row(bounce_rows: dict, ours: str, theirs: str) -> tuple:
    """One oblique bounce's table row: the bounce and its laws' answers (the
    same on every engine's row), then refsim's and the oracle's lateral
    speed and the oracle's spin."""
    r = next(iter(bounce_rows.values()))
    return (r.body, r.rotation, r.v_t, _f(r.v_n, 4), _f(r.seed_analytic),
            _f(r.coulomb_point), _f(r.coulomb_ball), "yes" if r.ball_slides else "no",
            _f(_at(bounce_rows, ours, "lateral")), _f(_at(bounce_rows, theirs, "lateral")),
            _f(_at(bounce_rows, theirs, "spin"), 3))


def _rest_row(drop: dict, ours: str, theirs: str) -> tuple:
    """One drop's time-to-rest row: the analytic settling, then refsim's and
    the oracle's."""
    from refsim.studies.bounce import ANALYTIC

    closed = drop[ANALYTIC]
    return (closed.body, closed.e, _f(closed.zeno), _f(closed.settle), closed.bounces,
            _f(_at(drop, ours, "settle")), _at(drop, ours, "bounces", 0),
            _f(_at(drop, theirs, "settle")), _at(drop, theirs, "bounces", 0))


def _at(case: dict, engine: str, field: str, missing=None):
    """``field`` of ``engine``'s row in one case of a long-form record
    (:func:`refsim.studies.bounce.by_case`), ``missing`` when the engine did
    not run it."""
    return getattr(case[engine], field) if engine in case else missing


def build(ctx) -> Section:
    from refsim.dynamics.choices import choices
    from refsim.studies import bounce
    from refsim.studies import dynamics as dyn_measure

    quick = ctx.quick
    run = ctx.run
    apex_rows = run.get("dynamics-apex")
    oblique_rows = run.get("dynamics-oblique")
    rest_rows = run.get("dynamics-rest")
    series = run.get("dynamics-energy")
    cost_run = run.get("dynamics-cost")
    cost = cost_run.study
    settings_rows = run.get("dynamics-pybullet-settings")
    step_rows = run.get("dynamics-step-cost")
    step_pairs = judged.step_cost_pairs(step_rows)
    spin_rows = run.get("dynamics-spin")
    c11_rows = run.get("dynamics-interpenetration")
    pb = "pybullet" not in run.missing
    missing = run.missing.get("pybullet", "")

    # -- figures and tables --------------------------------------------------------------
    figures, tables = [], []
    pb_note = "" if pb else f" pybullet is missing ({missing}): its columns are n/a."

    def stride(values, n=5):
        return list(values)[::n]

    curves = {c.engine: c for c in series}
    closed = curves[bounce.ANALYTIC]

    def curve_series(labels: dict, field: str) -> list:
        return [Series(label, stride(curves[engine].t),
                       stride(getattr(curves[engine], field)), style)
                for engine, (label, style) in labels.items() if engine in curves]

    figures.append(Figure(
        id="dynamics-bounce-heights", title="Bounce heights over time",
        svg=line_chart(curve_series({
            bounce.ANALYTIC: ("analytic", "-"),
            bounce.REFSIM: ("refsim (seed wall response, RK4)", "--"),
            judged.ORACLE: ("pybullet", ":")}, "height"),
            xlabel="time (s)", ylabel="height of the lowest point above the floor (m)",
            size=CHART_SIZE),
        caption=f"{closed.body}, e = {closed.e}, dropped from {bounce.DROP_HEIGHT} m, "
                f"h = {bounce.STEP} s, rotation off. "
                f"{_height_gaps(judged.height_gaps(series, apex_rows))}"
                f"{pb_note} Reproduce: {CMD_ENERGY}; {CMD_APEX}"))
    figures.append(Figure(
        id="dynamics-energy", title="Mechanical energy over time",
        svg=line_chart(curve_series({
            bounce.ANALYTIC: ("analytic (e^(2k) after bounce k)", "-"),
            bounce.REFSIM: ("refsim", "--"),
            judged.ORACLE: ("pybullet", ":")}, "energy"),
            xlabel="time (s)", ylabel="energy / (m g) (m)", size=CHART_SIZE),
        caption="Potential energy above the touching height plus kinetic, per unit weight. "
                "Between bounces it is constant (RK4 is exact for free flight; Bullet's "
                "symplectic Euler nearly so); each bounce multiplies it by e^2. "
                f"Reproduce: {CMD_ENERGY}"))

    ours, literal, theirs = bounce.REFSIM, bounce.SEED_WALL_SPEED, judged.ORACLE
    apex_table_rows = []
    for d in bounce.by_case(apex_rows, bounce.APEX_CASE).values():
        closed = d[bounce.ANALYTIC]
        apex_table_rows.append(
            (closed.body, closed.rotation, closed.e, _f(closed.ratio),
             _f(_at(d, ours, "ratio")), _pct(_at(d, ours, "error")),
             _f(_at(d, literal, "ratio")), _pct(_at(d, literal, "error")),
             _f(_at(d, theirs, "ratio")), _pct(_at(d, theirs, "error")),
             _f(_at(d, ours, "max_spin"), 3), _f(_at(d, theirs, "max_spin"), 3)))
    tables.append(Table(
        id="dynamics-apex-ratios", title="Apex ratios against e^2",
        columns=("body", "rotation", "e", "e^2", "refsim", "error", "refsim, seed's literal "
                 "wall speed", "error", "pybullet", "error", "refsim max |w| (rad/s)",
                 "pybullet max |w| (rad/s)"),
        rows=tuple(apex_table_rows),
        caption=f"Geometric mean of the first {bounce.BOUNCES} apex ratios, h = {bounce.STEP} "
                f"s, RK4, drop height {bounce.DROP_HEIGHT} m. "
                + _apex_findings(judged.apex_findings(apex_rows))
                + " pybullet detects a contact only once the hull overlaps the wall and "
                "restitutes that velocity (split impulse removes the overlap without "
                "energy)."
                + (" Quick run: the cube only at e = 0.8 with the seed's rotation." if quick
                   else "")
                + pb_note + f" Reproduce: {CMD_APEX}"))

    tables.append(Table(
        id="dynamics-oblique", title="Lateral velocity after an oblique bounce",
        columns=("body", "rotation", "v_t (m/s)", "v_n at impact (m/s)",
                 "seed: (1 - friction) v_t", "Coulomb, point mass", "Coulomb, ball",
                 "ball slides", "refsim", "pybullet", "pybullet |w| after (rad/s)"),
        rows=tuple(_oblique_row(b, ours, theirs)
                   for b in bounce.by_case(oblique_rows, bounce.OBLIQUE_CASE).values()),
        caption=f"friction = {bounce.OBLIQUE_FRICTION} (the seed's fraction; pybullet's "
                f"Coulomb mu), e = {bounce.OBLIQUE_E}, released 5 cm above the floor. The "
                "seed keeps (1 - friction) v_t whatever the normal speed; Coulomb friction "
                "removes mu (1 + e) |v_n| while sliding, and a ball that would stop its "
                "contact point leaves rolling at 5/7 v_t, which pybullet reproduces. "
                "pybullet's cube tips on the friction at its leading edge, so its centre "
                "keeps less. refsim's cube with the seed's rotation hits the floor again "
                "as it turns (its box grows), and each hit damps v_t by another 0.7."
                + pb_note + f" Reproduce: {CMD_OBLIQUE}"))

    tables.append(Table(
        id="dynamics-rest", title="Time to rest",
        columns=("body", "e", "Zeno time (s)", "analytic settle (s)", "bounce",
                 "refsim settle (s)", "bounce", "pybullet settle (s)", "bounce"),
        rows=tuple(_rest_row(d, ours, theirs)
                   for d in bounce.by_case(rest_rows, bounce.REST_CASE).values()),
        caption=f"The analytic bounces accumulate at the Zeno time t0 (1 + 2e/(1 - e)). "
                f"Measured: the time of the bounce after which every apex stays below "
                f"{bounce.REST_FRACTION} of the drop height. "
                + _rest_findings(judged.rest_findings(rest_rows))
                + (" Quick run: e = 0.5 only." if quick else "") + pb_note
                + f" Reproduce: {CMD_REST}"))

    cost_steps = sorted(dict.fromkeys(p.step for p in cost.points), reverse=True)
    cost_solvers = [x for x in dict.fromkeys(p.solver for p in cost.points)
                    if x not in ("pybullet", bounce.SEED_SPEED_SERIES)]
    cost_series = []
    for solver in dict.fromkeys(p.solver for p in cost.points):
        pts = [p for p in cost.points if p.solver == solver and math.isfinite(p.error)]
        cost_series.append(Series(solver, [p.seconds_per_second for p in pts],
                                  [max(p.error, ERROR_FLOOR) for p in pts],
                                  STYLES.get(solver, "o-")))
    figures.append(Figure(
        id="dynamics-error-cost", title="Apex-ratio error against cost, over step sizes",
        svg=line_chart(cost_series, xlabel="wall time per simulated second (s)",
                       ylabel="|apex ratio - e^2| / e^2", logx=True, logy=True,
                       size=CHART_SIZE),
        caption=f"{cost.body}, e = {cost.e}, {cost.bounces} bounces; each point one step "
                f"size from 1/{1 / max(cost_steps):.0f} to 1/{1 / min(cost_steps):.0f} s, in "
                f"the manner of Erez, Tassa and Todorov "
                f"(ICRA 2015). " + _order_findings(
                    judged.rounding_series(cost), cost_run.orders, judged.ROUNDING_ERROR)
                + " refsim's time is the whole simulate call; pybullet's the "
                "stepSimulation calls alone. Timings vary from run to run."
                + (f" Quick run: {len(cost_steps)} step sizes ("
                   + ", ".join(f"1/{1 / h:.0f}" for h in cost_steps) + f" s), "
                   f"{len(cost_solvers)} solvers." if quick else "") + pb_note
                + f" Reproduce: {CMD_COST}"))

    if settings_rows:
        tables.append(Table(
            id="dynamics-pybullet-settings", title="pybullet's settings, one at a time",
            columns=("changed from the oracle's settings", "apex ratio", "error against e^2",
                     "settles after bounce", "bounces in 9 s"),
            rows=tuple((r.change, _f(r.ratio), f"{100 * r.error:+.3g}%",
                        r.settle_bounce or "not within the run", r.bounces)
                       for r in settings_rows),
            caption=f"{bounce.SPHERE}, e = {bounce.OBLIQUE_E}, h = {bounce.STEP} s; the "
                    "analytic series settles after bounce "
                    f"{settings_rows[0].analytic_settle_bounce}. Each row changes one setting of "
                    "oracles/pybullet_adapter.py back to (or near) pybullet's default; the "
                    "module docstring says why each is set as it is. The restitution "
                    "threshold changes only the micro-bounces after settling (fewer "
                    f"bounces in all). Reproduce: {CMD_SETTINGS}"))
    tables.append(Table(
        id="dynamics-step-cost", title="Time per step against pybullet", timing=True,
        columns=("cubes", "rotation", "timed after step", "refsim (us/step)",
                 "pybullet (us/step)", "refsim / pybullet", "refsim's step by stage"),
        rows=tuple((p["bodies"], p["rotation"], p["warmup"], _f(1e6 * p["refsim_seconds"], 4),
                    _f(1e6 * p["pybullet_seconds"], 4), _f(p["ratio"], 3),
                    _stages(p["stage_seconds"])) for p in step_pairs),
        caption="Unit cubes on a grid with seeded random velocities, collision level "
                "\"aabb\", the seed's body response; the fastest of "
                + "; ".join(f"{rep} runs of {n} steps after a warm-up of {w}"
                            for w, n, rep in dict.fromkeys((p["warmup"], p["steps"],
                                                            p["repeats"])
                                                           for p in step_pairs))
                + ". " + _step_cost_findings(judged.step_cost_findings(step_rows))
                + " Timings vary from run to run. Reproduce: "
                "make bench (tests/benchmarks/test_bench_dynamics.py) or " + CMD_STEP_COST))

    spin_series = [Series(s.model, s.t, s.spin, "-") for s in spin_rows]
    energy_series = [Series(s.model, s.t, s.rotational_energy, "-") for s in spin_rows]
    figures.append(Figure(
        id="dynamics-c12-spin", title="C12: angular velocity over time",
        svg=line_chart(spin_series, xlabel="time (s)", ylabel="|w| (rad/s)", size=CHART_SIZE),
        caption="scenes/spinning-cube.toml: a cube dropped with spin (2, 5, 1) rad/s, "
                "e = 0.5, friction 0.3. \"seed\": the seed's rotation model (S9); "
                "\"impulse\": the corrected model (impulses with the real inertia and "
                "Coulomb friction at every contact vertex); pybullet: the same scene."
                + f" Reproduce: {CMD_SPIN}"))
    figures.append(Figure(
        id="dynamics-c12-energy", title="C12: rotational energy over time",
        svg=line_chart(energy_series, xlabel="time (s)", ylabel="w . I w / 2 (J)",
                       size=CHART_SIZE),
        caption="Rotational energy with each body's inertia tensor, for the same runs. "
                f"Reproduce: {CMD_SPIN}"))
    tables.append(Table(
        id="dynamics-c12", title="C12: spin at the end of the run",
        columns=("model", "mean |w| over the last second (rad/s)",
                 "mean |v| over the last second (m/s)", "at rest"),
        rows=tuple((s.model, _f(s.final_spin, 4), _f(s.final_speed, 4),
                    "yes" if s.at_rest else "no") for s in spin_rows),
        caption=f"At rest: |w| < {dyn_measure.REST_SPIN} rad/s and |v| < "
                f"{dyn_measure.REST_SPEED} m/s. Reproduce: {CMD_SPIN}"))
    tables.append(Table(
        id="dynamics-c11", title="C11: interpenetrating frames",
        columns=("case", "body response", "frames", "interpenetrating", "longest run",
                 "contacts"),
        rows=tuple((r.case, r.response, r.frames, r.interpenetrating, r.longest_run,
                    r.contacts) for r in c11_rows),
        caption="Frames (one per step) in which the exact triangle test finds the two "
                "bodies intersecting. chase: same direction, 2 and 0.5 m/s; slow: head-on "
                "at 0.05 m/s; stack: a body dropped onto another; glancing: an offset "
                "pass. \"seed\": the seed's velocity exchange along the centroid line "
                "(S8); \"impulse\": the corrected response with positional separation."
                + (" Quick run: 1 s per case." if quick else "")
                + f" Reproduce: {CMD_C11}"))
    choice_rows = tuple((tag, "AMBIGUITY" if tag.startswith("A") else "DEVIATION", text)
                        for tag, text in choices())
    tables.append(Table(
        id="dynamics-choices", title="Choices where the seed is silent or wrong",
        columns=("tag", "kind", "choice"), rows=choice_rows,
        caption="From refsim/dynamics/choices.py; each tag marks the code that makes "
                "the choice."))

    # -- verdicts ---------------------------------------------------------------------------
    verdicts = [_c11(run.claim("C11")), _c12(run.claim("C12"))]

    # -- results -------------------------------------------------------------------------------
    spin_results = [{"model": s.model, "final_spin": s.final_spin,
                     "final_speed": s.final_speed, "at_rest": s.at_rest, "t": s.t,
                     "spin": s.spin, "rotational_energy": s.rotational_energy}
                    for s in spin_rows]
    results = {
        "pybullet": pb,
        "apex_ratios": apex_rows,
        "oblique": oblique_rows,
        "rest": rest_rows,
        "energy": series,
        "cost": cost,
        "step_cost": step_rows,
        "pybullet_settings": settings_rows,
        "c12": spin_results,
        "c11": c11_rows,
        "choices": [list(c) for c in choices()],
        "settings": {"step": bounce.STEP, "solver": bounce.SOLVER,
                     "drop_height": bounce.DROP_HEIGHT, "bounces": bounce.BOUNCES,
                     "apex_ratio_target": judged.APEX_RATIO_TARGET},
    }
    intro = ("A body dropped onto the floor of the world cube is the seed's wall response "
             "(S7) in its simplest form: Newton's restitution law says each apex is e^2 "
             "of the one before, the bounces end at a finite (Zeno) time, and friction "
             "acts on the lateral velocity. refsim runs the seed's response, pybullet runs "
             "the same scene with the settings that bring its bounce closest to the ideal "
             "(oracles/pybullet_adapter.py lists each), and the analytic answers "
             "(refsim/dynamics/analytic.py) say what both should give. Then the seed's two "
             "admitted bugs: the angular velocity that does not damp (C12) and bodies that "
             "interpenetrate (C11), each against the corrected model.")
    replay_rows = run.get("replays")
    results["replays"] = replay_rows
    return Section(key="dynamics", title="Rigid-body dynamics", intro=intro, figures=figures,
                   tables=tables, verdicts=verdicts, results=results,
                   replays=[_replay(r) for r in replay_rows],
                   divergences=_divergences(judged.divergences(apex_rows, oblique_rows)),
                   agreements=_agreements(judged.agreement_findings(apex_rows, oblique_rows)))


#: The item of this section each replay is shown after (by the replay's name).
REPLAY_AFTER = {"c11-interpenetration": "dynamics-c11", "c12-spin": "dynamics-c12-spin",
                "wall-bounce-pybullet": "dynamics-bounce-heights",
                "wall-bounce-mujoco": "dynamics-bounce-heights"}

#: What each replay shows, for its caption (the scene and the runs, not a finding).
REPLAY_NOTES = {
    "c11-interpenetration": "The stack case of the C11 table (an icosahedron dropped onto "
                            "another resting on the floor, 2 s), with each body's box drawn.",
    "c12-spin": "scenes/spinning-cube.toml, 6 s, under each rotation model.",
    "wall-bounce-pybullet": "scenes/bounce.toml, 3 s: the drop, the bounce and the rise.",
    "wall-bounce-mujoco": "scenes/bounce.toml, 3 s, MuJoCo with its one-step damper "
                          "(oracles/mujoco_adapter.py).",
}


def _replay(r) -> Replay:
    """A replay record of the plan as the page shows it."""
    caption = REPLAY_NOTES.get(r.name, "")
    if r.status == "written":
        caption += (f" Left to right: {'; '.join(r.runs)}. {r.frames} of {r.timeline_frames} "
                    f"frames (every {r.stride}), {r.bytes / 1e6:.2f} MB; play, pause and scrub "
                    "in the frame. Reproduce: refsim study replays -o DIR")
    return Replay(id=f"replay-{r.name}", title=r.title, file=r.file, claim=r.claim,
                  caption=caption, missing=r.reason, after=REPLAY_AFTER.get(r.name, ""))


#: What each C11 case is, for the verdict sentence (the scene, not a finding).
C11_CASE_NOTES = {
    "chase": "same direction, 2 and 0.5 m/s",
    "slow": "head-on at 0.05 m/s",
    "stack": "a body dropped onto another, pressed together by gravity",
    "glancing": "an offset pass, where the centroid line is not the contact's normal, "
                "choices D4",
}


def _height_gaps(found: dict) -> str:
    """The heights chart's finding (:func:`refsim.claims.dynamics.height_gaps`)."""
    text = (f"Largest height difference from the analytic curve: refsim "
            f"{_f(found['refsim_height'], 3)} m, pybullet "
            f"{_f(found['pybullet_height'], 3)} m")
    if "bounces" in found:
        text += (f"; apex times over the first {found['bounces']} bounces differ "
                 f"from the analytic ones by up to {_f(found['refsim_apex_ms'], 3)} ms (refsim) "
                 f"and {_f(found['pybullet_apex_ms'], 3)} ms (pybullet)")
    return text + "."


def _apex_findings(found: dict) -> str:
    """The apex table's findings (:func:`refsim.claims.dynamics.apex_findings`)."""
    parts = []
    target = found["target"]
    if "off_worst" in found:
        text = ("With rotation off, refsim's default wall response (it flips the speed the "
                f"body had at the wall, DEVIATION D1) is at most {_pct(found['off_worst'])} "
                "from e^2 ("
                + ("rounding" if found["off_at_rounding"] else
                   ("inside" if found["off_within_target"] else "outside")
                   + f" a {_pct(target)} tolerance") + ")")
        if "literal_worst" in found:          # refsim with the seed's wall speed ran
            text += ("; the seed's literal flip (the deeper, faster speed one step past the "
                     f"wall) is at most {_pct(found['literal_worst'])} off, "
                     + ("inside" if found["literal_within_target"] else "outside")
                     + f" a {_pct(target)} tolerance")
        parts.append(text + ".")
    if "cube_off_worst" in found:
        parts.append(f"The cube's face-down bounce with rotation off: at most "
                     f"{_pct(found['cube_off_worst'])} from e^2.")
    if "seeded_drops" in found:
        text = (f"With the seed's rotation model (which picks one of the four tied bottom "
                f"vertices, AMBIGUITY A4) the cube turns at up to "
                f"{_f(found['seeded_max_spin'], 3)} rad/s and its apex ratio is off by up to "
                f"{_pct(found['seeded_worst'])}")
        if found["seeded_above_e2"]:
            text += (f", above e^2 in {found['seeded_above_e2']} of {found['seeded_drops']} "
                     "drops (w += Pi x I takes nothing from the linear motion, so the spin is "
                     "added energy)")
        parts.append(text + ".")
    if "pybullet_cube_spin" in found:
        parts.append(
            f"pybullet's cube reaches max |w| {_f(found['pybullet_cube_spin'], 3)} rad/s"
            + (": it meets the floor at four points solved one after another, which can "
               "break the symmetry and tip it." if found["pybullet_cube_tips"] else
               f", below {found['noticeable_spin']} rad/s: it does not tip."))
    return " ".join(parts)


def _rest_findings(found: list[dict]) -> str:
    """The time-to-rest table's finding, the settling bounce of each engine
    (:func:`refsim.claims.dynamics.rest_findings`)."""
    parts = []
    for r in found:
        text = f"e = {r['e']}: the analytic series settles after bounce {r['analytic_bounces']}"
        if "refsim_bounces" in r:
            text += (f", refsim after bounce {r['refsim_bounces']} "
                     f"({_f(r['refsim_offset_ms'], 3)} ms from the analytic time)")
        if "pybullet_bounces" in r:
            late = r["pybullet_bounces_late"]
            text += (f", pybullet after bounce {r['pybullet_bounces']} ("
                     + ("the same bounce" if late == 0 else
                        f"{abs(late)} bounce{'s' if abs(late) > 1 else ''} "
                        + ("later" if late > 0 else "earlier"))
                     + ")")
        parts.append(text)
    return ("; ".join(parts) + ".") if parts else ""


def _order_findings(at_rounding: list, orders: dict, rounding: float) -> str:
    """The cost chart's finding: which series stay at rounding
    (:func:`refsim.claims.dynamics.rounding_series`), and the fitted order in
    h of the others."""
    parts = []
    if at_rounding:
        parts.append(f"Errors at every step size below {rounding:g} (rounding, drawn at "
                     f"{ERROR_FLOOR:g} when smaller): " + ", ".join(at_rounding) + ".")
    if orders:
        parts.append("Fitted slope of log error against log h (the observed order): "
                     + ", ".join(f"{solver} {order:.2g}" for solver, order in orders.items())
                     + ".")
    return " ".join(parts)


def _stages(stages: dict) -> str:
    """The stages of refsim's step that took time, each with its time per
    step: the stages run inside the compiled loop are not timed one by one
    (their time is the loop's), so they are left out, not shown as 0."""
    timed = [f"{stage}: {_f(1e6 * seconds, 3)} us" for stage, seconds in stages.items()
             if seconds > 0]
    return "; ".join(timed) or "not timed by stage"


def _step_cost_findings(found: dict) -> str:
    """The step-cost table's findings: refsim's time with the fewest bodies,
    its largest stage, the ratios and the settled cubes
    (:func:`refsim.claims.dynamics.step_cost_findings`)."""
    parts = []
    single = found["single"]
    if single:
        parts.append(f"refsim's step with {single[0]['bodies']} body: "
                     + ", ".join(f"{_f(1e6 * r['refsim_seconds'], 3)} us (rotation "
                                 f"{r['rotation']})" for r in single)
                     + ", against pybullet's "
                     + ", ".join(f"{_f(1e6 * r['pybullet_seconds'], 3)} us" for r in single)
                     + ".")
        stage = found["largest_stage"]
        if stage is not None:
            parts.append(f"Its largest stage (rotation {stage['rotation']}): {stage['stage']}, "
                         f"{_pct(stage['fraction'])} of the step.")
    ratios = found["ratios"]
    parts.append("refsim / pybullet by body count: "
                 + "; ".join(f"{c}: " + ", ".join(f"{x:.2g}x" for x in ratios[c])
                             for c in ratios) + ".")
    if found["ratio_falls"] is not None:
        parts.append("The ratio falls as bodies are added: refsim's time per step grows far "
                     "less with the body count than pybullet's." if found["ratio_falls"] else
                     "The ratio does not fall steadily as bodies are added.")
    parts.append(f"At {found['largest_bodies']} bodies refsim's time per step is "
                 + ", ".join(f"{r['ratio']:.2g}x pybullet's (rotation {r['rotation']}, after step "
                             f"{r['warmup']}: {'within' if r['within_target'] else 'above'} a "
                             f"factor {found['target']:g})" for r in found["at_largest"]) + ".")
    late = found["settled"]
    if late:
        parts.append(f"Once the cubes have settled on the floor (timed after step "
                     f"{late[0]['warmup']}): refsim "
                     + ", ".join(f"{_f(1e6 * r['refsim_seconds'], 3)} us" for r in late)
                     + ", pybullet "
                     + ", ".join(f"{_f(1e6 * r['pybullet_seconds'], 3)} us" for r in late)
                     + " per step.")
    return " ".join(parts)


def _named(cases) -> str:
    return ", ".join(f"{c} ({C11_CASE_NOTES[c]})" if c in C11_CASE_NOTES else c for c in cases)


def _c11(result) -> Verdict:
    """C11's sentence from :func:`refsim.claims.dynamics.c11`'s facts."""
    f = result.facts
    text = ("With the seed's velocity exchange, interpenetrating frames (longest run): "
            + ", ".join(f"{c} {r['interpenetrating']} of {r['frames']} ({r['longest_run']})"
                        for c, r in f["seed"].items())
            + "; with the corrected response: "
            + ", ".join(f"{c} {r['interpenetrating']} ({r['longest_run']})"
                        for c, r in f["impulse"].items()) + ".")
    text += (" With the seed's response, overlap persists for more than a frame in: "
             + (_named(f["persistent"]) if f["persistent"] else "no case") + ".")
    if f["detection_only"]:
        text += (" Overlap in single frames only (the frame in which the contact is "
                 "detected) in: " + _named(f["detection_only"]) + ".")
    if f["never"]:
        text += " No overlap at all in: " + _named(f["never"]) + "."
    text += (" The corrected response lets overlap persist in: "
             + (", ".join(f["impulse_persistent"]) if f["impulse_persistent"] else "no case")
             + ".")
    return Verdict("C11", measured=text, verdict=result.verdict, evidence="dynamics-c11",
                   command=CMD_C11, timing=result.timing, summary=_c11_summary(f))


def _c11_summary(f: dict) -> str:
    """C11 in a sentence: the case where overlap lasts longest, and the
    corrected response."""
    persistent = f["persistent"]
    corrected = ("; the corrected response lets none persist." if not f["impulse_persistent"]
                 else "; so does the corrected response in "
                 + ", ".join(f["impulse_persistent"]) + ".")
    if not persistent:
        return "With the seed's response no overlap lasts beyond the frame that detects it."
    worst = max(persistent, key=lambda c: f["seed"][c]["longest_run"])
    r = f["seed"][worst]
    return (f"With the seed's response bodies stay interpenetrated in "
            f"{len(persistent)} of {len(f['seed'])} cases (up to {r['longest_run']} of "
            f"{r['frames']} frames in a row, {worst})" + corrected)


def _c12(result) -> Verdict:
    """C12's sentence from :func:`refsim.claims.dynamics.c12`'s facts."""
    f = result.facts
    measured = (
        f"With the seed's rotation model the dropped cube still turns at "
        f"{f['seed_final_spin']:.3g} rad/s (mean |w| over the last second; at rest: "
        f"{'yes' if f['seed_at_rest'] else 'no'}), its spin about the vertical at "
        f"{f['seed_vertical_spin_end']:.3g} rad/s against "
        f"{f['seed_vertical_spin_start']:.3g} "
        f"at the start: the seed's impulse I lies along the floor's normal, so the torque "
        f"Pi x I has no vertical component and no floor contact can slow that spin, and "
        f"nothing in S9 damps w between contacts; the corrected model ends at "
        f"{f['corrected_final_spin']:.3g} rad/s (at rest: "
        f"{'yes' if f['corrected_at_rest'] else 'no'})"
        + (f" and pybullet at {f['pybullet_final_spin']:.3g} rad/s"
           if f["pybullet_final_spin"] is not None else "") + ".")
    summary = (f"The seed's rotation model still spins at {f['seed_final_spin']:.2g} rad/s "
               "at the end" if not f["seed_at_rest"] else
               "The seed's rotation model comes to rest")
    summary += ("; the corrected model comes to rest." if f["corrected_at_rest"] else
                "; the corrected model does not come to rest either.")
    return Verdict("C12", measured=measured, verdict=result.verdict,
                   evidence="dynamics-c12-spin", command=CMD_SPIN, timing=result.timing,
                   summary=summary)


def _step(h: float) -> str:
    """A step size as the summary writes it: 1e-3, not 0.001."""
    mantissa, exponent = f"{h:.0e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _agreements(found: dict) -> list[Agreement]:
    """The summary lines: bounce ratios against the analytic answer and
    pybullet (:func:`refsim.claims.dynamics.agreement_findings`)."""
    rows = []
    if "refsim_worst" in found:
        es = ", ".join(str(e) for e in found["restitutions"])
        rows.append(Agreement(
            "analytic", f"apex ratio against e^2 (e = {es}), refsim's seed model, RK4, "
            f"h = {_step(found['step'])}", f"largest error {_pct(found['refsim_worst'])} over "
            f"{found['drops']} drops (tolerance {_pct(found['target'])})", CMD_APEX))
        if "pybullet_worst" in found:
            rows.append(Agreement(
                "pybullet", f"apex ratio against e^2 (e = {es}), same scenes",
                f"largest error {_pct(found['pybullet_worst'])} over "
                f"{found['pybullet_drops']} drops", CMD_APEX))
    if "coulomb_worst" in found:
        rows.append(Agreement(
            "pybullet", "lateral speed after an oblique bounce against Coulomb's law",
            f"within {100 * found['coulomb_worst']:.2g}% on {found['coulomb_bounces']} bounces "
            "(refsim's seed model keeps (1 - friction) v_t instead: see the divergence "
            "catalogue)", CMD_OBLIQUE))
    return rows


def _divergence(d: dict) -> Divergence:
    """One divergence of :func:`refsim.claims.dynamics.divergences` as the
    catalogue words it."""
    key = d["key"]
    if key == "pybullet-apex":
        return Divergence(
            "pybullet's apex ratios differ from e^2", d["class"],
            f"largest |error| {_pct(d['pybullet_error'])} ({d['body']}, e = {d['e']}) "
            f"against refsim's {_pct(d['refsim_error'])}: pybullet restitutes the velocity "
            "it has once the hull overlaps the wall, a step after the ideal contact",
            "dynamics-apex-ratios")
    if key == "literal-wall-flip":
        return Divergence(
            "the seed's literal wall flip gains energy", d["class"],
            f"flipping the speed one step past the wall (the seed's words) gives apex ratios "
            f"up to {_pct(d['seed_speed_error'])} high ({d['body']}, e = {d['e']}); refsim's "
            "default flips the speed at the wall", "dynamics-apex-ratios")
    if key == "lateral-friction":
        return Divergence(
            "lateral friction: the seed's damping against Coulomb's law", d["class"],
            "; ".join(f"v_t {r['v_t']} m/s: refsim {_f(r['refsim'])}, pybullet "
                      f"{_f(r['pybullet'])}, Coulomb {_f(r['coulomb'])}" for r in d["bounces"])
            + ": the seed keeps (1 - friction) v_t whatever the normal speed",
            "dynamics-oblique")
    return Divergence(
        "pybullet's falling cube tips and spins", d["class"],
        f"max |w| {d['spin']:.3g} rad/s after face-down "
        "bounces that start with no spin: pybullet solves the four floor contacts one "
        "after another, which breaks the symmetry", "dynamics-apex-ratios")


def _divergences(found: list[dict]) -> list[Divergence]:
    """Where pybullet and refsim's seed model part, with the figures
    (:func:`refsim.claims.dynamics.divergences`)."""
    return [_divergence(d) for d in found]
