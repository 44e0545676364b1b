"""One step of each solver against its formula in the seed's words, and nfev."""

from __future__ import annotations

import numpy as np
import pytest

import refsim

#: Evaluations of f per step (the seed's cost ranking, C9).
NFEV_PER_STEP = {"euler": 1, "averaged-euler": 2, "backwards-euler": 2, "midpoint": 2, "rk4": 4}


def f(t, y):
    """A non-autonomous, nonlinear right-hand side, so that a wrong stage
    time or a wrong weight shows."""
    return np.array([np.sin(t) * y[1] + y[0] ** 2, -y[0] + t**2])


def by_hand(name, t0, y0, h):
    """The seed's sentences, written out."""
    if name == "euler":
        return y0 + h * f(t0, y0)
    k1 = f(t0, y0)
    if name == "averaged-euler":
        k2 = f(t0 + h, y0 + h * k1)
        return y0 + h * (k1 + k2) / 2
    if name == "backwards-euler":
        k2 = f(t0 + h, y0 + h * k1)
        return y0 + h * k2
    if name == "midpoint":
        k2 = f(t0 + h / 2, y0 + h / 2 * k1)
        return y0 + h * k2
    k2 = f(t0 + h / 2, y0 + h / 2 * k1)
    k3 = f(t0 + h / 2, y0 + h / 2 * k2)
    k4 = f(t0 + h, y0 + h * k3)
    return y0 + h * (k1 + 2 * k2 + 2 * k3 + k4) / 6


#: The generic step sums term by term; by_hand groups differently. A few
#: ulps of the O(1) values here.
ROUNDING = 1e-14


@pytest.mark.parametrize("name", sorted(NFEV_PER_STEP))
def test_step_matches_the_formula(name):
    y0 = np.array([0.3, -0.7])
    got = refsim.SOLVERS[name].step(f, 0.4, y0, 0.1)
    np.testing.assert_allclose(got, by_hand(name, 0.4, y0, 0.1), rtol=0, atol=ROUNDING)


@pytest.mark.parametrize("name", sorted(NFEV_PER_STEP))
def test_nfev_per_step(name):
    result = refsim.solve_fixed_step(f, [0.3, -0.7], 0.0, 1.0, 0.125, name)
    assert result.steps == 8
    assert result.nfev == 8 * NFEV_PER_STEP[name]
    assert refsim.SOLVERS[name].stages == NFEV_PER_STEP[name]


@pytest.mark.parametrize("name", sorted(NFEV_PER_STEP))
def test_step_does_not_modify_y(name):
    y0 = np.array([0.3, -0.7])
    refsim.SOLVERS[name].step(f, 0.0, y0, 0.1)
    np.testing.assert_array_equal(y0, [0.3, -0.7])


def test_seed_literal_rk4_step_is_five_thirds_of_rk4_increment_for_constant_f():
    literal = refsim.SEED_LITERAL_VARIANTS["rk4-seed-literal"]
    y1 = literal.step(lambda t, y: np.array([2.0]), 0.0, np.array([1.0]), 0.3)
    np.testing.assert_allclose(y1, [1.0 + 5 / 3 * 0.3 * 2.0], rtol=ROUNDING)


@pytest.mark.parametrize("name", sorted(refsim.SOLVERS))
def test_the_step_into_buffers_is_the_step_bit_for_bit(name):
    from refsim.solvers.explicit_rk import rk_step, rk_step_into

    method = refsim.SOLVERS[name]
    rng = np.random.default_rng(11)
    M = rng.normal(size=(6, 6))

    def f(t, y):
        return np.sin(M @ y) - 0.3 * t * y

    def f_into(t, y, out):
        np.copyto(out, f(t, y))

    y = rng.normal(size=6)
    expected = rk_step(method, f, 0.2, y, 0.05)
    Y = y.copy()
    K, stage, scratch = np.empty((method.stages, 6)), np.empty(6), np.empty(6)
    rk_step_into(method, f_into, 0.2, Y, 0.05, K, stage, scratch)
    assert Y.tobytes() == expected.tobytes()


def test_step_into_without_the_stage_buffer_it_needs_raises():
    # Euler's stage is evaluated at y itself (stage may be None); rk4's are not.
    from refsim.solvers.explicit_rk import rk_step_into

    def f_into(t, y, out):
        np.copyto(out, -y)

    Y = np.ones(3)
    rk_step_into(refsim.SOLVERS["euler"], f_into, 0.0, Y, 0.5, np.empty((1, 3)), None,
                 np.empty(3))
    assert Y.tolist() == [0.5, 0.5, 0.5]                # y + h (-y), exact in binary
    method = refsim.SOLVERS["rk4"]
    with pytest.raises(ValueError, match="stage 1 of 'rk4' needs the stage buffer"):
        rk_step_into(method, f_into, 0.0, Y, 0.5, np.empty((method.stages, 3)), None,
                     np.empty(3))
