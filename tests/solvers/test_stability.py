"""Stability functions R(z) and stable step limits (HW II, section IV.2)."""

from __future__ import annotations

import math
from fractions import Fraction as F

import numpy as np
import pytest

from refsim.solvers.methods import RK4_SEED_LITERAL, SOLVERS
from refsim.solvers.stability import (
    amplification,
    growth_polynomial,
    imaginary_axis_limit,
    real_axis_limit,
    stability_grid,
    stability_polynomial,
)

#: Derived by hand from R(z) = 1 + sum_j b^T A^(j-1) 1 z^j.
POLYNOMIALS = {
    "euler": (1, 1),
    "averaged-euler": (1, 1, F(1, 2)),
    "backwards-euler": (1, 1, 1),
    "midpoint": (1, 1, F(1, 2)),
    "rk4": (1, 1, F(1, 2), F(1, 6), F(1, 24)),
}

#: Closed forms: Euler/Heun/midpoint |1 - x| <= 1 etc. (x = 2); backwards-euler
#: 1 + z + z^2 in [-1, 1] for z in [-1, 0]; rk4 2.785293563405... (the real
#: root of 1 - x + x^2/2 - x^3/6 + x^4/24 = 1, x != 0); imaginary axis:
#: 1 - y^2 + y^4 <= 1 for |y| <= 1; rk4 2 sqrt(2).
REAL_LIMIT = {"euler": 2.0, "averaged-euler": 2.0, "backwards-euler": 1.0, "midpoint": 2.0,
              "rk4": 2.785293563405}
IMAGINARY_LIMIT = {"euler": 0.0, "averaged-euler": 0.0, "backwards-euler": 1.0,
                   "midpoint": 0.0, "rk4": 2.0 * math.sqrt(2.0)}

#: Bisection leaves the boundary biased by STABLE_TOL (1e-12) in |R|^2.
LIMIT_TOL = 1e-9


@pytest.mark.parametrize("name", sorted(POLYNOMIALS))
def test_stability_polynomial(name):
    assert stability_polynomial(SOLVERS[name]) == tuple(F(x) for x in POLYNOMIALS[name])


def test_seed_literal_polynomial():
    assert stability_polynomial(RK4_SEED_LITERAL) == (1, F(5, 3), F(5, 6), F(1, 4), F(1, 24))


@pytest.mark.parametrize("name", sorted(POLYNOMIALS))
def test_limits(name):
    assert real_axis_limit(SOLVERS[name]) == pytest.approx(REAL_LIMIT[name], abs=LIMIT_TOL)
    assert imaginary_axis_limit(SOLVERS[name]) == pytest.approx(IMAGINARY_LIMIT[name],
                                                                abs=LIMIT_TOL)


def test_growth_polynomial_of_backwards_euler_on_imaginary_axis():
    # |1 + iy - y^2|^2 - 1 = -y^2 + y^4
    assert growth_polynomial(SOLVERS["backwards-euler"], "imaginary") == (0, 0, -1, 0, 1)


def test_heun_grows_on_imaginary_axis_at_fourth_order():
    # |1 + iy - y^2/2|^2 - 1 = y^4 / 4: unstable for every y > 0.
    assert growth_polynomial(SOLVERS["averaged-euler"], "imaginary") == (0, 0, 0, 0, F(1, 4))


@pytest.mark.parametrize("name", sorted(POLYNOMIALS))
def test_one_step_on_linear_equation_is_R(name):
    lam, h = -0.7 + 1.3j, 0.2
    y1 = SOLVERS[name].step(lambda t, y: lam * y, 0.0, np.array([1.0 + 0j]), h)
    assert y1[0] == pytest.approx(amplification(SOLVERS[name], h * lam), abs=1e-15)


def test_grid_layout():
    x, y, absR = stability_grid(SOLVERS["euler"], n=11)
    assert absR.shape == (11, 11)
    i, j = np.argmin(np.abs(y)), np.argmin(np.abs(x + 1.0))
    assert absR[i, j] == pytest.approx(0.0, abs=1e-12)      # R(-1) = 0 for Euler
