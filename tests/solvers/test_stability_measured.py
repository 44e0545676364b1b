"""Stability limits found by simulation agree with those predicted by R(z)."""

from __future__ import annotations

import pytest

from refsim.studies.solvers import (
    energy_per_period,
    measure_oscillator_energy,
    measure_stability,
    predicted_energy_per_period,
)

#: The simulated boundary is bisected to 1e-9 relative; the growth test
#: (GROWTH_TOL 1e-13 per step over 400 steps) places it within ~1e-9 too.
LIMIT_RTOL = 1e-6


@pytest.fixture(scope="module")
def limits():
    return {s.method: s for s in measure_stability()}


@pytest.mark.parametrize("method", ["euler", "averaged-euler", "backwards-euler", "midpoint",
                                    "rk4"])
def test_simulated_limits_match_prediction(limits, method):
    s = limits[method]
    print(s)
    assert s.drag_measured == pytest.approx(s.drag_predicted, rel=LIMIT_RTOL)
    assert s.oscillator_measured == pytest.approx(s.oscillator_predicted, rel=LIMIT_RTOL)


def test_backwards_euler_halves_the_stiff_drag_limit(limits):
    assert limits["backwards-euler"].drag_measured == pytest.approx(
        limits["euler"].drag_measured / 2, rel=LIMIT_RTOL)


@pytest.mark.parametrize(("method", "grows"), [("euler", True), ("averaged-euler", True),
                                               ("midpoint", True), ("backwards-euler", False),
                                               ("rk4", False)])
def test_energy_per_period_of_undamped_oscillator(method, grows):
    ratio = energy_per_period(method, 0.1)
    print(method, ratio)
    assert (ratio > 1.0) == grows


#: Energy after ~60 to 6000 steps of a linear map: rounding ~n eps.
ENERGY_RTOL = 1e-9


def test_energy_per_period_matches_stability_function():
    import math

    for e in measure_oscillator_energy(omega_hs=(0.01, 0.5, 2.0)):
        print(e)
        assert e.measured == pytest.approx(e.predicted, rel=ENERGY_RTOL)
    # Euler: |R(i h)|^2 = 1 + h^2 per step, 2 pi / h steps per period.
    assert predicted_energy_per_period("euler", 0.01) == pytest.approx(
        (1 + 0.01**2) ** (2 * math.pi / 0.01), rel=1e-12)
