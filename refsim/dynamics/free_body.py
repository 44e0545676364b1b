"""Closed-form motion of a torque-free rigid body (Euler's equations), the
reference for the textbook problems of free rotation.

What: a rigid body with principal moments ``I_1 < I_2 < I_3``, no force and
no torque, body-frame angular velocity ``W = (W_1, W_2, W_3)`` at t = 0.
Its energy ``E = sum I_i W_i^2 / 2`` and the square of its angular momentum
``M^2 = sum I_i^2 W_i^2`` are constant, and ``W(t)`` is given by Jacobi's
elliptic functions (L. D. Landau, E. M. Lifshitz, *Mechanics*, 3rd ed.,
section 37, eq. 37.10): for ``M^2 > 2 E I_2``

    W_1 = A_1 cn(tau, m),   A_1 = sqrt((2 E I_3 - M^2) / (I_1 (I_3 - I_1)))
    W_2 = A_2 sn(tau, m),   A_2 = sqrt((2 E I_3 - M^2) / (I_2 (I_3 - I_2)))
    W_3 = A_3 dn(tau, m),   A_3 = sqrt((M^2 - 2 E I_1) / (I_3 (I_3 - I_1)))

    tau = tau_0 + nu t,     nu = sqrt((I_3 - I_2) (M^2 - 2 E I_1) / (I_1 I_2 I_3))
    m = k^2 = (I_2 - I_1) (2 E I_3 - M^2) / ((I_3 - I_2) (M^2 - 2 E I_1)),

and for ``M^2 < 2 E I_2`` the same with the suffixes 1 and 3 exchanged. The
signs: Euler's equations are unchanged by ``(W_1, W_2, W_3) -> (-W_1, W_2,
-W_3)``, which this module uses to bring any start to ``W_3 > 0`` (resp.
``W_1 > 0``), and the phase ``tau_0 = F(am, m)``, ``am = atan2(W_2 / A_2, W_1 / A_1)`` (the
incomplete elliptic integral of the first kind).

The period of ``W`` is ``T = 4 K(m) / nu``, with K the complete elliptic
integral of the first kind. A body spun near its intermediate axis (the
tennis-racket or Dzhanibekov effect) keeps ``W_2`` near its extremes and
reverses it every half period: the flips come every ``2 K(m) / nu``.

The answers use scipy's elliptic functions (``scipy.special.ellipj``,
``ellipk``, ``ellipkinc``) and nothing of refsim's dynamics;
tests/dynamics/test_free_body.py checks them against a DOP853 solution of
Euler's equations.

Cost: O(1) per time.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class FreeBody:
    """The closed-form solution for one start (module docstring).

    moments : (3,) increasing principal moments ``I_1 < I_2 < I_3``;
    omega0 : (3,) body-frame angular velocity at t = 0 (rad/s).
    """

    moments: tuple[float, float, float]
    omega0: tuple[float, float, float]

    def __post_init__(self):
        I1, I2, I3 = self.moments
        if not (0.0 < I1 < I2 < I3):
            raise ValueError(f"moments must be increasing and distinct, got {self.moments}")

    @property
    def energy(self) -> float:
        return 0.5 * sum(I * w * w for I, w in zip(self.moments, self.omega0, strict=True))

    @property
    def momentum_squared(self) -> float:
        return sum((I * w) ** 2 for I, w in zip(self.moments, self.omega0, strict=True))

    def _frame(self):
        """(a, c, flip, A_a, A_b, A_c, nu, m, tau_0): the roles of the axes
        (a: cn, the middle one: sn, c: dn), the sign (+-1) of ``W_a`` and
        ``W_c`` that brings the start to ``W_c > 0``, and the solution's
        constants. With the suffixes exchanged (``M^2 < 2 E I_2``) the
        formulas hold as written, time running forwards: substituting them
        in Euler's equations gives ``nu > 0`` in both cases."""
        E, M2 = self.energy, self.momentum_squared
        I = self.moments
        # the axis whose W keeps its sign: 3 when M^2 > 2 E I_2, else 1
        a, c = (0, 2) if M2 > 2.0 * E * I[1] else (2, 0)
        I_a, I_b, I_c = I[a], I[1], I[c]
        A_a = math.sqrt((2.0 * E * I_c - M2) / (I_a * (I_c - I_a)))
        A_b = math.sqrt((2.0 * E * I_c - M2) / (I_b * (I_c - I_b)))
        A_c = math.sqrt((M2 - 2.0 * E * I_a) / (I_c * (I_c - I_a)))
        nu = math.sqrt((I_c - I_b) * (M2 - 2.0 * E * I_a) / (I_a * I_b * I_c))
        m = (I_b - I_a) * (2.0 * E * I_c - M2) / ((I_c - I_b) * (M2 - 2.0 * E * I_a))
        w = list(self.omega0)
        flip_c = -1.0 if w[c] < 0.0 else 1.0       # (W_a, W_b, W_c) -> (-W_a, W_b, -W_c)
        am = math.atan2(w[1] / A_b, flip_c * w[a] / A_a)
        from scipy.special import ellipkinc

        tau0 = math.copysign(float(ellipkinc(abs(am), m)), am)
        return a, c, flip_c, A_a, A_b, A_c, nu, m, tau0

    def omega(self, t) -> np.ndarray:
        """Body-frame angular velocity at the times ``t`` (F,): (F, 3)."""
        from scipy.special import ellipj

        a, c, flip_c, A_a, A_b, A_c, nu, m, tau0 = self._frame()
        tau = tau0 + nu * np.asarray(t, dtype=np.float64)
        sn, cn, dn, _ = ellipj(tau, m)
        out = np.empty((tau.shape[0], 3))
        out[:, a] = flip_c * A_a * cn
        out[:, 1] = A_b * sn
        out[:, c] = flip_c * A_c * dn
        return out

    @property
    def period(self) -> float:
        """The period of ``W(t)``, ``4 K(m) / nu`` (s)."""
        from scipy.special import ellipk

        *_, nu, m, _ = self._frame()
        return 4.0 * float(ellipk(m)) / nu

    @property
    def flip_interval(self) -> float:
        """Time between two reversals of ``W_2`` (half the period), s."""
        return 0.5 * self.period

    def flips(self, duration: float) -> int:
        """How many times ``W_2`` changes sign in ``(0, duration]``: the zeros of
        ``sn`` at ``tau = 2 K n`` between ``tau_0`` and ``tau(duration)``."""
        from scipy.special import ellipk

        *_, nu, m, tau0 = self._frame()
        two_k = 2.0 * float(ellipk(m))
        return int(math.floor((tau0 + nu * duration) / two_k) - math.floor(tau0 / two_k))
