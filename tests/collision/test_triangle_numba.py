"""The numba kernel returns exactly what the readable (and batch) one returns."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.collision.triangle import triangles_intersect
from refsim.collision.triangle_batch import triangles_intersect_batch
from refsim.collision.triangle_numba import triangles_intersect_numba  # noqa: E402
from refsim.errors import StateError
from refsim.studies.triangles import measure_throughput, near_degenerate_pairs

from .test_triangle import CASES, T


def _readable(A, B):
    return np.array([triangles_intersect(a, b) for a, b in zip(A, B, strict=True)], dtype=bool)


def test_random_pairs():
    rng = np.random.default_rng(21)
    A, B = rng.uniform(-1.0, 1.0, (2, 3000, 3, 3))
    np.testing.assert_array_equal(triangles_intersect_numba(A, B), _readable(A, B))


def test_near_degenerate_and_integer_pairs():
    A, B, _ = near_degenerate_pairs(3000, seed=8)
    np.testing.assert_array_equal(triangles_intersect_numba(A, B), _readable(A, B))
    rng = np.random.default_rng(22)
    A, B = rng.integers(-2, 3, (2, 2000, 3, 3)).astype(float)
    np.testing.assert_array_equal(triangles_intersect_numba(A, B), _readable(A, B))


def test_constructed_cases_and_scales():
    A = np.array([np.asarray(T, float)] * len(CASES))
    B = np.array([np.asarray(c[0], float) for c in CASES.values()])
    expected = np.array([c[1] for c in CASES.values()])
    for scale in (1.0, 2.0 ** -1000, 2.0 ** 900):
        # Keep the cases the power-of-two scale maps exactly (no underflow).
        exact = ((B * scale) / scale == B).all(axis=(1, 2))
        a, b = A[exact] * scale, B[exact] * scale
        assert exact.sum() >= len(CASES) - 3
        np.testing.assert_array_equal(triangles_intersect_numba(a, b), expected[exact])
        np.testing.assert_array_equal(triangles_intersect_numba(b, a), expected[exact])


def test_bad_input_raises():
    B = np.ones((1, 3, 3))
    B[0, 0, 0] = np.inf
    with pytest.raises(StateError):
        triangles_intersect_numba(np.zeros((1, 3, 3)), B)


def test_throughput_figures_are_consistent():
    # No timing assert: only that every kernel ran and agreed (the function
    # raises if the kernels disagree) and the figures are positive numbers.
    # The cold compile (a fresh interpreter, about 30 s) is the report's to
    # measure: its build runs measure_throughput with it (report/entries/collision.py).
    result = measure_throughput(n=2000, seed=0, cold_compile=False)
    print(f"\npairs/s readable={result.readable:.3g} batch={result.batch:.3g} "
          f"numba={result.numba:.3g}")
    assert result.readable > 0 and result.batch > 0 and result.numba > 0
    assert result.numba_compile_seconds is None
    assert result.batch_fallback_fraction == 0.0
    np.testing.assert_array_equal(
        triangles_intersect_numba(np.array([T]), np.array([CASES["piercing"][0]], float)),
        triangles_intersect_batch(np.array([T]), np.array([CASES["piercing"][0]], float)))
