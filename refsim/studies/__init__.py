"""Studies: the measurements behind the seed's claims and the report's charts.

A study receives the engines it compares (refsim's own algorithms, or the
adapters of :mod:`refsim.oracles`) and its settings as arguments, and returns
plain result records: numbers, counts and classified disagreements, with
timings marked as timings. It prints nothing and decides no verdict: the
claims (:mod:`refsim.claims`) judge the records, and the views (the report,
the command line) show them. Studies import algorithms and engines, never the
report, the claims or a particular oracle (docs/design.md, Architecture).

- ``bounds``: box update cost and visits, the incremental box's error,
  agreement with an AABB oracle (C1, C2);
- ``triangles``: the exact triangle test against a float oracle,
  near-parallel planes (C4);
- ``levels``: the four collision levels, agreement with body oracles, the
  hierarchy's speed (C3);
- ``solvers``: orders, stability limits, work against precision (C5, C7, C10);
- ``particles``: resting jitter, drag models, particle work-precision,
  throughput (C5, C6, C8, C9);
- ``bounce``: wall bounces against analytic answers and a rigid-body oracle;
- ``dynamics``: spin that never damps, interpenetration, energy (C11, C12);
- ``models``: model facts against a mesh oracle.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import Field, field
from types import MappingProxyType
from typing import Any

#: The key of a record field's metadata that marks it as a timing: a wall
#: time, or a figure derived from wall times (a rate, a ratio of times, a
#: crossover size). Timings vary from run to run and from machine to machine;
#: every other field of a study record is the same bytes on every run with the
#: same inputs (docs/design.md, Conventions), and the report's determinism test
#: compares those exactly.
TIMING = "timing"

#: The metadata of a timing field, read-only. A record declares one as
#: ``seconds: float = field(metadata=TIMED)``: mypy's dataclass
#: plugin knows a field's default (or its absence) only from a call of
#: ``dataclasses.field`` itself, not from a wrapper such as
#: :func:`timing_field`, so the records call ``field`` directly.
TIMED: Mapping[str, bool] = MappingProxyType({TIMING: True})


def timing_field(**kwargs: Any) -> Field:
    """A dataclass field marked as a timing (``field(metadata=TIMED)``)."""
    return field(metadata=TIMED, **kwargs)


def is_timing(f: Field) -> bool:
    """Whether a dataclass field's metadata marks it as a timing (:data:`TIMED`)."""
    return bool(f.metadata.get(TIMING, False))
