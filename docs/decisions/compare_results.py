"""The diff command of issue 13's redesign: every non-timing value in which
two report results differ.

    python docs/decisions/compare_results.py BASE/results.json NEW/results.json [--ignore KEY ...]

prints one line per path (keys joined by "/", list items by index) whose
value differs, is only in one file, or whose list lengths differ, then the
number of such paths. Exit status 0 when there are none, 1 otherwise.

Left out, because they may differ between two runs of the same code:

- ``environment`` (package versions, machine, commit: the run, not its
  measurements);
- every path that either file lists under ``timing_paths`` (lists of keys,
  ``"*"`` for any list item; refsim.report.section.to_json). A baseline made
  before timings were marked has none, so the newer file's list is applied to
  both;
- every list item marked ``"timing": true``: a verdict, a table or a
  catalogue entry that rests on timings (left out of its list before the
  items are paired);
- with ``--ignore KEY``, every value under a mapping key ``KEY`` at any depth
  (issue 13 changed every ``command`` on purpose: ``--ignore command``).

The report's results hold every figure the page shows (tables cell by cell,
as displayed) and the numbers behind the charts, so an empty output means the
redesign changed no number the report states.
"""

from __future__ import annotations

import json
import sys

#: Top-level keys that describe the run rather than measure anything.
IGNORED = ("environment", "timing_paths")

ANY_ITEM = "*"


def _timed(path: tuple, patterns: list[tuple]) -> bool:
    """Whether ``path`` is, or is inside, one of the timing ``patterns``."""
    for pattern in patterns:
        if len(path) >= len(pattern) and all(
                p == ANY_ITEM and isinstance(k, int) or p == k
                for p, k in zip(pattern, path, strict=False)):
            return True
    return False


def _marked(item) -> bool:
    return isinstance(item, dict) and item.get("timing") is True


def differences(base, new, patterns: list[tuple], path: tuple = (), ignored: tuple = ()):
    """Yield ``(path, base value, new value)`` for every differing leaf."""
    if _timed(path, patterns):
        return
    if isinstance(base, dict) and isinstance(new, dict):
        for key in sorted(set(base) | set(new)):
            if (not path and key in IGNORED) or key in ignored:
                continue
            if key not in base or key not in new:
                yield path + (key,), base.get(key, "<absent>"), new.get(key, "<absent>")
            else:
                yield from differences(base[key], new[key], patterns, path + (key,), ignored)
    elif isinstance(base, list) and isinstance(new, list):
        # Items resting on timings are left out of each list before the two
        # are compared item by item (a timing verdict may be a catalogue
        # entry in one run and not in the other); indices are the new file's.
        base = [item for item in base if not _marked(item)]
        new = [item for item in new if not _marked(item)]
        if len(base) != len(new):
            yield path + ("<length>",), len(base), len(new)
        for i, (a, b) in enumerate(zip(base, new, strict=False)):
            yield from differences(a, b, patterns, path + (i,), ignored)
    elif base != new:
        yield path, base, new


def main(argv: list[str]) -> int:
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.strip().splitlines()[0])
    parser.add_argument("base", help="the baseline results.json")
    parser.add_argument("new", help="the results.json to compare with it")
    parser.add_argument("--ignore", action="append", default=[], metavar="KEY",
                        help="leave out the values under this key, at any depth")
    args = parser.parse_args(argv)
    with open(args.base) as f:
        base = json.load(f)
    with open(args.new) as f:
        new = json.load(f)
    patterns = [tuple(p) for p in base.get("timing_paths", []) + new.get("timing_paths", [])]
    count = 0
    for path, a, b in differences(base, new, patterns, ignored=tuple(args.ignore)):
        count += 1
        print(f"{'/'.join(map(str, path))}: {json.dumps(a)[:200]} -> {json.dumps(b)[:200]}")
    print(f"{count} differing non-timing paths")
    return 1 if count else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
