"""Measurements of the seed's solvers: observed order, stability, cost.

What: the numbers behind claims C6, C7, C9 and C10 for the solvers on their
own (the particle-system measurements, C5 and C8, are in
:mod:`refsim.studies.particles`). Every function returns plain numbers or
frozen dataclasses; the tests gate on them and the report draws them.

- :func:`measure_convergence` / :func:`measure_orders`: error at ``t1``
  against scipy's DOP853 for a sequence of halving steps, and the observed
  order, the least-squares slope of ``log error`` against ``log h`` fitted
  between the error floor and the asymptotic ceiling.
- :func:`measure_seed_literal_rk4`: the seed's literal RK4 weights converge
  to the wrong equation.
- :func:`measure_stability`: the largest stable step predicted from ``R(z)``
  against the one found by simulation, for stiff linear drag and for an
  undamped oscillator; :func:`energy_per_period` for the oscillator.
- :func:`measure_work_precision`: error against evaluations and wall time,
  for the five solvers and for scipy's RK45 / DOP853.

Seed section: S6 (and S10 through the particle problem).

Reference: E. Hairer, S. P. Norsett, G. Wanner, *Solving Ordinary
Differential Equations I*, 2nd ed., section II.10 (numerical experiments,
work-precision diagrams); Hairer & Wanner, *Solving ODEs II*, section IV.2
(stability functions).

Cost: dominated by the Python loop of :func:`refsim.integrate`, about
5-10 microseconds per evaluation of ``f`` for the small problems here.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from refsim.errors import OptionError
from refsim.solvers.explicit_rk import ExplicitRungeKutta
from refsim.solvers.integrate import resolve_method, solve_fixed_step
from refsim.solvers.methods import SOLVERS
from refsim.solvers.problems import (
    Problem,
    exponential_decay,
    harmonic_oscillator,
    kepler_orbit,
    projectile_linear_drag,
)
from refsim.solvers.stability import (
    imaginary_axis_limit,
    real_axis_limit,
    stability_grid,
    stability_polynomial,
)
from refsim.studies import TIMED

EPS = np.finfo(np.float64).eps

#: Errors below this, relative to the problem's scale, are not fitted: they
#: are within reach of the DOP853 reference's own error (up to 5e-12
#: relative, on Kepler, at rtol = atol = 1e-13; ~1e-13 elsewhere) and of the
#: rounding that n steps accumulate (~n eps, ~1e-11 for 10^5 steps). At
#: 1e-10 those move the smallest fitted error by at most 5%, the slope by at
#: most 0.04 (Kepler rk4); a higher floor would leave rk4 too few points in
#: its asymptotic regime.
ERROR_FLOOR_REL = 1e-10

#: Errors above this, relative to the scale, are not fitted: the method is
#: not yet in its asymptotic regime (an error of 10% of the solution's size
#: is not small compared to the solution).
ERROR_CEILING_REL = 1e-1

#: Fewest points a slope is fitted to; fewer gives ``nan``.
MIN_FIT_POINTS = 3

#: The slope is fitted to the finest (smallest h) FIT_POINTS points between
#: floor and ceiling: the asymptotic regime is the small-h end, and coarser
#: points still carry the next term of the error expansion (rk4 on Kepler:
#: local slopes 4.6, 4.5, 4.3, 4.2, 4.1, 4.05, 4.0 as h halves). Three
#: points span a factor 4 in h.
FIT_POINTS = 3


@dataclass(frozen=True)
class Convergence:
    """Errors of one solver on one problem over halving steps.

    Attributes
    ----------
    method, problem : str
    h : numpy.ndarray
        (m,) step sizes, largest first.
    error : numpy.ndarray
        (m,) max-norm error at ``t1`` divided by the problem's scale.
    nfev : numpy.ndarray
        (m,) evaluations of ``f`` per run.
    fitted : numpy.ndarray
        (m,) bool: the points the slope was fitted to, the FIT_POINTS
        smallest steps with floor < error < ceiling.
    order : float
        Observed order: the least-squares slope of ``log error`` on ``log h``
        over the fitted points; ``nan`` with fewer than MIN_FIT_POINTS.
    """

    method: str
    problem: str
    h: np.ndarray
    error: np.ndarray
    nfev: np.ndarray
    fitted: np.ndarray
    order: float


def fit_order(h, error, floor=ERROR_FLOOR_REL, ceiling=ERROR_CEILING_REL,
              points=FIT_POINTS):
    """Slope of ``log error`` on ``log h`` over the ``points`` smallest steps
    whose error lies in (floor, ceiling).

    Returns ``(order, fitted_mask)``; order is ``nan`` with fewer than
    MIN_FIT_POINTS such points.
    """
    h = np.asarray(h, dtype=np.float64)
    error = np.asarray(error, dtype=np.float64)
    inside = (error > floor) & (error < ceiling) & np.isfinite(error)
    fitted = np.zeros_like(inside)
    fitted[np.flatnonzero(inside)[np.argsort(h[inside])[:points]]] = True
    if fitted.sum() < MIN_FIT_POINTS:
        return float("nan"), fitted
    slope, _ = np.polyfit(np.log(h[fitted]), np.log(error[fitted]), 1)
    return float(slope), fitted


# --------------------------------------------------------------------------
# Problems and their references
# --------------------------------------------------------------------------

#: Fewest and most steps over [t0, t1] per problem for the order study: the
#: most is where Euler on that problem reaches ERROR_CEILING_REL with two
#: halvings to spare (Kepler with e = 0.5 needs ~10^5 steps).
STEP_RANGE = {
    "exponential-decay": (4, 2**12),
    "harmonic-oscillator": (8, 2**13),
    "projectile-linear-drag": (4, 2**12),
    "kepler": (32, 2**17),
    "particles": (4, 2**12),
}


def particle_problem(count: int = 20, drag: float = 0.5, drag_model: str = "quadratic",
                     t1: float = 1.0, seed: int = 1) -> Problem:
    """A free particle system (no walls) as a :class:`Problem`, ``y`` = the
    flattened (2, N, 3) state; quadratic drag by default, so that ``f`` is
    nonlinear. No closed form: measured against DOP853."""
    from refsim.particles.config import ParticleConfig
    from refsim.particles.system import particle_rhs

    config = ParticleConfig(count=count, seed=seed, drag=drag, drag_model=drag_model,
                            walls=False, speed_min=1.0, speed_max=5.0)
    x, v = config.initial_state()
    y0 = np.stack([x, v]).reshape(-1)
    return Problem("particles", particle_rhs(config), y0, 0.0, t1, None,
                   float(np.abs(y0).max()))


def standard_problems() -> dict[str, Problem]:
    """The five problems of the order study, by name."""
    problems = [exponential_decay(), harmonic_oscillator(), projectile_linear_drag(),
                kepler_orbit(), particle_problem()]
    return {p.name: p for p in problems}


def reference_at_t1(problem: Problem, oracle=None) -> np.ndarray:
    """``y(t1)``: by ``oracle``, a reference solver
    (:class:`refsim.engines.ReferenceSolver`, e.g. scipy's DOP853), or, with
    ``oracle=None``, the problem's closed form.

    Raises
    ------
    OptionError
        ``oracle=None`` for a problem without a closed form.
    """
    if oracle is None:
        if problem.exact is None:
            raise OptionError(f"problem {problem.name!r} has no closed form: give a "
                              "reference solver (refsim.oracles.scipy_ivp:engine)")
        return problem.exact(problem.t1)
    return oracle.solution(problem.f, problem.y0, problem.t0, problem.t1).y[-1]


# --------------------------------------------------------------------------
# Order of convergence (C10)
# --------------------------------------------------------------------------

def measure_convergence(problem: Problem, method, steps=None, y_ref=None,
                        stop_at_floor: bool = True, oracle=None) -> Convergence:
    """Error at ``t1`` for step counts ``steps`` (default: doubling through
    ``STEP_RANGE[problem.name]``), and the observed order. The reference is
    ``y_ref``, or :func:`reference_at_t1` with ``oracle``.

    With ``stop_at_floor`` the doubling stops after the second error below
    ERROR_FLOOR_REL (more steps only measure rounding).
    """
    solver = resolve_method(method)
    if y_ref is None:
        y_ref = reference_at_t1(problem, oracle)
    if steps is None:
        lo, hi = STEP_RANGE[problem.name]
        steps = [lo * 2**k for k in range(int(math.log2(hi // lo)) + 1)]
    hs, errors, nfevs = [], [], []
    below_floor = 0
    for n in steps:
        h = (problem.t1 - problem.t0) / n
        result = solve_fixed_step(problem.f, problem.y0, problem.t0, problem.t1, h, solver)
        error = float(np.abs(result.y[-1] - y_ref).max()) / problem.scale
        hs.append(h)
        errors.append(error)
        nfevs.append(result.nfev)
        below_floor += error <= ERROR_FLOOR_REL
        if stop_at_floor and below_floor >= 2:
            break
    order, fitted = fit_order(hs, errors)
    return Convergence(solver.name, problem.name, np.array(hs), np.array(errors),
                       np.array(nfevs), fitted, order)


def measure_orders(problems: dict[str, Problem] | None = None,
                   methods=tuple(SOLVERS), oracle=None) -> dict[tuple[str, str], Convergence]:
    """:func:`measure_convergence` for every (problem, method); keys are
    ``(problem name, method name)``. One reference per problem, by ``oracle``
    (a reference solver; None: closed forms only)."""
    problems = standard_problems() if problems is None else problems
    out = {}
    for name, problem in problems.items():
        y_ref = reference_at_t1(problem, oracle)
        for method in methods:
            out[(name, resolve_method(method).name)] = measure_convergence(problem, method,
                                                                          y_ref=y_ref)
    return out


@dataclass(frozen=True)
class SeedLiteralRK4:
    """The seed's literal RK4 weights (sum 5/3) on one problem.

    Attributes
    ----------
    against_true : Convergence
        Error against the solution of ``y' = f``: does not go to zero.
    against_scaled : Convergence
        Error against the solution of ``y' = (5/3) f``: goes to zero; its
        ``order`` is the observed order for that equation (1).
    limit_error : float
        ``|y_scaled(t1) - y(t1)| / scale``: the error the literal method keeps
        as ``h -> 0``.
    """

    against_true: Convergence
    against_scaled: Convergence
    limit_error: float


def measure_seed_literal_rk4(problem: Problem | None = None, oracle=None) -> SeedLiteralRK4:
    """Show that the literal RK4 reading converges to ``y' = (5/3) f``
    (references by ``oracle``, a reference solver: the scaled problem has no
    closed form)."""
    from refsim.solvers.methods import RK4_SEED_LITERAL

    problem = harmonic_oscillator() if problem is None else problem
    scaled = Problem(problem.name, lambda t, y: (5.0 / 3.0) * problem.f(t, y), problem.y0,
                     problem.t0, problem.t1, None, problem.scale)
    y_true = reference_at_t1(problem, oracle)
    y_scaled = reference_at_t1(scaled, oracle)
    against_true = measure_convergence(problem, RK4_SEED_LITERAL, y_ref=y_true)
    against_scaled = measure_convergence(problem, RK4_SEED_LITERAL, y_ref=y_scaled)
    return SeedLiteralRK4(against_true, against_scaled,
                          float(np.abs(y_scaled - y_true).max()) / problem.scale)


# --------------------------------------------------------------------------
# Stability (C6, C7)
# --------------------------------------------------------------------------

#: Per-step growth of the log amplitude above which a run counts as growing.
#: A stable run's log amplitude drifts by rounding, ~eps per step, so
#: 1e-13 per step is growth, not noise.
GROWTH_TOL = 1e-13

#: Steps per simulated stability test. Growth per step near a boundary is
#: proportional to the distance from it, so more steps sharpen the boundary;
#: 400 places it to ~1e-10 relative with the tolerance above.
STABILITY_STEPS = 400


def log_growth_per_step(method: ExplicitRungeKutta, f, y0, h: float,
                        steps: int = STABILITY_STEPS) -> float:
    """Mean ``log(|y_{n+1}| / |y_n|)`` over ``steps`` steps of a linear ODE.

    The state is rescaled to unit length after each step (allowed because
    ``f`` is linear), so a growing run neither overflows nor loses digits.
    """
    y = np.asarray(y0, dtype=np.float64) / np.linalg.norm(y0)
    total = 0.0
    for n in range(steps):
        y = method.step(f, n * h, y, h)
        size = float(np.linalg.norm(y))
        if size == 0.0:
            return -math.inf
        total += math.log(size)
        y = y / size
    return total / steps


def _largest_non_growing(grows, lo: float, hi: float, rtol: float = 1e-9) -> float:
    """Largest x in [lo, hi] before ``grows(x)`` turns true, by a scan from
    ``lo`` in factors of 1.25 followed by bisection; 0.0 when ``lo`` already
    grows. (The stable sets of these methods along each axis are intervals
    from 0, so the scan cannot step over a stable island.)"""
    if grows(lo):
        return 0.0
    x_prev, x = lo, lo
    while x < hi:
        x = min(x * 1.25, hi)
        if grows(x):
            break
        x_prev = x
    else:
        return math.inf
    a, b = x_prev, x
    while b - a > rtol * b:
        mid = 0.5 * (a + b)
        if grows(mid):
            b = mid
        else:
            a = mid
    return a


@dataclass(frozen=True)
class StabilityLimit:
    """Predicted against simulated stability limits of one method.

    Attributes
    ----------
    method : str
    drag_predicted, drag_measured : float
        Largest stable ``h k / m`` for linear drag ``v' = -(k/m) v``:
        predicted from ``R`` (:func:`real_axis_limit`), measured with the
        particle system (one particle, no gravity, no walls).
    oscillator_predicted, oscillator_measured : float
        Largest ``h omega`` at which an undamped oscillator's amplitude does
        not grow; 0.0 means it grows at every step tried (down to
        ``1e-3``), ``inf`` never within the range tried.
    """

    method: str
    drag_predicted: float
    drag_measured: float
    oscillator_predicted: float
    oscillator_measured: float


def _drag_grows(method: ExplicitRungeKutta, hk: float) -> bool:
    """Simulate one particle with linear drag k = 1 (no gravity, no walls)
    with the particle system's own step and report velocity growth."""
    from refsim.particles.config import ParticleConfig
    from refsim.particles.system import ParticleSystem

    config = ParticleConfig(count=1, gravity=0.0, drag=1.0, walls=False,
                            solver=method.name, step=hk)
    system = ParticleSystem(config, positions=[[0.0, 0.0, 0.0]], velocities=[[1.0, 0.0, 0.0]])
    total = 0.0
    for _ in range(STABILITY_STEPS):
        system.step()
        size = abs(float(system.velocities[0, 0]))
        if size == 0.0:
            return False
        total += math.log(size)
        system.velocities[0, 0] /= size
    return total / STABILITY_STEPS > GROWTH_TOL


def _oscillator_grows(method: ExplicitRungeKutta, omega_h: float) -> bool:
    problem = harmonic_oscillator(omega=1.0)
    return log_growth_per_step(method, problem.f, problem.y0, omega_h) > GROWTH_TOL


def measure_stability(methods=tuple(SOLVERS)) -> list[StabilityLimit]:
    """:class:`StabilityLimit` for each method."""
    out = []
    for key in methods:
        method = resolve_method(key)
        out.append(StabilityLimit(
            method.name,
            real_axis_limit(method),
            _largest_non_growing(lambda x, m=method: _drag_grows(m, x), 1e-3, 8.0),
            imaginary_axis_limit(method),
            _largest_non_growing(lambda x, m=method: _oscillator_grows(m, x), 1e-3, 8.0),
        ))
    return out


def stability_regions(re: tuple[float, float], im: tuple[float, float], n: int):
    """Each method's stability polynomial R(z) (Fractions, lowest power
    first) and |R| on an ``n`` x ``n`` grid of z = h lambda over ``re`` x
    ``im``, one region per distinct R(z): methods with the same R share one
    (averaged-euler and midpoint), labelled "a = b (same R)".
    Returns ``(polynomials, x, y, regions)``: ``regions`` is a list of
    ``(label, |R| (n, n))``, ``x`` and ``y`` the grid's axes (None when there
    are no methods)."""
    polynomials = {name: stability_polynomial(s) for name, s in SOLVERS.items()}
    groups: dict[tuple, list[str]] = {}
    for name in SOLVERS:
        groups.setdefault(polynomials[name], []).append(name)
    regions = []
    x = y = None
    for names in groups.values():
        x, y, absR = stability_grid(SOLVERS[names[0]], re=re, im=im, n=n)
        regions.append((" = ".join(names) + (" (same R)" if len(names) > 1 else ""), absR))
    return polynomials, x, y, regions


def failing_order_conditions(solver) -> list[str]:
    """The order conditions up to the seed's stated order that the tableau
    fails (empty when it meets them all)."""
    if solver.row_sums() != solver.c:
        return ["c_i != sum_j a_ij"]
    return [f"{name.split(' = ')[0]} = {value}, not {want}"
            for p, name, value, want in solver.order_conditions()
            if p <= solver.seed_order and value != want]


def energy_per_period(method, omega_h: float, periods: int = 10) -> float:
    """Energy ratio ``E(T) / E(0)`` per period ``T = 2 pi`` of ``x'' = -x``
    (omega = 1, ``E = (x^2 + v^2) / 2``), simulated with
    :func:`refsim.solve_fixed_step` at ``h = omega_h`` for the whole number of
    steps ``n`` that first covers ``periods`` periods, as
    ``(E_n / E_0)^(T / (n h))``. 1 is exact; above 1 the amplitude grows.
    """
    n = math.ceil(periods * 2.0 * math.pi / omega_h)
    problem = harmonic_oscillator(omega=1.0)
    result = solve_fixed_step(problem.f, problem.y0, 0.0, n * omega_h, omega_h, method)
    energy = 0.5 * (result.y[:, 0] ** 2 + result.y[:, 1] ** 2)
    return float((energy[-1] / energy[0]) ** (2.0 * math.pi / (n * omega_h)))


def predicted_energy_per_period(method, omega_h: float) -> float:
    """``|R(i omega h)|^(2 T / h)``, ``T = 2 pi / omega``: what
    :func:`energy_per_period` should measure, from the stability function."""
    from refsim.solvers.stability import amplification

    R = abs(amplification(resolve_method(method), 1j * omega_h))
    return float(R ** (2.0 * 2.0 * math.pi / omega_h))


@dataclass(frozen=True)
class OscillatorEnergy:
    """Energy gain per period of an undamped oscillator.

    Attributes
    ----------
    method : str
    omega_h : float
    measured : float
        :func:`energy_per_period`.
    predicted : float
        :func:`predicted_energy_per_period`.
    """

    method: str
    omega_h: float
    measured: float
    predicted: float


def measure_oscillator_energy(omega_hs=(0.01, 0.1, 0.5, 1.0, 2.0),
                              methods=tuple(SOLVERS)) -> list[OscillatorEnergy]:
    """:class:`OscillatorEnergy` for every (method, omega h)."""
    return [OscillatorEnergy(resolve_method(m).name, w, energy_per_period(m, w),
                             predicted_energy_per_period(m, w))
            for m in methods for w in omega_hs]


# --------------------------------------------------------------------------
# Work-precision (C8, C9)
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class WorkPoint:
    """One run on a work-precision chart.

    Attributes
    ----------
    method : str
        A seed solver key, or "scipy-RK45" / "scipy-DOP853".
    parameter : float
        The step ``h`` (fixed-step) or the tolerance (scipy).
    error : float
        Max-norm error at ``t1`` relative to the problem's scale.
    nfev : int
    wall_time : float
        Seconds (best of ``repeats`` runs).
    """

    method: str
    parameter: float
    error: float
    nfev: int
    wall_time: float = field(metadata=TIMED)


#: The scipy tolerances of the work-precision anchors.
SCIPY_TOLERANCES = tuple(10.0 ** -k for k in range(3, 13))


def measure_work_precision(problem: Problem | None = None, methods=tuple(SOLVERS),
                           steps=None, tolerances=SCIPY_TOLERANCES,
                           repeats: int = 1, oracle=None) -> list[WorkPoint]:
    """Error against cost on one problem (default: Kepler, e = 0.5).

    Fixed-step solvers at the step counts ``steps`` (default: doubling
    through STEP_RANGE, capped at 2^14 to bound the time), and, with
    ``oracle`` (a reference solver), its adaptive RK45 and DOP853 at
    ``tolerances`` and its reference; without, the closed-form reference only.
    """
    problem = kepler_orbit() if problem is None else problem
    y_ref = reference_at_t1(problem, oracle)
    if steps is None:
        lo, hi = STEP_RANGE[problem.name]
        steps = [lo * 2**k for k in range(int(math.log2(min(hi, 2**14) // lo)) + 1)]
    out = []
    for key in methods:
        solver = resolve_method(key)
        for n in steps:
            h = (problem.t1 - problem.t0) / n
            best = math.inf
            for _ in range(repeats):
                start = time.perf_counter()
                result = solve_fixed_step(problem.f, problem.y0, problem.t0, problem.t1, h,
                                          solver)
                best = min(best, time.perf_counter() - start)
            error = float(np.abs(result.y[-1] - y_ref).max()) / problem.scale
            out.append(WorkPoint(solver.name, h, error, result.nfev, best))
    for scipy_method in ("RK45", "DOP853") if oracle is not None else ():
        for tol in tolerances:
            runs = [oracle.adaptive_run(problem.f, problem.y0, problem.t0, problem.t1,
                                        scipy_method, tol) for _ in range(repeats)]
            error = float(np.abs(runs[0].y1 - y_ref).max()) / problem.scale
            out.append(WorkPoint(f"scipy-{scipy_method}", tol, error, runs[0].nfev,
                                 min(r.wall_time for r in runs)))
    return out


def cost_for_error(points: list[WorkPoint], method: str, target: float,
                   cost: str = "nfev") -> float:
    """Cost (``"nfev"`` or ``"wall_time"``) at which ``method`` reaches
    relative error ``target``, by log-log interpolation between its points;
    ``inf`` when no run of it got there."""
    pts = sorted((p for p in points if p.method == method), key=lambda p: getattr(p, cost))
    for a, b in zip(pts, pts[1:], strict=False):
        if a.error >= target >= b.error and a.error > 0 and b.error > 0:
            if a.error == b.error:
                return float(getattr(a, cost))
            w = math.log(a.error / target) / math.log(a.error / b.error)
            return float(math.exp((1 - w) * math.log(getattr(a, cost))
                                  + w * math.log(getattr(b, cost))))
    if pts and pts[0].error <= target:
        return float(getattr(pts[0], cost))
    return math.inf


def error_at_cost(points: list[WorkPoint], method: str, budget: float,
                  cost: str = "nfev") -> float:
    """Error of ``method`` at cost ``budget`` by log-log interpolation between
    its runs; ``nan`` outside the range of costs measured."""
    pts = sorted((p for p in points if p.method == method), key=lambda p: getattr(p, cost))
    for a, b in zip(pts, pts[1:], strict=False):
        ca, cb = getattr(a, cost), getattr(b, cost)
        if ca <= budget <= cb and a.error > 0 and b.error > 0:
            if ca == cb:
                return float(min(a.error, b.error))
            w = math.log(budget / ca) / math.log(cb / ca)
            return float(math.exp((1 - w) * math.log(a.error) + w * math.log(b.error)))
    return math.nan
