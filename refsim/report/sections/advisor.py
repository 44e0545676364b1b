"""Report section: the fidelity advisor on every bundled scene.

Arranges the plan's ``advisor``: for each bundled scene, the answer of
:func:`refsim.advisor.advice.advise` at each of the report's tolerances
(the cheapest solver, step, collision level and box update whose run stays
within TOL of a reference run), its cost against the scene's own settings,
and whether the reference converged (or up to which horizon positions are
predictable). How the recommended cost moves with TOL is the scene's own
speed-accuracy trade-off; it is charted with the other such charts. The
advisor decides everything shown (what meets TOL, the recommendation, the
reference's convergence); this module only arranges its records.
"""

from __future__ import annotations

from refsim.report.charts import Series, line_chart
from refsim.report.plan import command
from refsim.report.section import Figure, Section, Table, Timing

CMD = command("advisor")


def _g(x, digits: int = 3) -> str:
    return "-" if x is None else f"{x:.{digits}g}"


def _settings(row: dict) -> str:
    """solver, step, collision level, box update of a run row."""
    return f"{row['solver']}, h = {_g(row['step'])} s, {row['level']}, {row['aabb']}"


def _reference(ref: dict, duration: float) -> str:
    """Whether the reference converged, else its horizon and why halving stopped."""
    if ref["converged"]:
        return f"converged (rk4, h = {_g(ref['step'])} s)"
    horizon = ref["horizon"]
    return (f"not converged ({ref['stop']}); positions predictable up to "
            f"{_g(horizon)} of {_g(duration)} s (rk4, h = {_g(ref['step'])} s)")


def _summary(advice: dict) -> dict:
    """The numbers of one advice that results.json keeps (timings marked)."""
    def run(row: dict) -> dict:
        return {"solver": row["solver"], "step": row["step"], "level": row["level"],
                "aabb": row["aabb"], "proxy": row["proxy"], "meets": row["meets"],
                "position_error": row["position_error"], "event_error": row["event_error"],
                "events": row["events"], "wall_seconds": Timing(row["wall_seconds"])}

    ref = advice["reference"]
    return {"tolerance": advice["tolerance"], "duration": advice["duration"],
            "recommended": run(advice["recommended"]), "own": run(advice["own"]),
            "proxy_saving": advice["proxy_saving"], "wall_saving": Timing(advice["wall_saving"]),
            "reference": {k: ref[k] for k in ("step", "converged", "stop", "horizon",
                                              "uncertainty")},
            "runs": len(advice["runs"]), "pruned": len(advice["pruned"]),
            "computed": advice["computed"], "resumed": advice["resumed"]}


def build(ctx) -> Section:
    record = ctx.run.get("advisor")
    rows, wall_rows, series, results = [], [], [], []
    for scene in record.scenes:
        if scene.refused or scene.skipped:
            why = (f"not advised: {scene.refused}" if scene.refused
                   else f"not advised in this run: {scene.skipped}")
            rows.append((scene.scene, "-", why, "-", "-", "-", "-", "-", "-", "-"))
            results.append({"scene": scene.scene, "refused": scene.refused,
                            "skipped": scene.skipped, "advice": []})
            continue
        for a in scene.advice:
            rec, own = a["recommended"], a["own"]
            rows.append((scene.scene, _g(a["tolerance"]), _settings(rec), rec["proxy"],
                         _settings(own), own["proxy"], "yes" if own["meets"] else "NO",
                         f"{a['proxy_saving']:.3g}x", _reference(a["reference"], a["duration"]),
                         f"{len(a['runs'])} ({len(a['pruned'])} pruned)"))
            wall_rows.append((scene.scene, _g(a["tolerance"]), _g(rec["wall_seconds"]),
                              _g(own["wall_seconds"]), f"{a['wall_saving']:.3g}x"))
        series.append(Series(scene.scene, [a["tolerance"] for a in scene.advice],
                             [a["recommended"]["proxy"] for a in scene.advice], "o-"))
        results.append({"scene": scene.scene, "refused": "", "skipped": "",
                        "advice": [_summary(a) for a in scene.advice]})
    tols = ", ".join(f"{t:g}" for t in record.tolerances)
    skipped = [s.scene for s in record.scenes if s.skipped]
    scope = (f"Quick run: the first {record.duration:g} s of each scene (its first impacts), "
             "each candidate timed once"
             + (f", {', '.join(skipped)} not advised (see its row)" if skipped else "")
             + "; the full report runs every rigid-body scene for its own duration at three "
             "tolerances." if ctx.quick and record.duration is not None
             else "Each scene's own duration" if record.duration is None
             else f"{record.duration:g} s of each scene") + f" TOL = {tols} m."
    table = Table(
        id="advisor-advice", title="The advisor's answer for each bundled scene",
        columns=("scene", "TOL (m)", "recommended (solver, step, level, boxes)", "cost",
                 "the scene's own settings", "own cost", "own meets TOL",
                 "saving (own / recommended cost)", "reference", "runs made"),
        rows=tuple(rows),
        caption=(f"{scope} cost: force evaluations x bodies + narrow-phase calls (machine-"
                 "independent; the advisor ranks by it). A run meets TOL when its positions "
                 "stay within TOL of the reference's up to the horizon, its impacts pair "
                 "with the reference's in order with times within TOL, and its end energy "
                 "is within the allowance; it is recommended only when its next finer step "
                 "meets TOL too (a step that meets TOL by chance, where contacts make the "
                 "error a staircase in h, is passed over). All tolerances of a scene are "
                 "judged against one reference, the strictest's, and its horizon. "
                 "A saving below 1 means the scene's own settings "
                 "are cheaper but miss TOL. Pruned: runs whose force evaluations alone "
                 "already cost more than the best run found. "
                 f"Reproduce: {CMD} (one scene: refsim advise SCENE --tolerance TOL)"))
    wall = Table(
        id="advisor-wall", title="The advisor's runs: wall time, recommended against own",
        columns=("scene", "TOL (m)", "recommended (s)", "own (s)", "saving"),
        rows=tuple(wall_rows), timing=True,
        caption=(f"Median wall time of {record.repeats} run(s) of each setting on a shared "
                 "machine (runs shared between tolerances are timed once); read ratios, "
                 "not absolute values. Reproduce: " + CMD))
    figure = Figure(
        id="advisor-tolerance", title="The advisor: cost of the recommendation against TOL",
        svg=line_chart(series, xlabel="TOL (m)", ylabel="cost of the recommended run",
                       logx=True, logy=True),
        caption=("Each bundled rigid-body scene's cheapest run within TOL of its reference: "
                 "how much modelling the scene needs for each accuracy. Each tolerance is "
                 "offered the stricter ones' recommendations, against one reference and "
                 "horizon, so the cost never grows as TOL loosens. " + scope
                 + f" Reproduce: {CMD}"))
    intro = ("Model no more than a scene needs: refsim advise holds a scene's physics fixed "
             "(rotation model, body response, forces) and searches its fidelity choices "
             "(solver, step, collision level, box update) for the cheapest run within TOL of "
             "a reference run (rk4, level exact, linear boxes, its step halved until it "
             "agrees with twice its step). A chaotic scene's reference may not converge; "
             "the advisor then says up to which time positions are predictable and judges "
             "the rest by energy and impact counts. Every bundled scene is listed; the "
             "advisor tunes rigid-body scenes only.")
    return Section(key="advisor", title="Model no more than a scene needs: the fidelity advisor",
                   intro=intro, tables=[table, wall], figures=[figure],
                   results={"scenes": results, "tolerances": list(record.tolerances),
                            "duration": record.duration, "repeats": record.repeats})
