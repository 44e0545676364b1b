"""The written-out products: each sum in one order, left to right."""

from __future__ import annotations

import numpy as np

from refsim.dynamics.products import dot, matmul, matTvec, matvec, norm


def test_dot_and_matvec_sum_left_to_right_bit_for_bit():
    rng = np.random.default_rng(16)
    a, b = rng.normal(size=(500, 3)), rng.normal(size=(500, 3))
    M = rng.normal(size=(500, 3, 3))
    for i in range(500):
        x, y = a[i].tolist(), b[i].tolist()
        assert dot(a[i], b[i]) == (x[0] * y[0] + x[1] * y[1]) + x[2] * y[2]
        assert norm(a[i]) == np.sqrt((x[0] * x[0] + x[1] * x[1]) + x[2] * x[2])
        m = M[i].tolist()
        expected = [(m[k][0] * x[0] + m[k][1] * x[1]) + m[k][2] * x[2] for k in range(3)]
        assert matvec(M[i], a[i]).tolist() == expected
    # batched: the same bits as one body at a time
    assert matvec(M, a).tobytes() == np.array([matvec(M[i], a[i]) for i in range(500)]).tobytes()


def test_a_unit_axis_gives_the_component_exactly():
    v = np.array([0.1, -0.7, 1e-300])
    for k in range(3):
        e = np.zeros(3)
        e[k] = 1.0
        assert dot(v, e) == v[k]
    assert norm(np.array([3.0, 4.0, 12.0])) == 13.0


def test_transposed_matvec_and_matmul_sum_left_to_right_bit_for_bit():
    rng = np.random.default_rng(17)
    a = rng.normal(size=(300, 3))
    A, M = rng.normal(size=(300, 3, 3)), rng.normal(size=(300, 3, 3))
    for i in range(300):
        x, m, p = a[i].tolist(), M[i].tolist(), A[i].tolist()
        expected = [(m[0][k] * x[0] + m[1][k] * x[1]) + m[2][k] * x[2] for k in range(3)]
        assert matTvec(M[i], a[i]).tolist() == expected
        product = [[(p[r][0] * m[0][c] + p[r][1] * m[1][c]) + p[r][2] * m[2][c]
                    for c in range(3)] for r in range(3)]
        assert matmul(A[i], M[i]).tolist() == product
    assert matmul(A, M).tobytes() == np.array([matmul(A[i], M[i]) for i in range(300)]).tobytes()
    assert np.allclose(matmul(A, M), A @ M, rtol=0, atol=1e-14)


def test_the_inverse_is_the_adjugate_over_the_determinant_at_any_scale():
    # against LAPACK's to a few ulps of the largest entry (LAPACK's last bits
    # are the processor's; the written-out inverse's are not), at scales from
    # 1e-150 to 1e150, where det (a product of three entries) would underflow
    # or overflow unscaled
    from refsim.dynamics.products import inverse

    rng = np.random.default_rng(3)
    for scale in (1e-150, 1e-3, 1.0, 1e5, 1e150):
        a = rng.normal(size=(100, 3, 3))
        inertia = (a @ np.swapaxes(a, 1, 2) + 0.1 * np.eye(3)) * scale
        ours, lapack = inverse(inertia), np.linalg.inv(inertia)
        largest = np.abs(lapack).max(axis=(1, 2), keepdims=True)
        assert np.all(np.abs(ours - lapack) <= 1e-13 * largest), scale
    diagonal = inverse(np.diag([2.0, 4.0, 8.0]))
    assert diagonal.tobytes() == np.diag([0.5, 0.25, 0.125]).tobytes()   # exact, and +0.0
    one = np.array([[1.0, 2.0, 3.0], [0.0, 1.0, 4.0], [5.0, 6.0, 0.0]])
    assert inverse(one).tolist() == [[-24.0, 18.0, 5.0], [20.0, -15.0, -4.0], [-5.0, 4.0, 1.0]]
