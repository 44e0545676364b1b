"""Every status and check is defined where a user reads it: the site's
tables are generated from these, so a status or check without a meaning
cannot ship."""

from __future__ import annotations

from refsim.conformance.registry import CHECKS
from refsim.conformance.results import STATUS_DEFINITIONS, STATUSES


def test_every_status_has_a_meaning():
    assert STATUSES == ("passed", "failed", "xfailed", "xpassed", "n/a")
    assert all(STATUS_DEFINITIONS[s].strip().endswith(".") for s in STATUSES)


def test_every_check_says_what_it_asks():
    for check in CHECKS:
        assert check.doc.startswith(check.key), check.key
        assert len(check.doc) > len(check.key) + 20, check.key
