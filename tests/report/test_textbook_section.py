"""The textbook section from constructed records: each engine's error on
each closed-form problem in its check's colour, and refsim's errors by step."""

from __future__ import annotations

import math
from types import SimpleNamespace

from refsim.conformance.checks_contact import STACK_TRAVEL
from refsim.conformance.checks_strikes import MOMENTUM_TOL, OFF_CENTRE_TOL
from refsim.conformance.matrix import Cell, Matrix
from refsim.conformance.textbook_problems import TEXTBOOK_PROBLEMS
from refsim.report.entries.conformance import TextbookConvergence
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
        ("rigid.free_rotation", "mujoco"): Cell("failed", 1, 0, 1, {"crash": 1}, {}),
    }
    matrix = Matrix(engines=("fcl", "mujoco"),
                    checks=("rigid.free_rotation", "rigid.off_centre", "rigid.stack"),
                    cells=cells, pages={}, divergences=(), refsim="x", seed=0, cases=20)
    convergence = TextbookConvergence((2e-3, 1e-3), {"rigid.stack": [2e-4, 5e-5],
                                                     "rigid.free_rotation": [math.inf, 1e-7]},
                                      {"rigid.stack": 0.2})
    records = {"conformance-matrix": SimpleNamespace(matrix=matrix),
               "textbook-convergence": convergence}
    return SimpleNamespace(run=SimpleNamespace(get=records.__getitem__))


def _problem(check: str) -> str:
    return next(p for p in TEXTBOOK_PROBLEMS if p.check == check).problem


def test_each_engine_s_worst_miss_over_its_tolerance_in_its_check_s_colour():
    """The strike's worst scene misses by 0.095 of the closing speed against
    2 %: 4.75 tolerances (its momentum drift, 2e-4 against 1e-3, less); the
    stack's 6e-5 m against 2.5e-4 m: 0.24. A check that crashed on every
    scene has no value, in its failure's colour."""
    section = build(_ctx())
    engines, _ = section.tables
    assert engines.columns[1:] == ("MuJoCo",)              # FCL has no rigid check
    rows = {row[0]: row for row in engines.rows}
    strike, stack = rows[_problem("rigid.off_centre")][1], rows[_problem("rigid.stack")][1]
    assert (strike.text, strike.status) == (f"{0.095 / OFF_CENTRE_TOL:.2g}", "declared")
    assert 2e-4 / MOMENTUM_TOL < 0.095 / OFF_CENTRE_TOL
    assert (stack.text, stack.status) == (f"{6e-5 / STACK_TRAVEL:.2g}", "pass")
    crashed = rows[_problem("rigid.free_rotation")][1]
    assert (crashed.text, crashed.status) == ("no value", "fail")
    assert rows[_problem("rigid.apex_ratio")][1].text == "not run"
    assert len(engines.rows) == len(TEXTBOOK_PROBLEMS)
    assert section.results["ratios"]["rigid.off_centre"] == {"mujoco": 0.095 / OFF_CENTRE_TOL}


def test_refsim_s_errors_by_step_with_wrong_flips_named():
    section = build(_ctx())
    _, steps = section.tables
    assert steps.columns[3:] == ("h = 0.002 s", "h = 0.001 s")
    rows = {row[1]: row for row in steps.rows}
    assert rows["largest vertex travel, m"][2:] == ("0.2", "0.0002", "5e-05")
    assert rows["relative drift (inf: wrong flips)"][3:] == ("wrong flips", "1e-07")
    assert section.results["convergence"]["rigid.free_rotation"] == ["inf", 1e-7]
