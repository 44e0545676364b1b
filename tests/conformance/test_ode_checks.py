"""The ``ode`` checks on refsim's five solvers (each passes with the order
its tableau has) and on the seed's stated orders (claim C10)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from refsim.conformance import check_engine
from refsim.conformance.cases_ode import end_error
from refsim.conformance.checks_ode import ORDER_TOL, real_axis_limit
from refsim.engines.refsim_engines import RefsimEngine
from refsim.solvers import problems
from refsim.solvers.methods import SOLVERS

#: Real-axis stability limits on the grid z = -k/8 (the exact ones: 2, 2, 1,
#: 2, 2.785 for RK4, whose grid point below is 2.75).
REAL_LIMITS = {"euler": 2.0, "averaged-euler": 2.0, "backwards-euler": 1.0, "midpoint": 2.0,
               "rk4": 2.75}


@pytest.mark.parametrize("solver", list(SOLVERS))
def test_each_refsim_solver_passes_with_its_tableau_order(solver):
    engine = RefsimEngine("corrected", solver)
    result = check_engine(engine, only="ode")
    assert result.failed_checks() == []
    order = result.check("ode.order")
    assert order.cases == 5 and order.passed == 5
    for observed in order.measured["observed_orders"].values():
        assert abs(observed - SOLVERS[solver].order) <= ORDER_TOL / 2     # within 0.15
    evaluations = result.check("ode.evaluations").measured["evaluations_per_step"]
    assert evaluations == SOLVERS[solver].stages
    assert result.check("ode.stability").measured["real_axis_limit"] == REAL_LIMITS[solver]


def test_backwards_euler_is_not_the_second_order_the_seed_states():
    # claim C10: the seed gives "backwards Euler" order h^2; its tableau has order 1
    engine = RefsimEngine("corrected", "backwards-euler")
    engine.ode_order = SOLVERS["backwards-euler"].seed_order
    result = check_engine(engine, only="ode")
    assert result.failed_checks() == ["ode.order"]
    assert result.check("ode.order").classes == {"bug": 5}


def test_a_declared_evaluation_count_is_compared():
    engine = RefsimEngine("corrected", "midpoint")
    engine.ode_evaluations = 3
    result = check_engine(engine, only="ode")
    assert result.failed_checks() == ["ode.evaluations"]
    example = result.check("ode.evaluations").examples[0]
    assert example["evaluations"] == 2 and example["expected"] == 3


def test_real_axis_limit_reads_the_grid():
    points = (0.0, -0.5, -1.0, -1.5)
    assert real_axis_limit([1.0, 0.5, 1.0, 1.2], points) == 1.0
    assert real_axis_limit([1.0, 1.1, 0.5, 0.5], points) == 0.0


def test_end_error_needs_an_exact_solution():
    # a problem without a closed form (exact None) was called: "'NoneType' object
    # is not callable"
    problem = replace(problems.kepler_orbit(), exact=None)
    with pytest.raises(ValueError, match="'kepler' has no exact solution"):
        end_error(SOLVERS["rk4"].step, problem, 10)


def test_an_order_that_does_not_show_is_unmeasurable_not_passed():
    """An engine exact to rounding at every step size shows no order: each
    problem is "unmeasurable", with the reason, not a pass."""
    from refsim.conformance.cases_ode import ode_cases
    from refsim.conformance.checks_ode import check_ode_order

    cases = ode_cases()
    exact = {id(p.f): p.exact for p in cases.problems}

    class Oracle:
        name = "exact-oracle"
        ode_order = 4

        def ode_step(self, f, t, y, h):
            return exact[id(f)](t + h)

    result = check_ode_order(Oracle(), cases)
    assert result.classes == {"unmeasurable": len(cases.problems)}
    assert all(v is None for v in result.measured["observed_orders"].values())
    assert "the order does not show" in result.examples[0]["reason"]


def test_a_non_finite_error_is_a_bug_not_unmeasurable():
    """A NaN at one step size is never "below rounding": the order is NaN,
    the problem a bug (the engine's answer is not a number)."""
    from refsim.conformance.cases_ode import ode_cases
    from refsim.conformance.checks_ode import check_ode_order

    rk4 = SOLVERS["rk4"]

    class NanAt64:
        name = "nan-at-64"
        ode_order = 4

        def ode_step(self, f, t, y, h):
            y_next = rk4.step(f, t, np.asarray(y, dtype=np.float64), h)
            return y_next * np.nan if abs(h * 64 - 2.0) < 1e-12 else y_next

    result = check_ode_order(NanAt64(), ode_cases())
    assert result.classes.get("bug", 0) >= 1 and "unmeasurable" not in result.classes


def test_an_order_that_does_not_fall_is_a_bug_not_unmeasurable():
    """RK4 with a constant 1e-9 error per step: the errors stand above
    rounding but do not fall at order 4: bug, as before."""
    from refsim.conformance.cases_ode import ode_cases
    from refsim.conformance.checks_ode import check_ode_order

    rk4 = SOLVERS["rk4"]

    class Noisy:
        name = "noisy-rk4"
        ode_order = 4

        def ode_step(self, f, t, y, h):
            return rk4.step(f, t, np.asarray(y, dtype=np.float64), h) + 1e-9

    result = check_ode_order(Noisy(), ode_cases())
    assert "unmeasurable" not in result.classes and result.classes.get("bug", 0) >= 3


def test_fitted_order_of_nan_is_nan():
    import math

    from refsim.conformance.cases_ode import fitted_order

    steps = [1 / 32, 1 / 64, 1 / 128, 1 / 256]
    assert math.isnan(fitted_order(steps, [1e-3, math.nan, 1e-3 / 256, 1e-3 / 4096]))
