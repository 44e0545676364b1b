"""What a conformance run returns: one :class:`CheckResult` per check, one
:class:`ConformanceResult` per engine.

Every failing case of a check is put in exactly one class, by the check that
found it (never by a human after the fact), and the classes are counted.
Their definitions are :data:`CLASS_DEFINITIONS` (the README's conformance
section shows the same table). Lengths are in the scene's unit (metres),
and every reported number names its unit in its field name (``gap_metres``,
``excess_metres``, ``excess_rounding_bounds``).

A check's **status** is one of :data:`STATUS_DEFINITIONS`: ``passed``,
``failed``, ``xfailed`` and ``xpassed`` (as an expected-failures
declaration, :mod:`refsim.conformance.expected`, accepts the failures or
finds none), or ``n/a``.

Cost: plain records; building them is O(checks).
"""

from __future__ import annotations

import json
import math
import traceback
from dataclasses import dataclass, field, fields, replace

#: What each class of failing case means, from the most to the least serious
#: (a case with several disagreements, e.g. a mesh pose, takes the first that
#: applies). The one place these are defined; the README repeats the table
#: (tests/conformance/test_classes.py keeps the two equal).
CLASS_DEFINITIONS: dict[str, str] = {
    "crash": "the engine raised an exception on the case, or returned an answer the kit "
             "cannot read (wrong type or shape); the example holds the case's input and "
             "the traceback's last line. Never accepted by a class-wide declaration: only "
             "an explicit [crash] in the expected-failures file accepts it.",
    "bug": "a well-conditioned case answered wrongly: a gap or excess beyond both the "
           "rounding bound and the engine's declared tolerances, or a measured quantity "
           "more than twice its tolerance.",
    "unmeasurable": "the engine's answer is well formed but the quantity the check measures "
                    "cannot be read from it (e.g. fewer bounces than the apex ratio needs); "
                    "the example's reason says what is missing.",
    "law": "the engine declares a contact law other than a restitution coefficient "
           "(contact_law, e.g. hunt-crossley) and the check assumes one; the example names "
           "the law.",
    "known-divergence": "the check recognises, in the answer itself, a documented other law "
                        "(the seed's lateral friction (1 - friction) v_t instead of "
                        "Coulomb's; an engine that declares solid = True finding one "
                        "body inside another).",
    "loose": "a box that encloses every point but stands outside the exact box by more "
             "than the rounding bound and the distance tolerance, and no more than the "
             "engine's declared box_slack (metres).",
    "tolerance": "the gap or excess (metres) is within the rounding bound of a float64 "
                 "evaluation (scaled to the engine's declared unit_roundoff) or within the "
                 "engine's declared distance_tolerance; or a "
                 "measured quantity misses its tolerance by at most a factor of two; or "
                 "a free body's drift, within 10 %, falls at the engine's declared "
                 "integrator_order when the step is halved (its truncation error); or "
                 "refsim's answer on the poses the engine declares it applies (pose_used, "
                 "e.g. rounded to float32) is the engine's.",
    "touching": "the exact answer turns on an exact contact: the two sets share a point but "
                "nothing crosses transversally (gap exactly 0). A float engine may answer "
                "either way.",
    "coplanar": "all the triangles' vertices lie on one plane, exactly.",
}

CLASSES = tuple(CLASS_DEFINITIONS)

#: Classes an expected-failures declaration without a class list accepts:
#: all but "crash" (see :mod:`refsim.conformance.expected`).
DECLARABLE_WITHOUT_NAMING = tuple(c for c in CLASSES if c != "crash")

#: What each status of a check means.
STATUS_DEFINITIONS = {
    "passed": "no case failed.",
    "failed": "a case failed, outside what any expected-failures declaration accepts; the "
              "reason says how many in which classes, or which declaration it broke.",
    "xfailed": "cases failed, every one in the classes (and within the bounds) an "
               "expected-failures declaration accepts; the reason is the declaration's.",
    "xpassed": "declared as an expected failure, yet nothing failed: not an error, the "
               "declaration may be stale.",
    "n/a": "the check needs something the engine does not give (e.g. ode_stability) or "
           "cannot pose (a scene key it refuses); no case was run, the reason says which.",
}

STATUSES = tuple(STATUS_DEFINITIONS)

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


@dataclass(frozen=True)
class Crash:
    """An exception raised while a case was run: the traceback's last line
    (``"ValueError: ..."``, the exception's type and message) and the
    traceback itself (its innermost frames). ``unposable``: the exception
    was :class:`refsim.errors.UnposableKey`, a scene key the engine refused
    to pose (a check reports such a scene as not posed, not as a crash)."""

    error: str
    traceback: str
    unposable: bool = False

    def example(self, **case) -> dict:
        """A failing-case example of class "crash" with the case's input."""
        return {"class": "crash", "error": self.error, **case, "traceback": self.traceback}


#: Innermost frames of a crash's traceback kept in its example.
CRASH_FRAMES = 6


def attempt(function, *args):
    """``function(*args)``, or a :class:`Crash` recording the exception it
    raised: a call of the engine together with the reading of its answer, so
    that an answer of the wrong type or shape is the engine's crash too."""
    try:
        return function(*args)
    except Exception as exc:  # noqa: BLE001 - recorded as the case's crash
        from refsim.errors import UnposableKey

        last = traceback.format_exception_only(type(exc), exc)[-1].strip()
        return Crash(error=last, traceback="".join(
            traceback.format_exception(type(exc), exc, exc.__traceback__,
                                       limit=-CRASH_FRAMES)),
            unposable=isinstance(exc, UnposableKey))


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
        why the check does not apply (``n/a``), or for a failed check how
        many cases failed in which classes, with each class's largest miss.
    measured : dict
        Numbers the check measured that a reader wants besides pass/fail
        (observed orders, evaluations per step, largest errors).
    largest_miss_metres : dict of str -> float
        Per class, the largest gap or excess (metres) of its failing cases,
        for the checks that measure one (triangles, pairs, collide, aabb):
        what a bounded declaration (``class <= bound``) is compared with.
    seconds : float
        Wall time of the check (a timing: differs per machine and run).
    failures : list of dict
        Every failing case's record (input, the engine's answer, class, gap),
        in case order, where ``examples`` keeps a few: written to
        ``failures.jsonl`` beside ``conformance.json``, not into it
        (:meth:`to_dict` leaves it out unless asked).
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
    largest_miss_metres: dict = field(default_factory=dict)
    seconds: float = 0.0
    failures: list = field(default_factory=list, repr=False)

    @property
    def key(self) -> str:
        """``capability.check``."""
        return f"{self.capability}.{self.check}"

    def with_status(self, status: str, reason: str = "") -> CheckResult:
        return replace(self, status=status, reason=reason)

    def to_dict(self, failures: bool = False) -> dict:
        """The record of ``conformance.json``; with ``failures`` every
        failure too (to send a result between processes whole)."""
        return {f.name: getattr(self, f.name) for f in fields(self)
                if failures or f.name != "failures"}

    @classmethod
    def from_dict(cls, data: dict) -> CheckResult:
        """The result :meth:`to_dict` gave (after a JSON round trip)."""
        return cls(**data)


def tally(capability: str, check: str, outcomes, *, examples=(), measured=None,
          misses=None, failures=None, seconds: float = 0.0) -> CheckResult:
    """A :class:`CheckResult` from per-case outcomes: ``None`` for a passing
    case, a class name (:data:`CLASSES`) for a failing one. ``misses``, when
    given, holds each case's gap or excess in metres (None where it has none).
    ``failures``: every failing case's record; by default the ``examples``
    (a check with few cases keeps every failure there)."""
    outcomes = list(outcomes)
    classes: dict[str, int] = {}
    largest: dict[str, float] = {}
    for n, outcome in enumerate(outcomes):
        if outcome is not None:
            if outcome not in CLASSES:
                raise ValueError(f"unknown class {outcome!r}")
            classes[outcome] = classes.get(outcome, 0) + 1
            miss = None if misses is None else misses[n]
            if miss is not None:
                largest[outcome] = max(largest.get(outcome, 0.0), abs(float(miss)))
    failed = sum(classes.values())
    reason = ""
    if failed:
        reason = f"{failed} of {len(outcomes)} cases failed: " + ", ".join(
            f"{c} {classes[c]}" + (f" (largest miss {largest[c]:.3g} m)" if c in largest else "")
            for c in CLASSES if c in classes)
    return CheckResult(capability=capability, check=check, cases=len(outcomes),
                       passed=len(outcomes) - failed, failed=failed,
                       classes={c: classes[c] for c in CLASSES if c in classes},
                       examples=list(examples), status="failed" if failed else "passed",
                       reason=reason,
                       measured=dict(measured or {}),
                       largest_miss_metres={c: largest[c] for c in CLASSES if c in largest},
                       failures=list(examples if failures is None else failures),
                       seconds=seconds)


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

    def to_dict(self, failures: bool = False) -> dict:
        """The record of ``conformance.json`` (with every check's failures
        when ``failures``: :meth:`CheckResult.to_dict`)."""
        data = {f.name: getattr(self, f.name) for f in fields(self)}
        data["capabilities"] = list(self.capabilities)
        data["checks"] = [c.to_dict(failures) for c in self.checks]
        data["case_seconds"] = dict(self.case_seconds)
        return data

    def failure_lines(self):
        """``failures.jsonl``: one strict-JSON line per failing case of every
        check, ``{"check": "capability.check", ...its record}``, in check
        and case order."""
        for check in self.checks:
            for failure in check.failures:
                yield strict_json({"check": check.key, **failure}, indent=None)

    def to_json(self) -> str:
        """Strict JSON (:func:`strict_json`), valid against the schema
        shipped beside this module (``conformance.schema.json``)."""
        return strict_json(self.to_dict())

    @classmethod
    def from_dict(cls, data: dict) -> ConformanceResult:
        """The result :meth:`to_dict` gave, after a JSON round trip (a sweep
        task's answer, :func:`refsim.conformance.matrix.run_matrix`): tuples
        come back from lists; examples stay plain JSON data."""
        data = dict(data)
        data["capabilities"] = tuple(data["capabilities"])
        data["checks"] = tuple(CheckResult.from_dict(c) for c in data["checks"])
        return cls(**data)


#: How a number that is not finite is written in the JSON records: strict
#: JSON has no NaN or infinity, so each is a string that ``float()`` reads
#: back. "NaN": not measured or not a number; "Infinity", "-Infinity": unbounded.
NON_FINITE = {"nan": "NaN", "inf": "Infinity", "-inf": "-Infinity"}


def plain(value):
    """``value`` as plain JSON data: numpy scalars and arrays as numbers and
    lists, tuples as lists, every non-finite float as its
    :data:`NON_FINITE` string."""
    import numpy as np

    if isinstance(value, dict):
        return {str(k): plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return plain(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return NON_FINITE[repr(value)]
    return value


def conformance_schema() -> dict:
    """The JSON Schema of ``conformance.json`` (draft 2020-12), shipped
    beside this module as ``conformance.schema.json``."""
    from importlib.resources import files

    return json.loads(files("refsim.conformance").joinpath("conformance.schema.json")
                      .read_text(encoding="utf-8"))


def strict_json(data, indent: int | None = 1) -> str:
    """``data`` (:func:`plain`) as strict JSON text, a newline at the end."""
    return json.dumps(plain(data), indent=indent, allow_nan=False) + "\n"


def summary_table(result: ConformanceResult) -> str:
    """The plain-text table the command line prints: check, cases, passed,
    failed, classes, status."""
    from refsim.conformance.registry import TRUTH_CHECKS

    rows = [("check", "cases", "passed", "failed", "classes", "status")]
    for c in result.checks:
        classes = ", ".join(f"{k} {v}" for k, v in c.classes.items()) or "-"
        key = c.key + (" *" if c.key in TRUTH_CHECKS else "")
        rows.append((key, str(c.cases), str(c.passed), str(c.failed), classes, c.status))
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    lines = []
    for n, row in enumerate(rows):
        cells = [cell.ljust(w) if i in (0, 4, 5) else cell.rjust(w)
                 for i, (cell, w) in enumerate(zip(row, widths, strict=True))]
        lines.append("  ".join(cells).rstrip())
        if n == 0:
            lines.append("  ".join("-" * w for w in widths))
    if any(c.key in TRUTH_CHECKS for c in result.checks):
        lines.append("* checks the kit's own ground truth; it does not call the engine")
    return "\n".join(lines)
