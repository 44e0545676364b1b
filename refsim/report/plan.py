"""The report's composition root: every named study run, its engines and sizes.

Each entry of :data:`STUDIES` is one measurement the report makes (or one
the command line offers beside it): which study function it calls, with
which engines (the oracle adapters of :mod:`refsim.oracles`, chosen here and
nowhere else) and with which sizes for the quick and the full report. The
report's sections ask a :class:`Run` for an entry's records and arrange
them; ``refsim study NAME`` runs the same entry and prints them, so the
command printed under a figure reproduces that figure (docs/design.md,
Architecture: an engine is chosen only at a composition root).

An entry that backs a seed claim names the claim and the function of
:mod:`refsim.claims` that judges it from the entry's records
(:meth:`Run.claim`). Where a claim rests on several measurements (C7, C8),
its entry gathers the records of the others, which a run measures once.

An oracle that is not installed raises :class:`refsim.oracles.OracleUnavailable`
from :meth:`Run.engine`; entries that can do without it ask
:meth:`Run.optional`, which records why it is missing (:attr:`Run.missing`)
for the report to say so.

Three entries run through :mod:`refsim.sweep` (:data:`SWEEP_ENTRIES`): the
shipped engines' conformance matrix, the replays of the viewer's demos and
the advisor on every bundled scene. A run given ``workers`` sends their
tasks to that many local processes, and with them every other entry but
the timed ones and those that gather others' records
(:data:`PARALLEL_ENTRIES`, one task each); it starts them at once
(:meth:`Run.prefetch`) and measures the timed entries here once the workers
are done, on an otherwise idle machine. The records are the same either
way. A run given ``out_dir`` has the matrix's and the replays' pages
written there (the report's directory).
"""

from __future__ import annotations

import importlib
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from refsim.claims.result import ClaimResult
from refsim.report.run import Run, Study

# -- engines -------------------------------------------------------------------------------


def _trimesh():
    from refsim.oracles.trimesh_adapter import TrimeshOracle

    return TrimeshOracle()


def _fcl():
    from refsim.oracles.fcl_adapter import FCLOracle

    return FCLOracle()


def _trimesh_collision():
    from refsim.oracles.trimesh_collision import TrimeshCollisionOracle

    return TrimeshCollisionOracle()


def _pybullet():
    from refsim.oracles.pybullet_adapter import PybulletOracle

    return PybulletOracle()


def _scipy():
    from refsim.oracles.scipy_ivp import ScipyReference

    return ScipyReference()


#: The oracle engines the report uses, by name: a factory each. One engine of
#: each is made per run and shared by the entries (one pybullet client serves
#: every bounce scene; each ``simulate`` resets it).
ENGINES: dict[str, Callable[[], Any]] = {
    "trimesh": _trimesh,
    "fcl": _fcl,
    "trimesh-collision": _trimesh_collision,
    "pybullet": _pybullet,
    "scipy": _scipy,
}


def pybullet_variants() -> list[tuple[str, Any]]:
    """pybullet with the oracle's settings, then with one setting at a time
    back at (or near) pybullet's default: ``(label, engine)`` pairs."""
    from dataclasses import replace

    from refsim.oracles.pybullet_adapter import PybulletOracle, PybulletSettings

    base = PybulletSettings()
    changes = (
        ("none (the oracle's settings)", base),
        ("useMaximalCoordinates=False (multibody)", replace(base, use_maximal_coordinates=False)),
        ("contactProcessingThreshold=1e30 (Bullet's default: all)",
         replace(base, contact_processing_threshold=1e30)),
        ("useSplitImpulse=0", replace(base, use_split_impulse=0)),
        ("restitutionVelocityThreshold=0.2 (Bullet's default)",
         replace(base, restitution_velocity_threshold=0.2)),
        ("linear/angular damping 0.04 (pybullet's default)",
         replace(base, linear_damping=0.04, angular_damping=0.04)),
    )
    return [(label, PybulletOracle(settings)) for label, settings in changes]


def command(name: str) -> str:
    """The command that reproduces the records of entry ``name``."""
    if name not in STUDIES:
        raise KeyError(f"no study {name!r} in the plan")
    return f"refsim study {name}"


def claim_command(claim: str) -> str:
    """The command that reproduces the verdict on ``claim``."""
    return command(CLAIM_STUDY[claim])


# -- records of entries that gather several measurements ----------------------------------


@dataclass(frozen=True)
class TrianglePairs:
    """The exact triangle test against FCL on one family of pairs."""

    pairs: str                  # what the pairs are
    agreement: Any              # refsim.studies.triangles.Agreement


@dataclass(frozen=True)
class C4Run:
    """Near-parallel triangles: the fixed frames and the random frames."""

    c4: Any                     # refsim.studies.triangles.C4Result
    sweep: Any                  # refsim.studies.triangles.C4Sweep


@dataclass(frozen=True)
class OrderRun:
    """Observed orders, with what the tableaux say of each method."""

    convergence: dict           # (problem, method) -> refsim.studies.solvers.Convergence
    derived: dict               # method -> order derived from its tableau
    stated: dict                # method -> order the seed states
    failing: dict               # method -> order conditions (up to the stated order) it fails


@dataclass(frozen=True)
class SeedLiteral:
    problem: str
    result: Any                 # refsim.studies.solvers.SeedLiteralRK4


@dataclass(frozen=True)
class StabilityRun:
    """Stability limits, each method's R(z), and |R| on a grid of the complex plane."""

    limits: list                # refsim.studies.solvers.StabilityLimit
    polynomials: dict           # method -> coefficients of R(z) (Fractions), lowest first
    grid: dict                  # {"re": (lo, hi), "im": (lo, hi), "n": points per axis}
    x: Any                      # (n,) real parts
    y: Any                      # (n,) imaginary parts
    regions: list               # (label, |R| (n, n)) per distinct R(z)


@dataclass(frozen=True)
class WorkPrecisionRun:
    points: list                # refsim.studies.solvers.WorkPoint
    repeats: int                # wall time: best of this many runs
    count: int = 0              # particles (0: not a particle system)
    orders: dict = field(default_factory=dict)   # method -> observed order


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
class AlikeRun:
    """C7's measurements: orders, stability limits, resting hops, and R(z)."""

    orders: dict
    limits: list
    jitter: list
    polynomials: dict


@dataclass(frozen=True)
class Rk4Run:
    """C8's measurements: the solver choice, frame-step differences, and the
    observed orders with walls."""

    choice: list
    frame_free: Any
    frame_walls: Any
    wall_orders: dict


@dataclass(frozen=True)
class CostRun:
    """Error against cost over step sizes, and the fitted order of each series."""

    study: Any                  # refsim.studies.bounce.CostStudy
    orders: dict                # series -> slope of log error against log h


@dataclass(frozen=True)
class TriangleSpeed:
    fallback: Any               # refsim.studies.triangles.FallbackRates
    throughput: Any             # refsim.studies.triangles.Throughput
    float_errors: Any           # refsim.studies.triangles.FloatErrors


# -- models ----------------------------------------------------------------------------------


def _models_facts(run: Run):
    from refsim.bundled import bundled_models
    from refsim.models.facts import describe
    from refsim.models.loading import load_model

    return [describe(load_model(path), name=path.name) for path in bundled_models()]


def _models_agreement(run: Run):
    from refsim.bundled import bundled_models
    from refsim.studies.models import measure_mesh_facts_agreement

    return measure_mesh_facts_agreement(run.engine("trimesh"), bundled_models())


# -- bounds ----------------------------------------------------------------------------------

#: Quick: meshes up to 32 frequencies of the geodesic sphere (the seed's 2000
#: triangles included), fewer frames and repeats.
BOUNDS_QUICK_FREQUENCIES = (3, 7, 10, 16, 32)


def _bounds_cost(run: Run):
    from refsim.studies import bounds

    meshes = bounds.sweep_meshes(BOUNDS_QUICK_FREQUENCIES) if run.quick \
        else bounds.sweep_meshes()
    return bounds.measure_update_cost(meshes, frames=run.size(50, 200),
                                      repeats=run.size(3, 5), seed=run.seed)


def _bounds_error(run: Run):
    from refsim.studies import bounds

    return [e for motion in ("coherent", "jump")
            for e in bounds.measure_incremental_error(motion=motion, frames=run.size(180, 720),
                                                      seed=run.seed)]


def _bounds_agreement(run: Run):
    from refsim.studies import bounds

    return bounds.measure_bounds_agreement(run.engine("trimesh"), poses=run.size(50, 200),
                                           seed=run.seed)


def _bounds_compile(run: Run):
    from refsim.studies import bounds

    return bounds.measure_numba_compile_cost()


# -- collision -------------------------------------------------------------------------------

#: (quick, full) sizes of each collision measurement: quick keeps the
#: section to seconds (after numba's first compile), full to minutes.
COLLISION_SIZES = {
    "repeats": (3, 21),
    "random_per_pair": (5, 50),
    "speed_repeats": (5, 31),
    "triangle_pairs": (2000, 20_000),
    "near_degenerate_pairs": (1000, 5000),
    "c4_frames": (10, 100),
}


def _collision(run: Run, key: str) -> int:
    return run.size(*COLLISION_SIZES[key])


def _fcl_triangles(run: Run):
    """FCL's triangle test, or None without python-fcl."""
    fcl = run.optional("fcl")
    return None if fcl is None else fcl.triangles_intersect


def _collision_levels(run: Run):
    from refsim.studies import levels

    return levels.measure_levels(repeats=_collision(run, "repeats"),
                                 random_per_pair=_collision(run, "random_per_pair"),
                                 seed=run.seed)


def _collision_body_oracles(run: Run):
    from refsim.studies import levels

    body = tuple(e for e in (run.optional("fcl"), run.optional("trimesh-collision"))
                 if e is not None)
    return levels.measure_body_oracles(body, run.optional("fcl"),
                                       random_per_pair=_collision(run, "random_per_pair"),
                                       seed=run.seed)


def _collision_speed(run: Run):
    from refsim.studies import levels

    return levels.measure_hierarchy_speed(run.optional("fcl"), _collision(run, "speed_repeats"),
                                          compile_cost=not run.quick)


def _collision_triangles(run: Run):
    import numpy as np

    from refsim.studies import triangles

    oracle = _fcl_triangles(run)
    if oracle is None:
        return []
    rng = np.random.default_rng(run.seed)
    n = _collision(run, "triangle_pairs")
    A, B = rng.uniform(-1.0, 1.0, (2, n, 3, 3))
    rows = [TrianglePairs("uniform random triangle pairs",
                          triangles.compare_with_oracle(A, B, oracle))]
    A, B, _ = triangles.near_degenerate_pairs(_collision(run, "near_degenerate_pairs"), run.seed)
    rows.append(TrianglePairs("near-degenerate triangle pairs",
                              triangles.compare_with_oracle(A, B, oracle)))
    return rows


def _collision_c4(run: Run):
    from refsim.studies import triangles

    oracle = _fcl_triangles(run)
    return C4Run(triangles.measure_c4(oracle, run.seed),
                 triangles.measure_c4_sweep(_collision(run, "c4_frames"), oracle, run.seed))


def _triangle_speed(run: Run):
    from refsim.studies import triangles

    n = run.size(2000, 20_000)
    oracle = _fcl_triangles(run)
    return TriangleSpeed(triangles.measure_filter_fallback(n, run.seed),
                         triangles.measure_throughput(n, run.seed, oracle),
                         triangles.measure_float_errors(min(n, 5000), run.seed, oracle))


# -- solvers and particles ---------------------------------------------------------------------

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

#: |R(z)| is drawn on this grid of z = h lambda.
STABILITY_GRID_RE, STABILITY_GRID_IM, STABILITY_GRID_N = (-5.5, 1.5), (-3.5, 3.5), 281
STABILITY_GRID = {"re": STABILITY_GRID_RE, "im": STABILITY_GRID_IM, "n": STABILITY_GRID_N}


def _failing_conditions(solver) -> list[str]:
    """The order conditions up to the seed's stated order that the tableau
    fails (empty when it meets them all)."""
    if solver.row_sums() != solver.c:
        return ["c_i != sum_j a_ij"]
    return [f"{name.split(' = ')[0]} = {value}, not {want}"
            for p, name, value, want in solver.order_conditions()
            if p <= solver.seed_order and value != want]


def _solvers_orders(run: Run):
    from refsim.solvers.methods import SOLVERS
    from refsim.studies import solvers as sm

    problems = sm.standard_problems()
    if run.quick:
        # Kepler needs 10^5-step Euler runs: the full report only. The others
        # stop at a quarter of STEP_RANGE's most steps, which still leaves each
        # solver three points inside the fitted error window.
        del problems["kepler"]
        convergence = {}
        for name, problem in problems.items():
            lo, hi = sm.STEP_RANGE[name]
            steps = [lo * 2**k for k in range(int(math.log2(hi // lo)) - 1)]
            y_ref = sm.reference_at_t1(problem, run.engine("scipy"))
            for method in SOLVERS:
                convergence[(name, method)] = sm.measure_convergence(problem, method, steps,
                                                                     y_ref=y_ref)
    else:
        convergence = sm.measure_orders(problems, oracle=run.engine("scipy"))
    return OrderRun(convergence, {k: s.order for k, s in SOLVERS.items()},
                    {k: s.seed_order for k, s in SOLVERS.items()},
                    {k: _failing_conditions(s) for k, s in SOLVERS.items()})


def _solvers_seed_literal(run: Run):
    from refsim.solvers.problems import exponential_decay, harmonic_oscillator, kepler_orbit
    from refsim.studies import solvers as sm

    problems = ([harmonic_oscillator()] if run.quick
                else [exponential_decay(), harmonic_oscillator(), kepler_orbit()])
    return [SeedLiteral(p.name, sm.measure_seed_literal_rk4(p, oracle=run.engine("scipy")))
            for p in problems]


def _solvers_stability(run: Run):
    from refsim.solvers.methods import SOLVERS
    from refsim.solvers.stability import stability_grid, stability_polynomial
    from refsim.studies import solvers as sm

    limits = sm.measure_stability()
    polynomials = {name: stability_polynomial(s) for name, s in SOLVERS.items()}
    # Methods with the same R(z) share one curve (averaged-euler and midpoint).
    groups: dict[tuple, list[str]] = {}
    for name in SOLVERS:
        groups.setdefault(polynomials[name], []).append(name)
    regions = []
    x = y = None
    for names in groups.values():
        x, y, absR = stability_grid(SOLVERS[names[0]], re=STABILITY_GRID_RE,
                                    im=STABILITY_GRID_IM, n=STABILITY_GRID_N)
        regions.append((" = ".join(names) + (" (same R)" if len(names) > 1 else ""), absR))
    return StabilityRun(limits, polynomials, STABILITY_GRID, x, y, regions)


def _solvers_energy(run: Run):
    from refsim.studies import solvers as sm

    return sm.measure_oscillator_energy()


def _repeats(run: Run) -> int:
    """Wall times: best of this many runs."""
    return run.size(2, 3)


def _solvers_work_precision(run: Run):
    from refsim.studies import solvers as sm

    repeats = _repeats(run)
    if run.quick:
        lo, _ = sm.STEP_RANGE["kepler"]
        points = sm.measure_work_precision(steps=[lo * 2**k for k in range(8)],
                                           tolerances=sm.SCIPY_TOLERANCES[:8], repeats=repeats,
                                           oracle=run.engine("scipy"))
    else:
        points = sm.measure_work_precision(repeats=repeats, oracle=run.engine("scipy"))
    return WorkPrecisionRun(points, repeats)


def _particle_config(run: Run, walls: bool):
    from refsim.studies import particles as pm

    return pm.particle_test_config(count=run.size(*PARTICLE_COUNT), walls=walls)


def _particles_work_precision(run: Run):
    from refsim.studies import particles as pm

    points = pm.measure_particle_work_precision(_particle_config(run, False),
                                                repeats=_repeats(run),
                                                oracle=run.engine("scipy"))
    return WorkPrecisionRun(points, _repeats(run), run.size(*PARTICLE_COUNT),
                            pm.observed_orders(points))


def _particles_work_precision_walls(run: Run):
    from refsim.studies import particles as pm

    steps = pm.PARTICLE_STEPS if run.quick else pm.PARTICLE_STEPS + (2048, 4096)
    points = pm.measure_particle_work_precision(_particle_config(run, True), steps=steps,
                                                repeats=_repeats(run),
                                                oracle=run.engine("scipy"))
    return WorkPrecisionRun(points, _repeats(run), run.size(*PARTICLE_COUNT),
                            pm.observed_orders(points))


def _particles_jitter(run: Run):
    from refsim.studies import particles as pm

    steps = run.size(JITTER_STEPS_QUICK, JITTER_STEPS_FULL)
    return JitterRun(pm.measure_jitter_table(steps=steps),
                     pm.measure_jitter_table(steps=steps, drag=JITTER_DAMPED_DRAG),
                     JITTER_DAMPED_DRAG,
                     {h: {"euler": pm.euler_jitter_estimate(h, JITTER_RESTITUTION),
                          "order-2-or-more": pm.exact_integrator_hop(h, JITTER_RESTITUTION)}
                      for h in steps})


def _particles_drag(run: Run):
    from refsim.studies import particles as pm

    scipy = run.engine("scipy")
    return pm.measure_drag_models(scipy, count=20_000, repeats=3) if run.quick \
        else pm.measure_drag_models(scipy)


def _particles_frame(run: Run):
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


def _particles_choice(run: Run):
    from refsim.studies import particles as pm

    if run.quick:
        return ChoiceRun(_quick_choice(run), run.size(*PARTICLE_COUNT), max(pm.PARTICLE_STEPS),
                         TARGET_FREE, BUDGET_WALLS)
    return ChoiceRun(pm.measure_solver_choice(target_free=TARGET_FREE, budget_walls=BUDGET_WALLS,
                                              count=CHOICE_COUNT, oracle=run.engine("scipy")),
                     CHOICE_COUNT, CHOICE_MAX_STEPS, TARGET_FREE, BUDGET_WALLS)


def _solvers_alike(run: Run):
    return AlikeRun(run.get("solvers-orders").convergence, run.get("solvers-stability").limits,
                    run.get("particles-jitter").undamped,
                    run.get("solvers-stability").polynomials)


def _particles_rk4(run: Run):
    frame = run.get("particles-frame")
    return Rk4Run(run.get("particles-choice").rows, frame.free, frame.walls,
                  run.get("particles-work-precision-walls").orders)


def _particles_throughput(run: Run):
    from refsim.studies import particles as pm

    return [pm.measure_throughput(count, solver)
            for count in run.size((1_000, 100_000), (1_000, 100_000, 1_000_000))
            for solver in ("euler", "rk4")]


def _particles_memory(run: Run):
    from refsim.particles.config import ParticleConfig
    from refsim.solvers.methods import SOLVERS
    from refsim.studies import particles as pm

    count = run.size(10_000, 100_000)
    return [pm.measure_step_memory(ParticleConfig(count=count, solver=solver, drag=0.1,
                                                  drag_model="quadratic",
                                                  wall_speed=pm.SEED_WALLS), 20)
            for solver in SOLVERS]


# -- dynamics --------------------------------------------------------------------------------


def _dynamics_apex(run: Run):
    from refsim.studies import bounce

    pb = run.optional("pybullet")
    if run.quick:
        rows = bounce.measure_apexes(models=(bounce.SPHERE,), oracle=pb)
        rows.append(bounce.measure_apex_row(bounce.CUBE, 0.8, rotation="seed", oracle=pb))
        return rows
    return bounce.measure_apexes(oracle=pb)


def _dynamics_oblique(run: Run):
    from refsim.studies import bounce

    return bounce.measure_oblique(oracle=run.optional("pybullet"))


def _dynamics_rest(run: Run):
    from refsim.studies import bounce

    return bounce.measure_rest(restitutions=run.size((0.5,), (0.5, 0.8)),
                               oracle=run.optional("pybullet"))


def _dynamics_energy(run: Run):
    from refsim.studies import bounce

    return bounce.measure_drop_energy(oracle=run.optional("pybullet"))


def _dynamics_cost(run: Run):
    from refsim.studies import bounce

    study = bounce.measure_cost(run.size(bounce.COST_STEPS_QUICK, bounce.COST_STEPS),
                                run.size(bounce.COST_SOLVERS_QUICK, bounce.COST_SOLVERS),
                                oracle=run.optional("pybullet"))
    return CostRun(study, bounce.fit_error_orders(study))


def _dynamics_pybullet_settings(run: Run):
    """Empty in a quick run and without pybullet."""
    from refsim.studies import bounce

    if run.optional("pybullet") is None or run.quick:
        return []
    return bounce.measure_engine_variants(pybullet_variants())


def _dynamics_step_cost(run: Run):
    from refsim.studies import bounce

    pb = run.optional("pybullet")
    rows = bounce.measure_step_cost(steps=run.size(50, 200), warmup=run.size(10, 20),
                                    repeats=run.size(3, 5), oracle=pb)
    if not run.quick:
        rows += bounce.measure_step_cost(counts=(bounce.BENCH_COUNTS[-1],),
                                         warmup=bounce.LATE_WARMUP, repeats=3, oracle=pb)
    return rows


#: The scene of C12 (a cube dropped with spin).
SPIN_SCENE = "spinning-cube.toml"


def _dynamics_spin(run: Run):
    """C12 runs its full 6 s in the quick report too: a shorter run stops
    before the corrected model comes to rest and would change the verdict.
    pybullet runs the same scene in a client of its own."""
    from refsim.bundled import scenes_dir
    from refsim.dynamics.simulation import default_every
    from refsim.scenes.loader import load_scene
    from refsim.studies import dynamics

    if run.optional("pybullet") is None:
        return dynamics.measure_spin()
    scene = load_scene(scenes_dir() / SPIN_SCENE)
    with _pybullet() as oracle:
        external = oracle.simulate(scene, every=default_every(scene.integration.n_steps))
    return dynamics.measure_spin(scene, external=external)


def _dynamics_interpenetration(run: Run):
    from refsim.studies import dynamics

    return dynamics.measure_interpenetration(duration=run.size(1.0, 2.0))


def _dynamics_rotation_energy(run: Run):
    from refsim.studies import dynamics

    return dynamics.measure_energy()


def _sweep_speed(run: Run):
    from refsim.studies import sweep

    if run.quick:
        return sweep.measure_sweep_speed(tasks=4, duration=1.0, trivial_tasks=20, repeats=1)
    return sweep.measure_sweep_speed()


# -- engines side by side (the conformance kit) -------------------------------------------

#: Cases in each generated conformance set (triangle pairs, mesh poses,
#: boxes): quick, full (the full one is ``refsim conform``'s default). The
#: rigid-body scenes and the ODE problems are fixed sets, the same in both.
MATRIX_CASES = (20, 200)

#: Where the engines' conformance pages go, inside the report's directory.
MATRIX_FOLDER = "conformance"


@dataclass(frozen=True)
class MatrixRun:
    """The shipped engines through the conformance kit, side by side.

    ``matrix``: :class:`refsim.conformance.matrix.Matrix` (its ``pages``
    relative to ``folder``); ``folder``: the pages' folder relative to the
    report's directory ("" when none was written); ``command``: the command
    that reproduces the matrix and its pages.
    """

    matrix: Any
    cases: int
    folder: str
    command: str


def _conformance_matrix(run: Run):
    from refsim.conformance.matrix import run_matrix

    cases = run.size(*MATRIX_CASES)
    out = None if run.out_dir is None else run.out_dir / MATRIX_FOLDER
    matrix, _ = run_matrix(cases=cases, seed=run.seed, out_dir=out, **run.sweep_options())
    return MatrixRun(matrix, cases, "" if out is None else MATRIX_FOLDER,
                     f"refsim conform --all --cases {cases} --seed {run.seed} -o DIR")


# -- textbook problems: refsim's corrected model as the step shrinks ------------------------

#: The steps (s) of the convergence table: quick, full.
TEXTBOOK_STEPS = ((2e-3, 1e-3), (2e-3, 1e-3, 5e-4))

#: The problems a quick run follows in h (a full run: every one of
#: refsim.conformance.checks_rigid.TEXTBOOK_PROBLEMS): the cheap ones.
TEXTBOOK_QUICK = ("rigid.oblique_bounce", "rigid.free_rotation", "rigid.off_centre")


@dataclass(frozen=True)
class TextbookConvergence:
    """refsim's corrected model on the kit's textbook problems at each step:
    ``errors[check]`` the error against the closed form at each of
    ``steps`` (in the problem's unit), and ``ratios[check]`` its misses
    over the check's tolerances at the kit's step (at most 1 passes)."""

    steps: tuple
    errors: dict
    ratios: dict


def _textbook_convergence(run: Run):
    from refsim.conformance import cases_rigid as R
    from refsim.conformance.checks_rigid import TEXTBOOK_PROBLEMS
    from refsim.conformance.registry import check_by_key
    from refsim.engines import load_engine

    engine = load_engine("refsim.engines.refsim_engines:corrected")
    steps = tuple(run.size(*TEXTBOOK_STEPS))
    problems = [p for p in TEXTBOOK_PROBLEMS if not run.quick or p.check in TEXTBOOK_QUICK]
    scenes = R.rigid_scenes()
    errors: dict = {p.check: [] for p in problems}
    ratios: dict = {}
    for h in steps:
        cases = R.RigidCases(scenes=tuple(R.with_step(s, h) for s in scenes))
        for p in problems:
            measured = check_by_key(p.check).run(engine, cases).measured
            errors[p.check].append(p.error(measured))
            if h == R.STEP:
                ratios[p.check] = p.ratio(measured)
    return TextbookConvergence(steps, errors, ratios)


# -- replays (the viewer's demos) -------------------------------------------------------------

#: Where the replays go, inside the report's directory.
REPLAY_FOLDER = "replays"

#: Each replay's size budget (bytes): viser's client (~0.8 MB) and a few
#: hundred frames, so that the report's directory stays a few MB.
REPORT_REPLAY_BYTES = 2_000_000

#: The replays the report shows: (name of :data:`refsim.report.tasks.DEMO_ENGINES`,
#: the seed claim it illustrates or "", its title).
REPLAYS = (
    ("c11-interpenetration", "C11",
     "C11: slow contact, the seed's velocity exchange beside the corrected impulse"),
    ("c12-spin", "C12", "C12: the spinning cube, the seed's rotation beside the corrected one"),
    ("wall-bounce-pybullet", "", "A wall bounce: refsim beside pybullet"),
    ("wall-bounce-mujoco", "", "A wall bounce: refsim beside MuJoCo"),
)


@dataclass(frozen=True)
class ReplayRecord:
    """One replay page: ``status`` "written" (``file`` relative to the
    report's directory, its size and frames), "unavailable" (``reason``: the
    viewer extra or the engine is missing) or "not written" (no output
    directory)."""

    name: str
    claim: str
    title: str
    status: str
    file: str = ""
    reason: str = ""
    bytes: int = 0
    frames: int = 0
    timeline_frames: int = 0
    stride: int = 0
    runs: tuple = ()


def _replays(run: Run):
    from refsim.conformance.matrix import make_directory
    from refsim.errors import SweepError
    from refsim.report.tasks import write_replay_demo
    from refsim.sweep import Task, run_sweep

    if run.out_dir is None:
        return [ReplayRecord(name, claim, title, "not written",
                             reason="no output directory (refsim report writes them into its own)")
                for name, claim, title in REPLAYS]
    folder = make_directory(run.out_dir / REPLAY_FOLDER)
    tasks = [Task(f"replay-{name}", write_replay_demo,
                  {"name": name, "path": str(folder / f"{name}.html"),
                   "max_bytes": REPORT_REPLAY_BYTES}) for name, _, _ in REPLAYS]
    sweep = run_sweep(tasks, progress=False, seed=run.seed, **run.sweep_options())
    records = []
    for (name, claim, title), result in zip(REPLAYS, sweep.results, strict=True):
        if result.status != "done":
            raise SweepError(f"replay {name}: {result.error}")
        answer = result.value
        if "unavailable" in answer:
            records.append(ReplayRecord(name, claim, title, "unavailable",
                                        reason=answer["unavailable"]))
            continue
        w = answer["written"]
        records.append(ReplayRecord(name, claim, title, "written",
                                    file=f"{REPLAY_FOLDER}/{w['file']}", bytes=w["bytes"],
                                    frames=w["frames"], timeline_frames=w["timeline_frames"],
                                    stride=w["stride"], runs=tuple(w["runs"])))
    return records


# -- the fidelity advisor ---------------------------------------------------------------------

#: The advisor's tolerances (m) and simulated duration (s; None: each
#: scene's own), quick and full. The quick report simulates 1 s of each
#: scene (its first impacts) and times each run once.
ADVISOR_TOLERANCES = ((1e-2, 1e-3), (1e-2, 3e-3, 1e-3))
ADVISOR_DURATION = (1.0, None)
ADVISOR_REPEATS = (1, 3)

#: Bundled scenes the quick report does not advise, and why (the full report
#: advises every scene): three bodies in contact need the finest steps at
#: 1 mm, the costliest advice by far (minutes, where the others take seconds).
ADVISOR_QUICK_SKIP = {"mixed.toml": "three bodies in contact, the costliest advice by far; "
                                    "the full report advises it"}


@dataclass(frozen=True)
class AdvisedScene:
    """The advisor on one bundled scene: ``advice``, one
    :meth:`refsim.studies.advisor.Advice.as_dict` per tolerance; or
    ``refused``, the advisor's reason for not tuning the scene; or
    ``skipped``, why this run did not ask (:data:`ADVISOR_QUICK_SKIP`)."""

    scene: str
    advice: tuple = ()
    refused: str = ""
    skipped: str = ""


@dataclass(frozen=True)
class AdvisorRun:
    scenes: tuple               # AdvisedScene, one per bundled scene, by name
    tolerances: tuple           # m
    duration: float | None      # s simulated (None: each scene's own)
    repeats: int                # wall-time repeats of each candidate run


def _advisor(run: Run):
    import tempfile

    from refsim.bundled import bundled_scenes
    from refsim.errors import SweepError
    from refsim.report.tasks import advise_scene
    from refsim.sweep import Task, run_sweep

    tolerances = run.size(*ADVISOR_TOLERANCES)
    duration = run.size(*ADVISOR_DURATION)
    repeats = run.size(*ADVISOR_REPEATS)
    every = [path.name for path in bundled_scenes()]
    skipped = ADVISOR_QUICK_SKIP if run.quick else {}
    names = [name for name in every if name not in skipped]
    with tempfile.TemporaryDirectory(prefix="refsim-advise-") as store:
        # each scene's runs are kept in a store of its own, which its
        # tolerances share (a run common to two tolerances is made once)
        tasks = [Task(f"advise-{name}", advise_scene,
                      {"scene": name, "tolerances": list(tolerances), "duration": duration,
                       "repeats": repeats, "store": str(Path(store) / Path(name).stem)})
                 for name in names]
        sweep = run_sweep(tasks, progress=False, seed=run.seed, **run.sweep_options())
    answers = {}
    for name, result in zip(names, sweep.results, strict=True):
        if result.status != "done":
            raise SweepError(f"advise {name}: {result.error}")
        answers[name] = result.value
    scenes = tuple(AdvisedScene(name, skipped=skipped[name]) if name in skipped
                   else AdvisedScene(name, tuple(answers[name].get("advice", ())),
                                     answers[name].get("refused", ""))
                   for name in every)
    return AdvisorRun(scenes, tuple(tolerances), duration, repeats)


# -- the plan --------------------------------------------------------------------------------


def _judge(function: str, *attrs: str) -> Callable[[Any], ClaimResult]:
    """The judge of a claim: ``refsim.claims.<area>.<name>`` (``function`` is
    ``"<area>.<name>"``) called with the entry's records, or with the named
    attributes of its record. The claims are imported when judged, so that
    the command line starts without the studies."""
    area, name = function.split(".")

    def judge(records) -> ClaimResult:
        fn = getattr(importlib.import_module(f"refsim.claims.{area}"), name)
        return fn(*(getattr(records, a) for a in attrs)) if attrs else fn(records)

    return judge


def _entries() -> dict[str, Study]:
    entries = (
        Study("models-facts", "models: facts of the bundled models", _models_facts),
        Study("models-agreement", "models: agreement with trimesh", _models_agreement),
        Study("bounds-cost", "bounds: cost per update (C1)", _bounds_cost,
              {"C1": _judge("bounds.c1")}, timed=True),
        Study("bounds-error", "bounds: incremental box on non-convex meshes (C2)",
              _bounds_error, {"C2": _judge("bounds.c2")}),
        Study("bounds-agreement", "bounds: agreement with trimesh", _bounds_agreement),
        Study("bounds-compile", "bounds: numba compile cost", _bounds_compile,
              in_report=False),
        Study("collision-levels", "collision: levels (C3)", _collision_levels,
              {"C3": _judge("collision.c3")}, timed=True),
        Study("collision-body-oracles", "collision: body-level oracles",
              _collision_body_oracles),
        Study("collision-speed", "collision: hierarchy against FCL", _collision_speed,
              timed=True),
        Study("collision-triangles", "collision: triangle pairs against FCL",
              _collision_triangles),
        Study("collision-c4", "collision: near-parallel triangles (C4)", _collision_c4,
              {"C4": _judge("collision.c4", "c4", "sweep")}),
        Study("triangles-speed", "collision: triangle test fallback rates and speed",
              _triangle_speed, in_report=False),
        Study("solvers-orders", "solvers: orders of convergence", _solvers_orders,
              {"C10": _judge("solvers.c10", "convergence", "derived", "stated")}),
        Study("solvers-seed-literal", "solvers: the seed's literal RK4 weights",
              _solvers_seed_literal),
        Study("solvers-stability", "solvers: stability limits", _solvers_stability),
        Study("solvers-energy", "solvers: energy per period", _solvers_energy),
        Study("solvers-alike", "solvers: the four other solvers (C7)", _solvers_alike,
              {"C7": _judge("solvers.c7", "orders", "limits", "jitter", "polynomials")},
              gathers=True),
        Study("solvers-work-precision", "solvers: work-precision, Kepler",
              _solvers_work_precision, timed=True),
        Study("particles-work-precision", "solvers: work-precision, particle system",
              _particles_work_precision, timed=True),
        Study("particles-work-precision-walls",
              "solvers: work-precision, particle system with walls",
              _particles_work_precision_walls, timed=True),
        Study("particles-jitter", "solvers: resting contact", _particles_jitter,
              {"C6": _judge("solvers.c6", "undamped", "damped")}),
        Study("particles-drag", "solvers: drag models", _particles_drag,
              {"C5": _judge("solvers.c5")}, timed=True),
        Study("particles-frame", "solvers: frame-step differences", _particles_frame),
        Study("particles-choice", "solvers: which solver (C9)", _particles_choice,
              {"C9": _judge("solvers.c9", "rows")}, gathers=True),
        Study("particles-rk4", "solvers: is RK4 worth its cost (C8)", _particles_rk4,
              {"C8": _judge("solvers.c8", "choice", "frame_free", "frame_walls",
                            "wall_orders")}, gathers=True),
        Study("particles-throughput", "particles: throughput", _particles_throughput,
              in_report=False),
        Study("particles-memory", "particles: memory per step", _particles_memory,
              in_report=False),
        Study("dynamics-apex", "dynamics: apex ratios", _dynamics_apex),
        Study("dynamics-oblique", "dynamics: oblique bounces", _dynamics_oblique),
        Study("dynamics-rest", "dynamics: time to rest", _dynamics_rest),
        Study("dynamics-energy", "dynamics: energy over time", _dynamics_energy),
        Study("dynamics-cost", "dynamics: error against cost", _dynamics_cost, timed=True),
        Study("dynamics-pybullet-settings", "dynamics: pybullet's settings",
              _dynamics_pybullet_settings),
        Study("dynamics-step-cost", "dynamics: step cost against pybullet",
              _dynamics_step_cost, timed=True),
        Study("dynamics-spin", "dynamics: C12 spin", _dynamics_spin,
              {"C12": _judge("dynamics.c12")}),
        Study("dynamics-interpenetration", "dynamics: C11 interpenetration",
              _dynamics_interpenetration, {"C11": _judge("dynamics.c11")}),
        Study("dynamics-rotation-energy", "dynamics: energy of the spinning cube",
              _dynamics_rotation_energy, in_report=False),
        Study("sweep-speed", "sweep: speed of each backend", _sweep_speed, in_report=False),
        Study("conformance-matrix", "conformance: the shipped engines side by side",
              _conformance_matrix),
        Study("textbook-convergence",
              "textbook problems: refsim's corrected model as the step shrinks",
              _textbook_convergence),
        Study("replays", "replays: C11, C12 and wall bounces", _replays),
        Study("advisor", "advisor: every bundled scene at each tolerance", _advisor),
    )
    return {e.name: e for e in entries}


#: Every named study run, by name.
STUDIES: dict[str, Study] = _entries()

#: The entries that run through refsim.sweep (on the run's workers, when it
#: has them): measured beside the others by :meth:`Run.prefetch`.
SWEEP_ENTRIES = ("replays", "conformance-matrix", "advisor")   # in the order the page needs them

#: The report's other entries that a run with workers sends to them, one
#: task each (:func:`refsim.report.tasks.measure_entry`): all but the timed
#: ones and those that gather others' records.
PARALLEL_ENTRIES = tuple(name for name, study in STUDIES.items()
                         if study.in_report and not (study.timed or study.gathers)
                         and name not in SWEEP_ENTRIES)

#: The entry that backs each seed claim.
CLAIM_STUDY: dict[str, str] = {claim: name for name, study in STUDIES.items()
                               for claim in study.claims}
