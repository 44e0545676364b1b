"""One quick report, built once per test session and shared by the report tests.

Under pytest-xdist every worker would build its own copy of a session
fixture; the first worker to get here builds the report into the session's
shared temporary directory (under a file lock), and the others read it.
"""

from __future__ import annotations

import fcntl
import io
import json

import pytest

from refsim.report.build import build_report


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
            build_report(out, quick=True, stream=io.StringIO())
    return out, (out / "index.html").read_text(), json.loads((out / "results.json").read_text())
