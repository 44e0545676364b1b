"""What a report section is made of: figures, tables, claim verdicts, numbers.

Each area of refsim contributes one :class:`Section`, built from its
``measure_*`` functions. The report computes nothing of its own (STYLE.md,
rule 9): a section only arranges numbers that a measurement returned, and
``results`` holds those numbers for results.json.

Timings vary from run to run; everything else must not. A results key that
holds a timing or a figure derived from timings has one of the words in
``TIMING_WORDS`` in its name, and a verdict that rests on timings says so
(``Verdict.timing``), and so does a table with timings in its cells
(``Table.timing``), so that the determinism test knows what may differ.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

VERDICTS = ("confirmed", "refuted", "partly", "not measured yet")

TIMING_WORDS = ("time", "seconds", "per_second", "rate", "ratio", "crossover", "speedup",
                "throughput")


@dataclass(frozen=True)
class Figure:
    """A chart, as inline SVG text."""

    id: str
    title: str
    svg: str
    caption: str = ""


@dataclass(frozen=True)
class Table:
    id: str
    title: str
    columns: tuple[str, ...]
    rows: tuple[tuple[Any, ...], ...]
    caption: str = ""
    timing: bool = False  # some cells are timings (they vary run to run)


@dataclass(frozen=True)
class Verdict:
    """A measured verdict on one of the seed's claims C1..C12."""

    claim: str          # "C1"
    measured: str       # what refsim measured, in a sentence with the figures
    verdict: str        # one of VERDICTS
    evidence: str       # id of the figure or table that shows it
    command: str = ""   # the one command that reproduces the figure
    timing: bool = False  # rests on wall-clock measurements (varies run to run)


@dataclass(frozen=True)
class Agreement:
    """One line of the page's summary: how refsim agrees with an oracle."""

    oracle: str         # "python-fcl", "trimesh", "scipy solve_ivp", "pybullet", "analytic"
    check: str          # what is compared
    result: str         # the figure, e.g. "20000 / 20000 agree"
    command: str        # the one command that reproduces it


@dataclass(frozen=True)
class Divergence:
    """One entry of the page's divergence catalogue: where refsim and an
    oracle (or the seed's words) part, what kind of difference it is, and the
    figure or table that shows it."""

    title: str          # "FCL misses contacts refsim finds near degenerate pairs"
    kind: str           # e.g. "oracle: tolerance", "oracle: containment", "seed issue"
    finding: str        # a sentence with the figures
    evidence: str       # id of a figure or table of this section


@dataclass
class Section:
    key: str
    title: str
    status: str = "measured"        # "measured" or "pending"
    intro: str = ""                 # HTML-safe text (escaped by the template)
    pending: str = ""               # what is not measured yet, said plainly
    figures: list[Figure] = field(default_factory=list)
    tables: list[Table] = field(default_factory=list)
    verdicts: list[Verdict] = field(default_factory=list)
    agreements: list[Agreement] = field(default_factory=list)
    divergences: list[Divergence] = field(default_factory=list)
    results: dict[str, Any] = field(default_factory=dict)
