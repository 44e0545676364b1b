"""Report section: textbook mechanics.

Arranges two records.

- From the plan's ``conformance-matrix``: each rigid-body engine's largest
  miss over its tolerance on each of the kit's problems that have a
  closed-form answer (:data:`refsim.conformance.textbook_problems.TEXTBOOK_PROBLEMS`,
  worst over the problem's scenes), in the colour of the check's status.
- From ``textbook-convergence``: refsim's corrected model on the same
  problems at several steps.

The errors, the tolerances and the statuses are the kit's
(:mod:`refsim.conformance.checks_rigid` lists the modules of the rigid
checks); this module only arranges them.
"""

from __future__ import annotations

import math

from refsim.conformance import cases_rigid as R
from refsim.conformance.textbook_problems import TEXTBOOK_PROBLEMS
from refsim.report.plan import command
from refsim.report.section import Cell, Section, Table
from refsim.report.sections.conformance import CELL_COLOURS, ENGINE_TITLES, LEGEND


def _number(x: float) -> str:
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return "n/a"
    if math.isinf(x):
        return "wrong flips" if x > 0 else "-inf"
    return "0" if x == 0.0 else f"{x:.2g}"


def build(ctx) -> Section:
    matrix = ctx.run.get("conformance-matrix").matrix
    convergence = ctx.run.get("textbook-convergence")
    engines = [e for e in matrix.engines
               if any(matrix.cell(p.check, e) is not None for p in TEXTBOOK_PROBLEMS)]
    rows = []
    for problem in TEXTBOOK_PROBLEMS:
        cells = []
        for engine in engines:
            cell = matrix.cell(problem.check, engine)
            if cell is None:
                cells.append(Cell("not run", "none"))
            elif cell.status == "n/a":              # a scene key it cannot pose
                cells.append(Cell("cannot pose", CELL_COLOURS[cell.status]))
            elif not cell.measured:      # every scene crashed or none was read
                cells.append(Cell("no value", CELL_COLOURS[cell.status]))
            else:
                cells.append(Cell(_number(problem.ratio(cell.measured)),
                                  CELL_COLOURS[cell.status]))
        rows.append((problem.problem, *cells))
    engines_table = Table(
        id="textbook-engines", title="Error against the closed form over its tolerance, by "
                                     "engine",
        columns=("problem", *(ENGINE_TITLES.get(e, e) for e in engines)),
        rows=tuple(rows), legend=LEGEND,
        caption="Each cell: the engine's largest miss over the problem's scenes, as a "
                "multiple of the kit's tolerance for it (every quantity the check tests; "
                "at most 1 passes), at the kit's step of "
                f"{R.STEP:g} s, in the colour of the kit's verdict. The closed forms, the "
                "scenes and the reason for each tolerance are in the kit's documentation "
                "(refsim/conformance/checks_rigid.py lists its modules). Reproduce: "
                f"{command('conformance-matrix')}")
    steps = convergence.steps
    steps_rows = tuple(
        (problem.problem, problem.unit,
         _number(convergence.ratios.get(problem.check, math.nan)),
         *(_number(x) for x in convergence.errors[problem.check]))
        for problem in TEXTBOOK_PROBLEMS if problem.check in convergence.errors)
    steps_table = Table(
        id="textbook-convergence", title="refsim's corrected model as the step shrinks",
        columns=("problem", "error measured as", f"over its tolerance at {R.STEP:g} s",
                 *(f"h = {h:g} s" for h in steps)),
        rows=steps_rows,
        caption="refsim's corrected model alone: each problem's headline error against "
                "the closed form (the worst scene's) at each step. Reproduce: "
                f"{command('textbook-convergence')}")
    intro = ("Problems whose answer mechanics gives in closed form: drops and their apex "
             "ratios, oblique impacts with Coulomb friction in every regime, a spin stopped "
             "by friction, a torque-free body flipping about its middle axis, a ball "
             "striking a free rod off its centre, stacks that must not move, a ball "
             "sliding into rolling and a box sliding to rest, a brick tumbling with "
             "elastic impacts, and the times of a drop's bounces. Every "
             "rigid-body engine runs them through the conformance kit; the first table "
             "shows each engine's misses against the kit's tolerances, the second how "
             "refsim's own error changes with the step.")
    results = {"engines": list(engines),
               "ratios": {p.check: {e: p.ratio(matrix.cell(p.check, e).measured)
                                    for e in engines if matrix.cell(p.check, e) is not None
                                    and matrix.cell(p.check, e).measured}
                          for p in TEXTBOOK_PROBLEMS},
               "steps": list(steps),
               "convergence": {k: list(v) for k, v in convergence.errors.items()},
               "ratios_at_kit_step": dict(convergence.ratios)}
    return Section(key="textbook", title="Textbook mechanics", intro=intro,
                   tables=[engines_table, steps_table], results=_finite(results))


def _finite(value):
    """``value`` with every non-finite float as a string ("inf", "nan"):
    results.json is strict JSON."""
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_finite(v) for v in value]
    return value
