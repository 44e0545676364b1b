"""The fidelity advisor: the cheapest settings whose run stays within TOL of
a reference run (model no more than a scene needs).

What: :func:`advise` holds a scene's physics fixed (rotation model, body
and wall response, wall speed, forces, world, bodies) and searches its four
fidelity choices, :class:`~refsim.studies.fidelity_runs.Fidelity`: solver,
step, collision level, box update. It returns an :class:`Advice` of plain
records: the recommended settings, every run tried with its cost and
errors, the reference and whether it converged, the scene's own settings
measured the same way. It prints and draws nothing (the command ``refsim
advise`` and :mod:`refsim.advise_view` do). :func:`advice_by_tolerance`
gives the advice for the bundled rigid-body scenes at several tolerances,
for the report.

Tolerance. TOL is in metres. Positions are compared as they are, event
times by the distance a time difference moves the body (``|dt| * v``), the
end energy as a fraction ``TOL / H`` of the scene's energy (``H`` the
cube's half size); :mod:`refsim.studies.fidelity_metrics` argues each. A run
**meets TOL** when it did not diverge, its positions stay within TOL of the
reference's up to the horizon, its impacts pair with the reference's in
order with times within TOL, its end energy is within the energy allowance
and (when the reference has not converged) its impact counts are within the
count allowance. The default TOL, ``DEFAULT_TOLERANCE``, is 1 cm.

1. Reference. rk4, level "exact", linear boxes: the finest setting. Its
   step starts at a quarter of the scene's (``REFERENCE_START``) and is
   halved until it and its check, the same run at twice its step, agree
   within ``REFERENCE_SHARE * TOL`` (so that the reference's own error, about
   that difference for a method whose error halves with the step, leaves
   most of TOL to the candidate). Its uncertainty counts the difference of
   the positions, of the event times, and the event times' resolution, one
   reference step at the fastest impact's speed: two runs can find a contact
   in the same step by coincidence and so agree exactly, yet both be a step
   late. Halving stops early when it does not shrink the difference by at
   least ``REDUCTION_MIN`` (the run is chaotic: more steps buy nothing), or
   when the next run would exceed ``max_reference_steps``. Advice at
   several tolerances halves for the strictest (``reference_tolerance``)
   and takes that one reference, its horizon and its allowances past the
   horizon for all of them: only TOL itself (and the energy allowance that
   grows with it) differs between them.

   The reference has **converged** when it and its check agree within TOL
   over the whole run (positions, events, end energy) and resolves event
   times to TOL. Otherwise the advice says so and gives the **horizon**: the
   last sample time up to which the two agree
   (:func:`~refsim.studies.fidelity_metrics.agreement_horizon`). Positions
   and events are then compared up to the horizon only; beyond it, only
   what stays meaningful: the end energy and the impact counts of the whole
   run, each allowed to differ from the reference's by ``SPREAD_FACTOR``
   times their **spread** (the energy by ``TOL / H`` at least, the counts by
   their square root at least, the spread of a count of events in a run
   whose details are unpredictable). The spread is the largest difference
   from the reference among the runs of the last comparison: the check,
   and the run at twice its step when the step was halved. Halving did not
   bring those closer, so they differ by the scene's unpredictability
   rather than by their step: each is a draw of how far equally fine runs
   end apart. The check itself meets TOL by construction, so a
   recommendation always exists.

2. Cost. Two measures, because wall time on a shared machine is noisy:
   the median wall time of ``repeats`` runs (a timing, reported) and a
   machine-independent **proxy**, by which runs are ranked: force
   evaluations times bodies plus narrow-phase calls. Each counts one call
   of a kernel that handles one body or one pair; the simulation's other
   stages (the divergence check, the walls, the rotation) are the same for
   every candidate, as the physics is fixed. The proxy cannot see the
   narrow phase's cost per call, which differs between levels, nor the box
   update's; ties on it are broken by box-update vertex visits and then by
   the coarser collision level, which models less.

3. Search, with pruning.

   *Integration* (solver and step, at the reference's level and boxes):
   each solver's error behaves as ``e = C h^p``. One measured error fixes
   ``C`` for a known ``p``; two fix both. ``p`` is the solver's order
   (``refsim.SOLVERS[name].order``) only away from contacts: a contact is
   found a whole step late at worst, which is an error of first order in
   ``h`` whatever the solver, so the observed order lies between 1 and the
   solver's. The first-order solvers are measured once at the scene's step
   (``p = 1``), the others twice (the scene's step and half of it), and
   ``p`` is read from the two, clamped to ``[1, order]``. The step
   predicted to meet ``PREDICTION_TARGET * TOL`` (a margin for a rough
   ``C`` and ``p``) is then run and measured; each further round predicts
   again from the bracket's edge (the largest step that met TOL, or while
   none has, the finest step measured), inside the bracket of
   the largest step that met TOL and the smallest that did not (aiming at
   TOL itself once a step meets it: the bracket keeps what was found; and
   bisecting the bracket, on a log scale, when the model points outside
   it, the safeguard of Brent's root finder), until the bracket is
   narrower than ``BRACKET_RATIO`` or ``SEARCH_ROUNDS`` rounds have run.
   A step is never assumed to meet TOL: only measured runs are recommended.

   *Branch and bound.* Before a run, its force evaluations are known
   exactly (steps x stages x bodies) and bound its proxy from below (its
   narrow-phase calls are not negative). A run whose bound is no less than
   the proxy of the best run already measured to meet TOL cannot be the
   answer and is not run; it is listed as pruned. In its place the solver
   gets a last chance, inside its bracket: the coarsest step at which any
   solver has met TOL (solvers that are exact between contacts, all but
   Euler's under constant forces, give the same run at the same step), or
   else the finest step that could still cost less than the best. The error
   model is rough where contacts make the error a staircase in ``h``, and a
   prediction past the affordable must not end a solver's search
   unmeasured. The reference's check meets TOL, so there is a bound from
   the start.

   *Geometry* (collision level and box update, at the best integration):
   a coarse level changes which contacts are found and when (every level is
   conservative: it finds a contact no later than the exact one, and often
   one that is not there), which does not depend on the step; so each
   coarser level is run once, at the chosen step, and kept when its run
   meets TOL: the same events and positions within TOL. The box update
   changes no result (the incremental walk finds the linear scan's extreme
   vertices on a convex mesh; "auto" scans non-convex meshes; meshes of at
   most ``BATCH_VERTICES`` vertices are scanned in one batch either way),
   only the vertex visits, so "auto" is run with each level and "linear"
   only as the reference's. A scene whose body-body stage never runs (one
   body, or ``body_response = "off"``) gives the same run at every level;
   only "none" is run.

   *Confirmation.* Where contacts make the error a staircase in ``h``, and
   where the scene is chaotic, a coarse step can land within TOL by chance
   while steps around it do not; such a run is no advice (a user who
   changes the step a little loses TOL), and it made the advice at a
   stricter TOL cheaper than at a looser one. So the recommendation is the
   cheapest run that meets TOL *and* whose next finer step on the ladder
   (``m + 1``, same solver, level and boxes) meets it too. The runs that
   meet TOL are confirmed in order of cost, one neighbour run each, until
   one is confirmed; one whose neighbour misses is marked "chance". The
   reference's check needs no neighbour (it meets TOL by construction).

   The scene's own settings are run and measured like any candidate, for
   the saving: the ratio of its cost to the recommendation's, and whether
   it meets TOL at all. So are ``candidates`` given by the caller:
   :func:`advice_by_tolerance` gives each tolerance the recommendations of
   the stricter ones, all against one reference (the strictest's), so that
   the recommended cost never grows as TOL loosens (see the function).

4. Runs go through :func:`refsim.sweep.run_sweep` round by round (the
   reference's halvings, the search's rounds, the geometry), in-process, on
   local processes or on a Dask cluster, with the same results on each:
   every decision depends on the measured positions, events, energies and
   counts, never on a timing. With a ``store`` every finished run is kept,
   so an interrupted advice resumes, and advice for the same scene at
   another tolerance reuses the runs it shares (a run's key names its
   settings and the scene's content, not TOL).

Cost: the reference's halvings dominate, about ``2 * max_reference_steps``
steps at most; the search adds about 3 runs per solver, the geometry at
most 5, each ``repeats`` times; see
:func:`refsim.studies.fidelity_runs.measure_run` for a run's cost.
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field, replace
from fractions import Fraction
from pathlib import Path

from refsim.errors import ArgumentTypeError, OptionError, StateError, SweepError, check_count
from refsim.scenes.schema import COLLISION_LEVELS, Scene
from refsim.solvers.integrate import whole_steps
from refsim.solvers.methods import SOLVERS
from refsim.studies import fidelity_metrics as metrics
from refsim.studies.fidelity_runs import (
    Fidelity,
    measure_run,
    scene_data,
    scene_fidelity,
)
from refsim.sweep.records import canonical, digest
from refsim.sweep.run import run_sweep
from refsim.sweep.tasks import Task

#: Default TOL (m): 1 cm, small against bodies of about a metre in a cube of
#: a few metres (the bundled scenes): a difference no one sees in a replay.
DEFAULT_TOLERANCE = 1e-2

#: The longest step considered and the spacing of the common sample times
#: (s): 10 ms, in which a body at the bundled scenes' impact speeds (a few
#: m/s) moves centimetres, more than any tolerance of interest. The actual
#: interval is the largest whole number of the scene's steps not above it
#: that divides the run, so that the scene's own step is among the steps tried.
SAMPLE_INTERVAL = 0.01

#: The reference's first step is the scene's divided by this (the scene's
#: step is what its author found good enough; the reference must be better).
REFERENCE_START = 4

#: Halve the reference's step until it and its check agree within this
#: fraction of TOL (see the module docstring).
REFERENCE_SHARE = 0.25

#: A halving of the reference's step that shrinks its difference with the
#: check by less than this factor is not converging (a first-order error
#: halves; a chaotic run's difference stays about the same).
REDUCTION_MIN = 1.5

#: Past the horizon a candidate may differ from the reference by this many
#: times the spread (end energy, impact counts). The spread is the largest
#: of one or two draws of how far equally fine runs of an unpredictable
#: scene end apart; allowing only that would fail a run as good as the
#: check by the luck of the draw (runs of solvers that are all exact for
#: constant gravity differ by rounding alone, and land on either side of it).
SPREAD_FACTOR = 2.0

#: Default most steps of one reference run: 5 s of simulated time at a step
#: of 1e-5 s; the cap keeps a reference for a fine tolerance finite.
MAX_REFERENCE_STEPS = 2**19

#: Until a solver has a step that meets TOL, the search aims each predicted
#: step at this fraction of TOL: a margin for the error model's rough
#: constant and order, so that a prediction usually meets TOL the first
#: time. Once one meets TOL, a coarser step is aimed at TOL itself
#: (``PROBE_TARGET``): a miss then costs one run, and the bracket keeps the step found.
PREDICTION_TARGET = 0.7
PROBE_TARGET = 1.0

#: A solver's search stops when its largest step that meets TOL and its
#: smallest that does not are within this ratio (within 25 %).
BRACKET_RATIO = 1.25

#: Rounds of prediction after the first measurements: a first prediction,
#: and enough bisections to narrow a bracket of 4 to BRACKET_RATIO
#: (4 -> 2 -> 1.41 -> 1.19), with one to spare.
SEARCH_ROUNDS = 5

#: Wall-time repeats of each candidate run (the median is reported); the
#: reference's halvings are timed once (they are not candidates but for
#: the check).
TIMING_REPEATS = 3

REFERENCE_SOLVER, REFERENCE_LEVEL, REFERENCE_AABB = "rk4", "exact", "linear"

#: The box update tried with every level (see the module docstring).
CANDIDATE_AABB = "auto"

#: Collision levels from the coarsest (rank 0) to the finest.
LEVEL_RANK = {level: i for i, level in enumerate(COLLISION_LEVELS)}

#: The bundled scenes the report asks about (rigid bodies, no particles).
BUNDLED_RIGID_SCENES = ("bounce.toml", "head-on.toml", "mixed.toml", "spinning-cube.toml")

#: Tolerances (m) for the report's view of how the advice moves with TOL.
REPORT_TOLERANCES = (1e-2, 3e-3, 1e-3)

#: Stop reasons of the reference's halving.
CONVERGED, NOT_CONVERGING, BUDGET = "converged", "not converging", "budget"


# -- the steps tried ----------------------------------------------------------------------


@dataclass(frozen=True)
class Ladder:
    """The steps the advisor tries: ``interval / m`` for whole ``m`` >= 1,
    where ``interval`` is ``divisions`` of the scene's own steps (so the
    scene's step is ``m = divisions``) and divides the run into ``samples``
    sample intervals. Every step on it is a whole number of steps per sample
    and per run. Steps are computed in exact fractions of the scene's step,
    so ``step(divisions)`` is the scene's step to the bit."""

    scene_step: float
    divisions: int
    samples: int

    @classmethod
    def for_scene(cls, step: float, duration: float) -> Ladder:
        n = whole_steps(duration, step)
        most = max(1, int(SAMPLE_INTERVAL / step * (1.0 + 1e-9)))
        divisions = max(k for k in range(1, min(most, n) + 1) if n % k == 0)
        return cls(step, divisions, n // divisions)

    @property
    def interval(self) -> float:
        return float(Fraction(self.scene_step) * self.divisions)

    def step(self, m: int) -> float:
        return float(Fraction(self.scene_step) * self.divisions / m)

    def n_steps(self, m: int) -> int:
        return self.samples * m


@dataclass(frozen=True, order=True)
class Setting:
    """A point of the search: solver, ``m`` on the ladder, level, box update."""

    solver: str
    m: int
    level: str
    aabb: str

    def fidelity(self, ladder: Ladder) -> Fidelity:
        return Fidelity(self.solver, ladder.step(self.m), self.level, self.aabb)

    def force_evaluations(self, ladder: Ladder, bodies: int) -> int:
        """Known before the run: steps x stages x bodies (a lower bound of the proxy)."""
        return ladder.n_steps(self.m) * SOLVERS[self.solver].stages * bodies


# -- the records returned ------------------------------------------------------------------


@dataclass(frozen=True)
class RunRow:
    """One run tried, measured against the reference (a row of the table).

    Settings: ``solver``, ``step`` (s), ``level``, ``aabb``; ``roles`` why
    it ran ("reference", "check", "reference ladder", "own", "search",
    "geometry", "stricter": recommended at a stricter TOL, "confirmation":
    the next finer step of a run that met TOL) and "chance" (met TOL, but
    its next finer step did not: not recommended). Work: ``steps``,
    ``proxy`` = ``force_evaluations`` + ``narrow_phase_calls``,
    ``box_visits``; ``wall_seconds`` the median of ``wall_repeats``
    timings (noisy). Errors against the reference up to the
    horizon: ``position_error`` and ``event_error`` (m), ``events``
    ("equal": paired within TOL; "late": paired, some farther apart than
    TOL; "differ": an impact missing or extra), ``event_note`` the first
    difference; ``energy_drift`` the run's own end-minus-start energy and
    ``energy_gap`` its end energy minus the reference's, both fractions of
    the reference's energy scale; ``count_gap`` its impacts minus the
    reference's, per kind, over the whole run. ``error_ratio``: the largest
    of the position error and event error over TOL and the energy gap over
    its allowance (what the search's error model fits; infinite when the
    impacts do not pair). ``meets``: the run meets TOL (module docstring).
    """

    solver: str
    step: float
    level: str
    aabb: str
    roles: tuple[str, ...]
    steps: int
    proxy: int
    force_evaluations: int
    narrow_phase_calls: int
    box_visits: int
    wall_seconds: float
    wall_repeats: int
    position_error: float
    event_error: float
    events: str
    event_note: str
    energy_drift: float
    energy_gap: float
    count_gap: dict
    error_ratio: float
    meets: bool
    diverged: str | None

    def fidelity(self) -> Fidelity:
        return Fidelity(self.solver, self.step, self.level, self.aabb)


@dataclass(frozen=True)
class ReferenceRow:
    """The reference and how far it can be trusted.

    ``step`` and ``check_step`` (s): the reference's and its check's (twice
    it). ``converged`` (module docstring) and ``stop`` why the halving
    stopped ("converged", "not converging", "budget"). ``horizon`` (s): the
    last sample time up to which reference and check agree within TOL
    (the duration when they agree throughout). ``uncertainty`` (m): the
    largest of ``position_gap`` (reference against check, whole run),
    ``event_gap`` (their event times, as distances) and ``resolution`` (one
    reference step at the fastest impact's speed). ``energy_gap``: the
    check's end energy minus the reference's (fraction of the scale);
    ``count_gap``: the check's impacts minus the reference's, per kind.
    ``energy_spread`` and ``count_spread``: the largest such differences
    over the runs of the last comparison (the check, and the run at twice
    its step when the step was halved), the spread past the horizon.
    ``impacts``: the reference's, per kind. ``halvings``: ``(step,
    uncertainty, horizon)`` for each pair compared. ``aim``: the tolerance
    all of these are measured at: TOL itself, or the strictest of the
    tolerances that share this reference (:func:`advice_by_tolerance`).
    """

    solver: str
    step: float
    check_step: float
    level: str
    aabb: str
    converged: bool
    stop: str
    horizon: float
    uncertainty: float
    position_gap: float
    event_gap: float
    resolution: float
    energy_gap: float
    count_gap: dict
    energy_spread: float
    count_spread: dict
    impacts: dict
    halvings: tuple[tuple[float, float, float], ...]
    aim: float


@dataclass(frozen=True)
class Pruned:
    """A run not made: its force evaluations alone (``bound``) were no less
    than the proxy of the best run that met TOL at the time (``best``)."""

    solver: str
    step: float
    level: str
    aabb: str
    bound: int
    best: int


@dataclass(frozen=True)
class Advice:
    """What :func:`advise` found (plain records; :meth:`as_dict` for JSON).

    ``tolerance`` (m), ``duration`` (s, simulated; ``scene_duration`` the
    scene's own), ``sample_interval`` (s);
    ``energy_allowance``: the end-energy difference allowed, as a fraction
    of ``energy_scale`` (J); ``count_allowance``: per kind, the impact-count
    difference allowed (0 when the reference converged).
    ``recommended`` and ``own``: rows of ``runs`` (the scene's own settings
    may be the recommendation). ``proxy_saving`` = own proxy / recommended
    proxy, ``wall_saving`` likewise for the median wall times (a timing).
    ``runs``: every run made, in order; ``pruned``: runs not made;
    ``computed`` and ``resumed``: runs simulated now and read from the store.
    """

    scene: str
    tolerance: float
    duration: float
    scene_duration: float
    sample_interval: float
    energy_scale: float
    energy_allowance: float
    count_allowance: dict
    reference: ReferenceRow
    recommended: RunRow
    own: RunRow
    proxy_saving: float
    wall_saving: float
    runs: tuple[RunRow, ...]
    pruned: tuple[Pruned, ...] = ()
    computed: int = 0
    resumed: int = 0
    units: dict = field(default_factory=lambda: dict(UNITS))

    def as_dict(self) -> dict:
        """The advice as plain data (for ``--json``; keys documented in
        :data:`UNITS` and the record types)."""
        return asdict(self)


#: What each number of an :class:`Advice` is measured in.
UNITS: dict[str, str] = {
    "tolerance": "m",
    "step": "s",
    "duration": "s",
    "sample_interval": "s",
    "horizon": "s",
    "position_error": "m: largest distance between a body's points (position and orientation), "
                      "at the samples up to the horizon",
    "event_error": "m: largest |dt| x response speed over paired impacts up to the horizon",
    "energy_gap": "fraction of energy_scale: end energy minus the reference's",
    "energy_drift": "fraction of energy_scale: the run's end energy minus its start energy",
    "energy_allowance": "fraction of energy_scale: TOL / half_size, or SPREAD_FACTOR x the "
                        "reference's energy_spread when it has not converged, the larger",
    "energy_scale": "J: the reference's largest total energy",
    "proxy": "force evaluations x bodies + narrow-phase calls (machine-independent)",
    "wall_seconds": "s: median of wall_repeats runs (a timing; noisy on a shared machine)",
    "proxy_saving": "own proxy / recommended proxy",
    "wall_saving": "own wall_seconds / recommended wall_seconds (a timing)",
}


# -- running through the sweep ---------------------------------------------------------------


class _Runner:
    """The runs made so far, by setting; :meth:`run` makes the missing ones
    through one :func:`run_sweep` call (state: the runs, their roles)."""

    def __init__(self, scene: Scene, ladder: Ladder, *, duration: float, backend: str,
                 workers, scheduler, store, progress: bool, repeats: int):
        # every run replaces [integration] and [collision] (measure_run): left
        # out, so that a run's key and fingerprint depend on the physics alone
        data = scene_data(scene)
        self.data = {k: v for k, v in data.items() if k not in ("integration", "collision")}
        self.name = digest(canonical(self.data))[:12]      # the scene's content, in each key
        self.ladder = ladder
        self.duration = duration
        self.options = dict(backend=backend, workers=workers, scheduler=scheduler, store=store,
                            progress=progress)
        self.repeats = repeats
        self.runs: dict[Setting, metrics.Run] = {}
        self.roles: dict[Setting, list[str]] = {}
        self.computed = 0
        self.resumed = 0
        self.progress = progress
        self._started = self._said = time.monotonic()

    def run(self, wanted: list[tuple[Setting, str]], *, once=()) -> None:
        """Make the runs of ``wanted`` not made yet, timed ``repeats`` times
        (those in ``once``: once); note each one's role."""
        tasks, settings = [], []
        for setting, role in wanted:
            roles = self.roles.setdefault(setting, [])
            if role not in roles:
                roles.append(role)
            if setting in self.runs or setting in settings:
                continue
            repeats = 1 if setting in once else self.repeats
            fidelity = setting.fidelity(self.ladder)
            key = f"{self.name} {fidelity.label()} T={self.duration!r} x{repeats}"
            tasks.append(Task(key, measure_run, dict(
                scene=self.data, solver=setting.solver, step=fidelity.step,
                level=setting.level, aabb=setting.aabb, duration=self.duration,
                every=setting.m, repeats=repeats)))
            settings.append(setting)
        if not tasks:
            return
        result = run_sweep(tasks, **self.options)
        if not result.ok:
            key, reason = next(iter(result.failures.items()))
            raise SweepError(f"run {key.split(' ', 1)[1]!r} failed: {reason}")
        for setting, task_result in zip(settings, result.results, strict=True):
            self.runs[setting] = metrics.Run.from_record(task_result.value)
            self.resumed += task_result.resumed
            self.computed += not task_result.resumed
        self._say_progress()

    def _say_progress(self) -> None:
        """With progress on: a line on stderr after a round of runs, at most
        every ``LOG_SECONDS`` (and not in the first ones), with the runs made
        so far: each round's sweep shows only its own runs, and an advice
        takes many rounds."""
        from refsim.sweep.progress import LOG_SECONDS

        now = time.monotonic()
        if not self.progress or now - self._said < LOG_SECONDS:
            return
        self._said = now
        minutes, seconds = divmod(int(now - self._started), 60)
        print(f"advise: {self.computed + self.resumed} runs so far ({self.resumed} from the "
              f"store), {minutes}:{seconds:02d} elapsed", file=sys.stderr, flush=True)


# -- the reference ------------------------------------------------------------------------


@dataclass(frozen=True)
class _Reference:
    """The reference, its check and what the comparison of the two allows."""

    run: metrics.Run
    setting: Setting
    check: Setting
    row: ReferenceRow
    scale: float
    energy_allowance: float
    count_allowance: dict


def _find_reference(runner: _Runner, tolerance: float, max_steps: int,
                    first: list[tuple[Setting, str]], aim: float) -> _Reference:
    """Halve the reference's step until it converges, stops converging or
    reaches the budget at the tolerance ``aim`` (module docstring, 1). The
    horizon and the allowances past it are ``aim``'s; only the energy
    allowance grows with ``tolerance`` (>= ``aim``: advice at several
    tolerances shares the reference of the strictest). ``first``: runs to
    make along with the first pair (the search's first round), so that one
    sweep runs them all."""
    ladder = runner.ladder
    m = ladder.divisions * REFERENCE_START
    if ladder.n_steps(2 * m) > max_steps:
        m = max_steps // (2 * ladder.samples)
        if m < 1:
            raise OptionError(f"max_reference_steps = {max_steps} is too few: the reference "
                              f"needs at least {2 * ladder.samples} steps "
                              f"({ladder.samples} samples of the run)")

    def ref(k: int) -> Setting:
        return Setting(REFERENCE_SOLVER, k, REFERENCE_LEVEL, REFERENCE_AABB)

    runner.run([(ref(m), "reference ladder"), (ref(2 * m), "reference ladder"), *first],
               once={ref(m), ref(2 * m)})
    halvings = []
    H = float(runner.data["world"]["half_size"])
    end = runner.duration                   # (a reference that diverged ends before it)

    def gaps(fine: metrics.Run, coarse: metrics.Run, h: float, scale: float, tol: float):
        horizon = metrics.agreement_horizon(fine, coarse, tol)
        position_gap = float(metrics.distances(fine, coarse).max())
        events = metrics.compare_events(fine, coarse, tol, end)
        event_gap = events.error if events.paired else math.inf
        fastest = max((e.speed for e in metrics.impacts(fine) if e.time <= horizon), default=0.0)
        resolution = fastest * h
        energy_gap = metrics.energy_drift(coarse, scale) - metrics.energy_drift(fine, scale)
        # all four as distances: the energy's by its allowance TOL / H (fidelity_metrics)
        uncertainty = max(position_gap, event_gap, resolution, abs(energy_gap) * H)
        return horizon, position_gap, event_gap, resolution, energy_gap, uncertainty

    while True:
        fine, coarse = runner.runs[ref(2 * m)], runner.runs[ref(m)]
        h = ladder.step(2 * m)
        scale = metrics.energy_scale(fine)
        horizon, position_gap, event_gap, resolution, energy_gap, uncertainty = gaps(
            fine, coarse, h, scale, aim)
        halvings.append((h, uncertainty, horizon))
        if uncertainty <= REFERENCE_SHARE * aim and horizon >= end * (1 - 1e-12):
            stop = CONVERGED
            break
        # halving did not help: the difference shrank by less than REDUCTION_MIN,
        # or the impacts still do not pair (an infinite difference)
        if len(halvings) > 1 and (math.isinf(uncertainty)
                                  or uncertainty * REDUCTION_MIN > halvings[-2][1]):
            stop = NOT_CONVERGING
            break
        if ladder.n_steps(4 * m) > max_steps:
            stop = BUDGET
            break
        m *= 2
        runner.run([(ref(2 * m), "reference ladder")], once={ref(2 * m)})

    reference, check = ref(2 * m), ref(m)
    runner.roles[reference] = ["reference"]
    runner.roles[check] = ["check"]
    converged = horizon >= end * (1 - 1e-12) and uncertainty <= aim
    ours, theirs = metrics.impact_counts(fine), metrics.impact_counts(coarse)
    count_gap = {k: theirs[k] - ours[k] for k in metrics.KINDS}
    # The spread past the horizon: how far the runs of the last comparison
    # (the check, and the run at twice its step when there was one) end from
    # the reference (module docstring, 1).
    drawn = [coarse] + ([runner.runs[ref(m // 2)]] if len(halvings) > 1 else [])
    energy_spread = max(abs(metrics.energy_drift(r, scale) - metrics.energy_drift(fine, scale))
                        for r in drawn)
    count_spread = {k: max(abs(metrics.impact_counts(r)[k] - ours[k]) for r in drawn)
                    for k in metrics.KINDS}
    if converged:
        count_allowance = dict.fromkeys(metrics.KINDS, 0)
        energy_allowance = tolerance / H
    else:
        count_allowance = {k: max(math.ceil(SPREAD_FACTOR * count_spread[k]),
                                  math.ceil(math.sqrt(ours[k])))
                           for k in metrics.KINDS}
        energy_allowance = max(tolerance / H, SPREAD_FACTOR * energy_spread)
    row = ReferenceRow(
        solver=REFERENCE_SOLVER, step=h, check_step=ladder.step(m), level=REFERENCE_LEVEL,
        aabb=REFERENCE_AABB, converged=converged, stop=stop,
        horizon=horizon, uncertainty=uncertainty, position_gap=position_gap,
        event_gap=event_gap, resolution=resolution, energy_gap=energy_gap,
        count_gap=count_gap, energy_spread=energy_spread, count_spread=count_spread,
        impacts=ours, halvings=tuple(halvings), aim=aim)
    return _Reference(run=fine, setting=reference, check=check, row=row, scale=scale,
                      energy_allowance=energy_allowance, count_allowance=count_allowance)


# -- judging a run ------------------------------------------------------------------------


@dataclass(frozen=True)
class _Verdict:
    comparison: metrics.Comparison
    ratio: float          # what the error model fits; inf when impacts do not pair
    meets: bool


def _judge(run: metrics.Run, ref: _Reference, tolerance: float) -> _Verdict:
    """Measure ``run`` against the reference (module docstring: meets TOL)."""
    c = metrics.compare(ref.run, run, tolerance, ref.row.horizon, ref.scale)
    ratio = max(c.position_error / tolerance, c.events.error / tolerance,
                abs(c.energy_gap) / ref.energy_allowance)
    if run.diverged is not None or not c.events.paired:
        ratio = math.inf
    # counts matter past the horizon only: before it the impacts are paired one by one
    counts_ok = ref.row.converged or all(abs(c.count_gap[k]) <= ref.count_allowance[k]
                                         for k in metrics.KINDS)
    meets = (run.diverged is None and c.events.agree and counts_ok
             and c.position_error <= tolerance and c.events.error <= tolerance
             and abs(c.energy_gap) <= ref.energy_allowance)
    return _Verdict(c, ratio, meets)


def _rank(setting: Setting, run: metrics.Run):
    """Sort key of a run that meets TOL: proxy, then box visits, then the
    coarser level, the larger step, the solver's name (module docstring, 2)."""
    return (run.proxy, run.box_visits, LEVEL_RANK[setting.level], setting.aabb != "auto",
            setting.m, setting.solver)


# -- the search ---------------------------------------------------------------------------


def _bracket(measured: list[tuple[int, float, bool]]) -> tuple[int, float]:
    """``(m_fail, m_pass)`` of ``(m, ratio, meets)`` measurements: the
    largest step meeting TOL is ``m_pass`` (infinite when none does), the
    smallest step above it that does not is ``m_fail`` (0 when none)."""
    meeting = [m for m, _, ok in measured if ok]
    m_pass = min(meeting) if meeting else math.inf
    failing = [m for m, _, ok in measured if not ok and m < m_pass]
    return (max(failing) if failing else 0), m_pass


def _last_chance(measured: list[tuple[int, float, bool]], passing: set[int],
                 m_max: int) -> int | None:
    """The last run of a solver whose predicted step costs too much (module
    docstring, 3): the coarsest step at which any solver met TOL, or else
    the finest step that could still cost less than the best (``m_max``),
    inside the solver's bracket and not measured yet; None when there is none.
    Another solver's step comes first because solvers that are exact between
    contacts (all but Euler's for constant forces) give the same run at the
    same step."""
    m_fail, m_pass = _bracket(measured)
    tried = {m for m, _, _ in measured}
    for m in sorted(passing) + [m_max]:
        if m_fail < m < m_pass and m <= m_max and m not in tried:
            return m
    return None


def _propose(solver: str, measured: list[tuple[int, float, bool]],
             m_max: int | None = None) -> int | None:
    """The next ``m`` to run for ``solver`` from its ``(m, ratio, meets)``
    measurements, at most ``m_max`` (None: no bound), or None when its search
    is done (module docstring, 3)."""
    order = max(1, SOLVERS[solver].order)
    meeting = [m for m, _, ok in measured if ok]
    target = PROBE_TARGET if meeting else PREDICTION_TARGET
    m_fail, m_pass = _bracket(measured)
    if meeting and m_fail and m_pass / m_fail <= BRACKET_RATIO:
        return None
    usable = sorted((m, r) for m, r, _ in measured if math.isfinite(r))
    if not usable:
        proposal = 2 * max(m for m, _, _ in measured)       # no error to fit: halve the step
    else:
        p: float = order
        positive = [(m, r) for m, r in usable if r > 0.0]
        if len(positive) >= 2:
            (m1, r1), (m2, r2) = positive[-2:]               # the two finest steps measured
            observed = math.log(r1 / r2) / math.log(m2 / m1)
            p = min(order, max(1.0, observed)) if math.isfinite(observed) else 1.0
        elif order > 1:
            p = 1.0                          # one measurement: assume contacts limit the order
        # extrapolate from the bracket's edge: the largest step meeting TOL, or
        # while none does, the finest step measured (the nearest to meeting it)
        m_a, r_a = (next(mr for mr in usable if mr[0] == m_pass) if meeting
                    else max(usable))
        if r_a == 0.0:
            proposal = 1                                     # exact: the longest step
        else:
            proposal = math.ceil(m_a * (r_a / target) ** (1.0 / p) * (1.0 - 1e-12))
    if meeting and m_fail and not m_fail < proposal < m_pass:
        # the model points outside the bracket: bisect it (on a log scale)
        proposal = round(math.sqrt(m_fail * m_pass))
    if m_max is not None:
        proposal = min(proposal, m_max)
    proposal = max(proposal, m_fail + 1)
    if proposal >= m_pass or (m_max is not None and proposal > m_max):
        return None
    if any(m == proposal for m, _, _ in measured):
        return None
    return proposal


def advise(scene, tolerance: float = DEFAULT_TOLERANCE, *, duration: float | None = None,
           backend: str = "inprocess", workers: int | None = None,
           scheduler: str | None = None, store=None, progress: bool = False,
           repeats: int = TIMING_REPEATS,
           max_reference_steps: int = MAX_REFERENCE_STEPS,
           reference_tolerance: float | None = None,
           candidates: Sequence[Fidelity] = ()) -> Advice:
    """The cheapest fidelity settings of ``scene`` whose run stays within
    ``tolerance`` of the reference (the module docstring explains each step).

    Parameters
    ----------
    scene : refsim.Scene or str or PathLike
        A loaded scene, or a scene file (a bare name finds a bundled scene).
        Rigid bodies only (no ``[particles]``).
    tolerance : float
        TOL in metres (> 0, finite); times and energy by the conversions of
        :mod:`refsim.studies.fidelity_metrics`.
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
        The most steps of one reference run (module docstring, 1).
    reference_tolerance : float, optional
        The tolerance the reference's halving aims at and its horizon and
        allowances past the horizon are measured at, at most ``tolerance``
        (default: ``tolerance``). Advice at several tolerances shares the
        reference of the strictest (:func:`advice_by_tolerance`).
    candidates : sequence of Fidelity
        Settings run and judged along with the search's (the
        recommendations at stricter tolerances: module docstring, 3); each
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
    runner = _Runner(scene, ladder, duration=duration, backend=backend, workers=workers,
                     scheduler=scheduler, store=store, progress=progress, repeats=repeats)
    B = len(scene.bodies)
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
    ref = _find_reference(runner, tolerance, max_reference_steps, first[1:], aim)

    verdicts: dict[Setting, _Verdict] = {}

    def verdict(setting: Setting) -> _Verdict:
        if setting not in verdicts:
            verdicts[setting] = _judge(runner.runs[setting], ref, tolerance)
        return verdicts[setting]

    def made():
        return [s for s in runner.runs if s != ref.setting]

    def best_proxy() -> int:
        meeting = [s for s in made() if verdict(s).meets]
        return min(runner.runs[s].proxy for s in meeting)

    # Integration search (module docstring, 3), at the reference's level and boxes.
    pruned: dict[Setting, Pruned] = {}          # the last time each was pruned
    for _ in range(SEARCH_ROUNDS):
        best = best_proxy()
        wanted = []
        for name in SOLVERS:
            measured = [(s.m, verdict(s).ratio, verdict(s).meets) for s in made()
                        if (s.solver, s.level, s.aabb) == (name, REFERENCE_LEVEL,
                                                           REFERENCE_AABB)]
            m = _propose(name, measured) if measured else None
            if m is None:
                continue
            per_m = ladder.n_steps(1) * SOLVERS[name].stages * B   # force evaluations / m
            if m * per_m >= best:
                pruned[Setting(name, m, REFERENCE_LEVEL, REFERENCE_AABB)] = Pruned(
                    name, ladder.step(m), REFERENCE_LEVEL, REFERENCE_AABB, m * per_m, best)
                passing = {s.m for s in made() if verdict(s).meets
                           and (s.level, s.aabb) == (REFERENCE_LEVEL, REFERENCE_AABB)}
                m = _last_chance(measured, passing, (best - 1) // per_m)
                if m is None:
                    continue
            wanted.append((Setting(name, m, REFERENCE_LEVEL, REFERENCE_AABB), "search"))
        if not wanted:
            break
        runner.run(wanted)

    # Geometry at the best integration (module docstring, 3).
    integration = min((s for s in made() if verdict(s).meets
                       and (s.level, s.aabb) == (REFERENCE_LEVEL, REFERENCE_AABB)),
                      key=lambda s: _rank(s, runner.runs[s]))
    body_stage = B >= 2 and scene.dynamics.body_response != "off"
    levels = COLLISION_LEVELS if body_stage else ("none",)
    runner.run([(Setting(integration.solver, integration.m, level, CANDIDATE_AABB), "geometry")
                for level in levels])

    # Confirmation (module docstring, 3): the cheapest run that meets TOL and
    # whose next finer step on the ladder meets it too.
    chosen = None
    for s in sorted((s for s in made() if verdict(s).meets),
                    key=lambda s: _rank(s, runner.runs[s])):
        if s == ref.check:
            chosen = s                  # meets by construction, against the reference
            break
        finer = replace(s, m=s.m + 1)
        runner.run([(finer, "confirmation")])
        if verdict(finer).meets:
            chosen = s
            break
        runner.roles[s].append("chance")
    assert chosen is not None           # the check is among the runs that meet TOL
    rows = {s: _row(s, runner, ref, verdict(s) if s != ref.setting else None)
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


def _row(setting: Setting, runner: _Runner, ref: _Reference, v: _Verdict | None) -> RunRow:
    """The table row of one run (``v`` None for the reference itself)."""
    run = runner.runs[setting]
    fidelity = setting.fidelity(runner.ladder)
    if v is None:
        zero = metrics.Comparison(0.0, metrics.EventAgreement(True, True, 0.0, None, ""), 0.0,
                                  dict.fromkeys(metrics.KINDS, 0))
        v = _Verdict(zero, 0.0, True)
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


# -- for the report ------------------------------------------------------------------------


@dataclass(frozen=True)
class ToleranceSeries:
    """How the advice for one scene moves with TOL: one :class:`Advice` per
    tolerance, in the order asked."""

    scene: str
    tolerances: tuple[float, ...]
    advice: tuple[Advice, ...]


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
