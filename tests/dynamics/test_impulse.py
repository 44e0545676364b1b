"""The corrected contact impulse: momentum, energy, Coulomb cone, and the
compiled kernel against the plain one."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.dynamics import impulse
from refsim.kernels import CONTACT_IMPULSES

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


def _solve_on(kernel: str):
    """The solve on kernel "readable" or "compiled", as the pair dispatches
    it (the readable one on Python floats, refsim.kernels.python_floats)."""
    return CONTACT_IMPULSES(kernel)


@pytest.mark.parametrize("kernel", ["readable", "compiled"])
def test_momentum_conserved_and_energy_not_increased(kernel):
    solve = _solve_on(kernel)
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


@pytest.mark.parametrize("kernel", ["readable", "compiled"])
def test_a_static_b_given_as_none_gives_the_values_of_zero_arrays(kernel):
    # wall_impulses passes the wall's arrays as None (B's terms left out);
    # the general solve with B's arrays +0.0 must give the same bits: the
    # velocities, the impulses, signs of zero included
    solve = _solve_on(kernel)
    rng = np.random.default_rng(77)
    solved = 0
    for trial in range(300):
        c = 1 + trial % 4
        n = np.zeros(3)
        n[trial % 3] = 1.0 if trial % 2 else -1.0
        r = rng.normal(size=(c, 3))
        r -= 0.8 * np.outer(r @ n, n)                        # points near the contact plane
        m_inv = rng.uniform(0.1, 2.0)
        M = rng.normal(size=(3, 3))
        I_inv = np.linalg.inv(M @ M.T + np.eye(3))
        v0, w0 = rng.normal(size=3), rng.normal(size=3)
        v0 -= 2.0 * n * rng.uniform(0, 1)                    # approaching, most of the time
        e, mu = rng.uniform(0, 1), rng.choice([0.0, rng.uniform(0, 1)])
        out = []
        for static in (None, "zeros"):
            v, w, P = v0.copy(), w0.copy(), np.empty((c, 4))
            if static is None:
                b_arrays = (None, None, None, None)
            else:
                b_arrays = (np.zeros((c, 3)), np.zeros((3, 3)), np.zeros(3), np.zeros(3))
            r_b, I_b, v_b, w_b = b_arrays
            approaching = solve(r, r_b, n, m_inv, I_inv, v, w, 0.0, I_b, v_b, w_b, e, mu,
                                impulse.RESTITUTION_THRESHOLD, impulse.ITERATIONS, P)
            out.append((approaching, v.tobytes(), w.tobytes(), P.tobytes()))
            if static is not None:
                assert not (v_b.any() or w_b.any())          # the zero wall stays at rest
        assert out[0] == out[1]
        solved += out[0][0] > 0
    assert solved > 150                                      # impulses, not only no-ops


#: Coulomb's answer for one contact straight below a ball's centre, against
#: the solve: the sweeps converge exactly for one contact (each friction
#: impulse stops the slip or reaches the cone at once), so only rounding.
BALL_TOL = 1e-12


@pytest.mark.parametrize(("v_t", "w", "v_n", "mu", "e"), [
    (5.0, 0.0, 2.2318, 0.3, 0.8),      # slides throughout
    (2.0, 0.0, 2.2318, 0.3, 0.8),      # leaves rolling
    (0.0, 3.0, 2.0, 0.1, 1.0),         # spin only, e = 1: slides throughout
    (0.2, 3.0, 1.0, 0.4, 0.5),         # backspin: slides, its velocity reverses
    (3.0, 0.0, 2.0, 0.3, 0.0),         # e = 0
    (1.0, -5.0, 2.0, 0.3, 0.5),        # topspin, leaves rolling
])
@pytest.mark.parametrize("kernel", ["readable", "compiled"])
def test_ball_impact_is_coulombs_over_the_whole_impact(v_t, w, v_n, mu, e, kernel):
    """A uniform ball (m = 1, I = 2/5, radius 1) on a fixed floor: lateral
    velocity and spin after the impact as
    refsim.dynamics.analytic.oblique_impact_ball gives them (Stronge, Impact
    Mechanics, 5.1), friction acting through restitution as well."""
    from refsim.dynamics.analytic import oblique_impact_ball

    inertia = 0.4
    v = np.array([v_t, -v_n, 0.0])
    spin = np.array([0.0, 0.0, w])
    impulse.wall_impulses(np.array([[0.0, -1.0, 0.0]]), np.array([0.0, 1.0, 0.0]), 1.0,
                          np.eye(3) / inertia, v, spin, e, mu, kernel=kernel)
    v_t_after, w_after = oblique_impact_ball(v_t, w, v_n, mu, e, 1.0, 1.0, inertia)
    print(f"v_t {v[0]:.6f} ({v_t_after:.6f}), w {spin[2]:.6f} ({w_after:.6f})")
    assert abs(v[0] - v_t_after) < BALL_TOL
    assert abs(spin[2] - w_after) < BALL_TOL
    assert abs(v[1] - e * v_n) < BALL_TOL           # the normal impulse passes the centre


def test_closed_form_ball_impact_regimes():
    """The closed form's own regimes: sliding throughout takes mu (1 + e) v_n
    of lateral speed; a ball that leaves rolling keeps 5/7 of v_t (no spin
    before, I = 2/5); the slip never reverses."""
    from refsim.dynamics.analytic import oblique_impact_ball

    assert oblique_impact_ball(5.0, 0.0, 2.0, 0.3, 0.8, 1.0, 1.0, 0.4)[0] == pytest.approx(
        5.0 - 0.3 * 1.8 * 2.0)
    v_t, w = oblique_impact_ball(2.0, 0.0, 2.0, 0.3, 0.8, 1.0, 1.0, 0.4)
    assert (v_t, w) == pytest.approx((10.0 / 7.0, -10.0 / 7.0))     # rolling: v + w r = 0
    v_t, w = oblique_impact_ball(0.2, 3.0, 1.0, 0.4, 0.5, 1.0, 1.0, 0.4)
    assert v_t == pytest.approx(0.2 - 0.6) and v_t + w > 0.0        # reversed, still slipping
