"""What a claim function returns, and the comparisons the claims share.

A :class:`ClaimResult` is the verdict on one seed claim and the facts it
rests on: every number and boolean a sentence about the verdict may quote.
The comparisons :func:`tied`, :func:`lower` and :func:`rank` decide when two
measured values count as the same; each caller passes the relative tolerance
it names beside its claim.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

#: The verdicts a claim function may return. "partly": some of the claim's
#: parts hold and some do not (each function says which parts it weighs).
VERDICTS = ("confirmed", "refuted", "partly")


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
