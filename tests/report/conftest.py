"""One quick report, built once per test session and shared by the report tests.

Under pytest-xdist every worker would build its own copy of a session
fixture; the first worker to get here builds the report into the session's
shared temporary directory (under a file lock), and the others read it.
Beside it, ``entry-records.json`` keeps the records of every entry the
report's run measured, timings left out (:func:`records_without_timings`),
for the test that measures them again on workers.
"""

from __future__ import annotations

import fcntl
import io
import json

import pytest

from refsim.report import build
from refsim.report.section import EVERY_ITEM, to_json

#: Where the quick report's entries' records are kept, beside its page.
ENTRY_RECORDS = "entry-records.json"


def records_without_timings(records) -> str:
    """An entry's records as canonical JSON text without their timing fields
    (those the records mark: :func:`refsim.studies.timing_field`): values
    JSON has no type for (a Fraction) as their ``repr``, and text so that a
    NaN equals itself."""
    timings: set[tuple] = set()
    data = to_json(records, (), timings)
    return json.dumps(without_timings(data, [tuple(p) for p in timings]), sort_keys=True,
                      default=repr)


def _timed(path: tuple, patterns: list[tuple]) -> bool:
    return any(len(path) == len(p) and all(q == k or (q == EVERY_ITEM and isinstance(k, int))
                                           for q, k in zip(p, path, strict=True))
               for p in patterns)


def without_timings(value, patterns, path=()):
    """``value`` without the timing paths ``patterns`` and the items marked
    ``timing``."""
    if isinstance(value, dict):
        return {k: without_timings(v, patterns, path + (k,)) for k, v in value.items()
                if not _timed(path + (k,), patterns)}
    if isinstance(value, list):
        return [without_timings(v, patterns, path + (i,)) for i, v in enumerate(value)
                if not (isinstance(v, dict) and v.get("timing") is True)
                and not _timed(path + (i,), patterns)]
    return value


@pytest.fixture(scope="session")
def quick_report(tmp_path_factory, worker_id):
    """``(out_dir, html, results)`` of ``refsim report --quick``."""
    # xdist's workers each have a basetemp below the session's; without
    # xdist ("master") the session's own basetemp is the shared one.
    shared = tmp_path_factory.getbasetemp()
    if worker_id != "master":
        shared = shared.parent
    out = shared / "quick-report"
    with open(shared / "quick-report.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (out / "index.html").exists():    # written last: the build finished
            runs = []

            class Kept(build.Run):                # the report's run, kept for its records
                def __init__(self, **kwargs):
                    super().__init__(**kwargs)
                    runs.append(self)

            with pytest.MonkeyPatch.context() as patch:
                patch.setattr(build, "Run", Kept)
                build.build_report(out, quick=True, stream=io.StringIO())
            (run,) = runs
            kept = {name: records_without_timings(run.get(name)) for name in run._records}
            (out / ENTRY_RECORDS).write_text(json.dumps(kept, sort_keys=True))
    return out, (out / "index.html").read_text(), json.loads((out / "results.json").read_text())
