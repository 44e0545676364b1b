"""Measurements of the particle system (S10): claims C5, C6, C7, C8, C9.

What: plain numbers and frozen dataclasses for the report and the tests.

- :func:`measure_resting_jitter`: a particle resting on the floor under
  gravity with restitution and no drag; how far it hops (C6, C7).
- :func:`measure_drag_models`: quadratic against linear drag, trajectory
  difference and cost per step (C5).
- :func:`measure_particle_work_precision`: error against wall time and
  evaluations for the five solvers in a particle system, with or without
  walls, and scipy's RK45 / DOP853 on the same system (C8, C9).
- :func:`wall_reference`: the event-located reference with walls (DOP853
  stopped exactly at each wall contact).
- :func:`measure_throughput`: particle-steps per second against the
  streaming rate of the same memory (:func:`streaming_step`).
- :func:`measure_streaming_bound`: a step's time against its own
  streaming bound, the time to copy the state it reads and writes.
- :func:`measure_step_memory`: tracemalloc peak of a run of steps.

Seed section: S10 with S5, S6, S7.

Reference: HNW I, section II.10 (work-precision diagrams); for the bounce
energy balance see :func:`euler_jitter_estimate`; for the streaming
baseline, J. D. McCalpin, "Memory bandwidth and machine balance", IEEE TCCA
newsletter 1995 (the STREAM "daxpy"-like kernels).

Cost: see each function; the defaults keep every one under a few seconds.
"""

from __future__ import annotations

import math
import time
import tracemalloc
from dataclasses import dataclass, field, replace

import numpy as np

from refsim.particles.config import ParticleConfig
from refsim.particles.system import ParticleSystem, particle_rhs
from refsim.solvers.methods import SOLVERS
from refsim.studies import TIMED
from refsim.studies.solvers import WorkPoint, fit_order

# --------------------------------------------------------------------------
# Resting contact jitter (C6, C7)
# --------------------------------------------------------------------------

#: The wall law of every particle system these studies build: the seed's own
#: (its literal normal speed, refsim.dynamics.walls), since C6, C8 and C9 are
#: claims about the seed's particle system, not about refsim's corrected
#: wall speed (the scene default, "wall").
SEED_WALLS = "seed"


@dataclass(frozen=True)
class Jitter:
    """A particle placed at rest on the floor, after ``duration`` seconds.

    Attributes
    ----------
    method : str
    h, restitution, drag : float
    max_height : float
        Largest height above the floor (m) over the last ``window`` seconds:
        how far the particle visibly hops.
    max_height_gh2 : float
        ``max_height / (g h^2)``: the hop in the natural unit of one step's
        fall, independent of ``h`` when the jitter is a discretization effect.
    rms_velocity : float
        Root mean square of the vertical velocity (m/s) over the window.
    bounces_per_second : float
        Wall responses per second over the window.
    """

    method: str
    h: float
    restitution: float
    drag: float
    max_height: float
    max_height_gh2: float
    rms_velocity: float
    bounces_per_second: float


def measure_resting_jitter(method: str, h: float, restitution: float = 0.8,
                           gravity: float = 9.81, drag: float = 0.0, duration: float = 5.0,
                           window: float = 1.0) -> Jitter:
    """Place one particle on the floor at rest, step for ``duration``, and
    measure the last ``window`` seconds. Exact rest would give zeros."""
    half_size = 5.0
    config = ParticleConfig(count=1, solver=method, step=h, restitution=restitution,
                            gravity=gravity, drag=drag, half_size=half_size,
                            wall_speed=SEED_WALLS)
    system = ParticleSystem(config, positions=[[0.0, -half_size, 0.0]],
                            velocities=[[0.0, 0.0, 0.0]])
    steps = round(duration / h)
    last = round(window / h)
    heights = np.empty(last)
    speeds = np.empty(last)
    bounces_before = 0
    for n in range(steps):
        if n == steps - last:
            bounces_before = system.bounces
        system.step()
        if n >= steps - last:
            heights[n - (steps - last)] = system.positions[0, 1] + half_size
            speeds[n - (steps - last)] = system.velocities[0, 1]
    max_height = float(heights.max())
    return Jitter(method, h, restitution, drag, max_height, max_height / (gravity * h * h),
                  float(np.sqrt(np.mean(speeds**2))),
                  (system.bounces - bounces_before) / (last * h))


def euler_jitter_estimate(h: float, restitution: float, gravity: float = 9.81) -> float:
    """Estimated hop height of forward Euler resting on the floor, ``2 g h^2 / (1 - e^2)^2``.

    Energy balance: a forward Euler step of free fall changes
    ``E = v^2/2 + g y`` by exactly ``+g^2 h^2 / 2``; a bounce at speed
    ``v_b`` removes ``(1 - e^2) v_b^2 / 2``. In a steady hop of ``N`` steps
    with ``v_b = g N h / 2`` the two balance when ``N = 4 / (1 - e^2)``, and
    the hop height is ``v_b^2 / (2 g) = g h^2 N^2 / 8``. An estimate (it
    ignores the push-back's potential energy), within 25% of the measured
    height for ``e >= 0.8``; it says the hop grows without bound as
    ``e -> 1``. Methods of order >= 2 are exact for constant gravity, so
    they neither gain nor lose energy in flight.
    """
    return 2.0 * gravity * h * h / (1.0 - restitution**2) ** 2


def exact_integrator_hop(h: float, restitution: float, gravity: float = 9.81) -> float:
    """Hop height on the floor of any method exact for constant gravity
    (order >= 2: averaged-euler, midpoint, rk4): ``(3e - 1) / (2 (1 + e)) g h^2``.

    Derivation: leaving the floor at speed ``u``, one step rises to
    ``u h - g h^2 / 2`` and a second ends at ``2 u h - 2 g h^2 < 0`` (when
    ``u < g h``), where the wall response sends it up at ``e (2 g h - u)``.
    The steady two-step cycle has ``u = 2 e g h / (1 + e)``, and the hop is
    its first step's height. Valid for ``1/3 <= e < 1`` (the first step must
    stay above the floor); ``7/18 g h^2`` at ``e = 0.8``.

    Backwards-euler instead sinks at every step (its position moves with the
    end-of-step velocity ``u - g h < 0``), is pushed back onto the floor and
    keeps the upward velocity ``e g h / (1 + e)`` without ever rising: its hop
    is 0.
    """
    e = restitution
    return (3.0 * e - 1.0) / (2.0 * (1.0 + e)) * gravity * h * h


def measure_jitter_table(steps=(1 / 30, 1 / 100, 1 / 1000), methods=tuple(SOLVERS),
                         restitution: float = 0.8, drag: float = 0.0) -> list[Jitter]:
    """:func:`measure_resting_jitter` for every (method, h)."""
    return [measure_resting_jitter(m, h, restitution=restitution, drag=drag)
            for m in methods for h in steps]


# --------------------------------------------------------------------------
# Linear against quadratic drag (C5)
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class DragComparison:
    """Quadratic against linear drag for a projectile and a particle system.

    Attributes
    ----------
    terminal_speed : float
        The common terminal speed ``v_T`` (m/s) of the matched coefficients.
    k_linear, k_quadratic : float
        ``k_linear = m g / v_T``, ``k_quadratic = m g / v_T^2``.
    same_terminal_difference : float
        Largest distance (m) between the two trajectories over ``duration``
        with matched terminal speed.
    same_terminal_distance : float
        Path length (m) of the linear-drag trajectory over ``duration``, for
        scale.
    same_k_difference : float
        Largest distance (m) with the same ``k`` in both laws (``k_linear``).
    cost_ratio : float
        Wall time per particle-system step, quadratic over linear (Euler,
        ``count`` particles, best of ``repeats``).
    cost_ratios : tuple of float
        The same ratio for each repeat (the ``k``-th quadratic step over the
        ``k``-th linear one): its run-to-run spread.
    """

    terminal_speed: float
    k_linear: float
    k_quadratic: float
    same_terminal_difference: float
    same_terminal_distance: float
    same_k_difference: float
    cost_ratio: float = field(metadata=TIMED)
    cost_ratios: tuple[float, ...] = field(default=(), metadata=TIMED)


def _trajectory(config: ParticleConfig, x0, v0, t_eval, oracle):
    y0 = np.concatenate([x0, v0])
    ref = oracle.solution(particle_rhs(config, count=1), y0, 0.0, float(t_eval[-1]),
                          t_eval=t_eval)
    return ref.y[:, :3]


def measure_drag_models(oracle, terminal_speed: float = 10.0, launch_speed: float = 15.0,
                        duration: float = 2.0, gravity: float = 9.81, count: int = 100_000,
                        repeats: int = 5) -> DragComparison:
    """Trajectory difference and cost of quadratic against linear drag.

    A projectile launched at 45 degrees at ``launch_speed``; trajectories by
    the DOP853 reference (so the difference is the force law's, not a
    solver's). Cost by timing ``count``-particle Euler steps.
    """
    mass = 1.0
    k_linear = mass * gravity / terminal_speed
    k_quadratic = mass * gravity / terminal_speed**2
    x0 = np.zeros(3)
    v0 = launch_speed * np.array([math.sqrt(0.5), math.sqrt(0.5), 0.0])
    t_eval = np.linspace(0.0, duration, 401)
    base = ParticleConfig(count=1, gravity=gravity, mass=mass, walls=False)
    linear = _trajectory(replace(base, drag=k_linear, drag_model="linear"), x0, v0, t_eval,
                         oracle)
    quad = _trajectory(replace(base, drag=k_quadratic, drag_model="quadratic"), x0, v0, t_eval,
                       oracle)
    quad_same_k = _trajectory(replace(base, drag=k_linear, drag_model="quadratic"), x0, v0,
                              t_eval, oracle)
    distance = float(np.linalg.norm(np.diff(linear, axis=0), axis=1).sum())

    times: dict[str, list[float]] = {}
    for model, k in (("linear", k_linear), ("quadratic", k_quadratic)):
        system = ParticleSystem(ParticleConfig(count=count, drag=k, drag_model=model,
                                               solver="euler", walls=False, step=1e-3))
        times[model] = []
        for _ in range(repeats):
            start = time.perf_counter()
            system.step()
            times[model].append(time.perf_counter() - start)
    return DragComparison(
        terminal_speed, k_linear, k_quadratic,
        float(np.linalg.norm(quad - linear, axis=1).max()), distance,
        float(np.linalg.norm(quad_same_k - linear, axis=1).max()),
        min(times["quadratic"]) / min(times["linear"]),
        tuple(q / lin for q, lin in zip(times["quadratic"], times["linear"], strict=True)))


# --------------------------------------------------------------------------
# Reference with walls: event location
# --------------------------------------------------------------------------

#: Most wall contacts followed per particle in :func:`wall_reference`; a
#: particle settling on the floor would make infinitely many (Zeno).
MAX_CONTACTS = 200


@dataclass(frozen=True)
class _WallEvent:
    """The wall at ``sign * x[axis] = L`` as a scipy event: a callable with
    ``terminal`` and ``direction`` (``solve_ivp``'s protocol), > 0 beyond the
    wall, stopping the integration when crossed outward."""

    axis: int
    sign: float
    L: float
    terminal: bool = True
    direction: float = 1.0

    def __call__(self, t: float, y: np.ndarray) -> float:
        return self.sign * y[self.axis] - self.L


def wall_reference(config: ParticleConfig, x0: np.ndarray, v0: np.ndarray,
                   t1: float, oracle) -> np.ndarray:
    """Positions and velocities at ``t1`` with each wall contact located exactly.

    Each particle is integrated by the reference solver ``oracle``
    (:class:`refsim.engines.ReferenceSolver`: scipy's DOP853) until an event function
    ``x_a -+ half_size`` crosses zero outward; there the seed's response is
    applied (normal component times ``-e``, lateral times ``1 - friction``)
    and integration restarts. Returns (2, N, 3).

    Raises
    ------
    RuntimeError
        A particle needs more than MAX_CONTACTS contacts (choose a shorter
        ``t1``: it is coming to rest on a wall).
    """
    f = particle_rhs(config, count=1)
    L = config.half_size
    events = [_WallEvent(axis, sign, L) for axis in range(3) for sign in (-1.0, 1.0)]
    out = np.empty((2, len(x0), 3))
    for i in range(len(x0)):
        t, y = 0.0, np.concatenate([x0[i], v0[i]])
        for _ in range(MAX_CONTACTS):
            sol = oracle.solve_with_events(f, y, t, t1, events)
            y = sol.y[:, -1].copy()
            t = float(sol.t[-1])
            if sol.status != 1:
                break
            hit = next(k for k, te in enumerate(sol.t_events) if len(te))
            axis, sign = events[hit].axis, events[hit].sign
            y = sol.y_events[hit][0].copy()
            y[axis] = sign * L
            y[3 + axis] *= -config.restitution
            for lateral in range(3):
                if lateral != axis:
                    y[3 + lateral] *= 1.0 - config.friction
        else:
            raise RuntimeError(f"particle {i}: more than {MAX_CONTACTS} wall contacts")
        out[0, i], out[1, i] = y[:3], y[3:]
    return out


# --------------------------------------------------------------------------
# Work-precision in a particle system (C8, C9)
# --------------------------------------------------------------------------

def particle_test_config(count: int = 200, walls: bool = False, seed: int = 3) -> ParticleConfig:
    """The particle system of the work-precision and wall-order studies:
    quadratic drag k = 0.1 (terminal speed ~10 m/s), gravity, speeds 1-5 m/s,
    a cube of half size 2 with e = 0.8 and friction 0.1 when ``walls``."""
    return ParticleConfig(count=count, seed=seed, drag=0.1, drag_model="quadratic",
                          half_size=2.0, box_lo=(-1.5, -1.5, -1.5), box_hi=(1.5, 1.5, 1.5),
                          speed_min=1.0, speed_max=5.0, restitution=0.8, friction=0.1,
                          walls=walls, wall_speed=SEED_WALLS)


def particle_reference(config: ParticleConfig, t1: float, oracle) -> np.ndarray:
    """(2, N, 3) state at ``t1`` from ``config.initial_state()``: the
    reference solver ``oracle`` on the whole system without walls,
    :func:`wall_reference` with."""
    x0, v0 = config.initial_state()
    if config.walls:
        return wall_reference(config, x0, v0, t1, oracle)
    y = oracle.solution(particle_rhs(config), np.stack([x0, v0]).reshape(-1), 0.0, t1).y[-1]
    return y.reshape(2, config.count, 3)


def _state_error(Y: np.ndarray, Y_ref: np.ndarray) -> float:
    """Largest position error (m) over all particles: what a viewer sees."""
    return float(np.abs(Y[0] - Y_ref[0]).max())


#: Step counts over 1 s of the particle work-precision study.
PARTICLE_STEPS = (8, 16, 32, 64, 128, 256, 512, 1024)


def measure_particle_work_precision(config: ParticleConfig | None = None, t1: float = 1.0,
                                    methods=tuple(SOLVERS), steps=PARTICLE_STEPS,
                                    scipy_tolerances=(1e-3, 1e-5, 1e-7, 1e-9),
                                    repeats: int = 1, *, oracle) -> list[WorkPoint]:
    """Position error at ``t1`` (m, max over particles) against wall time and
    ``nfev`` (force evaluations of the whole system) for each solver at
    ``steps`` steps (the particle system's fast path), and for scipy RK45 /
    DOP853 on the same system (only without walls: scipy would step through
    the walls). Default system: :func:`particle_test_config`."""
    config = particle_test_config() if config is None else config
    Y_ref = particle_reference(config, t1, oracle)
    x0, v0 = config.initial_state()
    out = []
    for method in methods:
        for n in steps:
            run_config = replace(config, solver=method, step=t1 / n)
            best = math.inf
            for _ in range(repeats):
                system = ParticleSystem(run_config, positions=x0, velocities=v0)
                start = time.perf_counter()
                system.run(n)
                best = min(best, time.perf_counter() - start)
            out.append(WorkPoint(method, t1 / n, _state_error(system.state, Y_ref),
                                 system.nfev, best))
    if not config.walls:
        y0 = np.stack([x0, v0]).reshape(-1)
        for scipy_method in ("RK45", "DOP853"):
            for tol in scipy_tolerances:
                runs = [oracle.adaptive_run(particle_rhs(config), y0, 0.0, t1, scipy_method,
                                            tol)
                        for _ in range(repeats)]
                Y = runs[0].y1.reshape(2, config.count, 3)
                out.append(WorkPoint(f"scipy-{scipy_method}", tol, _state_error(Y, Y_ref),
                                     runs[0].nfev, min(r.wall_time for r in runs)))
    return out


def observed_orders(points: list[WorkPoint], floor: float = 1e-10,
                    ceiling: float = 1e-1) -> dict[str, float]:
    """Observed order per fixed-step method from work-precision points (the
    slope of ``log error`` on ``log h``; see refsim.studies.solvers.fit_order).
    ``floor``/``ceiling`` in the points' error unit (m)."""
    out = {}
    for method in dict.fromkeys(p.method for p in points):
        if method.startswith("scipy-"):
            continue
        pts = [p for p in points if p.method == method]
        out[method], _ = fit_order([p.parameter for p in pts], [p.error for p in pts],
                                   floor=floor, ceiling=ceiling)
    return out


@dataclass(frozen=True)
class FrameStepDifference:
    """How different the solvers look at an interactive frame step.

    Attributes
    ----------
    h : float
    difference : dict
        Method -> largest position difference (m) from rk4 after ``t1``.
    error : dict
        Method -> largest position error (m) against the reference.
    half_size : float
        The cube's half size, for scale.
    """

    h: float
    difference: dict
    error: dict
    half_size: float


def measure_frame_step_difference(config: ParticleConfig | None = None, h: float = 1 / 60,
                                  t1: float = 1.0, *, oracle) -> FrameStepDifference:
    """C8's "no noticeable difference": each solver against rk4 at step ``h``
    (and against the reference of the solver ``oracle``)."""
    config = particle_test_config() if config is None else config
    n = round(t1 / h)
    Y_ref = particle_reference(config, n * h, oracle)
    states = {}
    for method in SOLVERS:
        system = ParticleSystem(replace(config, solver=method, step=h))
        system.run(n)
        states[method] = system.state.copy()
    return FrameStepDifference(
        h, {m: _state_error(Y, states["rk4"]) for m, Y in states.items()},
        {m: _state_error(Y, Y_ref) for m, Y in states.items()}, config.half_size)


# --------------------------------------------------------------------------
# Throughput and memory
# --------------------------------------------------------------------------

def streaming_step(x: np.ndarray, v: np.ndarray, scratch: np.ndarray, h: float) -> None:
    """The streaming baseline: ``x += h v`` in place over (N, 3) arrays,
    as ``np.multiply(v, h, out=scratch); np.add(x, scratch, out=x)``.

    It moves 5 x 24 N bytes (read ``v``; write ``scratch``; read ``x`` and
    ``scratch``; write ``x``): the least memory traffic of any step that
    touches the state with numpy's in-place operations, so its rate is the
    ceiling a particle step can be compared with.
    """
    np.multiply(v, h, out=scratch)
    np.add(x, scratch, out=x)


#: Bytes moved by one :func:`streaming_step` per particle (see there).
STREAMING_BYTES_PER_PARTICLE = 5 * 24


@dataclass(frozen=True)
class Throughput:
    """Speed of particle steps against the streaming baseline.

    Attributes
    ----------
    count : int
    solver : str
    particle_steps_per_s : float
        ``count / (best seconds per step)``.
    streaming_particle_steps_per_s : float
        ``count / (best seconds per streaming_step)`` on the same arrays.
    streaming_bytes_per_s : float
        The baseline's memory rate, STREAMING_BYTES_PER_PARTICLE per particle.
    ratio : float
        ``streaming / particle`` steps per second: how many baseline passes
        one step costs.
    """

    count: int
    solver: str
    particle_steps_per_s: float = field(metadata=TIMED)
    streaming_particle_steps_per_s: float = field(metadata=TIMED)
    streaming_bytes_per_s: float = field(metadata=TIMED)
    ratio: float = field(metadata=TIMED)


def measure_throughput(count: int, solver: str, repeats: int = 10,
                       drag_model: str = "linear") -> Throughput:
    """Best-of-``repeats`` time of one step and of one streaming pass."""
    config = ParticleConfig(count=count, solver=solver, drag=0.1, drag_model=drag_model,
                            step=1e-3, wall_speed=SEED_WALLS)
    system = ParticleSystem(config)
    scratch = np.empty_like(system.positions)
    best_step = best_stream = math.inf
    for _ in range(repeats):
        start = time.perf_counter()
        system.step()
        best_step = min(best_step, time.perf_counter() - start)
        start = time.perf_counter()
        streaming_step(system.positions, system.velocities, scratch, 1e-9)
        best_stream = min(best_stream, time.perf_counter() - start)
    rate = count / best_step
    stream = count / best_stream
    return Throughput(count, solver, rate, stream, stream * STREAMING_BYTES_PER_PARTICLE,
                      stream / rate)


#: Bytes a particle step must move per particle: the state read once and
#: written once, position and velocity, 6 float64 each way.
STEP_BYTES_PER_PARTICLE = 2 * 48


@dataclass(frozen=True)
class StreamingBound:
    """A particle step against its own streaming bound, medians of one run.

    The bound is the time to move the bytes a step must read and write
    (:data:`STEP_BYTES_PER_PARTICLE`: the state in and out once) at the
    machine's copy rate, measured in the same run as the step: the median
    time of ``np.copyto`` of a state-sized array, which moves those bytes.
    Each round times one call of the step and one copy, one after the other,
    so that a machine busy with other work slows both alike.

    Attributes
    ----------
    count : int
    solver, kernel : str
    steps_per_call : int
        Steps per timed call (1: ``step()``; more: ``run(steps_per_call)``).
    step_s : float
        Median seconds per step.
    copy_s : float
        Median seconds of one copy of the state: the bound.
    copy_bytes_per_s : float
        The copy rate, bytes read plus written per second.
    fraction : float
        ``copy_s / step_s``: the step's speed as a fraction of its bound
        (above 1 when several steps share one pass over memory).
    """

    count: int
    solver: str
    kernel: str
    steps_per_call: int
    step_s: float = field(metadata=TIMED)
    copy_s: float = field(metadata=TIMED)
    copy_bytes_per_s: float = field(metadata=TIMED)
    fraction: float = field(metadata=TIMED)


def measure_streaming_bound(count: int, solver: str, kernel: str | None = None,
                            rounds: int = 21, steps_per_call: int = 1,
                            drag_model: str = "linear") -> StreamingBound:
    """Median time of a step of ``count`` particles and of a copy of their
    state, over ``rounds`` interleaved rounds (:class:`StreamingBound`).

    The system is the throughput benchmark's (drag 0.1, h = 1e-3, the default
    cube: no particle reaches a wall in these steps, as in most steps of a
    large system). One step is taken before timing, so a compiled kernel's
    load is not timed.
    """
    config = ParticleConfig(count=count, solver=solver, drag=0.1, drag_model=drag_model,
                            step=1e-3)
    system = ParticleSystem(config, kernel=kernel)
    system.step()
    copy = np.empty_like(system.state)
    np.copyto(copy, system.state)
    steps, copies = [], []
    for _ in range(rounds):
        start = time.perf_counter()
        if steps_per_call == 1:
            system.step()
        else:
            system.run(steps_per_call)      # with its check that the state is finite
        steps.append((time.perf_counter() - start) / steps_per_call)
        start = time.perf_counter()
        np.copyto(copy, system.state)
        copies.append(time.perf_counter() - start)
    step_s, copy_s = float(np.median(steps)), float(np.median(copies))
    return StreamingBound(count, solver, system.kernel, steps_per_call, step_s, copy_s,
                          STEP_BYTES_PER_PARTICLE * count / copy_s, copy_s / step_s)


@dataclass(frozen=True)
class StepMemory:
    """tracemalloc measurements of building a system and running it.

    Attributes
    ----------
    count, steps : int
    solver : str
    state_bytes : int
        The (2, N, 3) state: 48 N bytes.
    buffer_bytes : int
        The step buffers (:meth:`ParticleSystem.buffer_bytes`).
    peak_bytes : int
        Peak traced memory from before the system was built to the end of
        the run (state, buffers, and anything a step allocates).
    transient_bytes : int
        Peak during the steps minus the memory held before them: what the
        steps themselves allocate at worst.
    retained_bytes : int
        Memory held after the steps minus before them (a leak would grow it).
    state_sized_arrays : float
        ``peak_bytes / state_bytes``.
    bytes_per_particle : float
        ``peak_bytes / count``.
    """

    count: int
    steps: int
    solver: str
    state_bytes: int
    buffer_bytes: int
    peak_bytes: int
    transient_bytes: int
    retained_bytes: int
    state_sized_arrays: float
    bytes_per_particle: float


def measure_step_memory(config: ParticleConfig, steps: int) -> StepMemory:
    """Trace the allocations of ``ParticleSystem(config)`` and ``steps``
    steps. The initial positions and velocities are made before tracing
    starts (they are the caller's, not the step's), and a small system of
    the same configuration is run once first, so that loading a compiled
    kernel (numba's one-time cost per process) is not counted as the step's."""
    ParticleSystem(replace(config, count=8)).run(1)
    x0, v0 = config.initial_state()
    started = not tracemalloc.is_tracing()
    if started:
        tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        base, _ = tracemalloc.get_traced_memory()
        system = ParticleSystem(config, positions=x0, velocities=v0)
        built, _ = tracemalloc.get_traced_memory()
        _, peak_build = tracemalloc.get_traced_memory()
        tracemalloc.reset_peak()
        system.run(steps)
        after, peak_run = tracemalloc.get_traced_memory()
    finally:
        if started:
            tracemalloc.stop()
    peak = max(peak_build, peak_run) - base
    state_bytes = system.state.nbytes
    return StepMemory(config.count, steps, config.solver, state_bytes, system.buffer_bytes(),
                      peak, peak_run - built, after - built, peak / state_bytes,
                      peak / config.count)


# --------------------------------------------------------------------------
# Which solver in general (C9)
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class SolverChoice:
    """The facts C9 ("backwards Euler is the best general choice") rests on,
    for one method.

    Attributes
    ----------
    method : str
    order : int
        Derived from the tableau.
    stages : int
        Force evaluations per step: the cost of a step.
    drag_limit : float
        Largest stable ``h k / m`` for linear drag.
    oscillator_limit : float
        Largest non-growing ``h omega`` for an undamped oscillation.
    nfev_free : float
        Force evaluations to reach ``target_free`` (m) in the particle system
        without walls (interpolated; ``inf`` if never reached).
    error_walls_at_budget : float
        Position error (m) with walls at ``budget_walls`` force evaluations
        (interpolated).
    hop_height_gh2 : float
        Resting-contact hop (C6) in units of ``g h^2`` at ``h = 0.01``.
    """

    method: str
    order: int
    stages: int
    drag_limit: float
    oscillator_limit: float
    nfev_free: float
    error_walls_at_budget: float
    hop_height_gh2: float


def measure_solver_choice(target_free: float = 1e-4, budget_walls: float = 512,
                          count: int = 50, *, oracle) -> list[SolverChoice]:
    """One :class:`SolverChoice` per solver, from the particle work-precision
    runs (``count`` particles, 1 s, with and without walls), the stability
    polynomials and the resting-contact jitter."""
    from refsim.solvers.stability import imaginary_axis_limit, real_axis_limit
    from refsim.studies.solvers import cost_for_error, error_at_cost

    free = measure_particle_work_precision(particle_test_config(count=count), methods=SOLVERS,
                                           steps=tuple(8 * 2**k for k in range(12)),
                                           scipy_tolerances=(), oracle=oracle)
    walls = measure_particle_work_precision(particle_test_config(count=count, walls=True),
                                            methods=SOLVERS, steps=(64, 128, 256, 512, 1024),
                                            oracle=oracle)
    out = []
    for name, method in SOLVERS.items():
        out.append(SolverChoice(
            name, method.order, method.stages, real_axis_limit(method),
            imaginary_axis_limit(method), cost_for_error(free, name, target_free),
            error_at_cost(walls, name, budget_walls),
            measure_resting_jitter(name, 0.01).max_height_gh2))
    return out
