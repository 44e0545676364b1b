"""What a report section is made of: figures, tables, claim verdicts, numbers.

Each area of refsim contributes one :class:`Section`, built from the records
of the plan's studies (:mod:`refsim.report.plan`) and the verdicts of
:mod:`refsim.claims`. The report computes nothing of its own
(``docs/design.md``, Views): a section only arranges what a measurement returned, and
``results`` holds those records for results.json.

Timings vary from run to run; everything else must not. What is a timing is
said by metadata, never guessed from a name: a study record marks its timing
fields (:func:`refsim.studies.timing_field`), a section wraps any other
timing it puts into ``results`` in :class:`Timing`, a verdict that rests on
timings says so (``Verdict.timing``), and so does a table with timings in its
cells (``Table.timing``). :func:`to_json` turns ``results`` into plain JSON
and collects the paths of the timings, which results.json lists under
``timing_paths`` for the determinism test.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, is_dataclass
from pathlib import Path
from typing import Any

from refsim.claims import VERDICTS as CLAIM_VERDICTS
from refsim.studies import is_timing

VERDICTS = (*CLAIM_VERDICTS, "not measured yet")

#: In a timing path, the step that stands for every item of a list.
EVERY_ITEM = "*"


@dataclass(frozen=True)
class Figure:
    """A chart, as inline SVG text."""

    id: str
    title: str
    svg: str
    caption: str = ""


@dataclass(frozen=True)
class Cell:
    """A table cell shown in the colour of its ``status`` (one of a table's
    ``legend`` keys); results.json records its text, as for any cell."""

    text: str
    status: str

    def __str__(self) -> str:
        return self.text


@dataclass(frozen=True)
class Table:
    id: str
    title: str
    columns: tuple[str, ...]
    rows: tuple[tuple[Any, ...], ...]
    caption: str = ""
    timing: bool = False  # some cells are timings (they vary run to run)
    # a link per column heading (a path relative to the page, "" for none)
    column_links: tuple[str, ...] = ()
    # the sentence the page shows in the table's place when it has no rows
    empty: str = ""
    # (status, what it means) for the colours of the table's Cells, in order
    legend: tuple[tuple[str, str], ...] = ()


@dataclass(frozen=True)
class Replay:
    """A replay page written beside the report (S12), embedded where it
    illustrates a claim or a measurement, or the reason it is not there."""

    id: str
    title: str
    file: str           # path relative to the report's page ("" when not written)
    claim: str = ""     # the seed claim it illustrates ("C12"), or ""
    caption: str = ""
    missing: str = ""   # why it was not written (e.g. the viewer extra is not installed)
    after: str = ""     # id of the section's table or figure it is shown after ("": at the end)


@dataclass(frozen=True)
class Verdict:
    """A measured verdict on one of the seed's claims C1..C12."""

    claim: str          # "C1"
    measured: str       # what refsim measured, with the figures (one click away on the page)
    verdict: str        # one of VERDICTS
    evidence: str       # id of the figure or table that shows it
    command: str = ""   # the one command that reproduces the figure
    timing: bool = False  # rests on wall-clock measurements (varies run to run)
    summary: str = ""   # the finding in one short sentence, shown beside the verdict


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
    replays: list[Replay] = field(default_factory=list)
    results: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class Timing:
    """A value of a section's ``results`` that is a timing, or derived from
    timings, and is not a field of a study record (those carry their own
    mark): e.g. a ratio of two measured times."""

    value: Any


def fields_of(record) -> dict:
    """A study record's fields as a dict, each timing field's value wrapped in
    :class:`Timing`: for a section that adds keys to a record's fields."""
    return {f.name: Timing(getattr(record, f.name)) if is_timing(f) else getattr(record, f.name)
            for f in fields(record)}


def _key(key) -> str:
    """A mapping key as JSON writes it."""
    if hasattr(key, "item"):            # a numpy scalar
        key = key.item()
    if isinstance(key, str):
        return key
    if isinstance(key, bool) or key is None:
        return {True: "true", False: "false", None: "null"}[key]
    return repr(key) if isinstance(key, float) else str(key)


def to_json(value, path: tuple = (), timings: set | None = None):
    """``value`` as plain JSON data: dataclasses as mappings of their fields,
    tuples and numpy arrays as lists, numpy scalars as numbers, paths as
    text, and ``inf`` ("never reached", "no limit") and ``nan`` ("not
    defined") as None, so that results.json is strict JSON.

    ``timings``, when given, receives the path (a tuple of keys from
    ``path`` on, :data:`EVERY_ITEM` for any list item) of every timing: each
    timing field of a record and each :class:`Timing` value.
    """
    def note(where):
        if timings is not None:
            timings.add(where)

    if isinstance(value, Timing):
        note(path)
        return to_json(value.value, path, None)
    if is_dataclass(value) and not isinstance(value, type):
        out = {}
        for f in fields(value):
            if is_timing(f):
                note(path + (f.name,))
            out[f.name] = to_json(getattr(value, f.name), path + (f.name,),
                                  None if is_timing(f) else timings)
        return out
    if isinstance(value, dict):
        return {_key(k): to_json(v, path + (_key(k),), timings) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [to_json(v, path + (EVERY_ITEM,), timings) for v in value]
    if hasattr(value, "tolist"):        # numpy arrays and scalars
        return to_json(value.tolist(), path, timings)
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
