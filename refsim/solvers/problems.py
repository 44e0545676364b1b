"""Test problems for the solver measurements, each with a right-hand side
and, where one exists in closed form, its exact solution.

What: exponential decay, the harmonic oscillator, a projectile with linear
drag, the two-body Kepler orbit, and a small particle system with quadratic
drag (the seed's S10 forces, no walls). The first four have exact solutions;
the particle system is measured against scipy's DOP853
(:mod:`refsim.oracles.scipy_ivp`).

Seed section: S6 (the solvers these problems measure) and S5/S10 (the
forces of the projectile and particle problems).

Reference: the Kepler problem as in E. Hairer, C. Lubich, G. Wanner,
*Geometric Numerical Integration*, 2nd ed., Springer 2006, section I.2; the
drag solution is the textbook one for ``v' = g - (k/m) v`` (J. R. Taylor,
*Classical Mechanics*, University Science Books 2005, chapter 2).

Cost: each ``f`` is O(d).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

STANDARD_GRAVITY = 9.81


@dataclass(frozen=True)
class Problem:
    """An initial value problem ``y' = f(t, y)``, ``y(t0) = y0`` on ``[t0, t1]``.

    Attributes
    ----------
    name : str
    f : callable
        ``f(t, y) -> dy/dt``, shapes (d,) -> (d,).
    y0 : numpy.ndarray
        (d,).
    t0, t1 : float
    exact : callable or None
        ``exact(t) -> y(t)``, (d,), where a closed form exists.
    scale : float
        The size errors are measured relative to (the largest ``|y|`` along
        the exact or reference solution, roughly).
    """

    name: str
    f: Callable
    y0: np.ndarray
    t0: float
    t1: float
    exact: Callable | None
    scale: float


def exponential_decay(rate: float = 1.0, t1: float = 1.0) -> Problem:
    """``y' = -rate y``, ``y(0) = 1``: the test equation with ``lambda = -rate``."""
    return Problem("exponential-decay", lambda t, y: -rate * y, np.array([1.0]), 0.0, t1,
                   lambda t: np.array([np.exp(-rate * t)]), 1.0)


def harmonic_oscillator(omega: float = 1.0, periods: float = 1.0) -> Problem:
    """``x'' = -omega^2 x`` as ``y = (x, v)``, ``y(0) = (1, 0)``; eigenvalues
    ``+-i omega``."""
    def f(t, y):
        return np.array([y[1], -omega**2 * y[0]])

    def exact(t):
        return np.array([np.cos(omega * t), -omega * np.sin(omega * t)])

    return Problem("harmonic-oscillator", f, np.array([1.0, 0.0]), 0.0,
                   periods * 2.0 * np.pi / omega, exact, max(1.0, omega))


def projectile_linear_drag(drag: float = 0.5, mass: float = 1.0,
                           gravity: float = STANDARD_GRAVITY,
                           velocity=(3.0, 8.0, 1.0), t1: float = 2.0) -> Problem:
    """A point mass under gravity ``(0, -g, 0)`` and drag ``-k v`` (seed S5),
    ``y = (x, v)`` in 3-D, from the origin.

    Exact solution, with ``r = k/m`` and terminal velocity ``v_T = g_vec / r``::

        v(t) = v_T + (v0 - v_T) e^{-r t}
        x(t) = v_T t + (v0 - v_T) (1 - e^{-r t}) / r
    """
    r = drag / mass
    g = np.array([0.0, -gravity, 0.0])
    v0 = np.asarray(velocity, dtype=np.float64)
    v_terminal = g / r

    def f(t, y):
        v = y[3:]
        return np.concatenate([v, g - r * v])

    def exact(t):
        decay = np.exp(-r * t)
        v = v_terminal + (v0 - v_terminal) * decay
        x = v_terminal * t + (v0 - v_terminal) * (1.0 - decay) / r
        return np.concatenate([x, v])

    y0 = np.concatenate([np.zeros(3), v0])
    return Problem("projectile-linear-drag", f, y0, 0.0, t1, exact,
                   float(np.abs(np.concatenate([exact(t1), v0])).max()))


def kepler_orbit(eccentricity: float = 0.5, periods: float = 1.0) -> Problem:
    """The two-body problem in relative coordinates, ``mu = 1``, semi-major
    axis 1 (period ``2 pi``), ``y = (q1, q2, p1, p2)``, started at perihelion.

    ``q'' = -q / |q|^3``; at perihelion ``q = (1 - e, 0)`` and
    ``p = (0, sqrt((1 + e) / (1 - e)))`` (Hairer, Lubich & Wanner, section I.2).
    After whole periods the exact solution is the initial state; in between
    it is found from Kepler's equation ``E - e sin E = t``.
    """
    e = eccentricity
    y0 = np.array([1.0 - e, 0.0, 0.0, np.sqrt((1.0 + e) / (1.0 - e))])

    def f(t, y):
        q = y[:2]
        r3 = (q[0] * q[0] + q[1] * q[1]) ** 1.5
        return np.array([y[2], y[3], -q[0] / r3, -q[1] / r3])

    def exact(t):
        # Solve Kepler's equation for the eccentric anomaly E by Newton's
        # method (converges from E = M for e < 0.8 in a handful of steps).
        M = t
        E = M
        for _ in range(50):
            dE = (E - e * np.sin(E) - M) / (1.0 - e * np.cos(E))
            E -= dE
            if abs(dE) < 1e-16:
                break
        b = np.sqrt(1.0 - e * e)
        q = np.array([np.cos(E) - e, b * np.sin(E)])
        Edot = 1.0 / (1.0 - e * np.cos(E))
        p = np.array([-np.sin(E) * Edot, b * np.cos(E) * Edot])
        return np.concatenate([q, p])

    return Problem("kepler", f, y0, 0.0, periods * 2.0 * np.pi, exact,
                   float(np.sqrt((1.0 + e) / (1.0 - e))))
