"""The triangulation's cost, counted (seed S1).

:func:`measure_ear_clip_work` runs the indexed ear clipping
(:func:`refsim.models.triangulate.ear_clip_indexed`) on one polygon of a
family of :mod:`refsim.models.polygons` and returns what it did: ear tests,
point tests, tree nodes visited and fallback clips. These are counts, not
timings: the same on every machine, so the tests can gate on how they grow
with the number of corners (near-linear for the typical families, where the
specification grows as k^2). :func:`measure_ear_clip_seconds` times either
implementation (the median of ``repeats`` calls of ``time.perf_counter``,
this machine's figure, not a law); the benchmark
(tests/benchmarks/test_bench_ear_clip.py) times the same calls, except the
reference beyond 1000 corners, which only this function times (minutes at
20 000 corners, hours extrapolated at 100 000).

Cost: one triangulation per repeat: O(k log k) indexed for the typical
families, O(k^2) for the reference.
"""

from __future__ import annotations

import statistics
import time
from dataclasses import dataclass

import numpy as np

from refsim.errors import check_option
from refsim.models import ear_index, polygons
from refsim.models.triangulate import ear_clip_indexed, ear_clip_reference


@dataclass(frozen=True)
class EarClipWork:
    """What the indexed clipping did on one polygon of ``corners`` corners."""

    kind: str
    corners: int
    ear_tests: int
    point_tests: int
    node_visits: int
    fallbacks: int

    @property
    def per_corner(self) -> float:
        """Ear tests, point tests and nodes visited, per corner."""
        return (self.ear_tests + self.point_tests + self.node_visits) / self.corners


def measure_ear_clip_work(kind: str, corners: int) -> EarClipWork:
    """Count the work of clipping ``polygons.KINDS[kind](corners)``."""
    points = polygons.KINDS[kind](corners)
    work = np.zeros(4, np.int64)
    ear_clip_indexed(points, work=work)
    return EarClipWork(kind=kind, corners=len(points),
                       ear_tests=int(work[ear_index.EAR_TESTS]),
                       point_tests=int(work[ear_index.POINT_TESTS]),
                       node_visits=int(work[ear_index.NODE_VISITS]),
                       fallbacks=int(work[ear_index.FALLBACKS]))


def measure_ear_clip_seconds(kind: str, corners: int, *, method: str = "indexed",
                             repeats: int = 5) -> float:
    """Median seconds of one triangulation of ``polygons.KINDS[kind](corners)``
    by ``method``: "indexed" (compiled; compiled once before timing) or
    "reference"."""
    methods = {"indexed": ear_clip_indexed, "reference": ear_clip_reference}
    clip = methods[check_option("method", method, tuple(methods))]
    points = polygons.KINDS[kind](corners)
    if method == "indexed":
        ear_clip_indexed(polygons.star(64))  # numba's compile or cache load, untimed
    seconds = []
    for _ in range(repeats):
        start = time.perf_counter()
        clip(points)
        seconds.append(time.perf_counter() - start)
    return statistics.median(seconds)
