"""The advisor's search: the rounds that look for the cheapest run that
meets TOL, once the reference is known (docs/advisor.md, The search).

- :func:`search_integration`: solver and step, at the reference's level and
  boxes; each solver's next step is predicted from its measured errors
  (:func:`propose`), and a run that cannot beat the best one found is
  pruned, with a last chance for its solver (:func:`last_chance`);
- :func:`search_geometry`: each collision level once, at the best
  integration found;
- :func:`confirm`: the cheapest run that meets TOL and whose next finer
  step meets it too.

:class:`Judged` holds what the rounds share: the runs made, each judged
against the reference once.
"""

from __future__ import annotations

import math
from dataclasses import replace

from refsim.advisor import metrics
from refsim.advisor.records import Pruned
from refsim.advisor.reference import (
    REFERENCE_AABB,
    REFERENCE_LEVEL,
    Reference,
    Verdict,
    judge,
)
from refsim.advisor.runner import Runner, Setting
from refsim.scenes.schema import COLLISION_LEVELS, Scene
from refsim.solvers.methods import SOLVERS

#: Until a solver has a step that meets TOL, the search aims each predicted
#: step at this fraction of TOL: a margin for the error model's rough
#: constant and order, so that a prediction usually meets TOL the first
#: time. Once one meets TOL, a coarser step is aimed at TOL itself
#: (``PROBE_TARGET``): a miss then costs one run, and the bracket keeps the
#: step found.
PREDICTION_TARGET = 0.7
PROBE_TARGET = 1.0

#: A solver's search stops when its largest step that meets TOL and its
#: smallest that does not are within this ratio (within 25 %).
BRACKET_RATIO = 1.25

#: Rounds of prediction after the first measurements: a first prediction,
#: and enough bisections to narrow a bracket of 4 to BRACKET_RATIO
#: (4 -> 2 -> 1.41 -> 1.19), with one to spare.
SEARCH_ROUNDS = 5

#: The box update tried with every level: it changes no result, only the
#: vertex visits (docs/advisor.md, Geometry).
CANDIDATE_AABB = "auto"

#: Collision levels from the coarsest (rank 0) to the finest.
LEVEL_RANK = {level: i for i, level in enumerate(COLLISION_LEVELS)}


class Judged:
    """The runs made so far, other than the reference itself, each judged
    against the reference once (:func:`~refsim.advisor.reference.judge`),
    when first asked."""

    def __init__(self, runner: Runner, ref: Reference, tolerance: float):
        self.runner = runner
        self.ref = ref
        self.tolerance = tolerance
        self._verdicts: dict[Setting, Verdict] = {}

    def verdict(self, setting: Setting) -> Verdict:
        """The run of ``setting`` (made) measured against the reference."""
        if setting not in self._verdicts:
            self._verdicts[setting] = judge(self.runner.runs[setting], self.ref, self.tolerance)
        return self._verdicts[setting]

    def made(self) -> list[Setting]:
        """Every run made but the reference, in the order made."""
        return [s for s in self.runner.runs if s != self.ref.setting]

    def meeting(self) -> list[Setting]:
        """The runs made that meet TOL, in the order made."""
        return [s for s in self.made() if self.verdict(s).meets]

    def best_proxy(self) -> int:
        """The least proxy of the runs that meet TOL (the check always does)."""
        return min(self.runner.runs[s].proxy for s in self.meeting())

    def sort_key(self, setting: Setting):
        """The order of cost of a run made (:func:`rank`)."""
        return rank(setting, self.runner.runs[setting])


def rank(setting: Setting, run: metrics.Run):
    """Sort key of a run that meets TOL: proxy, then box visits, then the
    coarser level, the larger step, the solver's name (docs/advisor.md, Cost)."""
    return (run.proxy, run.box_visits, LEVEL_RANK[setting.level], setting.aabb != "auto",
            setting.m, setting.solver)


def bracket(measured: list[tuple[int, float, bool]]) -> tuple[int, float]:
    """``(m_fail, m_pass)`` of ``(m, ratio, meets)`` measurements: the
    largest step meeting TOL is ``m_pass`` (infinite when none does), the
    smallest step above it that does not is ``m_fail`` (0 when none)."""
    meeting = [m for m, _, ok in measured if ok]
    m_pass = min(meeting) if meeting else math.inf
    failing = [m for m, _, ok in measured if not ok and m < m_pass]
    return (max(failing) if failing else 0), m_pass


def last_chance(measured: list[tuple[int, float, bool]], passing: set[int],
                 m_max: int) -> int | None:
    """The last run of a solver whose predicted step costs too much
    (docs/advisor.md, Branch and bound): the coarsest step at which any solver met TOL, or else
    the finest step that could still cost less than the best (``m_max``),
    inside the solver's bracket and not measured yet; None when there is none.
    Another solver's step comes first because solvers that are exact between
    contacts (all but Euler's for constant forces) give the same run at the
    same step."""
    m_fail, m_pass = bracket(measured)
    tried = {m for m, _, _ in measured}
    for m in sorted(passing) + [m_max]:
        if m_fail < m < m_pass and m <= m_max and m not in tried:
            return m
    return None


def propose(solver: str, measured: list[tuple[int, float, bool]],
             m_max: int | None = None) -> int | None:
    """The next ``m`` to run for ``solver`` from its ``(m, ratio, meets)``
    measurements, at most ``m_max`` (None: no bound), or None when its search
    is done (docs/advisor.md, Integration)."""
    order = max(1, SOLVERS[solver].order)
    meeting = [m for m, _, ok in measured if ok]
    target = PROBE_TARGET if meeting else PREDICTION_TARGET
    m_fail, m_pass = bracket(measured)
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


def search_integration(judged: Judged, bodies: int) -> dict[Setting, Pruned]:
    """Search each solver's step at the reference's level and boxes, for up
    to :data:`SEARCH_ROUNDS` rounds of one run per solver, made together
    (docs/advisor.md, Integration; Branch and bound). A step whose force
    evaluations alone cost no less than the best run found so far is not
    run but pruned, and its solver gets :func:`last_chance` instead.
    Returns the runs pruned, each as it was the last time it was pruned."""
    runner, verdict, made = judged.runner, judged.verdict, judged.made
    ladder = runner.ladder
    pruned: dict[Setting, Pruned] = {}
    for _ in range(SEARCH_ROUNDS):
        best = judged.best_proxy()
        wanted = []
        for name in SOLVERS:
            measured = [(s.m, verdict(s).ratio, verdict(s).meets) for s in made()
                        if (s.solver, s.level, s.aabb) == (name, REFERENCE_LEVEL,
                                                           REFERENCE_AABB)]
            m = propose(name, measured) if measured else None
            if m is None:
                continue
            per_m = ladder.n_steps(1) * SOLVERS[name].stages * bodies  # force evaluations / m
            if m * per_m >= best:
                pruned[Setting(name, m, REFERENCE_LEVEL, REFERENCE_AABB)] = Pruned(
                    name, ladder.step(m), REFERENCE_LEVEL, REFERENCE_AABB, m * per_m, best)
                passing = {s.m for s in made() if verdict(s).meets
                           and (s.level, s.aabb) == (REFERENCE_LEVEL, REFERENCE_AABB)}
                m = last_chance(measured, passing, (best - 1) // per_m)
                if m is None:
                    continue
            wanted.append((Setting(name, m, REFERENCE_LEVEL, REFERENCE_AABB), "search"))
        if not wanted:
            break
        runner.run(wanted)
    return pruned


def search_geometry(judged: Judged, scene: Scene) -> None:
    """Run each collision level once, with :data:`CANDIDATE_AABB`, at the
    solver and step of the best run at the reference's level and boxes
    (docs/advisor.md, Geometry). A scene whose body-body stage never runs
    (one body, or ``body_response = "off"``) gives the same run at every
    level, so only "none" is run."""
    integration = min((s for s in judged.meeting()
                       if (s.level, s.aabb) == (REFERENCE_LEVEL, REFERENCE_AABB)),
                      key=judged.sort_key)
    body_stage = len(scene.bodies) >= 2 and scene.dynamics.body_response != "off"
    levels = COLLISION_LEVELS if body_stage else ("none",)
    judged.runner.run([(Setting(integration.solver, integration.m, level, CANDIDATE_AABB),
                        "geometry") for level in levels])


def confirm(judged: Judged) -> Setting:
    """The recommendation: the cheapest run that meets TOL and whose next
    finer step on the ladder (``m + 1``, same solver, level and boxes) meets
    it too (docs/advisor.md, Confirmation). The runs that meet TOL are tried
    in order of cost, one neighbour run each; a run whose neighbour misses
    gets the role "chance". The reference's check needs no neighbour."""
    runner = judged.runner
    chosen = None
    for s in sorted(judged.meeting(), key=judged.sort_key):
        if s == judged.ref.check:
            chosen = s                  # meets by construction, against the reference
            break
        finer = replace(s, m=s.m + 1)
        runner.run([(finer, "confirmation")])
        if judged.verdict(finer).meets:
            chosen = s
            break
        runner.roles[s].append("chance")
    assert chosen is not None           # the check is among the runs that meet TOL
    return chosen
