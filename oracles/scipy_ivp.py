"""scipy's ``solve_ivp`` as the oracle for the ODE solvers (S6, S10).

Two queries, both on ``y' = f(t, y)`` with ``f(t, y) -> (d,)``:

- :func:`reference_solution`: the "true" solution to compare the seed's
  fixed-step solvers against, by DOP853 (Dormand & Prince's 8th-order
  method with step control, HNW I, section II.10) at ``rtol = atol = 1e-13``
  (:data:`REFERENCE_TOL`).
- :func:`adaptive_run`: one run of an adaptive scipy method (RK45, DOP853) at
  a given tolerance, returning the solution at ``t1``, the evaluations of
  ``f`` and the wall time: the anchors of the work-precision charts.

Conventions: scipy wants ``f(t, y)`` and returns ``y`` as (d, n_times); the
adapter returns (n_times, d) like :func:`refsim.integrate`. scipy is a core
dependency of refsim, so no :class:`refsim.oracles.OracleUnavailable` is raised.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

#: DOP853 tolerances for reference solutions. Tighter than ~1e-13 buys
#: nothing in float64 (scipy warns below 100 eps for rtol); at this setting
#: the global error on the problems here is ~1e-12 relative (checked against
#: closed forms in tests/solvers/test_scipy_oracle.py), far below the
#: fixed-step errors being measured (floor: ERROR_FLOOR_REL in
#: refsim.studies.solvers).
REFERENCE_TOL = 1e-13


@dataclass(frozen=True)
class ReferenceSolution:
    """A DOP853 reference.

    Attributes
    ----------
    t : numpy.ndarray
        (n,) times asked for.
    y : numpy.ndarray
        (n, d) states at ``t``.
    nfev : int
    """

    t: np.ndarray
    y: np.ndarray
    nfev: int


@dataclass(frozen=True)
class AdaptiveRun:
    """One adaptive scipy run.

    Attributes
    ----------
    method : str
        scipy's name, "RK45" or "DOP853".
    tol : float
        Used as both ``rtol`` and ``atol``.
    y1 : numpy.ndarray
        (d,) solution at ``t1``.
    nfev : int
    wall_time : float
        Seconds for the ``solve_ivp`` call (``time.perf_counter``).
    """

    method: str
    tol: float
    y1: np.ndarray
    nfev: int
    wall_time: float


class OracleFailure(RuntimeError):
    """scipy reported failure (a reference that cannot be trusted)."""


def reference_solution(f, y0, t0: float, t1: float, t_eval=None,
                       tol: float = REFERENCE_TOL) -> ReferenceSolution:
    """DOP853 at ``rtol = atol = tol``; at ``t_eval`` (default ``[t1]``)."""
    y0 = np.atleast_1d(np.asarray(y0, dtype=np.float64))
    t_eval = np.array([t1], dtype=np.float64) if t_eval is None else np.asarray(t_eval, float)
    if t1 == t0:
        return ReferenceSolution(t_eval, np.tile(y0, (len(t_eval), 1)), 0)
    sol = solve_ivp(f, (t0, t1), y0, method="DOP853", rtol=tol, atol=tol, t_eval=t_eval)
    if not sol.success:
        raise OracleFailure(f"DOP853 reference failed: {sol.message}")
    return ReferenceSolution(sol.t, sol.y.T.copy(), int(sol.nfev))


def adaptive_run(f, y0, t0: float, t1: float, method: str, tol: float) -> AdaptiveRun:
    """One ``solve_ivp`` run with ``rtol = atol = tol``, timed."""
    y0 = np.atleast_1d(np.asarray(y0, dtype=np.float64))
    start = time.perf_counter()
    sol = solve_ivp(f, (t0, t1), y0, method=method, rtol=tol, atol=tol)
    wall_time = time.perf_counter() - start
    if not sol.success:
        raise OracleFailure(f"{method} at tol {tol:g} failed: {sol.message}")
    return AdaptiveRun(method, tol, sol.y[:, -1].copy(), int(sol.nfev), wall_time)


def solve_with_events(f, y0, t0: float, t1: float, events, tol: float = REFERENCE_TOL):
    """DOP853 at ``rtol = atol = tol`` from ``t0`` until ``t1`` or the first
    terminal event (scipy's event functions: ``terminal``, ``direction``).
    Returns scipy's result (``status`` 1 when an event stopped it,
    ``t_events``, ``y_events``, ``t``, ``y`` as (d, n))."""
    y0 = np.atleast_1d(np.asarray(y0, dtype=np.float64))
    sol = solve_ivp(f, (t0, t1), y0, method="DOP853", rtol=tol, atol=tol, events=events)
    if sol.status < 0:
        raise OracleFailure(f"DOP853 with events failed: {sol.message}")
    return sol


class ScipyReference:
    """scipy's ``solve_ivp`` as a reference solver for the studies: a DOP853
    reference (``solution``, ``solve_with_events``) and adaptive runs to
    compare against (``adaptive_run``); :class:`refsim.engines.ReferenceSolver`."""

    name = "scipy"
    tolerance = REFERENCE_TOL

    def solution(self, f, y0, t0: float, t1: float, t_eval=None) -> ReferenceSolution:
        return reference_solution(f, y0, t0, t1, t_eval=t_eval)

    def solve_with_events(self, f, y0, t0: float, t1: float, events):
        return solve_with_events(f, y0, t0, t1, events)

    def adaptive_run(self, f, y0, t0: float, t1: float, method: str,
                     tol: float) -> AdaptiveRun:
        return adaptive_run(f, y0, t0, t1, method, tol)


def engine() -> ScipyReference:
    """The reference solver (``refsim.oracles.scipy_ivp:engine``)."""
    return ScipyReference()
