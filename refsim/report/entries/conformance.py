"""The report's conformance entries: engines side by side, textbook problems.

``conformance-matrix`` runs the shipped engines through the conformance kit
(:func:`refsim.conformance.matrix.run_matrix`, on the run's workers when it
has them) and writes their pages into the report's directory;
``textbook-convergence`` follows refsim's corrected model on the kit's
textbook problems as the step shrinks.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from refsim.report.run import Run

#: Cases in each generated conformance set (triangle pairs, mesh poses,
#: boxes): quick, full (the full one is ``refsim conform``'s default). The
#: rigid-body scenes and the ODE problems are fixed sets, the same in both.
MATRIX_CASES = (20, 200)

#: Where the engines' conformance pages go, inside the report's directory.
MATRIX_FOLDER = "conformance"


@dataclass(frozen=True)
class MatrixRun:
    """The shipped engines through the conformance kit, side by side.

    ``matrix``: :class:`refsim.conformance.matrix.Matrix` (its ``pages``
    relative to ``folder``); ``folder``: the pages' folder relative to the
    report's directory ("" when none was written); ``command``: the command
    that reproduces the matrix and its pages.
    """

    matrix: Any
    cases: int
    folder: str
    command: str


def conformance_matrix(run: Run):
    from refsim.conformance.matrix import run_matrix

    cases = run.size(*MATRIX_CASES)
    out = None if run.out_dir is None else run.out_dir / MATRIX_FOLDER
    matrix, _ = run_matrix(cases=cases, seed=run.seed, out_dir=out, **run.sweep_options())
    return MatrixRun(matrix, cases, "" if out is None else MATRIX_FOLDER,
                     f"refsim conform --all --cases {cases} --seed {run.seed} -o DIR")


#: The steps (s) of the convergence table: quick, full.
TEXTBOOK_STEPS = ((2e-3, 1e-3), (2e-3, 1e-3, 5e-4))

#: The problems a quick run follows in h (a full run: every one of
#: refsim.conformance.textbook_problems.TEXTBOOK_PROBLEMS): the cheap ones.
TEXTBOOK_QUICK = ("rigid.oblique_bounce", "rigid.free_rotation", "rigid.off_centre",
                  "rigid.cradle")


@dataclass(frozen=True)
class TextbookConvergence:
    """refsim's corrected model on the kit's textbook problems at each step:
    ``errors[check]`` the error against the closed form at each of
    ``steps`` (in the problem's unit), and ``ratios[check]`` its misses
    over the check's tolerances at the kit's step (at most 1 passes)."""

    steps: tuple
    errors: dict
    ratios: dict


def textbook_convergence(run: Run):
    from refsim.conformance import cases_rigid as R
    from refsim.conformance.registry import check_by_key
    from refsim.conformance.textbook_problems import TEXTBOOK_PROBLEMS
    from refsim.engines.registry import build

    engine = build("refsim-corrected")
    steps = tuple(run.size(*TEXTBOOK_STEPS))
    problems = [p for p in TEXTBOOK_PROBLEMS if not run.quick or p.check in TEXTBOOK_QUICK]
    scenes = R.rigid_scenes()
    errors: dict = {p.check: [] for p in problems}
    ratios: dict = {}
    for h in steps:
        cases = R.RigidCases(scenes=tuple(R.with_step(s, h) for s in scenes))
        for p in problems:
            measured = check_by_key(p.check).run(engine, cases).measured
            errors[p.check].append(p.error(measured))
            if h == R.STEP:
                ratios[p.check] = p.ratio(measured)
    return TextbookConvergence(steps, errors, ratios)
