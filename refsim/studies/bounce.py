"""Bounce studies: refsim's wall response against the analytic answer and pybullet.

What: a body dropped onto the floor of the world cube (seed S5, S7), run by
each engine a study receives on the same scene and compared with the closed
forms of :mod:`refsim.dynamics.analytic`. refsim is received as an engine
too (:func:`refsim_engines`: the scene as posed, and with the seed's
literal wall speed); the report adds the pybullet oracle
(:mod:`refsim.oracles.pybullet_adapter`). The records are long-form: one
row per case and engine, the engine's name in its ``engine`` field, the
closed form a row of its own (:data:`ANALYTIC`) where it has the engines'
shape; :func:`by_case` groups them back by case.

- :func:`measure_apexes`: apex heights and times of the first bounces, and
  the apex ratio (ideal ``e^2``), for a sphere-like body (``sphere-2k.ac``,
  rotation "off": translation only) and the cube (face down);
- :func:`measure_oblique`: the lateral velocity after one oblique bounce
  (the seed's ``(1 - friction) v_t`` against Coulomb's
  ``v_t - mu (1 + e) |v_n|``);
- :func:`measure_rest`: the time until the bounces die out (Zeno time);
- :func:`measure_drop_energy`: mechanical energy over time;
- :func:`measure_cost`: apex-ratio error against wall time per simulated
  second over step sizes 1/30 .. 1/4000 s, for refsim's solvers and pybullet,
  in the manner of the work-precision comparisons of T. Erez, Y. Tassa and
  E. Todorov, "Simulation tools for model-based robotics: comparison of
  Bullet, Havok, MuJoCo, ODE and PhysX", ICRA 2015;
- :func:`measure_engine_variants`: the oracle's bounce with one pybullet
  setting at a time put back to its default (why each setting);
- :func:`measure_step_cost`: seconds per step of 1, 10 and 40 cubes
  (:func:`cubes_scene`), refsim's ``Simulation.advance`` beside each
  engine's own stepping (pybullet's ``stepSimulation``; the benchmarks in
  tests/benchmarks/test_bench_dynamics.py
  time the same scenes).

How heights are read from a trajectory: the height is the body's lowest
point above the floor, ``y - y_touch`` with ``y_touch = -half_size + d`` and
``d`` the depth of the (rotated, scaled) mesh below its origin, for a body
that does not rotate; the scenes and the reading of bounces and apexes are
:mod:`refsim.studies.bounce_scenes`, which the conformance kit's rigid
cases and the step benchmarks share.

``refsim study dynamics-apex`` (and the other ``dynamics-*`` entries of
:mod:`refsim.report.plan`) prints each figure; ``--quick`` gives the short
version the quick report uses.

Cost: each study is a few simulations of 10^3 - 10^4 steps.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from refsim.dynamics import analytic
from refsim.errors import StateError
from refsim.studies import TIMED
from refsim.studies.bounce_scenes import (
    BENCH_COUNTS,
    BENCH_ROTATIONS,
    BOUNCES,
    CUBE,
    DROP_HEIGHT,
    GRAVITY,
    REST_FRACTION,
    SOLVER,
    SPHERE,
    STEP,
    Bounces,
    apex_ratio,
    cubes_scene,
    drop_scene,
    duration_for,
    energy_above_touch,
    read_bounces,
    settle_time,
    touch_height,
)

#: Restitutions of the apex study.
RESTITUTIONS = (0.5, 0.8, 0.9)
#: Relative apex-ratio errors below this are rounding (a few ulps per step
#: over a few thousand steps): :func:`fit_error_orders` leaves them out.
ROUNDING_ERROR = 1e-9
#: Steps of the speed-vs-accuracy study, seconds.
COST_STEPS = (1 / 30, 1 / 60, 1 / 125, 1 / 250, 1 / 500, 1 / 1000, 1 / 2000, 1 / 4000)
COST_STEPS_QUICK = (1 / 30, 1 / 125, 1 / 500)
COST_SOLVERS = ("euler", "averaged-euler", "backwards-euler", "midpoint", "rk4")
COST_SOLVERS_QUICK = ("euler", "backwards-euler", "rk4")


# -- running an engine ---------------------------------------------------------------


def run_engine(scene, engine):
    """A rigid-body engine's trajectory of ``scene`` (:mod:`refsim.engines`,
    capability ``rigid``) and its stepping time, seconds: the engine's own
    ``stage_seconds["step"]`` when it reports one (pybullet's
    ``stepSimulation`` alone, not the reading of state), else the wall time
    of ``simulate``."""
    start = time.perf_counter()
    trajectory = engine.simulate(scene)
    seconds = time.perf_counter() - start
    return trajectory, getattr(trajectory, "stage_seconds", {}).get("step", seconds)


# -- the studies --------------------------------------------------------------------

#: The names the records carry in their ``engine`` field besides an engine's
#: own: the closed-form answer (a row of its own where it has the engines'
#: shape: apexes, time to rest, energy) and refsim's two engines
#: (:class:`refsim.engines.refsim_engines.PosedRefsim`: the scene as posed,
#: and the same with the seed's literal wall speed).
ANALYTIC = "analytic"
REFSIM = "refsim"
SEED_WALL_SPEED = "refsim-seed-wall-speed"

#: The fields that name one case of each long-form record (the rest is one
#: engine's answer to it): :func:`by_case` groups rows by them.
APEX_CASE = ("body", "rotation", "e", "step", "solver")
OBLIQUE_CASE = ("body", "rotation", "e", "friction", "v_t", "v_n")
REST_CASE = ("body", "e")
STEP_CASE = ("bodies", "rotation", "warmup", "steps", "repeats")


def refsim_engines(seed_wall_speed: bool = True) -> tuple:
    """refsim as the studies receive it when not told otherwise: the scene as
    posed (:data:`REFSIM`) and, with ``seed_wall_speed``, the same with the
    seed's literal wall speed (:data:`SEED_WALL_SPEED`); built from
    :mod:`refsim.engines.registry`."""
    from refsim.engines.registry import build

    return tuple(build(name) for name in
                 ((REFSIM, SEED_WALL_SPEED) if seed_wall_speed else (REFSIM,)))


def by_case(rows, fields) -> dict[tuple, dict]:
    """Long-form ``rows`` grouped by the values of ``fields`` (in the order
    the cases first appear), each group a dict from engine name to row.

    Raises
    ------
    StateError
        One case has two rows of one engine name (two engines named alike,
        or ``fields`` that leave out part of the case)."""
    groups: dict[tuple, dict] = {}
    for row in rows:
        case = tuple(getattr(row, f) for f in fields)
        group = groups.setdefault(case, {})
        if row.engine in group:
            raise StateError(f"two rows of engine {row.engine!r} for one case "
                             f"{dict(zip(fields, case, strict=True))}: each engine of a study "
                             "needs a name of its own")
        group[row.engine] = row
    return groups


def _received(engines, seed_wall_speed: bool):
    return refsim_engines(seed_wall_speed) if engines is None else tuple(engines)


def bounces_of(trajectory, y_touch: float) -> Bounces:
    """:func:`read_bounces` of body 0's height in ``trajectory``."""
    return read_bounces(trajectory.t, trajectory.position[:, 0, 1],
                        trajectory.velocity[:, 0, 1], y_touch)


@dataclass(frozen=True)
class ApexRow:
    """Apexes of one drop as one engine ran it, or as the closed form gives
    them (``engine`` :data:`ANALYTIC`).

    The drop is ``body``, ``rotation``, the restitution ``e``, ``step`` and
    ``solver`` (:data:`APEX_CASE`). ``heights``/``times``: the first
    ``BOUNCES + 1`` apexes, the release included (nan past the last one
    read); ``ratio``: the geometric mean apex ratio; ``first_ratio``:
    h_1 / h_0; ``error``: ``|ratio - e^2| / e^2``; ``max_spin``: the largest
    angular velocity component over the run, rad/s. The analytic row's ratio
    is e^2 itself, its error and spin 0.
    """

    body: str
    rotation: str
    e: float
    step: float
    solver: str
    engine: str
    heights: list[float]
    times: list[float]
    ratio: float
    first_ratio: float
    error: float
    max_spin: float


def _first(values, k) -> list[float]:
    values = [float(v) for v in values[:k]]
    return values + [math.nan] * (k - len(values))


def measure_apex_drop(model: str, e: float, *, rotation: str = "off", step: float = STEP,
                      solver: str = SOLVER, bounces: int = BOUNCES,
                      engines=None) -> list[ApexRow]:
    """The apexes of one drop: the analytic row, then one row per engine of
    ``engines`` (rigid-body engines; default :func:`refsim_engines`)."""
    scene = drop_scene(model, e, step=step, solver=solver, rotation=rotation,
                       duration=duration_for(e, bounces))
    y_touch = touch_height(scene)
    k = bounces + 1
    ideal = analytic.apex_ratio(e)
    drop: dict[str, Any] = {"body": model, "rotation": rotation, "e": e, "step": step,
                            "solver": solver}
    a_times = np.concatenate([[0.0], analytic.apex_times(DROP_HEIGHT, GRAVITY, e, bounces)])
    rows = [ApexRow(**drop, engine=ANALYTIC,
                    heights=_first(analytic.apex_heights(DROP_HEIGHT, e, bounces), k),
                    times=_first(a_times, k), ratio=ideal, first_ratio=ideal, error=0.0,
                    max_spin=0.0)]
    for engine in _received(engines, seed_wall_speed=True):
        trajectory, _ = run_engine(scene, engine)
        b = bounces_of(trajectory, y_touch)
        ratio = apex_ratio(b.apex_heights, bounces)
        rows.append(ApexRow(**drop, engine=engine.name, heights=_first(b.apex_heights, k),
                            times=_first(b.apex_times, k), ratio=ratio,
                            first_ratio=apex_ratio(b.apex_heights, 1),
                            error=abs(ratio - ideal) / ideal,
                            max_spin=float(np.abs(trajectory.angular_velocity).max())))
    return rows


def _variants(models) -> list[tuple[str, str]]:
    """(model, rotation) pairs studied: the sphere-like body translating only
    ("off"); every other body with rotation "off" and the seed's model."""
    return [(m, r) for m in models for r in (("off",) if m == SPHERE else ("off", "seed"))]


def measure_apexes(models=(SPHERE, CUBE), restitutions=RESTITUTIONS, *, step: float = STEP,
                   solver: str = SOLVER, engines=None) -> list[ApexRow]:
    """:func:`measure_apex_drop` for each model and restitution: the
    sphere-like body with rotation "off"; the cube with rotation "off" and
    with the seed's model."""
    engines = _received(engines, seed_wall_speed=True)
    rows = []
    for model, rotation in _variants(models):
        for e in restitutions:
            rows += measure_apex_drop(model, e, rotation=rotation, step=step, solver=solver,
                                      engines=engines)
    return rows


@dataclass(frozen=True)
class ObliqueRow:
    """One engine's lateral velocity after one oblique bounce (v_t along +x,
    v_n into the floor: :data:`OBLIQUE_CASE`), beside what each law gives
    for the same bounce."""

    body: str
    rotation: str
    e: float
    friction: float
    v_t: float
    v_n: float
    seed_analytic: float          # (1 - friction) v_t
    coulomb_point: float          # max(v_t - mu (1 + e) v_n, 0)
    coulomb_ball: float           # point mass unless the ball reaches rolling (5/7 v_t)
    ball_slides: bool             # the ball slides through the impact
    engine: str
    lateral: float                # the centre's x velocity at the end, m/s
    spin: float                   # |w| at the end, rad/s


#: The oblique bounces: (v_t, v_n). With mu = 0.3 and e = 0.8 the first keeps
#: a ball sliding through the impact (mu (1+e) v_n = 1.08 <= 2/7 * 5), the
#: second does not (the ball leaves rolling at 5/7 v_t).
OBLIQUE_CASES = ((5.0, 2.0), (2.0, 2.0))
OBLIQUE_FRICTION = 0.3
OBLIQUE_E = 0.8


def measure_oblique(models=(SPHERE, CUBE), cases=OBLIQUE_CASES, *, friction=OBLIQUE_FRICTION,
                    e=OBLIQUE_E, step: float = STEP, solver: str = SOLVER,
                    engines=None) -> list[ObliqueRow]:
    """Lateral velocity after the first bounce of a body released 5 cm above
    the floor moving at ``(v_t, -v_n, 0)``, read at the apex after it, in
    each of ``engines`` (default: refsim as posed)."""
    engines = _received(engines, seed_wall_speed=False)
    rows = []
    for model, rotation in _variants(models):
        for v_t, v_n in cases:
            # Falls 5 cm (v_n grows a little: use the speed at impact).
            height = 0.05
            v_impact = math.sqrt(v_n * v_n + 2 * GRAVITY * height)
            duration = (v_impact - v_n) / GRAVITY + e * v_impact / GRAVITY + 0.02
            scene = drop_scene(model, e, step=step, solver=solver, rotation=rotation,
                               friction=friction, height=height, duration=duration,
                               velocity=(v_t, -v_n, 0.0))
            case = {"body": model, "rotation": rotation, "e": e, "friction": friction,
                    "v_t": v_t, "v_n": v_impact,
                    "seed_analytic": analytic.lateral_velocity_seed(v_t, friction),
                    "coulomb_point": analytic.lateral_velocity_coulomb(v_t, v_impact,
                                                                       friction, e),
                    "coulomb_ball": analytic.lateral_velocity_coulomb_ball(v_t, v_impact,
                                                                           friction, e),
                    "ball_slides": analytic.sliding_throughout(v_t, v_impact, friction, e)}
            for engine in engines:
                trajectory, _ = run_engine(scene, engine)
                # The centre's velocity (the mesh origin's includes w x r).
                rows.append(ObliqueRow(
                    **case, engine=engine.name,
                    lateral=float(trajectory.velocity[-1, 0, 0]),
                    spin=float(np.linalg.norm(trajectory.angular_velocity[-1, 0]))))
    return rows


@dataclass(frozen=True)
class RestRow:
    """When one engine's bounces die out, or the analytic series' (``engine``
    :data:`ANALYTIC`): ``settle``, the time of the bounce after which every
    apex stays below ``REST_FRACTION h0``, and ``bounces``, that bounce's
    number (nan and 0 when the run never settles); ``zeno``, the analytic
    Zeno time of the drop."""

    body: str
    e: float
    zeno: float
    engine: str
    settle: float
    bounces: int


def measure_rest(model: str = SPHERE, restitutions=(0.5, 0.8), *, step: float = STEP,
                 solver: str = SOLVER, engines=None) -> list[RestRow]:
    """The time to rest of each restitution: the analytic row, then one row
    per engine (default: refsim as posed)."""
    engines = _received(engines, seed_wall_speed=False)
    rows = []
    for e in restitutions:
        h0 = DROP_HEIGHT
        zeno = analytic.time_to_rest(h0, GRAVITY, e)
        scene = drop_scene(model, e, step=step, solver=solver, duration=zeno + 0.5)
        y_touch = touch_height(scene)
        rows.append(RestRow(body=model, e=e, zeno=zeno, engine=ANALYTIC,
                            settle=analytic.time_to_settle(h0, GRAVITY, e, REST_FRACTION),
                            bounces=analytic.bounces_until(e, REST_FRACTION)))
        for engine in engines:
            trajectory, _ = run_engine(scene, engine)
            settle, k = settle_time(bounces_of(trajectory, y_touch), h0)
            rows.append(RestRow(body=model, e=e, zeno=zeno, engine=engine.name, settle=settle,
                                bounces=k))
    return rows


@dataclass(frozen=True)
class DropEnergy:
    """Height and energy over time of one drop (every ``stride``-th frame)
    as one engine ran it, or the closed form (``engine`` :data:`ANALYTIC`,
    at the first engine's frame times)."""

    body: str
    e: float
    engine: str
    t: list[float]
    height: list[float]
    energy: list[float]


def measure_drop_energy(model: str = SPHERE, e: float = 0.8, *, duration: float = 6.0,
                        step: float = STEP, solver: str = SOLVER, stride: int = 10,
                        engines=None) -> list[DropEnergy]:
    """Height above the touching height and mechanical energy (per unit
    weight ``m g``: metres) over time: the analytic curves, then one per
    engine (default: refsim as posed; at least one engine)."""
    engines = _received(engines, seed_wall_speed=False)
    if not engines:
        raise StateError("measure_drop_energy: give at least one engine (the analytic "
                         "curves are drawn at its frame times)")
    scene = drop_scene(model, e, step=step, solver=solver, duration=duration)
    y_touch = touch_height(scene)
    curves = []
    for engine in engines:
        trajectory, _ = run_engine(scene, engine)
        curves.append(DropEnergy(
            body=model, e=e, engine=engine.name, t=trajectory.t[::stride].tolist(),
            height=(trajectory.position[::stride, 0, 1] - y_touch).tolist(),
            energy=energy_above_touch(scene, trajectory, y_touch)[::stride].tolist()))
    t = np.asarray(curves[0].t)
    closed = DropEnergy(body=model, e=e, engine=ANALYTIC, t=curves[0].t,
                        height=analytic.height(t, DROP_HEIGHT, GRAVITY, e).tolist(),
                        energy=(analytic.energy(t, DROP_HEIGHT, GRAVITY, e) / GRAVITY).tolist())
    return [closed, *curves]


#: The cost study's series of RK4 with the seed's literal wall speed (the
#: series of engine :data:`SEED_WALL_SPEED`).
SEED_SPEED_SERIES = "rk4, seed wall speed"


@dataclass(frozen=True)
class CostPoint:
    """One point of the speed-vs-accuracy study."""

    engine: str            # the engine's name: "refsim", "refsim-seed-wall-speed", "pybullet"
    solver: str            # the series: refsim's solver, SEED_SPEED_SERIES, or the engine's name
    step: float
    ratio: float           # measured apex ratio (geometric mean over BOUNCES)
    error: float           # |ratio - e^2| / e^2
    seconds_per_second: float = field(metadata=TIMED)  # wall time per simulated second


@dataclass(frozen=True)
class CostStudy:
    e: float
    body: str
    bounces: int
    points: list[CostPoint] = field(default_factory=list)


def measure_cost(steps=COST_STEPS, solvers=COST_SOLVERS, *, model: str = SPHERE,
                 e: float = 0.8, bounces: int = BOUNCES, engines=None) -> CostStudy:
    """Apex-ratio error against wall time per simulated second, per step size.

    Each engine of ``engines`` (default :func:`refsim_engines`) is one
    series at every step size with the solver :data:`SOLVER`, but the engine
    named :data:`REFSIM` (refsim as posed: it runs the scene's solver),
    which is a series per solver of ``solvers``;
    refsim with the seed's wall speed is the series
    :data:`SEED_SPEED_SERIES`, any other engine the series of its name. The
    time is what :func:`run_engine` reports: refsim's whole
    ``refsim.simulate`` call (its loop, its wall test and recording the
    frames), pybullet's ``stepSimulation`` calls alone (not the reading of
    state through the Python API, which would otherwise dominate).
    """
    ideal = analytic.apex_ratio(e)
    duration = duration_for(e, bounces)
    points = []
    series = []
    for engine in _received(engines, seed_wall_speed=True):
        if engine.name == REFSIM:
            series += [(engine, solver, solver) for solver in solvers]
        else:
            label = SEED_SPEED_SERIES if engine.name == SEED_WALL_SPEED else engine.name
            series.append((engine, label, SOLVER))
    for engine, label, method in series:
        for h in steps:
            scene = drop_scene(model, e, step=h, solver=method, duration=duration)
            traj, seconds = run_engine(scene, engine)
            ratio = apex_ratio(bounces_of(traj, touch_height(scene)).apex_heights, bounces)
            points.append(CostPoint(engine=engine.name, solver=label, step=float(h),
                                    ratio=ratio, error=abs(ratio - ideal) / ideal,
                                    seconds_per_second=seconds / traj.t[-1]))
    return CostStudy(e=e, body=model, bounces=bounces, points=points)


def fit_error_orders(study: CostStudy, floor: float = ROUNDING_ERROR) -> dict[str, float]:
    """Per series of ``study``: the least-squares slope of log(error) against
    log(step) over its points with a finite error above ``floor`` (the
    observed order in h); series with fewer than two such points are left out."""
    orders = {}
    for solver in dict.fromkeys(p.solver for p in study.points):
        pts = [p for p in study.points
               if p.solver == solver and math.isfinite(p.error) and p.error > floor]
        if len(pts) >= 2:
            x = np.log([p.step for p in pts])
            y = np.log([p.error for p in pts])
            orders[solver] = float(np.polyfit(x, y, 1)[0])
    return orders


# -- pybullet's settings, one at a time ---------------------------------------------------


@dataclass(frozen=True)
class SettingRow:
    """The sphere's bounce in pybullet with one setting changed from the oracle's."""

    change: str
    ratio: float                # apex ratio over BOUNCES bounces
    error: float                # (ratio - e^2) / e^2, signed
    settle_bounce: int          # bounce after which apexes stay below REST_FRACTION h0
    bounces: int                # bounces detected in the run
    analytic_settle_bounce: int     # the same for the analytic series


def measure_engine_variants(variants, e: float = 0.8, duration: float = 9.0
                            ) -> list[SettingRow]:
    """The sphere's bounce in each of ``variants``, ``(label, engine)`` pairs
    of rigid-body engines (the report passes pybullet with its oracle
    settings, then with one setting at a time back at, or near, pybullet's
    default: why each setting of
    :class:`refsim.oracles.pybullet_adapter.PybulletSettings`)."""
    scene = drop_scene(SPHERE, e, duration=duration)
    y_touch = touch_height(scene)
    ideal = analytic.apex_ratio(e)
    rows = []
    for label, engine in variants:
        traj, _ = run_engine(scene, engine)
        b = bounces_of(traj, y_touch)
        ratio = apex_ratio(b.apex_heights, BOUNCES)
        _, k = settle_time(b, DROP_HEIGHT)
        rows.append(SettingRow(change=label, ratio=ratio, error=(ratio - ideal) / ideal,
                               settle_bounce=k, bounces=len(b.bounce_times),
                               analytic_settle_bounce=analytic.bounces_until(e, REST_FRACTION)))
    return rows


# -- step cost against pybullet ---------------------------------------------------------


#: The "stage" of :func:`measure_step_cost`'s breakdown that is the compiled
#: loop's time (its stages run inside one call, not timed one by one).
LOOP_STAGE = "compiled loop"


@dataclass(frozen=True)
class StepCost:
    """Mean seconds per step of one scene (:data:`STEP_CASE`) in one engine:
    refsim's ``Simulation.advance`` (``engine`` :data:`REFSIM`, with its
    stages), or an engine's own stepping (pybullet's ``stepSimulation``)."""

    bodies: int
    rotation: str
    warmup: int                         # steps taken before the timed ones
    engine: str
    seconds: float = field(metadata=TIMED)
    stage_seconds: dict = field(metadata=TIMED)    # per step, by stage of refsim's loop
    steps: int = 0                      # timed steps per repeat
    repeats: int = 0                    # repeats (the fastest kept)


def _refsim_step_cost(scene, steps: int, warmup: int, repeats: int) -> tuple[float, dict]:
    """refsim's fastest mean seconds per step over ``repeats`` runs of
    ``scene``, and that repeat's stage breakdown (:func:`measure_step_cost`)."""
    from refsim.dynamics.simulation import Simulation

    ours, stages = math.inf, {}
    for _ in range(repeats):
        sim = Simulation(scene)
        sim.advance(warmup)
        before = dict(sim.stage_seconds)
        loop_before = sim.loop_seconds
        start = time.perf_counter()
        sim.advance(steps)
        mean = (time.perf_counter() - start) / steps
        if mean < ours:
            ours = mean
            stages = {k: (sim.stage_seconds[k] - before[k]) / steps for k in before}
            if sim.loop_seconds > loop_before:
                stages[LOOP_STAGE] = (sim.loop_seconds - loop_before) / steps
    return ours, stages


def measure_step_cost(counts=BENCH_COUNTS, rotations=BENCH_ROTATIONS, *, steps: int = 200,
                      warmup: int = 20, repeats: int = 5,
                      engines=()) -> list[StepCost]:
    """Seconds per step of each cubes scene in refsim and in each of
    ``engines`` (rigid-body engines with ``step_time(scene, steps,
    warmup)``: pybullet's). The one study that does not receive refsim as
    an engine: what it times is refsim's own ``Simulation.advance``, stage by
    stage, beside the engines; its rows are named :data:`REFSIM`. The
    compiled loop, where the scene allows it, is the stage ``LOOP_STAGE``
    (not split).

    Each engine runs the scene ``repeats`` times from its start: ``warmup``
    untimed steps (they also pay any first-call compilation), then ``steps``
    timed ones; the fastest repeat's mean is kept (the least disturbed by
    other processes on a shared machine). The stage breakdown is refsim's
    ``stage_seconds`` over the timed steps of that repeat.
    """
    rows = []
    for count in counts:
        for rotation in rotations:
            scene = cubes_scene(count, rotation)
            case = {"bodies": count, "rotation": rotation, "warmup": warmup, "steps": steps,
                    "repeats": repeats}
            ours, stages = _refsim_step_cost(scene, steps, warmup, repeats)
            rows.append(StepCost(**case, engine=REFSIM, seconds=ours, stage_seconds=stages))
            for engine in engines:
                theirs = min(engine.step_time(scene, steps, warmup) for _ in range(repeats))
                rows.append(StepCost(**case, engine=engine.name, seconds=theirs,
                                     stage_seconds={}))
    return rows


def as_dict(obj) -> dict:
    """A study's dataclass as JSON-able data."""
    return asdict(obj)
