"""The corrected rotation model's stages: the exponential map against
scipy's, orthonormality, the principal frame, the free step's invariants
(angular momentum, bounded energy, exact for symmetric bodies), and the one
written-out order of their arithmetic (which the compiled loop repeats)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from refsim.dynamics.products import matmul
from refsim.dynamics.rotation_impulse import (
    SERIES_BELOW,
    free_rotation_steps,
    principal_frame,
    rotation_exp_into,
    world_inertia,
)

#: rotation_exp against scipy's Rotation.from_rotvec (quaternion route): a few
#: units in the last place of entries of size <= 1.
AGREE_TOL = 2e-15
#: |R^T R - E| of one exp: rounding of a few products and sums.
ORTHONORMAL_TOL = 2e-15
#: One free step's change of the world angular momentum, relative: each of
#: its five sub-steps keeps it exactly in exact arithmetic, so only the
#: rounding of some hundred operations remains (a few units in the last place).
STEP_MOMENTUM_TOL = 1e-13


def rotation_exp(theta: np.ndarray) -> np.ndarray:
    """:func:`rotation_exp_into` of each row of ``theta`` (n, 3): (n, 3, 3)."""
    out = np.empty((len(theta), 3, 3))
    for t, E in zip(theta.tolist(), out, strict=True):
        rotation_exp_into(t[0], t[1], t[2], E)
    return out


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


def _free_bodies(n: int, seed: int):
    """n random orientations, angular velocities and inertia tensors of
    bodies with three different moments, not aligned with the mesh axes."""
    Rotation = pytest.importorskip("scipy.spatial.transform").Rotation
    rng = np.random.default_rng(seed)
    R = Rotation.random(n, random_state=seed).as_matrix()
    axes = Rotation.random(n, random_state=seed + 1).as_matrix()
    I_body = np.array([a @ np.diag(d) @ a.T for a, d in
                       zip(axes, rng.uniform(0.1, 2.0, size=(n, 3)), strict=True)])
    return R, rng.normal(size=(n, 3)), I_body


def _frames(I_body):
    Q = np.empty_like(I_body)
    moments = np.empty((len(I_body), 3))
    for i, I in enumerate(I_body):
        Q[i], moments[i] = principal_frame(I)
    return Q, moments


def test_principal_frame_diagonalises_the_inertia():
    _, _, I_body = _free_bodies(50, 5)
    Q, moments = _frames(I_body)
    for I, q, m in zip(I_body, Q, moments, strict=True):
        assert np.linalg.det(q) == pytest.approx(1.0, abs=1e-14)
        assert np.abs(q.T @ q - np.eye(3)).max() < 1e-14
        # Q^T I Q is diag(moments) to rounding (Jacobi stops at exact zeros)
        assert np.abs(q.T @ I @ q - np.diag(m)).max() < 1e-14 * m.max()
        assert m[0] <= m[1] <= m[2]
    # a tensor that is already diagonal keeps the identity and its diagonal
    Q, m = principal_frame(np.diag([0.5, 0.25, 0.75]))
    assert np.abs(Q).tolist() == [[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    assert np.linalg.det(Q) == 1.0
    assert m.tolist() == [0.25, 0.5, 0.75]


def test_world_inertia_and_the_free_step_keep_angular_momentum():
    R, w, I_body = _free_bodies(50, 3)
    assert np.allclose(world_inertia(R, I_body), R @ I_body @ np.swapaxes(R, 1, 2),
                       rtol=0, atol=1e-14)
    Q, moments = _frames(I_body)
    R_next, w_next = R.copy(), w.copy()
    free_rotation_steps(R_next, w_next, Q, moments, 1e-3)
    # torque-free: the angular momentum R I R^T w is kept to rounding
    L0 = np.einsum("bij,bj->bi", world_inertia(R, I_body), w)
    L1 = np.einsum("bij,bj->bi", world_inertia(R_next, I_body), w_next)
    print(f"max |L1 - L0| / max |L0| = {np.abs(L0 - L1).max() / np.abs(L0).max():.2e}")
    assert np.abs(L0 - L1).max() < STEP_MOMENTUM_TOL * np.abs(L0).max()
    assert np.abs(matmul(np.swapaxes(R_next, 1, 2), R_next) - np.eye(3)).max() < 4e-15


def test_free_step_of_equal_moments_is_the_exact_rotation():
    """A body with equal moments (a cube) turns at constant w: the step is
    exp(h [w]x) R, to rounding, and w does not change."""
    Rotation = pytest.importorskip("scipy.spatial.transform").Rotation
    R = Rotation.random(20, random_state=7).as_matrix()
    w = np.random.default_rng(7).normal(size=(20, 3)) * 5.0
    I_body = np.array([np.eye(3) / 6.0] * 20)
    Q, moments = _frames(I_body)
    R_next, w_next = R.copy(), w.copy()
    h = 1e-2
    free_rotation_steps(R_next, w_next, Q, moments, h)
    expected = Rotation.from_rotvec(h * w).as_matrix() @ R
    assert np.abs(R_next - expected).max() < 1e-14
    assert np.abs(w_next - w).max() < 1e-13


def test_free_step_of_a_symmetric_top_is_exact():
    """A symmetric top (I_1 = I_2 = A < I_3 = C), body-frame angular velocity
    (W_p cos(W t), W_p sin(W t), W_3) with W = (C - A) W_3 / A (Landau &
    Lifshitz, Mechanics, section 36; Goldstein, Classical Mechanics, 5-6):
    the splitting's axis term for the pair vanishes and the other commutes
    with the rotor, so any step is exact; a step of 0.1 s over 40 steps stays
    on the closed form to rounding."""
    A, C = 0.5, 0.8
    W_p, W_3 = 0.7, 3.0
    I_body = np.array([np.diag([A, A, C])])
    Q, moments = _frames(I_body)
    R = np.eye(3)[None].copy()
    w = np.array([[W_p, 0.0, W_3]])
    W = (C - A) * W_3 / A
    h = 0.1
    for k in range(1, 41):
        free_rotation_steps(R, w, Q, moments, h)
        body = R[0].T @ w[0]
        # Euler's equations: W_1' = -W W_2, W_2' = W W_1
        expected = [W_p * math.cos(W * k * h), W_p * math.sin(W * k * h), W_3]
        assert np.abs(body - expected).max() < 1e-12, k
