"""rigid.free_rotation and a declared integrator order: a drift that falls at
the declared order when the step is halved is the integrator's truncation
error, "tolerance"; otherwise, or undeclared, "bug"."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from refsim.conformance.cases_rigid import RigidCases, rigid_scenes
from refsim.conformance.checks_rotation import check_rigid_free_rotation
from refsim.engines import declarations
from refsim.engines.refsim_engines import corrected
from refsim.errors import OptionError


class DriftingEngine:
    """refsim's corrected model with its angular velocity scaled by
    ``1 + rate * h^order * t``: energy and momentum drift as a method of
    that order would (about 5 % over the brick's 12 s at h = 1e-3 for order
    1), flips unchanged."""

    name = "drifting"

    def __init__(self, order: int, declared, scale: float = 1.0):
        self.order = order
        self.rate = scale * 2.0 * 1e-3 / 1e-3 ** order
        self.inner = corrected()
        if declared is not None:
            self.integrator_order = declared

    def simulate(self, scene):
        trajectory = self.inner.simulate(scene)
        h = scene.integration.step
        grow = 1.0 + self.rate * h ** self.order * np.asarray(trajectory.t)
        return replace(trajectory, angular_velocity=np.asarray(trajectory.angular_velocity)
                       * grow[:, None, None])


@pytest.fixture(scope="module")
def free_brick():
    return tuple(s for s in rigid_scenes() if s.kind == "free")


@pytest.mark.parametrize("order, declared, expected", [
    (1, 1, "tolerance"),    # first-order drift, declared first order
    (1, 2, "bug"),          # it does not fall as fast as declared
    (1, None, "bug"),       # nothing declared: no excuse
])
def test_a_drift_is_tolerance_only_at_the_declared_order(free_brick, order, declared, expected):
    result = check_rigid_free_rotation(DriftingEngine(order, declared), RigidCases(free_brick))
    assert result.classes == {expected: 1}
    measured = next(iter(result.measured.values()))
    assert measured["energy_drift"] > 0.01
    if declared is not None:
        assert measured["observed_drift_order"] == pytest.approx(1.0, abs=0.05)
        assert measured["drift_at_half_step"] == pytest.approx(measured["energy_drift"] / 2,
                                                               rel=0.05)


@pytest.mark.parametrize("value", [0, 1.5, True, "1"])
def test_integrator_order_must_be_a_whole_number(value):
    class Engine:
        name = "e"
        integrator_order = value

    with pytest.raises(OptionError, match="integrator_order must be a whole number"):
        declarations(Engine())


def test_a_drift_beyond_the_excusable_limit_is_a_bug_at_any_order(free_brick):
    """Ten times the rate: about 50 % of the energy gained, falling at order
    1 all the same: no declared order excuses it."""
    result = check_rigid_free_rotation(DriftingEngine(1, 1, scale=10.0), RigidCases(free_brick))
    measured = next(iter(result.measured.values()))
    assert measured["falls_at_declared_order"] and measured["energy_drift"] > 0.3
    assert result.classes == {"bug": 1}
