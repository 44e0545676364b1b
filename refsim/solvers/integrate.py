"""Fixed-step integration of ``y' = f(t, y)`` with one of the seed's solvers.

What: repeat a solver's step from ``t0`` to ``t1`` with a constant step ``h``,
the way the seed's simulation advances its state vector, and count the
evaluations of ``f`` (``nfev``) as scipy's ``solve_ivp`` does.

Seed section: S6 (docs/design.md, Public API: ``refsim.integrate``).

Reference: E. Hairer, S. P. Norsett, G. Wanner, *Solving Ordinary Differential
Equations I*, 2nd ed., section II.3 (convergence of one-step methods with a
constant step). Bookkeeping after scipy ``integrate/_ivp/base.py``.

Cost: ``steps * stages`` evaluations of ``f``, O(steps * d) memory for the
returned trajectory.

The number of steps is ``n = (t1 - t0) / h``. When that is an integer to
within :data:`STEP_COUNT_RTOL` the grid is ``t_i = t0 + i h`` and the last time
is set to ``t1`` exactly. Otherwise the choice is explicit, ``last_step=``:
``"error"`` (the default) raises :class:`refsim.errors.StateError`, because a
silently shortened final step changes the method; ``"short"`` takes
``floor(n)`` steps of ``h`` and one shorter step to land on ``t1``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from refsim.errors import (
    DivergenceError,
    OptionError,
    StateError,
    as_numbers,
    check_callable,
    check_number,
    check_option,
)
from refsim.limits import MAX_RESULT_BYTES, MAX_STEPS
from refsim.solvers.explicit_rk import ExplicitRungeKutta, rk_step
from refsim.solvers.methods import SEED_LITERAL_VARIANTS, SOLVERS

#: How far ``(t1 - t0) / h`` may be from an integer, relative to it, and still
#: count as that integer. A step read from text (0.001) times a step count
#: (5000) misses the duration by a few ulps; 1e-9 admits that rounding and
#: nothing a user would call a different step.
STEP_COUNT_RTOL = 1e-9


def whole_steps(duration: float, h: float, max_steps: int = MAX_STEPS) -> int:
    """The number of steps of ``h`` in ``duration``, which must be a whole
    number of them (to ``STEP_COUNT_RTOL``), at least one and at most
    ``max_steps`` (default ``MAX_STEPS``; a scene's is
    ``refsim.limits.DEFAULT_MAX_STEPS`` unless raised).

    Raises
    ------
    StateError
        Naming ``duration / h``; the scene loader turns it into a
        :class:`~refsim.errors.SceneError` naming the key.
    """
    if not (math.isfinite(duration) and math.isfinite(h) and duration > 0.0 and h > 0.0):
        raise StateError(f"duration {duration!r} and step {h!r} must be finite and > 0")
    ratio = duration / h
    if ratio > max_steps:
        limit = f"{max_steps:.3g}" if float(f"{max_steps:.3g}") == max_steps else max_steps
        raise StateError(f"duration / step = {duration:g} / {h:g} = {ratio:.3g} steps exceeds "
                         f"the limit of {limit}")
    n = round(ratio)
    if n < 1:
        raise StateError(f"duration {duration:g} is shorter than one step of {h:g}")
    if abs(ratio - n) > STEP_COUNT_RTOL * n:
        raise StateError(f"duration / step = {duration:g} / {h:g} = {ratio:.9g} is not a whole "
                         f"number of steps "
                         f"(try duration = {math.floor(ratio) * h:.9g} or "
                         f"{math.ceil(ratio) * h:.9g})")
    return n


@dataclass(frozen=True)
class FixedStepResult:
    """What :func:`solve_fixed_step` returns.

    Attributes
    ----------
    t : numpy.ndarray
        (steps + 1,) times, ``t[0] = t0``, ``t[-1] = t1``.
    y : numpy.ndarray
        (steps + 1, d) states; ``y[0] = y0``.
    nfev : int
        Evaluations of ``f`` made (``steps * stages``).
    steps : int
    method : str
        The solver's key.
    """

    t: np.ndarray
    y: np.ndarray
    nfev: int
    steps: int
    method: str


def resolve_method(method) -> ExplicitRungeKutta:
    """A solver from its key (in SOLVERS or SEED_LITERAL_VARIANTS) or itself."""
    if isinstance(method, ExplicitRungeKutta):
        return method
    if method in SOLVERS:
        return SOLVERS[method]
    if method in SEED_LITERAL_VARIANTS:
        return SEED_LITERAL_VARIANTS[method]
    known = ", ".join(sorted(SOLVERS))
    raise OptionError(f"unknown solver {method!r}; expected one of {known}")


def covering_duration(duration: float, h: float) -> float:
    """The shortest whole number of steps of ``h`` that covers ``duration``,
    as a duration: for a study that needs "at least this long"."""
    return max(1, math.ceil(duration / h * (1.0 - STEP_COUNT_RTOL))) * h


def step_grid(t0: float, t1: float, h: float,
              last_step: str = "error") -> tuple[np.ndarray, np.ndarray]:
    """The times ``t_0 .. t_n`` of a fixed-step run and the ``n`` steps taken.

    Every step is ``h`` exactly except, with ``last_step="short"``, the last
    one (``t1 - t_{n-1}``); see the module docstring.
    """
    t0, t1, h = check_number("t0", t0), check_number("t1", t1), check_number("h", h)
    for name, value in (("t0", t0), ("t1", t1), ("h", h)):
        if not math.isfinite(value):
            raise StateError(f"{name} is not finite: {value!r}")
    if not h > 0.0:
        raise StateError(f"step h must be positive, got {h!r}")
    if t1 < t0:
        raise StateError(f"t1 = {t1!r} is before t0 = {t0!r}")
    check_option("last_step", last_step, ("error", "short"))
    ratio = (t1 - t0) / h
    if ratio > MAX_STEPS:
        raise StateError(f"(t1 - t0) / h = {ratio:.3g} steps exceeds the limit of "
                         f"{MAX_STEPS:.0e}")
    n = round(ratio)
    if abs(ratio - n) <= STEP_COUNT_RTOL * max(n, 1):
        t = t0 + h * np.arange(n + 1, dtype=np.float64)
        t[-1] = t1
        return t, np.full(n, h)
    elif last_step == "error":
        raise StateError(f"(t1 - t0) / h = {ratio!r} is not an integer; choose h to divide "
                         "the interval or pass last_step='short'")
    else:
        n = math.floor(ratio)
        t = np.append(t0 + h * np.arange(n + 1, dtype=np.float64), t1)
        steps = np.full(n + 1, h)
        steps[-1] = t1 - t[-2]
        return t, steps


def solve_fixed_step(f, y0, t0: float, t1: float, h: float, method="rk4", *,
                     last_step: str = "error") -> FixedStepResult:
    """Integrate ``y' = f(t, y)`` from ``t0`` to ``t1`` with constant step ``h``.

    Parameters
    ----------
    f : callable
        ``f(t, y) -> dy/dt`` for ``y`` of shape (d,).
    y0 : array_like
        (d,) initial state; a scalar is taken as d = 1.
    t0, t1 : float
    h : float
        The step, > 0.
    method : str or ExplicitRungeKutta
        A key of :data:`refsim.SOLVERS` (or of ``SEED_LITERAL_VARIANTS``).
    last_step : {"error", "short"}
        What to do when ``h`` does not divide ``t1 - t0`` (module docstring).

    Raises
    ------
    ArgumentTypeError
        ``f`` not callable, ``y0`` not numbers, ``t0``/``t1``/``h`` not real
        numbers.
    StateError
        Non-finite ``y0``, ``t0``, ``t1`` or ``h``; ``h <= 0``; ``t1 < t0``;
        ``f`` returning the wrong shape; an unknown method.
    DivergenceError
        The state became non-finite; ``partial`` holds the result so far.
    """
    solver = resolve_method(method)
    check_callable("f", f)
    y0 = np.atleast_1d(as_numbers("y0", y0))
    if y0.ndim != 1:
        raise StateError(f"y0 must be a vector, got shape {y0.shape}")
    if not np.isfinite(y0).all():
        raise StateError("y0 has a non-finite value")
    t, hs = step_grid(t0, t1, h, last_step)
    steps = len(hs)
    size = (steps + 1) * y0.size * 8
    if size > MAX_RESULT_BYTES:
        raise StateError(f"the trajectory of {steps + 1} states of size {y0.size} would take "
                         f"{size / 2**30:.3g} GiB (at most {MAX_RESULT_BYTES / 2**30:g} GiB); "
                         "integrate a shorter interval or a larger step")

    nfev = 0

    def counted_f(t_, y_):
        nonlocal nfev
        nfev += 1
        dy = np.asarray(f(t_, y_), dtype=np.float64)
        if dy.shape != y0.shape:
            raise StateError(f"f returned shape {dy.shape}, expected {y0.shape}")
        return dy

    y = np.empty((steps + 1, y0.size), dtype=np.float64)
    y[0] = y0
    for i in range(steps):
        y[i + 1] = rk_step(solver, counted_f, t[i], y[i], hs[i])
        if not np.isfinite(y[i + 1]).all():
            partial = FixedStepResult(t[:i + 1], y[:i + 1], nfev, i, solver.name)
            raise DivergenceError("state is not finite", step=i + 1, time=float(t[i + 1]),
                                  partial=partial)
    return FixedStepResult(t, y, nfev, steps, solver.name)


def integrate(f, y0, t0: float, t1: float, h: float, method="rk4", *,
              last_step: str = "error") -> tuple[np.ndarray, np.ndarray]:
    """Integrate ``y' = f(t, y)`` from ``t0`` to ``t1`` with a fixed step ``h``
    by one of the seed's solvers (S6; docs/design.md, Public API).

    Parameters
    ----------
    f : callable
        ``f(t, y) -> dy/dt`` for ``y`` of shape (d,).
    y0 : array_like
        (d,) initial state; a scalar is taken as d = 1.
    t0, t1 : float
        The interval, ``t1 >= t0``.
    h : float
        The step, > 0; ``(t1 - t0) / h`` must be a whole number of steps
        unless ``last_step="short"``, and at most ``refsim.limits.MAX_STEPS``.
    method : str or ExplicitRungeKutta
        A key of :data:`refsim.SOLVERS` (default "rk4").
    last_step : {"error", "short"}
        What to do when ``h`` does not divide the interval (module docstring).

    Returns
    -------
    t : numpy.ndarray
        (steps + 1,) times, ``t[0] = t0``, ``t[-1] = t1``.
    y : numpy.ndarray
        (steps + 1, d) states, ``y[0] = y0``.

    Raises
    ------
    ArgumentTypeError
        ``f`` not callable, ``y0`` not numbers, ``t0``/``t1``/``h`` not real
        numbers.
    StateError
        A non-finite input, ``h <= 0``, ``t1 < t0``, too many steps or too
        large a result (``refsim.limits``), ``f`` returning the wrong shape.
    OptionError
        An unknown method.
    DivergenceError
        The state became non-finite; ``partial`` holds the result so far.

    :func:`solve_fixed_step` returns the evaluation count as well.
    """
    result = solve_fixed_step(f, y0, t0, t1, h, method, last_step=last_step)
    return result.t, result.y
