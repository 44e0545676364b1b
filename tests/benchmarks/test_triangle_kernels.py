"""Speed of the triangle-triangle kernels on the same 2000 random pairs:
readable, numpy batch, numba, and python-fcl (one-face BVH models per pair,
as ``FCLOracle.triangles_intersect`` builds them). ``make bench`` reports
min / median / max; divide 2000 by the time for pairs per second. The numba
kernel is compiled before timing; its compile time is measured separately by
``refsim.studies.triangles.measure_throughput``. No timing asserts: each
benchmark checks its answers against the readable kernel's.
"""

from __future__ import annotations

import numpy as np
import pytest
from refsim.oracles.fcl_adapter import FCLOracle

from refsim.collision.triangle import triangles_intersect
from refsim.collision.triangle_batch import triangles_intersect_batch

N_PAIRS = 2000


@pytest.fixture(scope="module")
def pairs():
    rng = np.random.default_rng(0)
    A, B = rng.uniform(-1.0, 1.0, (2, N_PAIRS, 3, 3))
    expected = np.array([triangles_intersect(a, b) for a, b in zip(A, B, strict=True)])
    return A, B, expected


def test_readable(benchmark, pairs):
    A, B, expected = pairs
    got = benchmark(lambda: [triangles_intersect(a, b) for a, b in zip(A, B, strict=True)])
    np.testing.assert_array_equal(got, expected)


def test_batch(benchmark, pairs):
    A, B, expected = pairs
    np.testing.assert_array_equal(benchmark(triangles_intersect_batch, A, B), expected)


def test_numba(benchmark, pairs):
    from refsim.collision.triangle_numba import triangles_intersect_numba

    A, B, expected = pairs
    triangles_intersect_numba(A[:1], B[:1])          # compile outside the timing
    np.testing.assert_array_equal(benchmark(triangles_intersect_numba, A, B), expected)


@pytest.mark.oracle
def test_fcl(benchmark, pairs, oracle):
    fcl = oracle(FCLOracle)
    A, B, expected = pairs
    got = benchmark(lambda: [fcl.triangles_intersect(a, b) for a, b in zip(A, B, strict=True)])
    np.testing.assert_array_equal(got, expected)
