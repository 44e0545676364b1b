"""The fidelity advisor's answer: :func:`advise` gives the cheapest
settings of a scene whose run stays within TOL of a reference run, and
:func:`advice_by_tolerance` the advice for several scenes at several
tolerances, for the report.

:func:`advise` holds the scene's physics fixed (rotation model, body and
wall response, wall speed, forces, world, bodies) and searches its four
fidelity choices (:class:`~refsim.advisor.records.Fidelity`: solver, step,
collision level, box update) in rounds: the reference
(:mod:`refsim.advisor.reference`), then the search
(:mod:`refsim.advisor.search`). It returns an
:class:`~refsim.advisor.records.Advice` of plain records and prints nothing
but progress lines; ``refsim advise`` shows it through
:mod:`refsim.advisor.view`. docs/advisor.md explains each step.

Cost: the reference's halvings dominate, about ``2 * max_reference_steps``
steps at most; the search adds about 3 runs per solver, the geometry at
most 5, each ``repeats`` times; see :func:`refsim.advisor.runs.measure_run`
for a run's cost.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Sequence
from pathlib import Path

from refsim.advisor import metrics
from refsim.advisor.records import Advice, Fidelity, RunRow, ToleranceSeries
from refsim.advisor.reference import (
    MAX_REFERENCE_STEPS,
    REFERENCE_AABB,
    REFERENCE_LEVEL,
    Reference,
    Verdict,
    find_reference,
)
from refsim.advisor.runner import TIMING_REPEATS, Ladder, Runner, Setting
from refsim.advisor.runs import scene_fidelity
from refsim.advisor.search import Judged, confirm, search_geometry, search_integration
from refsim.errors import ArgumentTypeError, StateError, check_count
from refsim.scenes.schema import Scene
from refsim.solvers.methods import SOLVERS

#: Default TOL (m): 1 cm, small against bodies of about a metre in a cube of
#: a few metres (the bundled scenes): a difference no one sees in a replay.
DEFAULT_TOLERANCE = 1e-2

#: The bundled scenes the report asks about (rigid bodies, no particles).
BUNDLED_RIGID_SCENES = ("bounce.toml", "head-on.toml", "mixed.toml", "spinning-cube.toml")

#: Tolerances (m) for the report's view of how the advice moves with TOL.
REPORT_TOLERANCES = (1e-2, 3e-3, 1e-3)


def advise(scene, tolerance: float = DEFAULT_TOLERANCE, *, duration: float | None = None,
           backend: str = "inprocess", workers: int | None = None,
           scheduler: str | None = None, store=None, progress: bool = False,
           repeats: int = TIMING_REPEATS,
           max_reference_steps: int = MAX_REFERENCE_STEPS,
           reference_tolerance: float | None = None,
           candidates: Sequence[Fidelity] = ()) -> Advice:
    """The cheapest fidelity settings of ``scene`` whose run stays within
    ``tolerance`` of the reference (docs/advisor.md explains each step).

    Parameters
    ----------
    scene : refsim.Scene or str or PathLike
        A loaded scene, or a scene file (a bare name finds a bundled scene).
        Rigid bodies only (no ``[particles]``).
    tolerance : float
        TOL in metres (> 0, finite); times and energy by the conversions of
        :mod:`refsim.advisor.metrics`.
    duration : float, optional
        Simulate this long (s) instead of the scene's duration; a whole
        number of the scene's steps.
    backend, workers, scheduler, store, progress
        As :func:`refsim.sweep.run_sweep`: where the runs go ("inprocess",
        "processes" with ``workers``, "dask" at ``scheduler``), and a store
        directory that makes an interrupted advice resume.
    repeats : int
        Wall-time repeats of each candidate run (its median is reported).
    max_reference_steps : int
        The most steps of one reference run (docs/advisor.md, The reference).
    reference_tolerance : float, optional
        The tolerance the reference's halving aims at and its horizon and
        allowances past the horizon are measured at, at most ``tolerance``
        (default: ``tolerance``). Advice at several tolerances shares the
        reference of the strictest (:func:`advice_by_tolerance`).
    candidates : sequence of Fidelity
        Settings run and judged along with the search's (the
        recommendations at stricter tolerances: docs/advisor.md, The
        scene's own settings and candidates); each
        step a whole number of steps per sample interval.

    Returns
    -------
    Advice

    Raises
    ------
    StateError
        A tolerance that is not a finite number > 0; a scene with particles
        or without bodies; a duration that is not a whole number of steps.
    OptionError, SweepError
        A bad backend option; a store of another task list; a run that
        raised (its message).
    """
    from refsim.scenes.loader import load_scene

    if isinstance(tolerance, bool) or not isinstance(tolerance, int | float):
        raise ArgumentTypeError(f"tolerance must be a number of metres, got {tolerance!r}")
    tolerance = float(tolerance)
    if not (math.isfinite(tolerance) and tolerance > 0.0):
        raise StateError(f"tolerance must be a finite number of metres > 0, got {tolerance!r}")
    repeats = check_count("repeats", repeats, minimum=1)
    max_reference_steps = check_count("max_reference_steps", max_reference_steps, minimum=2)
    aim = tolerance if reference_tolerance is None else float(reference_tolerance)
    if not (math.isfinite(aim) and 0.0 < aim <= tolerance):
        raise StateError(f"reference_tolerance must be a finite number of metres in "
                         f"(0, tolerance = {tolerance!r}], got {reference_tolerance!r}")
    if not isinstance(scene, Scene):
        scene = load_scene(scene)
    if not scene.bodies:
        raise StateError("the scene has no [[body]]: refsim advise tunes rigid-body scenes")
    duration = scene.integration.duration if duration is None else float(duration)
    ladder = Ladder.for_scene(scene.integration.step, duration)
    runner = Runner(scene, ladder, duration=duration, backend=backend, workers=workers,
                    scheduler=scheduler, store=store, progress=progress, repeats=repeats)
    own_fidelity = scene_fidelity(scene)
    own = Setting(own_fidelity.solver, ladder.divisions, own_fidelity.level, own_fidelity.aabb)

    # Round 1: the reference's first pair, the scene's own settings and each
    # solver's first measurements, in one sweep (the reference's runs timed once).
    first = [(own, "own")]
    for name, method in SOLVERS.items():
        first.append((Setting(name, ladder.divisions, REFERENCE_LEVEL, REFERENCE_AABB),
                      "search"))
        if method.order > 1:
            first.append((Setting(name, 2 * ladder.divisions, REFERENCE_LEVEL,
                                  REFERENCE_AABB), "search"))
    first += [(_on_ladder(ladder, fidelity), "stricter") for fidelity in candidates]
    runner.run(first[:1])            # the scene's own settings first: a scene that cannot
    #                                  run at all fails here, before the long reference runs
    ref = find_reference(runner, tolerance, max_reference_steps, first[1:], aim)

    # The search (docs/advisor.md, The search), against the reference.
    judged = Judged(runner, ref, tolerance)
    pruned = search_integration(judged, bodies=len(scene.bodies))
    search_geometry(judged, scene)
    chosen = confirm(judged)

    rows = {s: _row(s, runner, ref, judged.verdict(s) if s != ref.setting else None)
            for s in runner.runs}
    recommended, own_row = rows[chosen], rows[own]
    return Advice(
        scene=str(scene.path) if scene.path is not None else "<scene>",
        tolerance=tolerance, duration=duration,
        scene_duration=scene.integration.duration, sample_interval=ladder.interval,
        energy_scale=ref.scale, energy_allowance=ref.energy_allowance,
        count_allowance=ref.count_allowance, reference=ref.row, recommended=recommended,
        own=own_row, proxy_saving=own_row.proxy / recommended.proxy,
        wall_saving=own_row.wall_seconds / recommended.wall_seconds,
        runs=tuple(rows.values()), pruned=tuple(pruned.values()), computed=runner.computed,
        resumed=runner.resumed)


def _on_ladder(ladder: Ladder, fidelity: Fidelity) -> Setting:
    """The setting of ``fidelity``, whose step must be on the ladder."""
    m = round(ladder.interval / fidelity.step)
    if m < 1 or ladder.step(m) != fidelity.step:
        raise StateError(f"candidate step {fidelity.step!r} s is not a whole number of steps "
                         f"per sample interval ({ladder.interval!r} s)")
    return Setting(fidelity.solver, m, fidelity.level, fidelity.aabb)


def _row(setting: Setting, runner: Runner, ref: Reference, v: Verdict | None) -> RunRow:
    """The table row of one run (``v`` None for the reference itself)."""
    run = runner.runs[setting]
    fidelity = setting.fidelity(runner.ladder)
    if v is None:
        zero = metrics.Comparison(0.0, metrics.EventAgreement(True, True, 0.0, None, ""), 0.0,
                                  dict.fromkeys(metrics.KINDS, 0))
        v = Verdict(zero, 0.0, True)
    c = v.comparison
    events = "equal" if c.events.agree else ("late" if c.events.paired else "differ")
    diverged = None
    if run.diverged is not None:
        diverged = (f"diverged at step {run.diverged['step']}, "
                    f"t = {run.diverged['time']:.6g}: {run.diverged['message']}")
    return RunRow(
        solver=fidelity.solver, step=fidelity.step, level=fidelity.level, aabb=fidelity.aabb,
        roles=tuple(runner.roles.get(setting, ())), steps=run.steps, proxy=run.proxy,
        force_evaluations=run.force_evaluations, narrow_phase_calls=run.narrow_phase_calls,
        box_visits=run.box_visits, wall_seconds=float(statistics.median(run.wall_seconds)),
        wall_repeats=len(run.wall_seconds), position_error=c.position_error,
        event_error=c.events.error, events=events, event_note=c.events.note,
        energy_drift=metrics.energy_drift(run, ref.scale), energy_gap=c.energy_gap,
        count_gap=dict(c.count_gap), error_ratio=v.ratio, meets=v.meets, diverged=diverged)


def advice_by_tolerance(scenes=BUNDLED_RIGID_SCENES, tolerances=REPORT_TOLERANCES, *,
                        store=None, **options) -> tuple[ToleranceSeries, ...]:
    """For each scene (bundled names or paths), :func:`advise` at each
    tolerance: the report's view of how the recommendation moves with TOL.

    The tolerances of a scene are advised from the strictest to the
    loosest, all against the reference of the strictest, its horizon and
    its allowances past the horizon (``reference_tolerance``), and each is
    offered the recommendations of the stricter ones as candidates. Then a
    run that meets a stricter TOL meets every looser one (each test is a
    bound that grows with TOL), its next finer step too, so the recommended
    cost never grows as TOL loosens: the series is one speed-accuracy
    trade-off. A lone :func:`advise` at a loose TOL may differ from the
    series' entry: it compares positions up to its own, later, horizon.

    ``store``: a directory; each scene gets its own store inside it, which
    every tolerance shares (runs common to two tolerances are made once).
    Other options go to :func:`advise` (``backend``, ``workers``,
    ``repeats``, ``duration``...). Cost: the advices', less what is shared.
    Returns each scene's advice in the order of ``tolerances``.
    """
    tolerances = tuple(float(t) for t in tolerances)
    strictest = min(tolerances, default=DEFAULT_TOLERANCE)
    series = []
    for name in scenes:
        scene_store = None if store is None else Path(store) / Path(str(name)).stem
        found: dict[float, Advice] = {}
        for tol in sorted(set(tolerances)):
            stricter = [a.recommended.fidelity() for a in found.values()]
            found[tol] = advise(name, tol, store=scene_store, reference_tolerance=strictest,
                                candidates=list(dict.fromkeys(stricter)), **options)
        series.append(ToleranceSeries(str(name), tolerances,
                                      tuple(found[t] for t in tolerances)))
    return tuple(series)
