"""Suite-wide pytest hooks.

In CI a skipped test is a check that silently did not run (a missing
optional engine, numba or Chromium), so there every skip fails instead:
``.ci/run`` sets ``REFSIM_NO_SKIPS=1``, as does ``CI=true``. Locally a skip
stays a skip, with its reason in the summary (``pytest -rs``).

The signal tests expect the dispositions a terminal gives: a suite started
by ``nohup`` or as a background job of a non-interactive shell inherits
SIGHUP, SIGINT and SIGQUIT ignored, and so would every process it starts,
which then cannot be stopped by the signals the tests send. Each test
process puts them back as an interactive shell would have them
(:func:`pytest_configure`).

The conformance kit's case sets are not kept on disk during the tests
(``REFSIM_CACHE_DIR`` empty, inherited by the commands the tests start): a
test's result never depends on a file an earlier run left in the user's
cache. The cache's own tests give it a directory of their own. For the
same reason the command line's notice of numba compiling
(``REFSIM_COMPILE_NOTICE``) is off: whether a command compiles depends on
numba's cache, not on the command. So is the tiered start
(``REFSIM_TIERED_START``, :class:`refsim.kernels.Tier`): a default call
takes the compiled kernels as it did, whatever the cache holds; the tier's
own tests turn it on. On an empty numba cache the long compiles run once,
before the workers start (:func:`pytest_sessionstart`).
"""

from __future__ import annotations

import os
import signal

import pytest

os.environ["REFSIM_CACHE_DIR"] = ""
os.environ["REFSIM_COMPILE_NOTICE"] = "0"
os.environ["REFSIM_TIERED_START"] = "0"


def pytest_configure(config) -> None:
    """Signals the suite's launcher left ignored get their usual handling:
    Python's KeyboardInterrupt for SIGINT, the system's default for the rest."""
    for signum in (signal.SIGINT, signal.SIGHUP, signal.SIGQUIT, signal.SIGTERM):
        if signal.getsignal(signum) is signal.SIG_IGN:
            signal.signal(signum, signal.default_int_handler if signum == signal.SIGINT
                          else signal.SIG_DFL)

@pytest.hookimpl(tryfirst=True)
def pytest_sessionstart(session) -> None:
    """Before pytest-xdist starts its workers, the kernel families whose
    first compile takes tens of seconds (:func:`refsim.warm.tiers`) are
    compiled into numba's cache, side by side, if it lacks them: otherwise
    every worker compiles each of them for itself on an empty cache (a
    fresh clone). A warm cache costs a look at its index."""
    config = session.config
    workers = getattr(config.option, "numprocesses", None)
    if hasattr(config, "workerinput") or not isinstance(workers, int) or workers < 2:
        return
    from refsim.warm import compile_side_by_side

    compile_side_by_side()


#: pytester runs a small suite in a temporary directory (tests/test_no_skips_in_ci.py).
pytest_plugins = ["pytester"]


def _skips_fail() -> bool:
    return (os.environ.get("REFSIM_NO_SKIPS") == "1"
            or os.environ.get("CI", "").lower() == "true")


def _fail_skip(report) -> None:
    if report.skipped and not hasattr(report, "wasxfail") and _skips_fail():
        reason = report.longrepr[2] if isinstance(report.longrepr, tuple) else report.longrepr
        report.outcome = "failed"
        report.longrepr = f"skipped where every check must run (REFSIM_NO_SKIPS / CI): {reason}"


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """A test skipped in setup or in its body (``pytest.skip``, ``skipif``)."""
    outcome = yield
    _fail_skip(outcome.get_result())


@pytest.hookimpl(hookwrapper=True)
def pytest_make_collect_report(collector):
    """A module skipped as it is collected (``pytest.importorskip`` at the top)."""
    outcome = yield
    _fail_skip(outcome.get_result())
