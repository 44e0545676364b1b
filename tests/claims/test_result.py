"""The shared parts of the claims (refsim.claims.result): the verdict record
and the comparisons that decide when two measurements are the same."""

from __future__ import annotations

import math

import pytest

from refsim.claims import CLAIMS
from refsim.claims.result import ClaimResult, by_parts, lower, rank, relative_difference, tied


def test_a_verdict_outside_the_three_is_refused():
    with pytest.raises(ValueError, match="C1"):
        ClaimResult("C1", "not measured yet")


@pytest.mark.parametrize(("held", "parts", "verdict"), [
    (2, 2, "confirmed"), (1, 2, "partly"), (0, 2, "refuted"), (3, 5, "partly")])
def test_by_parts(held, parts, verdict):
    assert by_parts(held, parts) == verdict


def test_tied_at_its_tolerance():
    assert relative_difference(20.0, 18.0) == 0.1
    assert tied(20.0, 18.0, 0.1) and not tied(20.0 * (1 + 1e-9), 18.0, 0.1)
    assert tied(math.inf, math.inf, 0.1) and not tied(math.inf, 1e300, 0.1)
    assert not tied(math.nan, math.nan, 0.1)


def test_lower_means_lower_by_more_than_a_tie():
    assert not lower(18.0, 20.0, 0.1) and lower(17.9, 20.0, 0.1)
    assert not lower(math.nan, 1.0, 0.1) and lower(1.0, math.inf, 0.1)


@pytest.mark.parametrize(("value", "others", "expected"), [
    (1.0, {"a": 1.05, "b": 0.95}, {"position": "all tied", "tied_with": ["a", "b"]}),
    (1.0, {"a": 2.0, "b": 1.05}, {"position": "lowest", "tied_with": ["b"]}),
    (3.0, {"a": 2.0, "b": 1.0}, {"position": "highest", "tied_with": []}),
    (1.5, {"a": 2.0, "b": 1.0}, {"position": "between", "tied_with": []}),
    (1.5, {}, {"position": "lowest", "tied_with": []}),
])
def test_rank(value, others, expected):
    assert rank(value, others, 0.1) == expected


def test_every_claim_has_an_area_and_words():
    assert list(CLAIMS) == [f"C{i}" for i in range(1, 13)]
    assert {area for area, _ in CLAIMS.values()} == {"bounds", "collision", "solvers",
                                                     "dynamics"}
