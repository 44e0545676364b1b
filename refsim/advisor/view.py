"""The view of ``refsim advise``: an :class:`~refsim.advisor.records.Advice`
as text, as a TOML snippet to paste into the scene, as one JSON document,
and as a work-precision chart (SVG with matplotlib, or text).

It arranges what the advisor measured and computes nothing of its own
(docs/design.md, Architecture: views). matplotlib is the ``report`` extra: it is
imported only to draw the SVG, and :func:`svg_available` says whether it
can be.

The JSON document (:func:`advice_document`) is :meth:`Advice.as_dict` with
``"format"``, ``"toml"`` (the snippet) and ``"chart"`` (the chart's path or
null) added. JSON has no infinity: an infinite number (an error of a run
whose impacts do not pair, a diverged run) is written as null.

Cost: O(runs).
"""

from __future__ import annotations

import math

#: The JSON document's format name and version.
FORMAT = "refsim advise 1"

#: One letter per solver on the text chart (upper case: the run meets TOL).
SOLVER_LETTERS = {"euler": "e", "averaged-euler": "a", "backwards-euler": "b",
                  "midpoint": "m", "rk4": "r"}

#: One marker per solver on the SVG chart (identical runs of two solvers,
#: such as midpoint and averaged Euler in free flight, stay told apart).
SOLVER_MARKERS = {"euler": "o", "averaged-euler": "s", "backwards-euler": "^",
                  "midpoint": "D", "rk4": "v"}

#: The text chart's plotting area, in characters.
CHART_WIDTH, CHART_HEIGHT = 60, 14

#: On the chart an error of 0 (a run identical to the reference up to the
#: horizon) is drawn at this fraction of TOL: log axes have no 0.
ZERO_ERROR_FRACTION = 1e-3


def chart_error(row) -> float:
    """The error a run is charted at (m): the larger of its position and
    event errors; infinite when its impacts do not pair or it diverged."""
    if row.events == "differ" or row.diverged is not None:
        return math.inf
    return max(row.position_error, row.event_error)


# -- the snippet ---------------------------------------------------------------------------


def toml_snippet(advice) -> str:
    """The recommended ``[integration]`` and ``[collision]`` keys, ready to
    paste over the scene's own (the other keys of those tables stay)."""
    rec = advice.recommended
    lines = ["[integration]", f'solver = "{rec.solver}"', f"step = {rec.step!r}"]
    n = advice.scene_duration / rec.step
    if abs(n - round(n)) > 1e-9 * n:
        lines.append(f"# duration = {advice.scene_duration!r} is not a whole number of these "
                     f"steps: use a multiple of {advice.sample_interval!r}")
    lines += ["", "[collision]", f'level = "{rec.level}"', f'aabb = "{rec.aabb}"']
    return "\n".join(lines) + "\n"


# -- JSON -----------------------------------------------------------------------------------


def _finite(value):
    """``value`` with every infinite or NaN float replaced by None."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_finite(v) for v in value]
    return value


def advice_document(advice, chart: str | None = None) -> dict:
    """The ``--json`` document (module docstring); strict JSON (no NaN or
    infinity: ``json.dumps(..., allow_nan=False)`` accepts it)."""
    document = {"format": FORMAT, **advice.as_dict(), "toml": toml_snippet(advice),
                "chart": chart}
    return _finite(document)


# -- text -----------------------------------------------------------------------------------


def _m(x: float) -> str:
    return "inf" if not math.isfinite(x) else f"{x:.3g}"


def _settings(row) -> str:
    return f"{row.solver}, h = {row.step:.6g} s, level {row.level}, aabb {row.aabb}"


def _saving(x: float) -> str:
    return "-" if not math.isfinite(x) or x <= 0 else f"{x:.3g}x"


def reference_text(advice) -> list[str]:
    """What the reference is and whether it converged, in a few lines."""
    ref = advice.reference
    lines = [f"reference: {ref.solver}, h = {ref.step:.6g} s, level {ref.level}, aabb "
             f"{ref.aabb}; its check at h = {ref.check_step:.6g} s"]
    if ref.converged:
        lines.append(f"  converged: reference and check agree within "
                     f"{_m(ref.uncertainty)} m over the whole run")
        return lines
    why = {"not converging": "halving its step did not bring it and its check closer",
           "budget": "its next halving would exceed the step budget (--max-reference-steps)",
           "converged": "its event times are not resolved to TOL"}[ref.stop]
    lines.append(f"  NOT converged: {why} (difference {_m(ref.uncertainty)} m)")
    lines.append(f"  horizon: positions and events are predictable up to t = "
                 f"{ref.horizon:.6g} s of {advice.duration:.6g} s; runs are compared up to it, "
                 f"and beyond it by the end energy (within {advice.energy_allowance:.3g} of "
                 f"the energy scale) and impact counts (within "
                 + ", ".join(f"{n} {kind}" for kind, n in advice.count_allowance.items()) + ")")
    return lines


def row_text(row) -> str:
    return (f"{_settings(row)}: proxy {row.proxy}, wall {row.wall_seconds:.3g} s "
            f"(median of {row.wall_repeats}), position error {_m(row.position_error)} m, "
            f"events {row.events}, energy gap {row.energy_gap:+.2g}, "
            f"meets TOL: {'yes' if row.meets else 'no'}")


#: What the ``proxy`` column and figures count, said where they are shown.
PROXY_MEANING = ("a run's cost counted, not timed: force evaluations x bodies + "
                 "narrow-phase calls (the same on every machine and every run)")

TABLE_COLUMNS = ("role", "solver", "step s", "level", "aabb", "proxy", "wall s", "pos err m",
                 "event err m", "events", "energy gap", "meets")


def table_text(advice) -> str:
    """Every run tried, one row each (columns: :data:`TABLE_COLUMNS`)."""
    rows = [TABLE_COLUMNS]
    for r in advice.runs:
        rows.append((",".join(r.roles), r.solver, f"{r.step:.6g}", r.level, r.aabb,
                     str(r.proxy), f"{r.wall_seconds:.3g}", _m(r.position_error),
                     _m(r.event_error) if r.events != "differ" else "-", r.events,
                     f"{r.energy_gap:+.2g}" if math.isfinite(r.energy_gap) else "inf",
                     "yes" if r.meets else "no"))
    widths = [max(len(row[i]) for row in rows) for i in range(len(TABLE_COLUMNS))]
    return "\n".join("  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip()
                     for row in rows)


def advice_text(advice, chart: str | None = None) -> str:
    """The whole advice for a terminal: summary, snippet, table, chart (text,
    or the line naming the SVG file)."""
    rec, own = advice.recommended, advice.own
    lines = [f"refsim advise {advice.scene}: TOL = {advice.tolerance:g} m, "
             f"{advice.duration:g} s simulated, compared every {advice.sample_interval:g} s",
             *reference_text(advice),
             f"recommended: {row_text(rec)}",
             f"scene's own: {row_text(own)}",
             f"saving: {_saving(advice.proxy_saving)} by the proxy, "
             f"{_saving(advice.wall_saving)} by wall time (medians; noisy)"
             + ("" if own.meets else "; the scene's own settings do not meet TOL"),
             f"proxy: {PROXY_MEANING}",
             "", "paste into the scene:", toml_snippet(advice),
             f"runs: {advice.computed} simulated, {advice.resumed} read from the store, "
             f"{len(advice.pruned)} pruned (their force evaluations alone cost more than "
             "the best run found)",
             table_text(advice), ""]
    lines.append(chart if chart is not None else text_chart(advice))
    return "\n".join(lines) + "\n"


def text_chart(advice) -> str:
    """Work against precision as characters: proxy (up) against error
    (right), log scales; a letter per run (:data:`SOLVER_LETTERS`, upper
    case when it meets TOL), ``O`` the scene's own settings, ``*`` the
    recommendation, ``|`` TOL. Runs whose impacts do not pair are left out."""
    tol = advice.tolerance
    points = []
    for r in advice.runs:
        if "reference" in r.roles:
            continue
        e = chart_error(r)
        if not math.isfinite(e):
            continue
        mark = SOLVER_LETTERS[r.solver].upper() if r.meets else SOLVER_LETTERS[r.solver]
        if r == advice.own:
            mark = "O"
        if r == advice.recommended:
            mark = "*"
        points.append((max(e, tol * ZERO_ERROR_FRACTION), r.proxy, mark))
    if not points:
        return "(no run's impacts pair with the reference's: nothing to chart)"
    xs = [math.log10(x) for x, _, _ in points] + [math.log10(tol)]
    ys = [math.log10(max(y, 1)) for _, y, _ in points]
    x0, x1 = min(xs), max(xs)
    y0, y1 = min(ys), max(ys)
    x1 = x1 if x1 > x0 else x0 + 1.0
    y1 = y1 if y1 > y0 else y0 + 1.0

    def col(x):
        return round((math.log10(x) - x0) / (x1 - x0) * (CHART_WIDTH - 1))

    def line(y):
        return CHART_HEIGHT - 1 - round((math.log10(max(y, 1)) - y0) / (y1 - y0)
                                        * (CHART_HEIGHT - 1))

    grid = [[" "] * CHART_WIDTH for _ in range(CHART_HEIGHT)]
    for row in grid:
        row[col(tol)] = "|"
    # the recommendation and the scene's own last, so that they stay visible
    for x, y, mark in sorted(points, key=lambda p: p[2] in "*O"):
        grid[line(y)][col(x)] = mark
    top, bottom = f"{10 ** y1:.3g}", f"{10 ** y0:.3g}"
    pad = max(len(top), len(bottom))
    out = ["work-precision: proxy (force evaluations x bodies + narrow-phase calls) against "
           "error (m)"]
    for i, row in enumerate(grid):
        label = top if i == 0 else bottom if i == CHART_HEIGHT - 1 else ""
        out.append(f"{label.rjust(pad)} |{''.join(row)}")
    axis = f"{10 ** x0:.2g} m".ljust(CHART_WIDTH - 8) + f"{10 ** x1:.2g} m"
    out.append(" " * pad + " +" + "-" * CHART_WIDTH)
    out.append(" " * (pad + 2) + axis)
    out.append(" " * (pad + 2) + "e a b m r: euler, averaged-euler, backwards-euler, midpoint, "
               "rk4 (upper case: meets TOL); O own; * recommended; | TOL")
    return "\n".join(out)


# -- SVG --------------------------------------------------------------------------------------


def svg_available() -> bool:
    """Whether matplotlib (the ``report`` extra) can be imported."""
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        return False
    return True


def svg_chart(advice) -> str:
    """The work-precision chart (:func:`chart_figure`) as SVG text.

    Raises ImportError without matplotlib (check :func:`svg_available`).
    """
    import io

    from matplotlib.backends.backend_svg import FigureCanvasSVG

    fig = chart_figure(advice)
    FigureCanvasSVG(fig)
    out = io.StringIO()
    fig.savefig(out, format="svg")
    return out.getvalue()


def chart_figure(advice):
    """The work-precision chart as a matplotlib ``Figure`` (no pyplot, no
    global state): proxy against error, log-log, a line per solver through
    its runs at the reference's level and boxes (a marker per solver,
    filled for runs that meet TOL; runs whose impacts do not pair are left
    out); the other levels, the scene's own settings and the recommendation
    marked; TOL as a dashed line."""
    from matplotlib.figure import Figure
    from matplotlib.ticker import NullFormatter

    tol = advice.tolerance
    fig = Figure(figsize=(7.0, 4.6))
    ax = fig.add_subplot()
    floor = tol * ZERO_ERROR_FRACTION
    ref = advice.reference
    for solver in SOLVER_LETTERS:
        rows = sorted((r for r in advice.runs if r.solver == solver
                       and (r.level, r.aabb) == (ref.level, ref.aabb)
                       and "reference" not in r.roles and math.isfinite(chart_error(r))),
                      key=lambda r: r.step)
        if not rows:
            continue
        xs = [max(chart_error(r), floor) for r in rows]
        ys = [r.proxy for r in rows]
        marker = SOLVER_MARKERS[solver]
        line, = ax.plot(xs, ys, "-", lw=1, marker=marker, ms=6, mfc="none", label=solver)
        for x, y, r in zip(xs, ys, rows, strict=True):
            ax.plot([x], [y], marker, color=line.get_color(), ms=6,
                    mfc=line.get_color() if r.meets else "white")
    others = [r for r in advice.runs if (r.level, r.aabb) != (ref.level, ref.aabb)
              and math.isfinite(chart_error(r))]
    if others:
        ax.plot([max(chart_error(r), floor) for r in others], [r.proxy for r in others], "s",
                color="0.4", mfc="none", ms=6, label="other levels / boxes")
    own, rec = advice.own, advice.recommended
    if math.isfinite(chart_error(own)):
        ax.plot([max(chart_error(own), floor)], [own.proxy], "*", color="black", ms=13,
                mfc="none", label="scene's own settings")
    else:                                       # named, not drawn: it has no finite error
        ax.plot([], [], "*", color="black", ms=13, mfc="none",
                label="scene's own settings: impacts differ (off the chart)")
    ax.plot([max(chart_error(rec), floor)], [rec.proxy], "o", color="crimson", ms=15,
            mfc="none", mew=2, label="recommended")
    ax.axvline(tol, color="crimson", ls="--", lw=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.xaxis.set_minor_formatter(NullFormatter())      # decades only: no crowded labels
    ax.yaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel("error against the reference (m): position, or event time x response speed")
    ax.set_ylabel("cost: force evaluations x bodies + narrow-phase calls")
    title = f"{advice.scene.rsplit('/', 1)[-1]}: TOL = {tol:g} m"
    if not ref.converged:
        title += f" (reference predictable to t = {ref.horizon:g} s)"
    ax.set_title(title, fontsize=10)
    ax.legend(fontsize=7, loc="best")
    ax.grid(True, which="both", lw=0.3, alpha=0.5)
    fig.tight_layout()
    return fig
