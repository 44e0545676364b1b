"""Shared, session-wide runs of the conformance kit (each is seconds; the
tests read them from several angles instead of running them again)."""

from __future__ import annotations

import pytest

#: Cases per generated set in these tests: enough for the float engines'
#: touching and near-degenerate failures to appear (a few per cent of the
#: near-degenerate families), small enough to keep tests/conformance
#: under a minute.
CASES = 40
SEED = 0


@pytest.fixture(scope="session")
def shipped_run(tmp_path_factory):
    """The shipped engines side by side, pages written: (matrix, results, dir)."""
    from refsim.conformance.matrix import run_matrix

    out = tmp_path_factory.mktemp("matrix")
    matrix, results = run_matrix(cases=CASES, seed=SEED, out_dir=out)
    return matrix, results, out
