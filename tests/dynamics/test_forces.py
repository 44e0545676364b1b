"""Forces (S5): gravity along -y, linear and quadratic drag, per body mass."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.dynamics.forces import acceleration, translational_rhs

# Each value below is one or two roundings from the exact one.
ULPS = 4 * np.finfo(np.float64).eps


def test_gravity_alone_is_minus_g_along_y():
    v = np.array([[1.0, 2.0, 3.0], [0.0, 0.0, 0.0]])
    a = acceleration(v, 9.81, 0.0, np.array([1.0, 2.0]))
    assert np.array_equal(a, [[0.0, -9.81, 0.0], [0.0, -9.81, 0.0]])


def test_linear_drag_is_minus_k_over_m_times_v():
    v = np.array([[2.0, -4.0, 1.0], [3.0, 0.0, 0.0]])
    mass = np.array([2.0, 4.0])
    a = acceleration(v, 0.0, 0.8, mass, "linear")
    expected = -0.8 / mass[:, None] * v
    assert np.allclose(a, expected, rtol=ULPS, atol=0.0)


def test_quadratic_drag_is_minus_k_over_m_speed_times_v():
    v = np.array([[3.0, 4.0, 0.0]])                      # |v| = 5
    a = acceleration(v, 1.0, 0.1, np.array([0.5]), "quadratic")   # k/m = 0.2
    expected = np.array([[-0.2 * 5 * 3.0, -0.2 * 5 * 4.0 - 1.0, 0.0]])
    assert np.allclose(a, expected, rtol=ULPS, atol=0.0)


def test_unknown_drag_model_raises():
    with pytest.raises(ValueError, match="drag model"):
        acceleration(np.zeros((1, 3)), 9.81, 0.1, np.ones(1), "cubic")


def test_rhs_is_velocity_then_acceleration_for_all_bodies():
    f = translational_rhs(9.81, 0.5, np.array([1.0, 0.5, 4.0]), "linear")
    x = np.arange(9.0).reshape(3, 3)
    v = -np.arange(9.0).reshape(3, 3)
    dy = f(0.0, np.concatenate([x.ravel(), v.ravel()])).reshape(2, 3, 3)
    assert np.array_equal(dy[0], v)
    assert np.array_equal(dy[1], acceleration(v, 9.81, 0.5, np.array([1.0, 0.5, 4.0])))


def test_one_mass_for_all_points_and_one_per_point_give_the_same_bits():
    # the particles' common mass and the bodies' per-body masses: one formula
    rng = np.random.default_rng(3)
    v = rng.normal(size=(50, 3)) * 7.0
    for model in ("linear", "quadratic"):
        common = acceleration(v, 9.81, 0.3, 1.7, model)
        each = acceleration(v, 9.81, 0.3, np.full(50, 1.7), model)
        assert np.array_equal(common, each)
        out, speed = np.empty_like(v), np.empty(50)
        from refsim.dynamics.forces import acceleration_into

        assert np.array_equal(acceleration_into(v, 9.81, 0.3, 1.7, model, out, speed), common)
