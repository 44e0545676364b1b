"""The textbook section from constructed records: each engine's error on
each closed-form problem in its check's colour, and refsim's errors by step."""

from __future__ import annotations

import math
from types import SimpleNamespace

from refsim.conformance.checks_rigid import OFF_CENTRE_TOL, STACK_TRAVEL, TEXTBOOK_PROBLEMS
from refsim.conformance.matrix import Cell, Matrix
from refsim.report.plan import TextbookConvergence
from refsim.report.sections.textbook import build

STRIKE = {"largest_miss_of_closing_speed": 0.095, "momentum_drift": 2e-4}
STACK = {"largest_vertex_travel_metres": 6e-5, "tolerance_metres": STACK_TRAVEL}


def _ctx():
    cells = {
        ("rigid.off_centre", "mujoco"): Cell("xfailed", 2, 0, 2, {"bug": 2},
                                             {"strike-e1": STRIKE,
                                              "strike-e0.5": {**STRIKE, "largest_miss_"
                                                              "of_closing_speed": 0.07}}),
        ("rigid.stack", "mujoco"): Cell("passed", 3, 3, 0, {}, {"offset-stack": STACK}),
        ("rigid.off_centre", "fcl"): None,
    }
    cells = {k: v for k, v in cells.items() if v is not None}
    matrix = Matrix(engines=("fcl", "mujoco"), checks=("rigid.off_centre", "rigid.stack"),
                    cells=cells, pages={}, divergences=(), refsim="x", seed=0, cases=20)
    convergence = TextbookConvergence((2e-3, 1e-3), {"rigid.stack": [2e-4, 5e-5],
                                                     "rigid.free_rotation": [math.inf, 1e-7]},
                                      {"rigid.stack": STACK_TRAVEL})
    records = {"conformance-matrix": SimpleNamespace(matrix=matrix),
               "textbook-convergence": convergence}
    return SimpleNamespace(run=SimpleNamespace(get=records.__getitem__))


def test_each_engine_s_worst_error_in_its_check_s_colour():
    section = build(_ctx())
    engines, steps = section.tables
    assert engines.columns[3:] == ("MuJoCo",)              # FCL has no rigid check
    rows = {row[0]: row for row in engines.rows}
    strike = next(p for p in TEXTBOOK_PROBLEMS if p.check == "rigid.off_centre").problem
    stack = next(p for p in TEXTBOOK_PROBLEMS if p.check == "rigid.stack").problem
    assert rows[strike][2] == f"{OFF_CENTRE_TOL:.2g}"
    assert (rows[strike][3].text, rows[strike][3].status) == ("0.095", "declared")
    assert (rows[stack][3].text, rows[stack][3].status) == ("6e-05", "pass")
    assert len(engines.rows) == len(TEXTBOOK_PROBLEMS)      # the others: "not run"
    assert section.results["errors"]["rigid.off_centre"] == {"mujoco": 0.095}


def test_refsim_s_errors_by_step_with_wrong_flips_named():
    section = build(_ctx())
    _, steps = section.tables
    assert steps.columns[3:] == ("h = 0.002 s", "h = 0.001 s")
    rows = {row[1]: row for row in steps.rows}
    assert rows["largest vertex travel, m"][3:] == ("0.0002", "5e-05")
    assert rows["relative drift (inf: wrong flips)"][3:] == ("wrong flips", "1e-07")
    assert section.results["convergence"]["rigid.free_rotation"] == ["inf", 1e-7]
