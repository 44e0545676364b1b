"""Expected failures: declared divergences, each with its reason.

An engine may fail a check for a reason its authors know and accept (a float
engine on touching triangles, the seed's friction law). An
expected-failures file says so, one declaration a line::

    # comments and blank lines are ignored
    capability.check  reason
    capability.check[class, class]  reason
    capability.check[touching, tolerance, bug <= 1e-10]  reason

- ``capability.check`` is a check of :data:`refsim.conformance.registry.CHECK_KEYS`
  (e.g. ``triangles.agreement``).
- ``[...]`` (optional) limits the declaration to those classes of failing
  case (:data:`refsim.conformance.results.CLASSES`):
  ``triangles.agreement[touching,tolerance]`` accepts a float engine's
  touching and near-degenerate misses but not a bug. Without it every class
  is accepted but ``crash``: an exception in the engine is accepted only
  where the list names ``crash`` itself (the crash is still counted and
  shown with its input and message).
- ``class <= BOUND`` accepts that class only while every failing case of it
  is within ``BOUND`` metres: its gap or excess (the check's
  ``largest_miss_metres``). Only the checks that measure a length take a
  bound (triangles, pairs, collide, aabb); a bound is a finite number >= 0.
- the reason, after at least one space, is required: it is shown beside the
  check in the table, the JSON and the page.

A check whose failing cases all fall in declared classes (and bounds) is
``xfailed``; one with a failing case outside them stays ``failed``, its
reason saying which; a declared check with no failing case is ``xpassed``
(reported, not an error: a small ``--cases`` may not meet a rare failure).
A malformed line is one :class:`~refsim.errors.OptionError` naming the file
and the line.

Files for the engines refsim ships are in ``refsim/conformance/expected/``
(:func:`shipped_expected_failures`).

Cost: O(lines).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from pathlib import Path

from refsim.errors import OptionError

_LINE = re.compile(r"^(?P<key>[a-z_]+\.[a-z_]+)\s*(?:\[(?P<classes>[^\]]*)\])?"
                   r"(?:\s+(?P<reason>\S.*))?$")
_ENTRY = re.compile(r"^(?P<name>[a-z\-]+)(?:\s*<=\s*(?P<bound>\S+))?$")


@dataclass(frozen=True)
class Expected:
    """One declaration: the check, the classes it accepts (None: all but
    "crash"), the bound in metres of each bounded class, why."""

    key: str
    classes: tuple | None
    reason: str
    line: int = 0
    bounds: dict = field(default_factory=dict)


def _entries(text: str, key: str, where: str) -> tuple[tuple, dict]:
    """The classes and bounds of a ``[...]`` list (module docstring)."""
    from refsim.conformance.registry import check_by_key
    from refsim.conformance.results import CLASSES

    names: list[str] = []
    bounds: dict[str, float] = {}
    for raw in text.split(","):
        entry = raw.strip()
        match = _ENTRY.match(entry)
        if match is None or match["name"] not in CLASSES:
            shown = (match["name"] if match else entry) or "(none given)"
            raise OptionError(f"{where}: {key}: unknown class {shown} (classes: "
                              f"{', '.join(CLASSES)}; a bound is written 'class <= 1e-6')")
        name = match["name"]
        if name in names:
            raise OptionError(f"{where}: {key}: class {name} is named twice")
        names.append(name)
        if match["bound"] is not None:
            try:
                bound = float(match["bound"])
            except ValueError:
                bound = math.nan
            if not (math.isfinite(bound) and bound >= 0.0):
                raise OptionError(f"{where}: {key}: the bound of {name} must be a finite "
                                  f"number of metres >= 0, got {match['bound']!r}")
            if check_by_key(key).miss_unit != "metres":
                raise OptionError(f"{where}: {key}: takes no bound (it measures no length; "
                                  f"bounds are for the triangles, pairs, collide and aabb "
                                  f"checks)")
            bounds[name] = bound
    return tuple(names), bounds


def parse_expected(text: str, source: str = "<expected failures>") -> dict[str, Expected]:
    """The declarations of ``text``, by check; :class:`OptionError` naming
    ``source`` and the line for anything malformed."""
    from refsim.conformance.registry import CHECK_KEYS

    found: dict[str, Expected] = {}
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        where = f"{source}:{number}"
        match = _LINE.match(line)
        if match is None:
            raise OptionError(f"{where}: expected 'capability.check[classes]  reason', "
                              f"got {line!r}")
        key = match["key"]
        if key not in CHECK_KEYS:
            raise OptionError(f"{where}: unknown check {key!r} (checks: "
                              f"{', '.join(CHECK_KEYS)})")
        if not match["reason"]:
            raise OptionError(f"{where}: {key}: a reason is required after the check")
        classes: tuple | None = None
        bounds: dict[str, float] = {}
        if match["classes"] is not None:
            classes, bounds = _entries(match["classes"], key, where)
        if key in found:
            raise OptionError(f"{where}: {key} is already declared on line "
                              f"{found[key].line}")
        found[key] = Expected(key, classes, match["reason"].strip(), number, bounds)
    return found


def read_expected(path) -> dict[str, Expected]:
    """:func:`parse_expected` of a file; a missing or unreadable file is an
    :class:`OptionError` naming it."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = getattr(exc, "strerror", None) or str(exc)
        raise OptionError(f"{path}: cannot read the expected-failures file: {reason}") from None
    return parse_expected(text, str(path))


def apply_expected(result, declarations: dict[str, Expected]):
    """``result`` (a CheckResult) with its status set by the declarations."""
    from refsim.conformance.results import DECLARABLE_WITHOUT_NAMING

    declared = declarations.get(result.key)
    if declared is None or result.status == "n/a":
        return result
    if result.failed == 0:
        return result.with_status("xpassed", declared.reason)
    accepted = declared.classes if declared.classes is not None else DECLARABLE_WITHOUT_NAMING
    outside = [c for c in result.classes if c not in accepted]
    beyond = [f"{c} <= {bound:g} m (measured up to "
              f"{result.largest_miss_metres.get(c, math.nan):.3g} m)"
              for c, bound in declared.bounds.items()
              if c in result.classes and not result.largest_miss_metres.get(c, math.inf) <= bound]
    if not outside and not beyond:
        return result.with_status("xfailed", declared.reason)
    why = []
    if outside:
        scope = (f"declared for {', '.join(declared.classes)} only"
                 if declared.classes is not None else "a crash is accepted only when named")
        why.append(f"{scope}; also {', '.join(outside)}")
    if beyond:
        why.append(f"declared {'; '.join(beyond)}")
    return replace(result, status="failed", reason=f"{'; '.join(why)}: {declared.reason}")


def shipped_expected_failures(engine_name: str) -> Path | None:
    """The bundled expected-failures file of a shipped engine (by its name),
    or None."""
    from importlib.resources import files

    path = Path(str(files("refsim.conformance"))) / "expected" / f"{engine_name}.txt"
    return path if path.is_file() else None
