"""The seed's simplified rotation (S9) on a constructed contact, by hand."""

from __future__ import annotations

import numpy as np

from refsim.dynamics.rotation_seed import (
    contact_spin_seed,
    contact_vertex_seed,
    gram_schmidt,
    orientation_step_seed,
)

# Results of a few roundings of values of order 1.
TOL = 1e-14


def test_contact_quantities_by_hand():
    Pi = np.array([0.5, -0.5, 0.5])          # a cube's corner, below the centroid
    N = np.array([0.0, 1.0, 0.0])            # the floor's normal, into the body
    w = np.array([0.0, 2.0, 0.0])
    Vel = np.array([1.0, -3.0, 0.0])
    c = contact_spin_seed(w, Vel, Pi, N, restitution=0.5, friction=0.3)
    # Vi = w x Pi + Vel = (1, 0, -1) + (1, -3, 0)
    assert np.allclose(c.Vi, [2.0, -3.0, -1.0], atol=TOL)
    # normal part -(Vi.N)N = (0, 3, 0); lateral Vi + normal = (2, 0, -1)
    # Rvi = 0.7 (2, 0, -1) + 0.5 (0, 3, 0)
    assert np.allclose(c.Rvi, [1.4, 1.5, -0.7], atol=TOL)
    assert np.allclose(c.I, [0.0, 1.5, 0.0], atol=TOL)
    # T = Pi x I = (-0.5 * 0 - 0.5 * 1.5, 0.5 * 0 - 0.5 * 0, 0.5 * 1.5 + 0.5 * 0)
    assert np.allclose(c.T, [-0.75, 0.0, 0.75], atol=TOL)
    assert np.allclose(c.w, [-0.75, 2.0, 0.75], atol=TOL)


def test_spin_about_the_normal_is_never_changed():
    # C12 (a): T = Pi x I is perpendicular to N, so w . N survives every contact.
    rng = np.random.default_rng(12)
    N = np.array([0.0, 1.0, 0.0])
    for _ in range(100):
        w, Vel, Pi = rng.normal(size=(3, 3))
        c = contact_spin_seed(w, Vel, Pi, N, restitution=rng.uniform(), friction=rng.uniform())
        assert abs(c.w[1] - w[1]) <= TOL * (1 + abs(w[1]))


def test_euler_step_of_the_axes_then_orthonormal():
    R = np.eye(3)[None]
    w = np.array([[0.0, 0.0, 2.0]])
    h = 1e-3
    R1 = orientation_step_seed(R, w, h)
    # X += h (w x X): X = e_x turns towards e_y by h |w|, then is normalized
    expected_x = np.array([1.0, 2e-3, 0.0]) / np.hypot(1.0, 2e-3)
    assert np.allclose(R1[0, :, 0], expected_x, atol=TOL)
    assert np.abs(R1[0].T @ R1[0] - np.eye(3)).max() < TOL
    assert np.linalg.det(R1[0]) > 0


def test_gram_schmidt_keeps_x_direction():
    R = np.array([[[2.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 3.0]]])
    Q = gram_schmidt(R)
    assert np.allclose(Q[0], np.eye(3), atol=TOL)


def test_contact_vertex_is_the_deepest_with_lowest_index_on_ties():
    W = np.array([[0.0, -1.0, 0.0], [1.0, -2.0, 0.0], [2.0, -2.0, 0.0], [0.0, 3.0, 0.0]])
    assert contact_vertex_seed(W, 1, low_wall=True) == 1
    assert contact_vertex_seed(W, 1, low_wall=False) == 3


def test_compiled_step_is_the_numpy_step_bit_for_bit():
    from refsim.dynamics.rotation_seed import orientation_step_seed_compiled
    from refsim.types import random_rotation

    rng = np.random.default_rng(9)
    R = np.array([random_rotation(rng) for _ in range(25)])
    w = 10.0 * rng.normal(size=(25, 3))
    for h in (1e-3, 0.05):
        assert np.array_equal(orientation_step_seed_compiled(R, w, h),
                              orientation_step_seed(R, w, h))
