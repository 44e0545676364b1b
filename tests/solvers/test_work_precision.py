"""Work-precision points and their interpolation (C8, C9)."""

from __future__ import annotations

import math

import pytest
from refsim.oracles.scipy_ivp import ScipyReference

from refsim.solvers.problems import kepler_orbit
from refsim.studies.solvers import (
    WorkPoint,
    cost_for_error,
    error_at_cost,
    measure_work_precision,
)


@pytest.fixture(scope="module")
def points():
    return measure_work_precision(kepler_orbit(), steps=[64, 128, 256, 512, 1024],
                                  tolerances=(1e-4, 1e-6, 1e-8), oracle=ScipyReference())


def test_every_run_is_recorded(points):
    methods = {p.method for p in points}
    assert methods == {"euler", "averaged-euler", "backwards-euler", "midpoint", "rk4",
                       "scipy-RK45", "scipy-DOP853"}
    rk4 = [p for p in points if p.method == "rk4"]
    assert [p.nfev for p in rk4] == [256, 512, 1024, 2048, 4096]


def test_rk4_beats_second_order_at_equal_evaluations_on_kepler(points):
    # At 1024 evaluations on Kepler: rk4 takes 256 steps, midpoint 512.
    rk4 = error_at_cost(points, "rk4", 1024)
    midpoint = error_at_cost(points, "midpoint", 1024)
    print(f"error at 1024 evaluations: rk4 {rk4:.2e}, midpoint {midpoint:.2e}")
    assert rk4 < midpoint / 10


def test_interpolation_helpers():
    pts = [WorkPoint("m", 0.1, 1e-2, 10, 1.0), WorkPoint("m", 0.05, 1e-4, 100, 2.0)]
    assert cost_for_error(pts, "m", 1e-3) == pytest.approx(math.sqrt(10 * 100))
    assert error_at_cost(pts, "m", math.sqrt(1000)) == pytest.approx(1e-3)
    assert cost_for_error(pts, "m", 1e-6) == math.inf
    assert math.isnan(error_at_cost(pts, "m", 1000))
