"""The corrected contact impulse: momentum, energy, Coulomb cone, and the
compiled kernel against the plain one."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.dynamics import impulse

#: Momentum sums of a handful of impulses of order 1: rounding only.
MOMENTUM_TOL = 1e-12
#: Energy may not rise by more than rounding of terms of order 1.
ENERGY_TOL = 1e-12


def _random_pair(rng):
    """Two bodies with random masses, inertia tensors and velocities, and one
    contact point between them with a normal that makes them approach."""
    def body():
        m = rng.uniform(0.5, 3.0)
        A = rng.normal(size=(3, 3))
        I = A @ A.T + np.eye(3) * 0.2                    # symmetric positive definite
        return m, I, rng.normal(size=3), rng.normal(size=3), rng.normal(size=3)

    (ma, Ia, xa, va, wa), (mb, Ib, xb, vb, wb) = body(), body()
    p = 0.5 * (xa + xb) + 0.1 * rng.normal(size=3)
    n = rng.normal(size=3)
    n /= np.linalg.norm(n)
    return ma, Ia, xa, va, wa, mb, Ib, xb, vb, wb, p, n


def _energy(m, I, v, w):
    return 0.5 * m * v @ v + 0.5 * w @ I @ w


def _solve(kernel, ma, Ia, xa, va, wa, mb, Ib, xb, vb, wb, p, n, e, mu):
    va, wa, vb, wb = va.copy(), wa.copy(), vb.copy(), wb.copy()
    P = np.empty((1, 4))
    kernel((p - xa)[None], (p - xb)[None], n, 1 / ma, np.linalg.inv(Ia), va, wa, 1 / mb,
           np.linalg.inv(Ib), vb, wb, e, mu, impulse.RESTITUTION_THRESHOLD,
           impulse.ITERATIONS, P)
    return va, wa, vb, wb, P


@pytest.mark.parametrize("kernel", ["readable", "compiled"])
def test_momentum_conserved_and_energy_not_increased(kernel):
    solve = impulse.solve_contacts_python if kernel == "readable" else impulse.solve_contacts
    rng = np.random.default_rng(2024)
    hits = 0
    for _ in range(200):
        ma, Ia, xa, va, wa, mb, Ib, xb, vb, wb, p, n = _random_pair(rng)
        e, mu = rng.uniform(0, 1), rng.uniform(0, 1)
        va2, wa2, vb2, wb2, P = _solve(solve, ma, Ia, xa, va, wa, mb, Ib, xb, vb, wb, p, n,
                                       e, mu)
        hits += P[0, 0] > 0
        linear = ma * va + mb * vb
        assert np.allclose(ma * va2 + mb * vb2, linear, atol=MOMENTUM_TOL)
        # angular momentum about the origin (a fixed point)
        L_before = np.cross(xa, ma * va) + Ia @ wa + np.cross(xb, mb * vb) + Ib @ wb
        L_after = np.cross(xa, ma * va2) + Ia @ wa2 + np.cross(xb, mb * vb2) + Ib @ wb2
        assert np.allclose(L_after, L_before, atol=MOMENTUM_TOL * 10)
        before = _energy(ma, Ia, va, wa) + _energy(mb, Ib, vb, wb)
        after = _energy(ma, Ia, va2, wa2) + _energy(mb, Ib, vb2, wb2)
        assert after <= before + ENERGY_TOL
        assert np.linalg.norm(P[0, 1:]) <= mu * P[0, 0] + 1e-12       # Coulomb cone
    assert hits > 50                                       # the test exercised impulses


def _normal_velocity(xa, va, wa, xb, vb, wb, p, n):
    return ((va + np.cross(wa, p - xa)) - (vb + np.cross(wb, p - xb))) @ n


def test_frictionless_single_contact_reverses_normal_velocity_times_e():
    rng = np.random.default_rng(5)
    for _ in range(50):
        ma, Ia, xa, va, wa, mb, Ib, xb, vb, wb, p, n = _random_pair(rng)
        vn = _normal_velocity(xa, va, wa, xb, vb, wb, p, n)
        va2, wa2, vb2, wb2, _ = _solve(impulse.solve_contacts_python, ma, Ia, xa, va, wa, mb,
                                       Ib, xb, vb, wb, p, n, 0.6, 0.0)
        if vn < -impulse.RESTITUTION_THRESHOLD:
            assert _normal_velocity(xa, va2, wa2, xb, vb2, wb2, p, n) == pytest.approx(
                -0.6 * vn, rel=1e-9, abs=1e-12)
        elif vn >= 0:
            assert np.array_equal(va2, va)                  # separating: untouched


def test_compiled_kernel_matches_plain():
    rng = np.random.default_rng(11)
    for _ in range(30):
        args = _random_pair(rng)
        a = _solve(impulse.solve_contacts_python, *args, 0.5, 0.4)
        b = _solve(impulse.solve_contacts, *args, 0.5, 0.4)
        for x, y in zip(a, b, strict=True):
            assert np.allclose(x, y, rtol=1e-13, atol=1e-14)


def test_four_corners_of_a_falling_cube_stop_it_and_bounce_by_e():
    r = np.array([[x, -0.5, z] for x in (-0.5, 0.5) for z in (-0.5, 0.5)])
    v, w = np.array([0.0, -3.0, 0.0]), np.zeros(3)
    P = np.empty((4, 4))
    impulse.solve_contacts_python(r, np.zeros_like(r), np.array([0.0, 1.0, 0.0]), 1.0,
                                  6.0 * np.eye(3), v, w, 0.0, np.zeros((3, 3)), np.zeros(3),
                                  np.zeros(3), 0.5, 0.3, impulse.RESTITUTION_THRESHOLD,
                                  impulse.ITERATIONS, P)
    assert v[1] == pytest.approx(1.5, rel=1e-9)          # converged: see ITERATIONS
    assert np.abs(w).max() < 1e-6                          # symmetric: no spin
