"""What a claim function returns, and the comparisons the claims share.

A :class:`ClaimResult` is the verdict on one seed claim and the facts it
rests on: every number and boolean a sentence about the verdict may quote.
The comparisons :func:`tied`, :func:`lower` and :func:`rank` decide when two
measured values count as the same; each caller passes the relative tolerance
it names beside its claim.

A claim that compares times decides each comparison with :func:`against`:
a timed value counts as above or below its threshold only when it lies
farther from it than its run-to-run spread (:func:`spread`, the
interquartile range of its repeats); inside the spread the comparison is
open, and :func:`by_timed_parts` says "undecided" when the open parts could
turn the verdict. A verdict at the edge of its band then reads "undecided"
in every run instead of flipping between two verdicts from run to run.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: The verdicts a claim function may return. "partly": some of the claim's
#: parts hold and some do not (each function says which parts it weighs).
#: "undecided": a claim on timings whose measured values lie within their
#: run-to-run spread of a threshold, so that another run may decide it
#: either way (:func:`by_timed_parts`).
VERDICTS = ("confirmed", "refuted", "partly", "undecided")


@dataclass(frozen=True)
class ClaimResult:
    """The verdict on one seed claim.

    ``facts`` maps a name to a number, a boolean, a string, None, or a list
    or mapping of these: what the verdict was decided from.
    ``timing``: the verdict rests on wall-clock measurements, so it may
    differ from run to run and from machine to machine.
    """

    claim: str
    verdict: str
    facts: dict[str, Any] = field(default_factory=dict)
    timing: bool = False

    def __post_init__(self):
        if self.verdict not in VERDICTS:
            raise ValueError(f"{self.claim}: verdict {self.verdict!r} is not one of {VERDICTS}")


def by_parts(held: int, parts: int) -> str:
    """"confirmed" when all ``parts`` of a claim hold, "refuted" when none
    does, "partly" in between."""
    return "confirmed" if held == parts else "refuted" if held == 0 else "partly"


#: A timed value decides a comparison when it lies farther from the
#: threshold than this many times its spread (the interquartile range of its
#: repeats). One spread: a value whose middle half of repeats straddles the
#: threshold is not on either side of it; a value clear of it by its whole
#: middle half stays on its side in most runs.
SPREAD_MARGIN = 1.0

#: The sides of a threshold a timed value can lie on (:func:`against`):
#: "at" only for a value equal to it with no spread (each claim says which
#: side a tie counts on, as without spreads).
SIDES = ("above", "below", "at", "within spread")


def spread(repeats: Sequence[float]) -> float:
    """The run-to-run spread of a timed value: the interquartile range of its
    repeats (numpy's linear interpolation), 0 for fewer than two."""
    finite = [float(x) for x in repeats if math.isfinite(x)]
    if len(finite) < 2:
        return 0.0
    q1, q3 = np.percentile(finite, [25.0, 75.0])
    return float(q3 - q1)


def against(value: float, threshold: float, value_spread: float) -> str:
    """Which side of ``threshold`` a timed ``value`` lies on: "above" or
    "below" when farther from it than :data:`SPREAD_MARGIN` times
    ``value_spread``, else "within spread" (nan is always within); "at" when
    it equals the threshold and has no spread."""
    if value == threshold and value_spread == 0:
        return "at"
    if math.isnan(value) or abs(value - threshold) <= SPREAD_MARGIN * value_spread:
        return "within spread"
    return "above" if value > threshold else "below"


def comparison(value: float, threshold: float, repeats: Sequence[float]) -> dict:
    """The facts of one timed comparison: the value, the threshold, the
    spread of the value's repeats, the distance in spreads (inf when the
    spread is 0 and the value is off the threshold) and the side."""
    s = spread(repeats)
    distance = abs(value - threshold)
    return {"value": value, "threshold": threshold, "spread": s,
            "spreads": distance / s if s else (math.inf if distance else 0.0),
            "side": against(value, threshold, s)}


def by_timed_parts(held: int, open_parts: int, parts: int) -> str:
    """:func:`by_parts` when ``open_parts`` of the ``parts`` are undecided
    (their timed values within the spread of their thresholds) and ``held``
    of the others hold: the verdict when every way the open parts could fall
    gives the same one, else "undecided"."""
    verdicts = {by_parts(held + k, parts) for k in range(open_parts + 1)}
    return verdicts.pop() if len(verdicts) == 1 else "undecided"


def relative_difference(a: float, b: float) -> float:
    """``|a - b| / max(|a|, |b|)``, 0 when ``a == b``."""
    return 0.0 if a == b else abs(a - b) / max(abs(a), abs(b))


def tied(a: float, b: float, rtol: float) -> bool:
    """Two measured values within ``rtol`` of each other, relative; inf ties
    only with inf, nan with nothing."""
    if math.isnan(a) or math.isnan(b):
        return False
    if math.isinf(a) or math.isinf(b):
        return a == b
    return relative_difference(a, b) <= rtol


def lower(a: float, b: float, rtol: float) -> bool:
    """``a`` below ``b`` by more than a tie (nan is never lower)."""
    return a < b and not tied(a, b, rtol)


#: Where a value stands among others (:func:`rank`).
RANKS = ("all tied", "lowest", "highest", "between")


def rank(value: float, others: Mapping[str, float], rtol: float) -> dict:
    """Where ``value`` stands among ``others`` (name -> value):
    ``{"position": one of RANKS, "tied_with": [names within rtol]}``.
    "lowest" and "highest" are against the others it does not tie with."""
    ties = [k for k, v in others.items() if tied(value, v, rtol)]
    rest = [v for k, v in others.items() if k not in ties]
    if ties and len(ties) == len(others):
        position = "all tied"
    elif all(lower(value, v, rtol) for v in rest):
        position = "lowest"
    elif all(lower(v, value, rtol) for v in rest):
        position = "highest"
    else:
        position = "between"
    return {"position": position, "tied_with": ties}
