"""The records of the fidelity advisor: the four settings it varies
(:class:`Fidelity`) and what :func:`refsim.advisor.advice.advise` returns,
plain frozen dataclasses that :meth:`Advice.as_dict` turns into JSON-ready
data.

The words "meets TOL", "reference", "check", "horizon" and "spread" are
defined in docs/advisor.md.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field


@dataclass(frozen=True)
class Fidelity:
    """The four choices the advisor varies; everything else in a scene is
    physics and stays as the scene has it.

    ``solver``: a key of :data:`refsim.SOLVERS`; ``step``: seconds;
    ``level``: a collision level ("none" .. "exact"); ``aabb``: the box
    update ("linear" | "incremental" | "auto").
    """

    solver: str
    step: float
    level: str
    aabb: str

    def label(self) -> str:
        """``"rk4 h=0.00025 exact linear"``: one line for tables and keys."""
        return f"{self.solver} h={self.step!r} {self.level} {self.aabb}"


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
    impacts do not pair). ``meets``: the run meets TOL (docs/advisor.md).
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
    it). ``converged`` (docs/advisor.md) and ``stop`` why the halving
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
    tolerances that share this reference
    (:func:`~refsim.advisor.advice.advice_by_tolerance`).
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
    """What :func:`~refsim.advisor.advice.advise` found (plain records;
    :meth:`as_dict` for JSON).

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


@dataclass(frozen=True)
class ToleranceSeries:
    """How the advice for one scene moves with TOL: one :class:`Advice` per
    tolerance, in the order asked."""

    scene: str
    tolerances: tuple[float, ...]
    advice: tuple[Advice, ...]
