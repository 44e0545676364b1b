"""The report's particle-system entries (seed S10, claims C5, C6, C8 and C9).

Work-precision without and with walls (timed), resting contact (C6), drag
models (C5, timed), frame-step differences, the seed's solver choice (C9)
and whether RK4 is worth its cost (C8), the last two gathering the others'
records; throughput and memory per step are offered by ``refsim study``
only. A quick run uses fewer particles and steps and reads the solver
choice off its own measurements (:func:`_quick_choice`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from refsim.report.entries.solvers import WorkPrecisionRun, wall_time_repeats
from refsim.report.run import Run

#: Steps of the resting-contact (jitter) study; the quick run leaves out 1 ms
#: (5000 steps a solver), which only confirms that the hop scales as h^2.
JITTER_STEPS_FULL = (1 / 30, 1 / 100, 1 / 1000)
JITTER_STEPS_QUICK = (1 / 30, 1 / 100)

#: Drag coefficient of the "damped" jitter runs: k/m = 1/s, a strong drag
#: (terminal speed 9.8 m/s) that still does not stop Euler's hop.
JITTER_DAMPED_DRAG = 1.0

#: The restitution of the resting-contact runs (refsim.studies.particles
#: measure_resting_jitter's default).
JITTER_RESTITUTION = 0.8

#: C8/C9 target and budget, the defaults of measure_solver_choice: an error
#: of 0.1 mm without walls, 512 evaluations with walls.
TARGET_FREE = 1e-4
BUDGET_WALLS = 512

#: Particles of the work-precision and frame-step runs (quick, full).
PARTICLE_COUNT = (50, 200)

#: Particles of measure_solver_choice's own runs in the full report, and the
#: most steps of them (8 * 2^11).
CHOICE_COUNT = 50
CHOICE_MAX_STEPS = 8 * 2**11


@dataclass(frozen=True)
class JitterRun:
    """Resting contact, without and with drag, and the predicted hops."""

    undamped: list              # refsim.studies.particles.Jitter
    damped: list
    damped_drag: float
    predicted: dict             # h -> {"euler": estimate, "order-2-or-more": exact hop}


@dataclass(frozen=True)
class FrameRun:
    free: Any                   # refsim.studies.particles.FrameStepDifference
    walls: Any


@dataclass(frozen=True)
class ChoiceRun:
    """The facts of the seed's solver choice, one row per solver."""

    rows: list                  # refsim.studies.particles.SolverChoice
    count: int                  # particles of the work-precision runs behind it
    max_steps: int              # the most steps of those runs ("never": not within it)
    target_free: float          # m, the error to reach without walls
    budget_walls: float         # evaluations, the budget with walls


@dataclass(frozen=True)
class Rk4Run:
    """C8's measurements: the solver choice, frame-step differences, and the
    observed orders with walls."""

    choice: list
    frame_free: Any
    frame_walls: Any
    wall_orders: dict


def _particle_config(run: Run, walls: bool):
    from refsim.studies import particles as pm

    return pm.particle_test_config(count=run.size(*PARTICLE_COUNT), walls=walls)


def particles_work_precision(run: Run):
    from refsim.studies import particles as pm

    points = pm.measure_particle_work_precision(_particle_config(run, False),
                                                repeats=wall_time_repeats(run),
                                                oracle=run.engine("scipy"))
    return WorkPrecisionRun(points, wall_time_repeats(run), run.size(*PARTICLE_COUNT),
                            pm.observed_orders(points))


def particles_work_precision_walls(run: Run):
    from refsim.studies import particles as pm

    steps = pm.PARTICLE_STEPS if run.quick else pm.PARTICLE_STEPS + (2048, 4096)
    points = pm.measure_particle_work_precision(_particle_config(run, True), steps=steps,
                                                repeats=wall_time_repeats(run),
                                                oracle=run.engine("scipy"))
    return WorkPrecisionRun(points, wall_time_repeats(run), run.size(*PARTICLE_COUNT),
                            pm.observed_orders(points))


def particles_jitter(run: Run):
    from refsim.studies import particles as pm

    steps = run.size(JITTER_STEPS_QUICK, JITTER_STEPS_FULL)
    return JitterRun(pm.measure_jitter_table(steps=steps),
                     pm.measure_jitter_table(steps=steps, drag=JITTER_DAMPED_DRAG),
                     JITTER_DAMPED_DRAG,
                     {h: {"euler": pm.euler_jitter_estimate(h, JITTER_RESTITUTION),
                          "order-2-or-more": pm.exact_integrator_hop(h, JITTER_RESTITUTION)}
                      for h in steps})


def particles_drag(run: Run):
    from refsim.studies import particles as pm

    scipy = run.engine("scipy")
    return pm.measure_drag_models(scipy, count=20_000, repeats=3) if run.quick \
        else pm.measure_drag_models(scipy)


def particles_frame(run: Run):
    from refsim.studies import particles as pm

    scipy = run.engine("scipy")
    return FrameRun(pm.measure_frame_step_difference(_particle_config(run, False), oracle=scipy),
                    pm.measure_frame_step_difference(_particle_config(run, True), oracle=scipy))


def _quick_choice(run: Run) -> list:
    """:class:`refsim.studies.particles.SolverChoice` rows read off the quick
    run's own measurements with the helpers measure_solver_choice uses
    (measure_solver_choice runs its own work-precision study, up to 16384
    steps per solver, whatever the particle count)."""
    from refsim.claims.solvers import JITTER_QUOTED_STEP, SAME_STEP
    from refsim.solvers.methods import SOLVERS
    from refsim.studies.particles import SolverChoice
    from refsim.studies.solvers import cost_for_error, error_at_cost

    limits = {s.method: s for s in run.get("solvers-stability").limits}
    hop = {j.method: j.max_height_gh2 for j in run.get("particles-jitter").undamped
           if abs(j.h - JITTER_QUOTED_STEP) < SAME_STEP}
    free = run.get("particles-work-precision").points
    walls = run.get("particles-work-precision-walls").points
    return [SolverChoice(name, method.order, method.stages, limits[name].drag_predicted,
                         limits[name].oscillator_predicted,
                         cost_for_error(free, name, TARGET_FREE),
                         error_at_cost(walls, name, BUDGET_WALLS), hop[name])
            for name, method in SOLVERS.items()]


def particles_choice(run: Run):
    from refsim.studies import particles as pm

    if run.quick:
        return ChoiceRun(_quick_choice(run), run.size(*PARTICLE_COUNT), max(pm.PARTICLE_STEPS),
                         TARGET_FREE, BUDGET_WALLS)
    return ChoiceRun(pm.measure_solver_choice(target_free=TARGET_FREE, budget_walls=BUDGET_WALLS,
                                              count=CHOICE_COUNT, oracle=run.engine("scipy")),
                     CHOICE_COUNT, CHOICE_MAX_STEPS, TARGET_FREE, BUDGET_WALLS)


def particles_rk4(run: Run):
    frame = run.get("particles-frame")
    return Rk4Run(run.get("particles-choice").rows, frame.free, frame.walls,
                  run.get("particles-work-precision-walls").orders)


def particles_throughput(run: Run):
    from refsim.studies import particles as pm

    return [pm.measure_throughput(count, solver)
            for count in run.size((1_000, 100_000), (1_000, 100_000, 1_000_000))
            for solver in ("euler", "rk4")]


def particles_memory(run: Run):
    from refsim.particles.config import ParticleConfig
    from refsim.solvers.methods import SOLVERS
    from refsim.studies import particles as pm

    count = run.size(10_000, 100_000)
    return [pm.measure_step_memory(ParticleConfig(count=count, solver=solver, drag=0.1,
                                                  drag_model="quadratic",
                                                  wall_speed=pm.SEED_WALLS), 20)
            for solver in SOLVERS]
