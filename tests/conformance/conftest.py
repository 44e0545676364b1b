"""Shared, session-wide runs of the conformance kit (each is seconds; the
tests read them from several angles instead of running them again)."""

from __future__ import annotations

import pytest

from tests.conftest import MATRIX_CASES, MATRIX_SEED

#: Cases per generated set in these tests: the session's shared matrix
#: (tests/conftest.py), which the quick report's page reads too; enough for
#: the float engines' touching and near-degenerate failures to appear (a few
#: per cent of the near-degenerate families).
CASES = MATRIX_CASES
SEED = MATRIX_SEED


@pytest.fixture(scope="session")
def shipped_run(shipped_matrix):
    """The shipped engines side by side, pages written: (matrix, results, dir)."""
    return shipped_matrix
