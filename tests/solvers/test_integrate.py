"""refsim.integrate: grid, shapes, the last step, bad input."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from refsim.errors import DivergenceError, OptionError, StateError


def decay(t, y):
    return -y


def test_shapes_and_grid():
    t, y = refsim.integrate(decay, [1.0, 2.0, 3.0], 0.0, 1.0, 0.1, method="euler")
    assert t.shape == (11,)
    assert y.shape == (11, 3)
    assert t[0] == 0.0 and t[-1] == 1.0
    np.testing.assert_allclose(np.diff(t), 0.1, rtol=1e-12)
    np.testing.assert_array_equal(y[0], [1.0, 2.0, 3.0])


def test_default_method_is_rk4():
    _, y_default = refsim.integrate(decay, [1.0], 0.0, 1.0, 0.25)
    _, y_rk4 = refsim.integrate(decay, [1.0], 0.0, 1.0, 0.25, method="rk4")
    np.testing.assert_array_equal(y_default, y_rk4)


def test_scalar_y0_is_one_dimensional():
    t, y = refsim.integrate(decay, 1.0, 0.0, 0.5, 0.25)
    assert y.shape == (3, 1)


def test_zero_length_interval():
    t, y = refsim.integrate(decay, [1.0], 2.0, 2.0, 0.1)
    assert t.shape == (1,) and y.shape == (1, 1)


def test_step_not_dividing_interval_is_an_error_by_default():
    with pytest.raises(StateError, match="last_step"):
        refsim.integrate(decay, [1.0], 0.0, 1.0, 0.3)


def test_short_last_step_lands_on_t1():
    result = refsim.solve_fixed_step(decay, [1.0], 0.0, 1.0, 0.3, "euler", last_step="short")
    np.testing.assert_allclose(result.t, [0.0, 0.3, 0.6, 0.9, 1.0], rtol=0, atol=1e-15)
    assert result.steps == 4
    # Euler with steps 0.3, 0.3, 0.3, 0.1 multiplies by (1 - h) each time.
    np.testing.assert_allclose(result.y[-1], [0.7**3 * 0.9], rtol=1e-15)


def test_step_count_tolerates_rounding_of_decimal_steps():
    t, _ = refsim.integrate(decay, [1.0], 0.0, 5.0, 0.001, method="euler")
    assert len(t) == 5001 and t[-1] == 5.0


@pytest.mark.parametrize("h", [0.0, -0.1, np.nan, np.inf])
def test_bad_step(h):
    with pytest.raises(StateError):
        refsim.integrate(decay, [1.0], 0.0, 1.0, h)


@pytest.mark.parametrize("y0", [[np.nan], [1.0, np.inf], [[1.0, 2.0]]])
def test_bad_initial_state(y0):
    with pytest.raises(StateError):
        refsim.integrate(decay, y0, 0.0, 1.0, 0.1)


def test_t1_before_t0():
    with pytest.raises(StateError):
        refsim.integrate(decay, [1.0], 1.0, 0.0, 0.1)


def test_unknown_method():
    with pytest.raises(OptionError, match="unknown solver"):
        refsim.integrate(decay, [1.0], 0.0, 1.0, 0.1, method="rk5")


def test_f_with_wrong_shape():
    with pytest.raises(StateError, match="shape"):
        refsim.integrate(lambda t, y: np.zeros(3), [1.0], 0.0, 1.0, 0.1)


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
def test_divergence_keeps_the_partial_result():
    # Euler on y' = -100 y with h = 1 multiplies by -99 each step.
    with pytest.raises(DivergenceError) as info:
        refsim.integrate(lambda t, y: -100.0 * y, [1.0], 0.0, 1000.0, 1.0, method="euler")
    partial = info.value.partial
    assert partial.y.shape[0] == partial.steps + 1
    assert np.isfinite(partial.y).all()
    assert info.value.step == partial.steps + 1


def test_seed_literal_variant_is_reachable_by_key():
    t, y = refsim.integrate(decay, [1.0], 0.0, 1.0, 0.5, method="rk4-seed-literal")
    assert y.shape == (3, 1)
