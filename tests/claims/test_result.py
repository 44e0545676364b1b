"""The shared parts of the claims (refsim.claims.result): the verdict record
and the comparisons that decide when two measurements are the same."""

from __future__ import annotations

import math

import pytest

from refsim.claims import CLAIMS
from refsim.claims.result import (
    ClaimResult,
    against,
    by_parts,
    by_timed_parts,
    comparison,
    lower,
    rank,
    relative_difference,
    spread,
    tied,
)


def test_a_verdict_outside_the_four_is_refused():
    with pytest.raises(ValueError, match="C1"):
        ClaimResult("C1", "not measured yet")


@pytest.mark.parametrize(("held", "parts", "verdict"), [
    (2, 2, "confirmed"), (1, 2, "partly"), (0, 2, "refuted"), (3, 5, "partly")])
def test_by_parts(held, parts, verdict):
    assert by_parts(held, parts) == verdict


def test_spread_is_the_interquartile_range_of_the_repeats():
    assert spread([1.0, 2.0, 3.0, 4.0, 5.0]) == 2.0          # quartiles 2 and 4
    assert spread([5.0, 1.0, 3.0, 2.0, 4.0]) == 2.0          # order does not matter
    assert spread([1.5]) == 0.0 and spread([]) == 0.0        # one repeat: no spread known
    assert spread([1.0, math.nan, 3.0]) == 1.0               # a lost repeat is left out


@pytest.mark.parametrize(("value", "threshold", "value_spread", "side"), [
    (1.3, 1.0, 0.1, "above"),            # three spreads above
    (0.7, 1.0, 0.1, "below"),
    (1.05, 1.0, 0.1, "within spread"),   # half a spread off: another run may fall below
    (1.1, 1.0, 0.1 + 1e-12, "within spread"),   # exactly one spread off is not clear
    (1.0, 1.0, 0.0, "at"),               # a tie without spread: the claim says which side
    (1.0 + 1e-12, 1.0, 0.0, "above"),    # no spread: any difference decides
    (math.nan, 1.0, 0.0, "within spread"),
])
def test_against_decides_only_beyond_the_spread(value, threshold, value_spread, side):
    assert against(value, threshold, value_spread) == side


def test_comparison_states_the_distance_in_spreads():
    facts = comparison(1.3, 1.0, [1.1, 1.2, 1.3, 1.4, 1.5])
    assert facts["spread"] == pytest.approx(0.2) and facts["spreads"] == pytest.approx(1.5)
    assert facts["side"] == "above"
    assert comparison(1.0, 1.0, [1.0])["spreads"] == 0.0
    assert comparison(2.0, 1.0, [2.0])["spreads"] == math.inf


@pytest.mark.parametrize(("held", "open_parts", "parts", "verdict"), [
    (2, 0, 2, "confirmed"), (1, 0, 2, "partly"), (0, 0, 2, "refuted"),
    (1, 1, 2, "undecided"),     # confirmed or partly, by where the open part falls
    (0, 1, 2, "undecided"),     # partly or refuted
    (0, 1, 1, "undecided"),
    (0, 0, 1, "refuted"),
])
def test_by_timed_parts_is_undecided_when_the_open_parts_could_turn_it(
        held, open_parts, parts, verdict):
    assert by_timed_parts(held, open_parts, parts) == verdict


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
