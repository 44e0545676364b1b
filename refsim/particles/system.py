"""A particle system: N point masses stepped by one of the seed's solvers (S10).

What: positions and velocities of N particles as one float64 array ``Y`` of
shape (2, N, 3) (structure of arrays: ``Y[0]`` positions, ``Y[1]``
velocities), advanced by an explicit Runge-Kutta step of
``Y' = (v, a(v))`` (:mod:`refsim.dynamics.forces`), followed by the wall
response (:mod:`refsim.dynamics.walls`), as the seed advances every body.

Seed section: S10, with S5 forces, S6 solvers and S7 walls.

Reference: the Runge-Kutta step of :mod:`refsim.solvers.explicit_rk` (HNW I,
definition II.1.1), done in place; the structure of arrays as in
A. Witkin, D. Baraff, *Physically Based Modeling*, SIGGRAPH 2001 course
notes, "Particle System Dynamics" (state vector of all particles).

Cost per step: ``s`` evaluations of the forces, O(s N) arithmetic, and no
O(N) allocation. Memory: the state plus ``s + 2`` state-sized buffers for a
method with ``s`` stages (``s`` stage derivatives ``K``, one stage state, one
product scratch); Euler needs ``s + 1`` (its only stage is the state itself).
RK4: 6 state-sized arrays in all, 48 bytes each per particle.

The step buffers belong to the readable kernel; they are allocated for both
kernels (``buffer_bytes`` reports them) and the compiled kernel never touches
them, so a large system's are address space without pages behind them.

The fast path here does the same arithmetic in the same order as the plain
path (:func:`plain_step`: :func:`refsim.solvers.explicit_rk.rk_step` on the
flattened state, then :func:`refsim.dynamics.walls.wall_response_points`), so the
two agree to the last bit; the tests check that. The compiled kernel does it
once more, fused into one loop over the particles, and agrees with both
(tests/particles/test_fused_step.py; docs/decisions/particles-fused-step.md
says how it is laid out and what it was measured at).
"""

from __future__ import annotations

import numpy as np

from refsim.dynamics.forces import acceleration, acceleration_into
from refsim.dynamics.walls import wall_response_points, wall_response_points_inplace
from refsim.errors import DivergenceError, OptionError, StateError, as_numbers, check_count
from refsim.kernels import PARTICLE_STEPS, Tier, choose_kernel
from refsim.limits import MAX_STEPS
from refsim.particles.config import ParticleConfig
from refsim.signals import raise_if_interrupted
from refsim.solvers.explicit_rk import rk_step, rk_step_into, stages_with_own_state
from refsim.solvers.integrate import resolve_method

#: Particle-steps per call of the fused loop in :meth:`ParticleSystem.run`:
#: a fraction of a second each, so that a long run is many calls (between
#: which Python sees Ctrl-C) while each call still takes a block of
#: particles through many steps.
FUSED_PARTICLE_STEPS = 50_000_000

#: The fused step as a family of compiled kernels (:class:`refsim.kernels.Tier`):
#: until numba's cache holds it, a system made with the default kernel
#: steps readable for up to ``compile_seconds`` in a process (its compile
#: time as measured in docs/decisions/cold-start.md), then compiles and goes
#: on fused, with the same bits.
FUSED_STEPS = Tier("fused particle steps", ("refsim.particles._numba_kernels:rk_steps_fused",),
                   compile_seconds=2.0)

#: Particle-steps between two looks at the readable budget while a run is
#: readable on a cold cache.
READABLE_PARTICLE_STEPS = 200_000


def particle_rhs(config: ParticleConfig, count: int | None = None):
    """``f(t, y)`` of the particle system for a flat state ``y`` (2 N 3,):
    the plain kernel, for :func:`refsim.integrate` and scipy's ``solve_ivp``."""
    n = config.count if count is None else count

    def f(t, y):
        Y = y.reshape(2, n, 3)
        dY = np.empty_like(Y)
        dY[0] = Y[1]
        dY[1] = acceleration(Y[1], config.gravity, config.drag, config.mass, config.drag_model)
        return dY.reshape(-1)

    return f


def plain_step(config: ParticleConfig, x: np.ndarray, v: np.ndarray, t: float = 0.0):
    """One step by the plain kernels: returns new ``(x, v)``, each (N, 3)."""
    n = x.shape[0]
    y = np.stack([x, v]).reshape(-1)
    y = rk_step(resolve_method(config.solver), particle_rhs(config, n), t, y, config.step)
    x, v = y.reshape(2, n, 3)
    if config.walls:
        x, v, _ = wall_response_points(x, v, config.half_size, config.restitution,
                                       config.friction, config.gravity, config.wall_speed)
    return x, v


class ParticleSystem:
    """N particles and their preallocated step buffers.

    Parameters
    ----------
    config : ParticleConfig
    positions, velocities : array_like, optional
        (N, 3) initial state; default ``config.initial_state()``. Copied.
    kernel : {"readable", "compiled"}, optional
        ``"readable"``: the generic step over the tableau, numpy operation
        by operation (:meth:`step`). ``"compiled"``: the same arithmetic fused
        into one compiled loop over the particles, many steps a call
        (:func:`refsim.particles._numba_kernels.rk_steps_fused`; the tableaux
        :func:`fused_tableau` takes). The two give the same bits. Default
        (:mod:`refsim.kernels`): ``"compiled"`` where numba works and the
        tableau is of the fused loop's shape, else ``"readable"``; while
        numba's cache does not hold the fused loop, the default starts
        readable and turns compiled once the process has spent
        :data:`FUSED_STEPS`' budget.

    Attributes
    ----------
    state : numpy.ndarray
        (2, N, 3) float64; ``positions`` and ``velocities`` are views of it.
    t : float
        Simulated time.
    steps : int
        Steps taken.
    nfev : int
        Force evaluations made (``steps * stages``).
    bounces : int
        (particle, wall) bounces handled.
    """

    def __init__(self, config: ParticleConfig, positions=None, velocities=None, *,
                 kernel: str | None = None):
        self.config = config
        self.method = resolve_method(config.solver)
        self.kernel = _choose_kernel(kernel, self.method)
        #: The tier a default system charges while it steps readable on a
        #: cold cache (:data:`FUSED_STEPS`), else None.
        self._tier: Tier | None = None
        if kernel is None and self.kernel == "compiled" and FUSED_STEPS.readable_first():
            self.kernel, self._tier = "readable", FUSED_STEPS
        self._fused_arguments = _fused_arguments(config, self.method)
        if positions is None and velocities is None:
            positions, velocities = config.initial_state()
        elif positions is None or velocities is None:
            raise StateError("give both positions and velocities, or neither")
        positions = as_numbers("positions", positions)
        velocities = as_numbers("velocities", velocities)
        if positions.ndim != 2 or positions.shape[1] != 3 or velocities.shape != positions.shape:
            raise StateError(f"positions and velocities must both be (N, 3), got "
                             f"{positions.shape} and {velocities.shape}")
        if not (np.isfinite(positions).all() and np.isfinite(velocities).all()):
            raise StateError("initial particle state has a non-finite value")
        n = positions.shape[0]
        self.state = np.empty((2, n, 3), dtype=np.float64)
        self.state[0] = positions
        self.state[1] = velocities
        self.t = 0.0
        self.steps = 0
        self.nfev = 0
        self.bounces = 0

        s = self.method.stages
        # Buffers (see the module docstring for the count). A stage is
        # evaluated at Y + h sum_j a_ij K_j, which is Y itself when row i of A
        # is zero: only then does it need no state of its own.
        self._K = np.empty((s, 2, n, 3), dtype=np.float64)           # stage derivatives k_i
        self._stage = (np.empty((2, n, 3), dtype=np.float64)          # stage state y_i
                       if any(stages_with_own_state(self.method)) else None)
        self._product = np.empty((2, n, 3), dtype=np.float64)         # (h a_ij) k_j scratch
        self._speed = np.empty(n, dtype=np.float64)                    # |v| for quadratic drag
        self._beyond = np.empty(n, dtype=bool)                        # wall-test mask
        # the normal speed at the wall (wall_speed "wall"): an (N,) scratch
        self._wall_scratch = (np.empty(n, dtype=np.float64)
                              if self.config.wall_speed == "wall" else None)

    @property
    def count(self) -> int:
        return self.state.shape[1]

    @property
    def positions(self) -> np.ndarray:
        return self.state[0]

    @property
    def velocities(self) -> np.ndarray:
        return self.state[1]

    def buffer_bytes(self) -> int:
        """Bytes held by the step buffers (not counting the state)."""
        arrays = [self._K, self._product, self._speed, self._beyond]
        for optional in (self._stage, self._wall_scratch):
            if optional is not None:
                arrays.append(optional)
        return sum(a.nbytes for a in arrays)

    def _derivative_into(self, t: float, Y: np.ndarray, out: np.ndarray) -> None:
        """``out = (v, a(v))`` for a (2, N, 3) state ``Y`` (autonomous: ``t`` unused)."""
        c = self.config
        np.copyto(out[0], Y[1])
        acceleration_into(Y[1], c.gravity, c.drag, c.mass, c.drag_model, out[1], self._speed)

    def step(self) -> None:
        """Advance one step of ``config.step``: the solver, then the walls.

        The readable kernel: the Runge-Kutta step in place into the system's
        buffers (:func:`refsim.solvers.explicit_rk.rk_step_into`, the
        arithmetic of :func:`refsim.solvers.explicit_rk.rk_step` term by
        term), then the walls in place. The compiled kernel: the same
        arithmetic fused into one loop over the particles
        (:func:`refsim.particles._numba_kernels.rk_steps_fused`). The two
        are the pair :data:`refsim.kernels.PARTICLE_STEPS`.
        """
        PARTICLE_STEPS.pick(self.kernel)(self, 1)

    def _advance_readable(self, steps: int) -> None:
        """``steps`` readable steps (:meth:`step`); says nothing of the
        state's finiteness (None)."""
        for _ in range(steps):
            self._step_readable()
            raise_if_interrupted()            # a signal a finalizer dropped

    def _step_readable(self) -> None:
        h = self.config.step
        rk_step_into(self.method, self._derivative_into, self.t, self.state, h, self._K,
                     self._stage, self._product)
        Y = self.state
        if self.config.walls:
            c = self.config
            self.bounces += wall_response_points_inplace(
                Y[0], Y[1], c.half_size, c.restitution, c.friction, self._beyond, c.gravity,
                c.wall_speed, self._wall_scratch)
        self.t += h
        self.steps += 1
        self.nfev += self.method.stages

    def _advance_fused(self, steps: int) -> int | None:
        """``steps`` steps by the fused loop in calls of at most
        :data:`FUSED_PARTICLE_STEPS` particle-steps (a fraction of a second
        each), each call one pass over the state. Returns the number of
        non-finite numbers in the state after them, counted by the last
        call (None for no steps)."""
        non_finite = None
        done, per_call = 0, max(1, FUSED_PARTICLE_STEPS // self.count)
        while done < steps:
            block = min(per_call, steps - done)
            non_finite = self._steps_fused(block)
            done += block
            raise_if_interrupted()            # a signal a finalizer dropped
        return non_finite

    def _steps_fused(self, steps: int) -> int:
        """``steps`` steps as one compiled loop (``kernel="compiled"``): each
        block of particles through all of them, in one pass over the state;
        the same bits as :meth:`step` with the readable kernel. Returns the
        number of non-finite numbers in the state after them."""
        from refsim.particles._numba_kernels import advance_time, rk_steps_fused

        if self._fused_arguments is None:     # _choose_kernel refuses "compiled" then
            raise OptionError(f"no fused step for {self.method.name!r}")
        bounces, non_finite = rk_steps_fused(self.state[0], self.state[1], steps,
                                             *self._fused_arguments)
        self.bounces += bounces
        # t as the readable step sums it: h added once per step
        h = self.config.step
        self.t = self.t + h if steps == 1 else advance_time(self.t, h, steps)
        self.steps += steps
        self.nfev += steps * self.method.stages
        return non_finite

    def run(self, steps: int) -> None:
        """Take ``steps`` steps, then check the state is finite.

        With the compiled kernel the steps go to the fused loop in calls of
        at most :data:`FUSED_PARTICLE_STEPS` particle-steps (a fraction of a
        second each), each call one pass over the state.

        Raises
        ------
        DivergenceError
            The state became non-finite (checked once, after the steps, to
            keep the loop at one pass over memory per operation).
        StateError, ArgumentTypeError
            ``steps`` is negative, more than ``refsim.limits.MAX_STEPS`` or not
            an integer.
        """
        steps = check_count("steps", steps, maximum=MAX_STEPS)
        done = self._run_tiered(steps)
        # Overflow on the way to inf is what the check below reports, once;
        # numpy's warnings would print it again, per operation.
        with np.errstate(over="ignore", invalid="ignore"):
            non_finite = PARTICLE_STEPS.pick(self.kernel)(self, steps - done)
        if non_finite is not None:
            # the last fused call counted the final state's non-finite numbers
            finite = non_finite == 0
        else:
            # max and min propagate NaN and see +-inf, without the (2, N, 3)
            # bool temporary of np.isfinite(state).all().
            finite = bool(np.isfinite(self.state.max()) and np.isfinite(self.state.min()))
        if not finite:
            raise DivergenceError("particle state is not finite", step=self.steps,
                                  time=self.t)

    def _steps_readable(self, steps: int) -> None:
        # Overflow on the way to inf is what run's check reports, once;
        # numpy's warnings would print it again, per operation.
        with np.errstate(over="ignore", invalid="ignore"):
            self._advance_readable(steps)

    def _run_tiered(self, steps: int) -> int:
        """The first of ``steps`` steps of a default system on a cold numba
        cache: readable, in blocks, while :data:`FUSED_STEPS` has budget
        left; once it has none, the kernel becomes "compiled" for the rest
        (the same bits: tests/particles/test_fused_step.py). Returns the
        steps taken."""
        done = 0
        per_block = max(1, READABLE_PARTICLE_STEPS // self.count)
        while self._tier is not None and done < steps:
            if not self._tier.readable_first():
                self.kernel, self._tier = "compiled", None
                break
            block = min(per_block, steps - done)
            with self._tier.charged():
                self._steps_readable(block)
            done += block
        return done

    def kinetic_energy(self) -> float:
        return 0.5 * self.config.mass * float(np.einsum("ij,ij->", self.velocities,
                                                        self.velocities))

    def potential_energy(self) -> float:
        """Gravitational, relative to ``y = 0``."""
        return self.config.mass * self.config.gravity * float(self.positions[:, 1].sum())


def fused_tableau(method, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The coefficients the fused step takes for step ``h``, or None when the
    tableau is not of its shape.

    The fused loop (:func:`refsim.particles._numba_kernels.rk_steps_fused`)
    takes tableaux with 1, 2 or 4 stages whose every stage after the first
    is evaluated at ``y + h a_i,i-1 k_i-1`` (``A`` nonzero on its
    subdiagonal and only there): the seed's five solvers and its literal RK4
    reading. Returns ``(hA, hb, b_used)``, each (s,): ``h * A[i, i-1]`` (0
    for the first stage), ``h * b[i]`` and ``b[i] != 0``, each product
    rounded once, as :func:`refsim.solvers.explicit_rk.rk_step_into` rounds it.
    """
    A, b = method.A_, method.b_
    s = method.stages
    subdiagonal = all((A[i, j] != 0.0) == (j == i - 1) for i in range(s) for j in range(i))
    if s not in (1, 2, 4) or not subdiagonal:
        return None
    hA = np.array([h * A[i, i - 1] if i > 0 else 0.0 for i in range(s)])
    hb = np.array([h * b[i] for i in range(s)])
    return hA, hb, b != 0.0


def _fused_arguments(config: ParticleConfig, method) -> tuple | None:
    """The arguments of :func:`refsim.particles._numba_kernels.rk_steps_fused`
    after ``x, v, steps``, made once per system; None when the tableau is not
    of the fused loop's shape (:func:`fused_tableau`)."""
    tableau = fused_tableau(method, config.step)
    if tableau is None:
        return None
    c = config
    return (method.stages, *tableau, c.gravity, c.drag / c.mass, c.drag_model == "quadratic",
            c.walls, c.half_size, c.restitution, 1.0 - c.friction, c.wall_speed == "wall")


def _choose_kernel(kernel: str | None, method) -> str:
    """"readable": the generic step over the tableau (any solver).
    "compiled": the step fused into one compiled loop (the tableaux
    :func:`fused_tableau` takes: the seed's five solvers and its literal
    RK4). Default: "compiled" where numba works and the tableau is of that
    shape, else "readable" (:mod:`refsim.kernels`)."""
    fusable = fused_tableau(method, 1.0) is not None
    if kernel is None and not fusable:
        return "readable"
    kernel = choose_kernel(kernel)
    if kernel == "compiled" and not fusable:
        raise OptionError(f"kernel 'compiled' takes tableaux with 1, 2 or 4 stages and A "
                          f"nonzero on its subdiagonal only, not {method.name!r}")
    return kernel
