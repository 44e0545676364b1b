"""How far one run of a scene is from another: positions, events, energy.

What: the advisor (:mod:`refsim.advisor`) measures every candidate
run against a reference run with these functions; it also measures the
reference against its check run (the same at twice the step) with them, to
find how long the reference is predictable (:func:`agreement_horizon`).
Runs are the records of :func:`refsim.advisor.runs.measure_run`,
decoded by :meth:`Run.from_record`; both runs are sampled on one grid of
times.

One tolerance TOL, in metres, covers all three measures:

- **Positions.** How far a body's points are from where the other run has
  them: over the bodies and the common sample times up to the horizon, the
  largest ``|dx| + r |R_a - R_b|_F / sqrt(2)``, with ``dx`` the difference
  of the reported positions, ``R_a``, ``R_b`` the orientations and ``r``
  the body's radius about its reported position. For two rotations,
  ``|R_a - R_b|_F / sqrt(2) = 2 sin(theta / 2)``, the chord that a point
  at unit distance from the axis of the rotation ``R_a^T R_b`` (angle
  theta) moves; so this is the largest distance any point of the body can
  be apart, attained by a point at the radius, perpendicular to the axis,
  when the two differences line up. Without it a run whose orientation is
  wrong (the seed's rotation step is of first order) would count as right
  until a contact showed it. With ``rotation = "off"`` it is the distance
  of the reported positions. Metres, compared with TOL as it is, at the
  sample times. Between them, the instants around a contact that the two
  runs respond to at different steps are judged by the event times (next
  item); but a response that moves a body at once (the wall push-back, the
  corrected model's push-apart of two bodies, DEVIATION D5) is a jump of
  position, and between the two runs' jumps they are the jump's size
  apart whatever the step, for less than a step of the coarser run. Such
  instants are not counted (a sample that falls on one is).
- **Event times.** A contact is found at the end of the step in which it
  began, so its time is known to one step. When two runs respond to the
  same contact ``dt`` apart, the run that responded first moves on with the
  changed velocity while the other still moves with the old one, until it
  responds too: the timing difference alone can put them up to ``u dt``
  apart, ``u`` the **response speed** (the largest change of a point's
  velocity that the response made, :mod:`refsim.advisor.runs`).
  So two events "agree within TOL" when ``|t_a - t_b| * u <= TOL``: a time
  difference is judged by the largest distance it can put between the
  runs, in the same metres as the positions, and a hard impact needs a
  finer step than a gentle one, as it should. The same product is the
  event error reported (metres). It is a bound: the later run's push-back
  out of the wall takes back part of it, and what stays between the runs
  after both responded (about ``e v dt`` for a wall bounce) is what the
  positions measure at the next sample (docs/decisions/advisor-metrics.md
  has both, measured).
- **Energy.** The total mechanical energy at the end of the run
  (:meth:`refsim.Simulation.energy`, summed over bodies), as a fraction of the
  reference's largest energy. The advisor allows ``TOL / H`` (``H`` the
  cube's half size): the energy of raising every body by TOL, relative to
  the energy of bodies raised through the cube, the same fraction of the
  scene's scale as TOL is of the cube's.

Events that are not impacts. A body at rest on the floor touches it again
and again (each step's gravity carries it a little into the floor); how
often depends on the step, and so the count of such contacts never
converges. A contact whose response speed is below ``REST_SPEED`` is a
resting contact: it is not required to have a twin in the other run (its
timing moves nothing by more than ``REST_SPEED`` times the time). An
extra contact in the other run is excused below ``EXCUSE_FACTOR`` times
that speed, so that an impact just above the boundary in one run and just
below it in the other is not called a mismatch.

Pairing. Events are compared per channel (kind, body, other): the i-th
required event of a channel pairs with the nearest event of the same
channel in the other run, in order; every event skipped on the way must be
a resting one. Comparing per channel rather than as one global list keeps
two events of different bodies that happen within their tolerance of each
other from being called out of order when the runs find them in the other
order, which says nothing about either run's accuracy. Pairs may be up to
``PAIRING_WINDOW`` tolerances apart, so that a late event is measured (its
error helps predict the step that fixes it) rather than only called missing.
An event within its own time tolerance of the end of the compared window
may fall on either side of it and is not required.

Cost: O(S B) for S samples of B bodies, O(E log E) for E events.
"""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from refsim.dynamics.impulse import RESTITUTION_THRESHOLD

#: Response speed (m/s) below which a contact is a resting contact, not an
#: impact: the corrected model's own boundary between a bounce and resting
#: contact (DEVIATION D6), the speed of a body falling for 5 ms.
REST_SPEED = RESTITUTION_THRESHOLD

#: An unpaired event in the other run is excused below this many times
#: REST_SPEED (hysteresis across the boundary, see the module docstring).
EXCUSE_FACTOR = 2.0

#: How many time tolerances apart two events may be and still be paired.
#: Beyond it an event is missing; within it a late event is measured. 16
#: covers the late events of a step up to 16 times too coarse.
PAIRING_WINDOW = 16.0

#: Event kinds, as :class:`refsim.dynamics.trajectory.Event` names them.
KINDS = ("wall", "body")


@dataclass(frozen=True)
class RunEvent:
    """One event of a run with its response speed (m/s)."""

    kind: str
    body: str
    other: str
    step: int
    time: float
    speed: float

    @property
    def channel(self) -> tuple[str, str, str]:
        return (self.kind, self.body, self.other)

    def describe(self) -> str:
        """``"wall ball y-"`` or ``"body left-right"``."""
        joint = " " if self.kind == "wall" else "-"
        return f"{self.kind} {self.body}{joint}{self.other}"


@dataclass(frozen=True)
class Run:
    """A decoded run record (:func:`refsim.advisor.runs.measure_run`).

    Arrays for S samples of B bodies: ``t`` (S,), ``position`` (S, B, 3),
    ``orientation`` (S, B, 3, 3), ``radius`` (B,), ``energy`` (S,).
    ``steps`` is the number of steps taken (fewer than asked when the run
    diverged; ``diverged`` then says where).
    """

    t: np.ndarray
    position: np.ndarray
    orientation: np.ndarray
    radius: np.ndarray
    energy: np.ndarray
    events: tuple[RunEvent, ...]
    steps: int
    bodies: int
    force_evaluations: int
    narrow_phase_calls: int
    box_visits: int
    diverged: dict | None
    wall_seconds: tuple[float, ...]

    @classmethod
    def from_record(cls, record: dict) -> Run:
        B = int(record["bodies"])
        position = np.asarray(record["position"], dtype=np.float64).reshape(-1, B, 3)
        orientation = np.asarray(record["orientation"], dtype=np.float64).reshape(-1, B, 3, 3)
        return cls(t=np.asarray(record["t"], dtype=np.float64), position=position,
                   orientation=orientation,
                   radius=np.asarray(record["radius"], dtype=np.float64).reshape(B),
                   energy=np.asarray(record["energy"], dtype=np.float64),
                   events=tuple(RunEvent(*e) for e in record["events"]),
                   steps=int(record["steps"]), bodies=B,
                   force_evaluations=int(record["force_evaluations"]),
                   narrow_phase_calls=int(record["narrow_phase_calls"]),
                   box_visits=int(record["box_visits"]), diverged=record["diverged"],
                   wall_seconds=tuple(record["wall_seconds"]))

    @property
    def proxy(self) -> int:
        """The machine-independent cost: force evaluations times bodies plus
        narrow-phase calls (docs/advisor.md argues the weights)."""
        return self.force_evaluations + self.narrow_phase_calls


def impacts(run: Run) -> list[RunEvent]:
    """The events of ``run`` that are impacts, not resting contacts."""
    return [e for e in run.events if e.speed >= REST_SPEED]


def energy_scale(reference: Run) -> float:
    """The energy that relative energy errors are fractions of: the
    reference's largest total energy (J), or 1 J for a scene with none (no
    gravity, nothing moving: every energy is then 0)."""
    largest = float(np.max(reference.energy)) if reference.energy.size else 0.0
    return largest if largest > 0.0 else 1.0


def energy_drift(run: Run, scale: float) -> float:
    """``(E(end) - E(0)) / scale``: the run's energy change, a fraction of
    ``scale``; infinite for a run that diverged."""
    if run.diverged is not None:
        return math.inf
    return float((run.energy[-1] - run.energy[0]) / scale)


def distances(reference: Run, other: Run) -> np.ndarray:
    """(S,) at each of the reference's S sample times, the largest distance
    between a body's points in the two runs (the module docstring's bound);
    infinite where ``other`` has no sample (it diverged before it)."""
    S = len(reference.t)
    n = min(S, len(other.t))
    gap = np.full(S, np.inf)
    d = reference.position[:n] - other.position[:n]                    # (n, B, 3)
    dR = reference.orientation[:n] - other.orientation[:n]             # (n, B, 3, 3)
    chord = np.sqrt((dR * dR).sum(axis=(2, 3)) / 2.0)                  # 2 sin(theta / 2)
    gap[:n] = (np.sqrt((d * d).sum(axis=2)) + chord * reference.radius).max(axis=1)
    return gap


@dataclass(frozen=True)
class EventAgreement:
    """How the events of two runs compare, up to a time (see the module
    docstring).

    ``agree``: every required event paired within its tolerance and no
    unexcused extra event. ``paired``: every required event has a twin
    within the pairing window and nothing unexcused is extra (the times may
    still be too far apart). ``error``: the largest ``|dt| * speed`` over
    the pairs, metres (0 with no pairs). ``failure_time``: the earliest time
    at which they stop agreeing, or None. ``note``: the first disagreement in
    words, or "".
    """

    agree: bool
    paired: bool
    error: float
    failure_time: float | None
    note: str


def compare_events(reference: Run, other: Run, tolerance: float,
                   until: float) -> EventAgreement:
    """Pair the impacts of ``reference`` up to time ``until`` with the events
    of ``other`` (the module docstring); TOL ``tolerance`` in metres."""
    excuse = EXCUSE_FACTOR * REST_SPEED
    required: dict[tuple, list[RunEvent]] = defaultdict(list)
    for e in reference.events:
        if e.time <= until and e.speed >= REST_SPEED:
            required[e.channel].append(e)
    offered: dict[tuple, list[RunEvent]] = defaultdict(list)
    for e in other.events:
        offered[e.channel].append(e)
    failures: list[tuple[float, str]] = []
    paired = True
    error = 0.0

    def edge(e: RunEvent, speed: float) -> bool:
        """Within its own time tolerance of the window's end."""
        return e.time + tolerance / max(speed, REST_SPEED) >= until

    for channel in sorted(set(required) | set(offered)):
        theirs = offered.get(channel, [])
        j = 0
        for r in required.get(channel, []):
            tol_t = tolerance / r.speed
            window = [k for k in range(j, len(theirs))
                      if abs(theirs[k].time - r.time) <= PAIRING_WINDOW * tol_t]
            if not window:
                if edge(r, r.speed):
                    continue
                failures.append((r.time, f"missing {r.describe()} at {r.time:.6g} s"))
                paired = False
                break                     # later pairs of this channel would be guesses
            k = min(window, key=lambda i: abs(theirs[i].time - r.time))
            for skipped in theirs[j:k]:
                if skipped.speed >= excuse and skipped.time <= until:
                    failures.append((skipped.time, f"extra {skipped.describe()} at "
                                                   f"{skipped.time:.6g} s"))
                    paired = False
            dt = abs(theirs[k].time - r.time)
            error = max(error, dt * r.speed)
            if dt * r.speed > tolerance:
                failures.append((min(r.time, theirs[k].time),
                                 f"{r.describe()} at {theirs[k].time:.6g} s, not "
                                 f"{r.time:.6g} s ({dt * r.speed:.3g} m at {r.speed:.3g} m/s)"))
            j = k + 1
        else:
            for extra in theirs[j:]:
                if extra.speed >= excuse and extra.time <= until and not edge(extra,
                                                                               extra.speed):
                    failures.append((extra.time, f"extra {extra.describe()} at "
                                                 f"{extra.time:.6g} s"))
                    paired = False
    if not failures:
        return EventAgreement(True, True, error, None, "")
    first = min(failures)
    return EventAgreement(False, paired, error, first[0], first[1])


def impact_counts(run: Run) -> dict[str, int]:
    """The number of impacts of each kind over the whole run."""
    counts = dict.fromkeys(KINDS, 0)
    for e in impacts(run):
        counts[e.kind] += 1
    return counts


@dataclass(frozen=True)
class Comparison:
    """A run measured against a reference up to the horizon.

    ``position_error``: metres, the largest distance over the samples up to
    the horizon (infinite when the run diverged before it). ``events``: the
    :class:`EventAgreement` up to the horizon. ``energy_gap``: the run's
    end energy minus the reference's, a fraction of the reference's energy
    scale (signed; infinite for a diverged run). ``count_gap``: per kind, the
    run's impacts minus the reference's over the whole run.
    """

    position_error: float
    events: EventAgreement
    energy_gap: float
    count_gap: dict[str, int]


def compare(reference: Run, run: Run, tolerance: float, horizon: float,
            scale: float) -> Comparison:
    """Measure ``run`` against ``reference`` (see the module docstring)."""
    d = distances(reference, run)
    upto = reference.t <= horizon
    position_error = float(d[upto].max()) if upto.any() else 0.0
    events = compare_events(reference, run, tolerance, horizon)
    if run.diverged is not None:
        gap = math.inf
    else:
        gap = float((run.energy[-1] - reference.energy[-1]) / scale)
    ours, theirs = impact_counts(run), impact_counts(reference)
    return Comparison(position_error, events, gap,
                      {kind: ours[kind] - theirs[kind] for kind in KINDS})


def agreement_horizon(reference: Run, check: Run, tolerance: float) -> float:
    """The last sample time up to which ``reference`` and ``check`` agree:
    every body within ``tolerance`` metres of its twin at every sample, and
    the events paired within their time tolerance. The end of the run when
    they agree throughout; 0 when they disagree before the first sample
    after the start."""
    end = float(reference.t[-1])
    d = distances(reference, check)
    over = np.flatnonzero(d > tolerance)
    first = float(reference.t[over[0]]) if over.size else math.inf
    events = compare_events(reference, check, tolerance, end)
    if events.failure_time is not None:
        first = min(first, events.failure_time)
    if first == math.inf:
        return end
    before = reference.t[reference.t < first]
    return float(before[-1]) if before.size else 0.0
