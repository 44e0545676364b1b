"""Speed of ear clipping one large polygon (seed S1): the indexed clipping
(compiled) on a circle, a star and a comb of 1000 to 100 000 corners, the
other families of :mod:`refsim.models.polygons` at 20 000, and the O(k^2)
reference at 1000 corners (it takes seconds at 4000, minutes at 20 000:
:func:`refsim.studies.ear_clip.measure_ear_clip_seconds` times it once when
asked).

Run: ``pytest tests/benchmarks/test_bench_ear_clip.py --benchmark-only``.
One round is one ``ear_clip`` call on the polygon's corners (projection,
tree and clipping); numba's compile is paid (or loaded from its cache)
before timing. No timing asserts: each benchmark checks its triangles (the
count and the area sum, and at 1000 corners the reference's indices).
Under ``--benchmark-disable`` (``make test``) each runs once.
"""

from __future__ import annotations

import numpy as np
import pytest

from refsim.models import polygons
from refsim.models.triangulate import ear_clip_indexed, ear_clip_reference, newell_normal

SIZES = [1000, 4000, 20_000, 100_000]
KINDS = ["circle", "star", "comb"]
OTHER_KINDS = sorted(set(polygons.KINDS) - set(KINDS))

#: The sum of k triangle areas against Newell's area: both round ~k u
#: relative (2e-11 at 100 000 corners); one missing triangle is >= 1/k^2.
AREA_RTOL = 1e-9


@pytest.fixture(scope="module", autouse=True)
def compiled():
    ear_clip_indexed(polygons.star(64))  # compile, or load numba's cache, untimed


def _check(p, tri):
    k = len(p)
    assert tri.shape == (k - 2, 3)
    v = p[tri]
    area = 0.5 * np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])[:, 2].sum()
    assert area == pytest.approx(0.5 * np.linalg.norm(newell_normal(p)), rel=AREA_RTOL)


@pytest.mark.parametrize("k", SIZES)
@pytest.mark.parametrize("kind", KINDS)
def test_bench_indexed(benchmark, kind, k):
    benchmark.group = f"ear clip: {kind}"
    p = polygons.KINDS[kind](k)
    tri = benchmark(ear_clip_indexed, p)
    _check(p, tri)
    if k <= 1000:
        assert tri.tolist() == ear_clip_reference(p).tolist()


@pytest.mark.parametrize("kind", OTHER_KINDS)
def test_bench_indexed_other_families(benchmark, kind):
    benchmark.group = "ear clip: other families, 20 000 corners"
    p = polygons.KINDS[kind](20_000)
    _check(p, benchmark(ear_clip_indexed, p))


@pytest.mark.parametrize("kind", KINDS)
def test_bench_reference(benchmark, kind):
    benchmark.group = f"ear clip: {kind}"
    p = polygons.KINDS[kind](1000)
    _check(p, benchmark.pedantic(ear_clip_reference, (p,), rounds=3, iterations=1))
