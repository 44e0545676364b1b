"""Laws of the seed's solvers (refsim.solvers): one step on a linear equation
is multiplication by R(h lambda); steps are deterministic, linear, and do not
depend on the time origin of an autonomous equation."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

import refsim
from properties.solvers.strategies import SOLVER_NAMES, STEP_SIZES, linear_test_equations
from refsim.solvers.stability import amplification

EPS = np.finfo(np.float64).eps

#: Rounding of one step: each of at most 4 stages and the final sum adds a
#: few ulps of the largest intermediate, which is at most (1 + |z|)^s |y|
#: with |z| <= 2 sqrt(2), s <= 4: (3.83)^4 ~ 215. 64 eps times that bound.
STEP_ROUNDING = 64 * EPS


@given(SOLVER_NAMES, linear_test_equations())
def test_one_step_is_multiplication_by_R(name, equation):
    lam, h, y0 = equation
    method = refsim.SOLVERS[name]
    y1 = method.step(lambda t, y: lam * y, 0.0, y0, h)
    z = h * lam
    bound = STEP_ROUNDING * (1 + abs(z)) ** method.stages * np.abs(y0).max()
    assert np.abs(y1 - amplification(method, z) * y0).max() <= bound


@given(SOLVER_NAMES, STEP_SIZES, st.integers(min_value=1, max_value=20))
def test_integrate_is_deterministic(name, h, steps):
    def f(t, y):
        return np.array([y[1], -np.sin(y[0]) + 0.1 * np.cos(t)])

    a = refsim.integrate(f, [1.0, 0.0], 0.0, steps * h, h, method=name)
    b = refsim.integrate(f, [1.0, 0.0], 0.0, steps * h, h, method=name)
    assert a[0].tobytes() == b[0].tobytes() and a[1].tobytes() == b[1].tobytes()
    assert a[1].shape == (steps + 1, 2)


@given(SOLVER_NAMES, linear_test_equations(), st.floats(min_value=-4.0, max_value=4.0))
def test_step_is_linear_in_y_for_a_linear_equation(name, equation, scale):
    lam, h, y0 = equation
    step = refsim.SOLVERS[name].step
    f = lambda t, y: lam * y                                   # noqa: E731
    y_scaled = step(f, 0.0, scale * y0, h)
    y_then_scaled = scale * step(f, 0.0, y0, h)
    bound = STEP_ROUNDING * (1 + abs(h * lam)) ** 4 * abs(scale) * np.abs(y0).max()
    assert np.abs(y_scaled - y_then_scaled).max() <= bound


@given(SOLVER_NAMES, STEP_SIZES, st.floats(min_value=-100.0, max_value=100.0))
def test_autonomous_step_ignores_the_time_origin(name, h, t0):
    def f(t, y):
        return np.array([y[1], -y[0] ** 3])

    y0 = np.array([0.5, -0.25])
    step = refsim.SOLVERS[name].step
    np.testing.assert_array_equal(step(f, t0, y0, h), step(f, 0.0, y0, h))
