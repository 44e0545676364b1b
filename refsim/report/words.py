"""Words the sections share for what the claims decided.

A timed comparison (:func:`refsim.claims.result.comparison`) is said with
its distance from the threshold against the run-to-run spread, so that a
reader sees why a verdict is, or is not, decided.
"""

from __future__ import annotations

import math


def against_spread(c: dict, digits: int = 2) -> str:
    """One timed comparison in words: "1.05 against 1 (0.05 off, spread
    0.1: within it)"."""
    value, threshold, spread = c["value"], c["threshold"], c["spread"]
    off = abs(value - threshold)
    if c["side"] == "at":
        where = "on it"
    elif spread == 0:
        where = "no spread measured"
    elif math.isinf(c["spreads"]):
        where = f"spread {spread:.{digits}g}"
    else:
        where = (f"spread {spread:.{digits}g}: "
                 + ("within it" if c["side"] == "within spread"
                    else f"{c['spreads']:.2g} spreads {c['side']}"))
    return f"{value:.{digits + 1}g} against {threshold:g} ({off:.{digits}g} off, {where})"


def listing(words: list[str]) -> str:
    """``["a", "b", "c"]`` as "a, b and c"."""
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]
