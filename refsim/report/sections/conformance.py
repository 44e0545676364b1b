"""Report section: the shipped engines side by side (the conformance kit).

Arranges the plan's ``conformance-matrix``: each shipped engine (refsim's
seed and corrected models, python-fcl, coal, trimesh, pybullet, MuJoCo, Drake
with point and with hydroelastic contact) run through every check its
capabilities call for, against answers that depend on no float engine
(:mod:`refsim.conformance`). One table, a row per check and a column per
engine that could be loaded, each heading a link to the engine's own
conformance page, written beside the report; the engines that
could not be loaded, with the reason; and every failing or declared
(expected-failure) check in the divergence catalogue, with its classes
counted. Which checks fail, and how each failure is classified, is decided
by the checks (:mod:`refsim.conformance.results`); this module only
arranges it.
"""

from __future__ import annotations

from refsim.engines.registry import TITLES
from refsim.report.plan import command
from refsim.report.section import Agreement, Cell, Divergence, Section, Table, Timing

#: Column headings of the shipped engines (the registry's titles:
#: refsim.engines.registry; the engines' own names otherwise).
ENGINE_TITLES = TITLES

#: Each status in the engine summaries of the page's agreement table ("12
#: pass; 5 fail as declared").
STATUS_WORDS = {"passed": "pass", "failed": "FAIL", "xfailed": "fail as declared",
                "xpassed": "pass though declared to fail", "n/a": "not run"}

#: The colour of a cell by the check's status, and the legend under the
#: matrix: (colour, what it means). A cell without the capability is "none".
CELL_COLOURS = {"passed": "pass", "xfailed": "declared", "failed": "fail",
                "xpassed": "declared", "n/a": "none"}
LEGEND = (("pass", "passes every case"),
          ("declared", "fails as the engine declares (a known divergence)"),
          ("fail", "fails, not declared"),
          ("none", "not run: the engine lacks the capability, cannot pose the check's "
                   "scenes (a scene key it refuses, named in the cell), or the check has "
                   "no case"))

#: A cell of an engine without the check's capability.
NO_CAPABILITY = "not run"


def _classes(classes: dict) -> str:
    return ", ".join(f"{name} {count}" for name, count in classes.items())


def _plural(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if n == 1 else "s")


def cell_text(cell) -> str:
    """One cell in words: what passed or failed of how many cases, the
    failing cases by class."""
    if cell is None:
        return NO_CAPABILITY
    classes = f" ({_classes(cell.classes)})" if cell.classes else ""
    if cell.status == "n/a":
        return f"not run ({cell.reason})" if cell.reason else "not run (no case)"
    if cell.status == "passed":
        return f"pass: {_plural(cell.cases, 'case')}"
    if cell.status == "xfailed":
        return (f"{cell.failed} of {_plural(cell.cases, 'case')} fail"
                + ("s" if cell.failed == 1 else "") + f" as declared{classes}")
    if cell.status == "xpassed":
        return f"pass: {_plural(cell.cases, 'case')}, though declared to fail"
    return f"FAIL: {cell.failed} of {_plural(cell.cases, 'case')}{classes}"


def matrix_cell(cell) -> Cell:
    """One cell as the matrix shows it: its words in its status's colour."""
    return Cell(cell_text(cell), "none" if cell is None else CELL_COLOURS[cell.status])


def build(ctx) -> Section:
    record = ctx.run.get("conformance-matrix")
    matrix = record.matrix
    title = {e: ENGINE_TITLES.get(e, e) for e in matrix.engines}
    links = tuple(f"{record.folder}/{matrix.pages[e]}" if record.folder and e in matrix.pages
                  else "" for e in matrix.engines)
    table = Table(
        id="conformance-matrix", title="The conformance matrix: checks against engines",
        columns=("check", *(title[e] for e in matrix.engines)),
        column_links=("", *links),
        rows=tuple((check, *(matrix_cell(matrix.cell(check, e)) for e in matrix.engines))
                   for check in matrix.checks),
        legend=LEGEND,
        caption=(f"Each cell: how many of the check's cases pass or fail ({matrix.cases} per "
                 "generated set: triangle pairs, mesh poses, boxes; the ODE problems and "
                 "rigid-body scenes are fixed sets), the failing cases by class in brackets. "
                 "\"as declared\": a divergence the engine declares "
                 "(refsim/conformance/expected/<engine>.txt), listed in the divergence "
                 "catalogue with its reason. Each engine's heading links to its own page "
                 + (f"({record.folder}/<engine>/index.html, with conformance.json and the "
                    f"minimal failing examples; the matrix alone: {record.folder}/index.html)"
                    if record.folder else "(not written: no output directory)")
                 + f". Reproduce: {record.command} (as the report runs it: "
                 f"{command('conformance-matrix')} -o DIR)"))
    unavailable = Table(
        id="conformance-unavailable", title="Engines that could not be run",
        columns=("engine", "why"),
        rows=tuple((ENGINE_TITLES.get(name, name), reason)
                   for name, reason in matrix.unavailable.items()),
        caption="Their columns are left out of the matrix above.",
        empty="None: every shipped engine ran.")
    agreements = [Agreement(
        title[e], f"conformance kit: {sum(matrix.status_counts(e).values())} checks",
        "; ".join(f"{count} {STATUS_WORDS[status]}"
                  for status, count in matrix.status_counts(e).items()),
        record.command) for e in matrix.engines]
    divergences = [Divergence(
        title=f"{title[d.engine]}: {d.check}",
        kind=("engine: expected failure (declared), " if d.status == "xfailed"
              else "engine: FAILURE (not declared), ") + _classes(d.classes),
        finding=(f"{matrix.cell(d.check, d.engine).failed} of "
                 f"{matrix.cell(d.check, d.engine).cases} cases fail "
                 f"({_classes(d.classes)}). Declared reason: {d.reason}"),
        evidence="conformance-matrix") for d in matrix.divergences]
    data = matrix.to_dict()
    data["seconds"] = Timing(data["seconds"])
    intro = ("The conformance kit (refsim conform) checks any engine against answers that "
             "depend on no float engine: exact rational triangle tests, refsim's exact "
             "mesh pairs, boxes in exact arithmetic, ODE problems with exact solutions and "
             "rigid-body scenes with analytic answers. Here the shipped engines run "
             "through the same cases side by side; every disagreement is classified "
             "(touching, coplanar, tolerance, known divergence, bug) by the check that "
             "found it.")
    return Section(key="conformance", title="Engines side by side: the conformance kit",
                   intro=intro, tables=[table, unavailable], agreements=agreements,
                   divergences=divergences,
                   results={"matrix": data, "cases": record.cases, "folder": record.folder,
                            "command": record.command})
