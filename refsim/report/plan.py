"""The report's composition root: every named study run, its engines and claims.

Each entry of :data:`STUDIES` is one measurement the report makes (or one
the command line offers beside it): its name, the entry function that
measures it and the seed claims it backs. The entry functions live in
:mod:`refsim.report.entries`, one module per area (models, bounds,
collision, solvers, particles, dynamics, conformance, replays, advisor,
sweep), each with the study functions it calls, its sizes for the quick and
the full report and the records it returns. The engines they measure
against are rows of the one engine table
(:data:`refsim.engines.registry.ENGINES`); an entry asks its run for one by
name. The report's sections ask a :class:`refsim.report.run.Run` for an
entry's records and arrange them; ``refsim study NAME`` runs the same entry and
prints them, so the command printed under a figure reproduces that figure
(docs/design.md, Architecture: an engine is chosen only at a composition
root).

An entry that backs a seed claim names the claim and the function of
:mod:`refsim.claims` that judges it from the entry's records
(:func:`_judge`, :meth:`refsim.report.run.Run.claim`). Where a claim rests
on several measurements (C7, C8), its entry gathers the records of the
others, which a run measures once.

An oracle that is not installed raises :class:`refsim.oracles.OracleUnavailable`
from :meth:`Run.engine <refsim.report.run.Run.engine>`; entries that can do
without it ask :meth:`Run.optional <refsim.report.run.Run.optional>`, which
records why it is missing (``Run.missing``) for the report to say so.

Three entries run through :mod:`refsim.sweep` (:data:`SWEEP_ENTRIES`): the
shipped engines' conformance matrix, the replays of the viewer's demos and
the advisor on every bundled scene. A run given ``workers`` sends their
tasks to that many local processes, and with them every other entry but
the timed ones and those that gather others' records
(:data:`PARALLEL_ENTRIES`, one task each); it starts them at once
(:meth:`Run.prefetch <refsim.report.run.Run.prefetch>`) and measures the
timed entries itself once the workers are done, on an otherwise idle
machine. The records are the same either way. A run given ``out_dir`` has
the matrix's and the replays' pages written there (the report's directory).

The command line imports this module at start-up: the entries modules
import their studies inside the entry functions, and the claims are
imported when judged, so that importing the plan imports no study.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any

from refsim.claims.result import ClaimResult
from refsim.report.entries.advisor import advisor
from refsim.report.entries.bounds import bounds_agreement, bounds_compile, bounds_cost, bounds_error
from refsim.report.entries.collision import (
    collision_body_oracles,
    collision_c4,
    collision_levels,
    collision_speed,
    collision_triangles,
    triangles_speed,
)
from refsim.report.entries.conformance import conformance_matrix, textbook_convergence
from refsim.report.entries.dynamics import (
    dynamics_apex,
    dynamics_cost,
    dynamics_energy,
    dynamics_interpenetration,
    dynamics_oblique,
    dynamics_pybullet_settings,
    dynamics_rest,
    dynamics_rotation_energy,
    dynamics_spin,
    dynamics_step_cost,
)
from refsim.report.entries.models import models_agreement, models_facts
from refsim.report.entries.particles import (
    particles_choice,
    particles_drag,
    particles_frame,
    particles_jitter,
    particles_memory,
    particles_rk4,
    particles_throughput,
    particles_work_precision,
    particles_work_precision_walls,
)
from refsim.report.entries.replays import replays
from refsim.report.entries.solvers import (
    solvers_alike,
    solvers_energy,
    solvers_orders,
    solvers_seed_literal,
    solvers_stability,
    solvers_work_precision,
)
from refsim.report.entries.sweep import sweep_speed
from refsim.report.run import Study


def command(name: str) -> str:
    """The command that reproduces the records of entry ``name``."""
    if name not in STUDIES:
        raise KeyError(f"no study {name!r} in the plan")
    return f"refsim study {name}"


def claim_command(claim: str) -> str:
    """The command that reproduces the verdict on ``claim``."""
    return command(CLAIM_STUDY[claim])


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
        Study("models-facts", "models: facts of the bundled models", models_facts),
        Study("models-agreement", "models: agreement with trimesh", models_agreement),
        Study("bounds-cost", "bounds: cost per update (C1)", bounds_cost,
              {"C1": _judge("bounds.c1")}, timed=True),
        Study("bounds-error", "bounds: incremental box on non-convex meshes (C2)",
              bounds_error, {"C2": _judge("bounds.c2")}),
        Study("bounds-agreement", "bounds: agreement with trimesh", bounds_agreement),
        Study("bounds-compile", "bounds: numba compile cost", bounds_compile,
              in_report=False),
        Study("collision-levels", "collision: levels (C3)", collision_levels,
              {"C3": _judge("collision.c3")}, timed=True),
        Study("collision-body-oracles", "collision: body-level oracles",
              collision_body_oracles),
        Study("collision-speed", "collision: hierarchy against FCL", collision_speed,
              timed=True),
        Study("collision-triangles", "collision: triangle pairs against FCL",
              collision_triangles),
        Study("collision-c4", "collision: near-parallel triangles (C4)", collision_c4,
              {"C4": _judge("collision.c4", "c4", "sweep")}),
        Study("triangles-speed", "collision: triangle test fallback rates and speed",
              triangles_speed, in_report=False),
        Study("solvers-orders", "solvers: orders of convergence", solvers_orders,
              {"C10": _judge("solvers.c10", "convergence", "derived", "stated")}),
        Study("solvers-seed-literal", "solvers: the seed's literal RK4 weights",
              solvers_seed_literal),
        Study("solvers-stability", "solvers: stability limits", solvers_stability),
        Study("solvers-energy", "solvers: energy per period", solvers_energy),
        Study("solvers-alike", "solvers: the four other solvers (C7)", solvers_alike,
              {"C7": _judge("solvers.c7", "orders", "limits", "jitter", "polynomials")},
              gathers=True),
        Study("solvers-work-precision", "solvers: work-precision, Kepler",
              solvers_work_precision, timed=True),
        Study("particles-work-precision", "solvers: work-precision, particle system",
              particles_work_precision, timed=True),
        Study("particles-work-precision-walls",
              "solvers: work-precision, particle system with walls",
              particles_work_precision_walls, timed=True),
        Study("particles-jitter", "solvers: resting contact", particles_jitter,
              {"C6": _judge("solvers.c6", "undamped", "damped")}),
        Study("particles-drag", "solvers: drag models", particles_drag,
              {"C5": _judge("solvers.c5")}, timed=True),
        Study("particles-frame", "solvers: frame-step differences", particles_frame),
        Study("particles-choice", "solvers: which solver (C9)", particles_choice,
              {"C9": _judge("solvers.c9", "rows")}, gathers=True),
        Study("particles-rk4", "solvers: is RK4 worth its cost (C8)", particles_rk4,
              {"C8": _judge("solvers.c8", "choice", "frame_free", "frame_walls",
                            "wall_orders")}, gathers=True),
        Study("particles-throughput", "particles: throughput", particles_throughput,
              in_report=False),
        Study("particles-memory", "particles: memory per step", particles_memory,
              in_report=False),
        Study("dynamics-apex", "dynamics: apex ratios", dynamics_apex),
        Study("dynamics-oblique", "dynamics: oblique bounces", dynamics_oblique),
        Study("dynamics-rest", "dynamics: time to rest", dynamics_rest),
        Study("dynamics-energy", "dynamics: energy over time", dynamics_energy),
        Study("dynamics-cost", "dynamics: error against cost", dynamics_cost, timed=True),
        Study("dynamics-pybullet-settings", "dynamics: pybullet's settings",
              dynamics_pybullet_settings),
        Study("dynamics-step-cost", "dynamics: step cost against pybullet",
              dynamics_step_cost, timed=True),
        Study("dynamics-spin", "dynamics: C12 spin", dynamics_spin,
              {"C12": _judge("dynamics.c12")}),
        Study("dynamics-interpenetration", "dynamics: C11 interpenetration",
              dynamics_interpenetration, {"C11": _judge("dynamics.c11")}),
        Study("dynamics-rotation-energy", "dynamics: energy of the spinning cube",
              dynamics_rotation_energy, in_report=False),
        Study("sweep-speed", "sweep: speed of each backend", sweep_speed, in_report=False),
        Study("conformance-matrix", "conformance: the shipped engines side by side",
              conformance_matrix),
        Study("textbook-convergence",
              "textbook problems: refsim's corrected model as the step shrinks",
              textbook_convergence),
        Study("replays", "replays: C11, C12 and wall bounces", replays),
        Study("advisor", "advisor: every bundled scene at each tolerance", advisor),
    )
    return {e.name: e for e in entries}


#: Every named study run, by name.
STUDIES: dict[str, Study] = _entries()

#: The entries that run through refsim.sweep (on the run's workers, when it
#: has them): measured beside the others by
#: :meth:`refsim.report.run.Run.prefetch`.
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
