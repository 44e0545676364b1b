"""What a conformance run returns: one :class:`CheckResult` per check, one
:class:`ConformanceResult` per engine.

Every failing case of a check is put in exactly one class, by the check that
found it (never by a human after the fact), and the classes are counted:

=====================  ======================================================
class                  meaning
=====================  ======================================================
``touching``           the exact answer turns on an exact contact: the two
                       sets share a point, but nothing crosses transversally
                       (a vertex on a face or an edge, edges meeting, a
                       shared boundary). A float engine may answer either way.
``coplanar``           all the triangles' vertices lie on one plane, exactly.
``tolerance``          explained by rounding or by a documented accuracy
                       bound: a near-degenerate decision (the orientation
                       margins of :func:`refsim.studies.triangles.decision_margin`
                       below ``NEAR_DEGENERATE_MARGIN``), a box off by no more
                       than float32 rounding, a pose rounded to float32, a
                       measured quantity within twice its tolerance.
``known-divergence``   the engine follows a different, documented law, which
                       the check recognises (e.g. the seed's lateral friction
                       ``(1 - friction) v_t`` instead of Coulomb's; a solid
                       engine finding one body inside another).
``bug``                none of the above: a well-conditioned case answered
                       wrongly.
=====================  ======================================================

A check's **status** is ``passed`` (no failing case), ``failed``,
``xfailed`` (failing cases, all of them in classes an expected-failures
declaration accepts, see :mod:`refsim.conformance.expected`), ``xpassed``
(declared, yet nothing failed: not an error, the declaration may be stale)
or ``n/a`` (the check needs something the engine does not give, e.g.
``ode_stability``; no case was run).

Cost: plain records; building them is O(checks).
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, replace

#: The classes of a failing case, from the most to the least serious (a case
#: with several disagreements, e.g. a mesh pose, takes the first that applies).
CLASSES = ("bug", "known-divergence", "tolerance", "touching", "coplanar")

STATUSES = ("passed", "failed", "xfailed", "xpassed", "n/a")

#: A measured quantity that misses its tolerance by no more than this factor
#: is classed "tolerance" (the engine does the right thing, less accurately
#: than the bound asks); beyond it, "bug". Two: a tolerance is a bound on the
#: error of a correct method, and a correct method's constant can be a few
#: times another's; an error ten times the bound is no longer "less accurate".
MARGINAL_FACTOR = 2.0


def classify_miss(miss: float, tolerance: float) -> str | None:
    """None when ``miss <= tolerance``; "tolerance" within
    :data:`MARGINAL_FACTOR` of it; else "bug" (nan: "bug")."""
    if miss <= tolerance:
        return None
    return "tolerance" if miss <= MARGINAL_FACTOR * tolerance else "bug"


def worst_class(classes) -> str:
    """The most serious of ``classes`` (in :data:`CLASSES` order)."""
    found = set(classes)
    for name in CLASSES:
        if name in found:
            return name
    raise ValueError(f"no known class among {sorted(found)}")


@dataclass(frozen=True)
class CheckResult:
    """One property checked on one engine.

    Attributes
    ----------
    capability, check : str
        ``capability.check`` names it (e.g. ``triangles.agreement``).
    cases, passed, failed : int
        Cases run, and how many passed and failed (``passed + failed == cases``).
    classes : dict of str -> int
        Failing cases per class (:data:`CLASSES`; only classes that occur).
    examples : list of dict
        Failing inputs, JSON-able, each with its ``class``; a minimal one
        found by Hypothesis first where the case is generated (``"shrunk":
        true``), then the first seeded failures of each class.
    status : str
        One of :data:`STATUSES` (see the module docstring).
    reason : str
        The expected-failure declaration's reason (``xfailed``/``xpassed``),
        or why the check does not apply (``n/a``).
    measured : dict
        Numbers the check measured that a reader wants besides pass/fail
        (observed orders, evaluations per step, largest errors).
    seconds : float
        Wall time of the check (a timing: differs per machine and run).
    """

    capability: str
    check: str
    cases: int
    passed: int
    failed: int
    classes: dict = field(default_factory=dict)
    examples: list = field(default_factory=list)
    status: str = "passed"
    reason: str = ""
    measured: dict = field(default_factory=dict)
    seconds: float = 0.0

    @property
    def key(self) -> str:
        """``capability.check``."""
        return f"{self.capability}.{self.check}"

    def with_status(self, status: str, reason: str = "") -> CheckResult:
        return replace(self, status=status, reason=reason)

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict) -> CheckResult:
        """The result :meth:`to_dict` gave (after a JSON round trip)."""
        return cls(**data)


def tally(capability: str, check: str, outcomes, *, examples=(), measured=None,
          seconds: float = 0.0) -> CheckResult:
    """A :class:`CheckResult` from per-case outcomes: ``None`` for a passing
    case, a class name (:data:`CLASSES`) for a failing one."""
    outcomes = list(outcomes)
    classes: dict[str, int] = {}
    for outcome in outcomes:
        if outcome is not None:
            if outcome not in CLASSES:
                raise ValueError(f"unknown class {outcome!r}")
            classes[outcome] = classes.get(outcome, 0) + 1
    failed = sum(classes.values())
    return CheckResult(capability=capability, check=check, cases=len(outcomes),
                       passed=len(outcomes) - failed, failed=failed,
                       classes={c: classes[c] for c in CLASSES if c in classes},
                       examples=list(examples), status="failed" if failed else "passed",
                       measured=dict(measured or {}), seconds=seconds)


def not_applicable(capability: str, check: str, reason: str) -> CheckResult:
    return CheckResult(capability=capability, check=check, cases=0, passed=0, failed=0,
                       status="n/a", reason=reason)


@dataclass(frozen=True)
class ConformanceResult:
    """Every check of one engine.

    ``engine`` is its name, ``spec`` the ``module:factory`` it was loaded
    from (when known), ``refsim`` the version of refsim that judged it,
    ``seed`` and ``cases`` the case-set settings, ``capabilities`` what the
    engine provides, ``expected_failures`` where the declarations came from
    (a path, or "" for none). ``seconds`` is the wall time of the run and
    ``case_seconds`` that of building each case set it built itself (the
    exact answers: shared case sets cost the run nothing). Timings differ
    per machine and run.
    """

    engine: str
    refsim: str
    seed: int
    cases: int
    capabilities: tuple
    checks: tuple
    spec: str = ""
    expected_failures: str = ""
    seconds: float = 0.0
    case_seconds: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """No check failed (expected failures aside)."""
        return not any(c.status == "failed" for c in self.checks)

    def check(self, key: str) -> CheckResult:
        """The result of ``capability.check``."""
        for c in self.checks:
            if c.key == key:
                return c
        raise KeyError(key)

    def failed_checks(self) -> list[str]:
        """``capability.check`` of every check that failed, in order."""
        return [c.key for c in self.checks if c.status == "failed"]

    def to_dict(self) -> dict:
        data = asdict(self)
        data["capabilities"] = list(self.capabilities)
        data["checks"] = [c.to_dict() for c in self.checks]
        return data

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=1, sort_keys=False, default=_jsonable) + "\n"

    @classmethod
    def from_dict(cls, data: dict) -> ConformanceResult:
        """The result :meth:`to_dict` gave, after a JSON round trip (a sweep
        task's answer, :func:`refsim.conformance.matrix.run_matrix`): tuples
        come back from lists; examples stay plain JSON data."""
        data = dict(data)
        data["capabilities"] = tuple(data["capabilities"])
        data["checks"] = tuple(CheckResult.from_dict(c) for c in data["checks"])
        return cls(**data)


def _jsonable(value):
    """numpy scalars and arrays, tuples of them, as plain JSON values."""
    import numpy as np

    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON-able: {type(value).__name__}")


def summary_table(result: ConformanceResult) -> str:
    """The plain-text table the command line prints: check, cases, passed,
    failed, classes, status."""
    rows = [("check", "cases", "passed", "failed", "classes", "status")]
    for c in result.checks:
        classes = ", ".join(f"{k} {v}" for k, v in c.classes.items()) or "-"
        rows.append((c.key, str(c.cases), str(c.passed), str(c.failed), classes, c.status))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = []
    for n, row in enumerate(rows):
        cells = [cell.ljust(w) if i in (0, 4, 5) else cell.rjust(w)
                 for i, (cell, w) in enumerate(zip(row, widths, strict=True))]
        lines.append("  ".join(cells).rstrip())
        if n == 0:
            lines.append("  ".join("-" * w for w in widths))
    return "\n".join(lines)
