"""Linear stability of the seed's solvers: the amplification factor R(z).

What: applied to the test equation ``y' = lambda y``, one step of an
explicit Runge-Kutta method multiplies ``y`` by a polynomial ``R(z)`` in
``z = h lambda``. Its coefficients follow from the tableau,

    R(z) = 1 + sum_{j=1..s} (b^T A^(j-1) 1) z^j,

(Hairer & Wanner, *Solving ODEs II*, section IV.2; for an explicit method ``A`` is
nilpotent, so the series ends at ``z^s``). A step is stable where
``|R(z)| <= 1``. This module gives the coefficients exactly, the largest
stable step on the negative real axis (stiff linear drag, ``lambda = -k/m``)
and on the imaginary axis (an undamped oscillation, ``lambda = i omega``),
and ``|R|`` on a grid for drawing the stability region.

Seed section: S6; claims C6 and C7 ("unstable without sufficient damping",
"the remaining four behaved very similarly in terms of stability").

Reference: E. Hairer, G. Wanner, *Solving Ordinary Differential Equations
II*, 2nd ed., Springer 1996, section IV.2 (the stability function of explicit
Runge-Kutta methods and their stability domains); Butcher 2016, chapter 2.

Cost: O(s^3) exact rational arithmetic for the coefficients; each boundary
is found on the exact polynomial ``|R|^2 - 1`` by a scan and bisection to a
relative width of :data:`BOUNDARY_RTOL`, O(10^4) vectorized evaluations.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from refsim.solvers.explicit_rk import ExplicitRungeKutta

#: Bisection stops when the bracket is this narrow relative to its end:
#: well past the 4-6 digits a stability limit is quoted to.
BOUNDARY_RTOL = 1e-14

#: ``|R|^2 - 1 <= STABLE_TOL`` counts as stable away from ``z = 0`` (where the
#: sign is decided exactly): rounding in a polynomial of size O(1) near a
#: point where it touches zero must not be called growth.
STABLE_TOL = 1e-12

#: Grid spacing of the outward scan for the first unstable point. Stability
#: intervals of these methods are O(1) long; 1e-3 cannot step over one.
SCAN_STEP = 1e-3

#: Search no farther than this for the end of a stability interval; every
#: explicit method with s <= 4 stages is unstable past |z| = 2 s.
SEARCH_LIMIT = 16.0


def stability_polynomial(method: ExplicitRungeKutta) -> tuple[Fraction, ...]:
    """Exact coefficients ``(1, g1, ..., gs)`` of ``R(z) = sum_j g_j z^j``,
    ``g_j = b^T A^(j-1) 1`` (lowest power first)."""
    s = method.stages
    coeffs = [Fraction(1)]
    v = [Fraction(1)] * s                       # A^(j-1) 1, starting at j = 1
    for _ in range(s):
        coeffs.append(sum((bi * vi for bi, vi in zip(method.b, v, strict=True)), Fraction(0)))
        v = [sum((aij * vj for aij, vj in zip(row, v, strict=True)), Fraction(0))
             for row in method.A]
    while len(coeffs) > 1 and coeffs[-1] == 0:
        coeffs.pop()
    return tuple(coeffs)


def amplification(method: ExplicitRungeKutta, z):
    """``R(z)`` for scalar or array ``z`` (complex allowed)."""
    coeffs = [float(g) for g in stability_polynomial(method)]
    return np.polynomial.polynomial.polyval(z, coeffs)


def _convolve(p, q):
    out = [Fraction(0)] * (len(p) + len(q) - 1)
    for i, pi in enumerate(p):
        for j, qj in enumerate(q):
            out[i + j] += pi * qj
    return out


def growth_polynomial(method: ExplicitRungeKutta, axis: str) -> tuple[Fraction, ...]:
    """Exact coefficients of ``G(x) = |R(z(x))|^2 - 1`` along an axis.

    ``axis="real"``: ``z = -x``; ``axis="imaginary"``: ``z = i x``. A step is
    unstable exactly where ``G(x) > 0``, and ``G`` has rational coefficients,
    so the sign of ``G`` just right of ``x = 0`` (where ``G(0) = 0``) is the
    sign of its lowest non-zero coefficient: decided exactly, not by
    rounding.
    """
    r = stability_polynomial(method)
    if axis == "real":
        re = [g * (-1) ** j for j, g in enumerate(r)]
        im = [Fraction(0)]
    elif axis == "imaginary":
        # i^j is 1, i, -1, -i, ...: even powers feed the real part, odd the imaginary.
        re = [g * (-1) ** (j // 2) if j % 2 == 0 else Fraction(0) for j, g in enumerate(r)]
        im = [g * (-1) ** (j // 2) if j % 2 == 1 else Fraction(0) for j, g in enumerate(r)]
    else:
        raise ValueError(f"axis must be 'real' or 'imaginary', got {axis!r}")
    square = _convolve(re, re)
    im_square = _convolve(im, im)
    coeffs = [a + (im_square[k] if k < len(im_square) else 0) for k, a in enumerate(square)]
    coeffs[0] -= 1
    while len(coeffs) > 1 and coeffs[-1] == 0:
        coeffs.pop()
    return tuple(coeffs)


def _stable_until(method: ExplicitRungeKutta, axis: str) -> float:
    """Largest ``x >= 0`` with ``G(x') <= 0`` for all ``0 <= x' <= x``
    (:func:`growth_polynomial`); 0.0 when unstable for every ``x > 0``."""
    G = growth_polynomial(method, axis)
    lowest = next((g for g in G if g != 0), Fraction(0))
    if lowest > 0:
        return 0.0
    if lowest == 0:
        return float("inf")                     # |R| = 1 along the whole axis
    coeffs = [float(g) for g in G]

    def unstable(x):
        return np.polynomial.polynomial.polyval(x, coeffs) > STABLE_TOL

    # Scan outward for the first unstable point, then bisect the bracket.
    xs = np.arange(1, int(SEARCH_LIMIT / SCAN_STEP) + 1) * SCAN_STEP
    bad = np.flatnonzero(unstable(xs))
    if bad.size == 0:
        return float("inf")
    hi = float(xs[bad[0]])
    lo = hi - SCAN_STEP
    while hi - lo > BOUNDARY_RTOL * hi:
        mid = 0.5 * (lo + hi)
        if unstable(mid):
            hi = mid
        else:
            lo = mid
    return lo


def real_axis_limit(method: ExplicitRungeKutta) -> float:
    """Largest ``x`` with ``|R(-x')| <= 1`` for all ``0 <= x' <= x``.

    For linear drag ``v' = -(k/m) v`` the largest stable step is
    ``x / (k/m)``: forward Euler and Heun 2, rk4 2.785, backwards-euler 1.
    """
    return _stable_until(method, "real")


def imaginary_axis_limit(method: ExplicitRungeKutta) -> float:
    """Largest ``y`` with ``|R(i y')| <= 1`` for all ``0 <= y' <= y``.

    For an undamped oscillation of angular frequency ``omega`` the largest
    non-growing step is ``y / omega``. 0 means amplitude grows at every step
    size (forward Euler, Heun, midpoint); rk4 2 sqrt(2); backwards-euler 1.
    """
    return _stable_until(method, "imaginary")


@dataclass(frozen=True)
class StabilitySummary:
    """Linear stability facts of one method.

    Attributes
    ----------
    method : str
    coefficients : tuple of Fraction
        Of ``R(z)``, lowest power first.
    real_limit : float
        :func:`real_axis_limit`, in units of ``h |lambda|``.
    imaginary_limit : float
        :func:`imaginary_axis_limit`, in units of ``h omega``.
    """

    method: str
    coefficients: tuple
    real_limit: float
    imaginary_limit: float


def stability_summary(method: ExplicitRungeKutta) -> StabilitySummary:
    return StabilitySummary(method.name, stability_polynomial(method),
                            real_axis_limit(method), imaginary_axis_limit(method))


def stability_grid(method: ExplicitRungeKutta, re=(-4.0, 1.0), im=(-3.5, 3.5),
                   n: int = 201) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``|R(x + i y)|`` on an ``n`` x ``n`` grid, for plotting the region.

    Returns ``x`` (n,), ``y`` (n,) and ``|R|`` (n, n) indexed ``[iy, ix]``
    (the layout ``matplotlib.pyplot.contour(x, y, absR, levels=[1])`` wants).
    """
    x = np.linspace(re[0], re[1], n)
    y = np.linspace(im[0], im[1], n)
    z = x[np.newaxis, :] + 1j * y[:, np.newaxis]
    return x, y, np.abs(amplification(method, z))
