"""Expected failures: declared divergences, each with its reason.

An engine may fail a check for a reason its authors know and accept (a float
engine on touching triangles, the seed's friction law). An
expected-failures file says so, one declaration a line::

    # comments and blank lines are ignored
    capability.check  reason
    capability.check[class,class]  reason

- ``capability.check`` is a check of :data:`refsim.conformance.registry.CHECK_KEYS`
  (e.g. ``triangles.agreement``).
- ``[class,...]`` (optional, no spaces) limits the declaration to those
  classes of failing case (:data:`refsim.conformance.results.CLASSES`):
  ``triangles.agreement[touching,tolerance]`` accepts a float engine's
  touching and near-degenerate misses but not a bug. Without it every class
  is accepted.
- the reason, after at least one space, is required: it is shown beside the
  check in the table, the JSON and the page.

A check whose failing cases all fall in declared classes is ``xfailed``;
one with a failing case outside them stays ``failed``; a declared check with
no failing case is ``xpassed`` (reported, not an error: a small ``--cases``
may not meet a rare failure). A malformed line is a
:class:`~refsim.errors.OptionError` naming the file and the line.

Files for the engines refsim ships are in ``refsim/conformance/expected/``
(:func:`shipped_expected_failures`).

Cost: O(lines).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

from refsim.errors import OptionError

_LINE = re.compile(r"^(?P<key>[a-z_]+\.[a-z_]+)(?:\[(?P<classes>[a-z,\-]*)\])?"
                   r"(?:\s+(?P<reason>\S.*))?$")


@dataclass(frozen=True)
class Expected:
    """One declaration: the check, the classes it accepts (None: all), why."""

    key: str
    classes: tuple | None
    reason: str
    line: int = 0


def parse_expected(text: str, source: str = "<expected failures>") -> dict[str, Expected]:
    """The declarations of ``text``, by check; :class:`OptionError` naming
    ``source`` and the line for anything malformed."""
    from refsim.conformance.registry import CHECK_KEYS
    from refsim.conformance.results import CLASSES

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
        classes = None
        if match["classes"] is not None:
            classes = tuple(c for c in match["classes"].split(",") if c)
            unknown = [c for c in classes if c not in CLASSES]
            if unknown or not classes:
                raise OptionError(f"{where}: {key}: unknown class "
                                  f"{', '.join(unknown) or '(none given)'} "
                                  f"(classes: {', '.join(CLASSES)})")
        if key in found:
            raise OptionError(f"{where}: {key} is already declared on line "
                              f"{found[key].line}")
        found[key] = Expected(key, classes, match["reason"].strip(), number)
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
    declared = declarations.get(result.key)
    if declared is None or result.status == "n/a":
        return result
    if result.failed == 0:
        return result.with_status("xpassed", declared.reason)
    if declared.classes is None or set(result.classes) <= set(declared.classes):
        return result.with_status("xfailed", declared.reason)
    outside = sorted(set(result.classes) - set(declared.classes))
    return replace(result, status="failed",
                   reason=f"declared for {', '.join(declared.classes)} only; also "
                          f"{', '.join(outside)}: {declared.reason}")


def shipped_expected_failures(engine_name: str) -> Path | None:
    """The bundled expected-failures file of a shipped engine (by its name),
    or None."""
    from importlib.resources import files

    path = Path(str(files("refsim.conformance"))) / "expected" / f"{engine_name}.txt"
    return path if path.is_file() else None
