"""The corrected rotation model's stages: the exponential map against
scipy's, orthonormality, the world inertia, and the one written-out order
of their arithmetic (which the compiled loop repeats)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from refsim.dynamics.products import matmul
from refsim.dynamics.rotation_impulse import (
    SERIES_BELOW,
    orientation_step_exact,
    rotation_exp,
    sin_cos,
    world_inertia,
)

#: rotation_exp against scipy's Rotation.from_rotvec (quaternion route): a few
#: units in the last place of entries of size <= 1.
AGREE_TOL = 2e-15
#: |R^T R - E| of one exp: rounding of a few products and sums.
ORTHONORMAL_TOL = 2e-15


def _rotation_vectors(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    axes = rng.normal(size=(n, 3))
    axes /= np.sqrt((axes ** 2).sum(axis=1))[:, None]
    # angles from 1e-9 (the series) through 1e-4 (the switch) to several turns
    angles = 10.0 ** rng.uniform(-9, 1.3, size=n)
    return axes * angles[:, None]


def test_rotation_exp_agrees_with_scipy_and_is_orthonormal():
    Rotation = pytest.importorskip("scipy.spatial.transform").Rotation
    theta = _rotation_vectors(2000, 1)
    E = rotation_exp(theta)
    reference = Rotation.from_rotvec(theta).as_matrix()
    error = np.abs(E - reference).max()
    drift = np.abs(matmul(np.swapaxes(E, 1, 2), E) - np.eye(3)).max()
    print(f"max |exp - scipy| = {error:.3g}, max |E^T E - I| = {drift:.3g}")
    assert error < AGREE_TOL
    assert drift < ORTHONORMAL_TOL


def test_rotation_exp_is_continuous_across_the_series_switch():
    axis = np.array([0.48, -0.6, 0.64])
    a = math.sqrt(SERIES_BELOW)
    below, above = rotation_exp(np.array([axis * a * (1 - 1e-12), axis * a * (1 + 1e-12)]))
    assert np.abs(below - above).max() < 1e-15


def test_entries_are_the_written_out_order_bit_for_bit():
    # one body at a time, plain Python floats and math.sin / math.cos
    for t in _rotation_vectors(200, 2).tolist():
        a2 = (t[0] * t[0] + t[1] * t[1]) + t[2] * t[2]
        if a2 < SERIES_BELOW:
            s, c, cos_a = 1.0 - a2 / 6.0, 0.5 - a2 / 24.0, 1.0 - 0.5 * a2
        else:
            a = math.sqrt(a2)
            s, cos_a = math.sin(a) / a, math.cos(a)
            c = (1.0 - cos_a) / (a * a)
        E = [[(c * t[i]) * t[j] for j in range(3)] for i in range(3)]
        E[0][1] -= s * t[2]
        E[0][2] += s * t[1]
        E[1][2] -= s * t[0]
        E[1][0] += s * t[2]
        E[2][0] -= s * t[1]
        E[2][1] += s * t[0]
        for k in range(3):
            E[k][k] += cos_a
        assert rotation_exp(np.array([t])).tolist() == [E]


def test_sin_cos_are_the_c_librarys():
    a = np.linspace(0.0, 40.0, 1001)
    sin_a, cos_a = sin_cos(a)
    assert sin_a.tolist() == [math.sin(x) for x in a.tolist()]
    assert cos_a.tolist() == [math.cos(x) for x in a.tolist()]


def test_world_inertia_and_the_free_step():
    Rotation = pytest.importorskip("scipy.spatial.transform").Rotation
    rng = np.random.default_rng(3)
    R = Rotation.random(50, random_state=4).as_matrix()
    I_body = np.array([np.diag(d) for d in rng.uniform(0.1, 2.0, size=(50, 3))])
    assert np.allclose(world_inertia(R, I_body), R @ I_body @ np.swapaxes(R, 1, 2),
                       rtol=0, atol=1e-14)
    w = rng.normal(size=(50, 3))
    R_next, w_next = orientation_step_exact(R, w, 1e-3, I_body, np.linalg.inv(I_body))
    # torque-free: the angular momentum R I R^T w is kept
    L0 = np.einsum("bij,bj->bi", world_inertia(R, I_body), w)
    L1 = np.einsum("bij,bj->bi", world_inertia(R_next, I_body), w_next)
    assert np.allclose(L0, L1, rtol=0, atol=1e-13)
    assert np.abs(matmul(np.swapaxes(R_next, 1, 2), R_next) - np.eye(3)).max() < 4e-15
