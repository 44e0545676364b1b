"""The report's rigid-body dynamics entries (seeds S5, S7, S8, S9, claims
C11 and C12).

The bounce studies of :mod:`refsim.studies.bounce` against the analytic
answers and pybullet (apexes, oblique bounces, time to rest, energy, error
against cost, pybullet's settings, step cost) and the C11/C12 measurements
of :mod:`refsim.studies.dynamics`. Each bounce study receives its engines
(:func:`_engines`: refsim's own from the registry, then pybullet; the step
cost times refsim itself, beside pybullet); without pybullet
(``run.optional``) it has no pybullet rows. A quick run has fewer
restitutions, step sizes and solvers, a shorter C11 run and fewer timed
steps.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from refsim.report.run import Run

#: The scene of C12 (a cube dropped with spin).
SPIN_SCENE = "spinning-cube.toml"


@dataclass(frozen=True)
class CostRun:
    """Error against cost over step sizes, and the fitted order of each series."""

    study: Any                  # refsim.studies.bounce.CostStudy
    orders: dict                # series -> slope of log error against log h


def _engines(run: Run, *, seed_wall_speed: bool = False, refsim: bool = True) -> list:
    """The engines a bounce study receives, all built by the run from the
    registry: refsim as posed (unless ``refsim`` is False: the step cost
    times refsim itself), with ``seed_wall_speed`` also refsim with the
    seed's literal wall speed, then the pybullet oracle when it is
    installed."""
    from refsim.studies import bounce

    names = ([bounce.REFSIM] if refsim else []) + ([bounce.SEED_WALL_SPEED]
                                                   if seed_wall_speed else [])
    oracle = run.optional("pybullet")
    return [run.engine(name) for name in names] + ([oracle] if oracle is not None else [])


def dynamics_apex(run: Run):
    from refsim.studies import bounce

    engines = _engines(run, seed_wall_speed=True)
    if run.quick:
        rows = bounce.measure_apexes(models=(bounce.SPHERE,), engines=engines)
        rows += bounce.measure_apex_drop(bounce.CUBE, 0.8, rotation="seed", engines=engines)
        return rows
    return bounce.measure_apexes(engines=engines)


def dynamics_oblique(run: Run):
    from refsim.studies import bounce

    return bounce.measure_oblique(engines=_engines(run))


def dynamics_rest(run: Run):
    from refsim.studies import bounce

    return bounce.measure_rest(restitutions=run.size((0.5,), (0.5, 0.8)),
                               engines=_engines(run))


def dynamics_energy(run: Run):
    from refsim.studies import bounce

    return bounce.measure_drop_energy(engines=_engines(run))


def dynamics_cost(run: Run):
    from refsim.studies import bounce

    study = bounce.measure_cost(run.size(bounce.COST_STEPS_QUICK, bounce.COST_STEPS),
                                run.size(bounce.COST_SOLVERS_QUICK, bounce.COST_SOLVERS),
                                engines=_engines(run, seed_wall_speed=True))
    return CostRun(study, bounce.fit_error_orders(study))


#: pybullet with the oracle's settings, then with one setting at a time back
#: at (or near) pybullet's default: (label, fields of
#: :class:`refsim.oracles.pybullet_adapter.PybulletSettings` changed).
PYBULLET_VARIANTS: tuple[tuple[str, dict], ...] = (
    ("none (the oracle's settings)", {}),
    ("useMaximalCoordinates=False (multibody)", {"use_maximal_coordinates": False}),
    ("contactProcessingThreshold=1e30 (Bullet's default: all)",
     {"contact_processing_threshold": 1e30}),
    ("useSplitImpulse=0", {"use_split_impulse": 0}),
    ("restitutionVelocityThreshold=0.2 (Bullet's default)",
     {"restitution_velocity_threshold": 0.2}),
    ("linear/angular damping 0.04 (pybullet's default)",
     {"linear_damping": 0.04, "angular_damping": 0.04}),
)


def dynamics_pybullet_settings(run: Run):
    """Empty in a quick run and without pybullet."""
    from refsim.engines.registry import build
    from refsim.studies import bounce

    if run.optional("pybullet") is None or run.quick:
        return []
    return bounce.measure_engine_variants(
        [(label, build("pybullet", **changes)) for label, changes in PYBULLET_VARIANTS])


def dynamics_step_cost(run: Run):
    from refsim.studies import bounce
    from refsim.studies.bounce_scenes import BENCH_COUNTS, LATE_WARMUP

    peers = _engines(run, refsim=False)
    rows = bounce.measure_step_cost(steps=run.size(50, 200), warmup=run.size(10, 20),
                                    repeats=run.size(3, 5), engines=peers)
    if not run.quick:
        rows += bounce.measure_step_cost(counts=(BENCH_COUNTS[-1],),
                                         warmup=LATE_WARMUP, repeats=3, engines=peers)
    return rows


def dynamics_spin(run: Run):
    """C12 runs its full 6 s in the quick report too: a shorter run stops
    before the corrected model comes to rest and would change the verdict.
    refsim runs the scene as posed, once per rotation model; pybullet runs
    it with its own model, in a client of its own (a second engine built
    from the registry, not the run's shared one)."""
    from refsim.bundled import scenes_dir
    from refsim.engines.registry import build
    from refsim.scenes.loader import load_scene
    from refsim.studies import bounce, dynamics

    scene = load_scene(scenes_dir() / SPIN_SCENE)
    refsim = run.engine(bounce.REFSIM)
    if run.optional("pybullet") is None:
        return dynamics.measure_spin(scene, engines=[refsim])
    with build("pybullet") as oracle:
        return dynamics.measure_spin(scene, engines=[refsim, oracle])


def dynamics_interpenetration(run: Run):
    from refsim.studies import bounce, dynamics

    return dynamics.measure_interpenetration(engine=run.engine(bounce.REFSIM),
                                             duration=run.size(1.0, 2.0))


def dynamics_rotation_energy(run: Run):
    from refsim.studies import bounce, dynamics

    return dynamics.measure_energy(engine=run.engine(bounce.REFSIM))
