"""One quick report, built once per test session and shared by the report tests.

Under pytest-xdist every worker would build its own copy of a session
fixture; the first worker to get here builds the report into the session's
shared temporary directory (``once_per_session``, tests/conftest.py), and
the others read it.
Beside it, ``entry-records.json`` keeps the records of every entry the
report's run measured, timings left out (:func:`records_without_timings`),
for the test that measures them again on workers.
"""

from __future__ import annotations

import io
import json
import shutil

import pytest

from refsim.report import build
from refsim.report.section import EVERY_ITEM, to_json
from tests.conftest import (
    MATRIX_CASES,
    MATRIX_SEED,
    once_per_session,
    shared_directory,
    shipped_matrix_in,
)

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
    """``(out_dir, html, results)`` of ``refsim report --quick``.

    Its conformance matrix is the session's shared one
    (``shipped_matrix_in``, tests/conftest.py: the quick report's cases and
    seed, pages copied into the report's folder), not a second run of
    every engine; asked for only when the report reaches it, so that a
    worker making the report does not wait from its start for the worker
    making the matrix. The report measures it through an in-process sweep
    (``Run.sweep_options``), which gives the same cells as the direct run,
    timings aside: tests/report/test_report_sweeps.py and
    tests/conformance/test_shards.py hold the two equal."""
    from refsim.conformance import matrix as conformance_matrix

    run_matrix = conformance_matrix.run_matrix

    def shared_matrix(specs=None, *, cases, seed=0, out_dir=None, only=None, **options):
        kept, results, pages = shipped_matrix_in(shared, run_matrix)
        if specs is not None or only is not None or (cases, seed) != (MATRIX_CASES, MATRIX_SEED):
            return run_matrix(specs, cases=cases, seed=seed, out_dir=out_dir, only=only,
                              **options)
        if out_dir is not None:
            shutil.copytree(pages, out_dir, dirs_exist_ok=True)
        return kept, results

    def build_quick(out):
        runs = []

        class Kept(build.Run):                # the report's run, kept for its records
            def __init__(self, **kwargs):
                super().__init__(**kwargs)
                runs.append(self)

        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(build, "Run", Kept)
            patch.setattr(conformance_matrix, "run_matrix", shared_matrix)
            build.build_report(out, quick=True, stream=io.StringIO())
        (run,) = runs
        kept = {name: records_without_timings(run.get(name)) for name in run._records}
        (out / ENTRY_RECORDS).write_text(json.dumps(kept, sort_keys=True))

    shared = shared_directory(tmp_path_factory, worker_id)
    out = shared / "quick-report"
    once_per_session(shared, out.name, build_quick)
    return out, (out / "index.html").read_text(), json.loads((out / "results.json").read_text())
