"""The vectorized kernel returns exactly what the readable one returns."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from refsim.collision.triangle import triangles_intersect
from refsim.collision.triangle_batch import certified_batch, triangles_intersect_batch
from refsim.errors import StateError
from refsim.studies.triangles import NEAR_DEGENERATE_FAMILIES, near_degenerate_pairs

from .test_triangle import CASES, T


def _readable(A, B):
    return np.array([triangles_intersect(a, b) for a, b in zip(A, B, strict=True)], dtype=bool)


def test_random_pairs():
    rng = np.random.default_rng(11)
    A, B = rng.uniform(-1.0, 1.0, (2, 4000, 3, 3))
    got = triangles_intersect_batch(A, B)
    assert got.dtype == bool and got.shape == (4000,)
    np.testing.assert_array_equal(got, _readable(A, B))
    # Both answers occur, so the comparison means something.
    assert 0.1 < got.mean() < 0.9


def test_random_pairs_at_other_scales():
    rng = np.random.default_rng(12)
    for scale, shift in ((1e-30, 0.0), (1e30, 0.0), (1.0, 1e6), (2.0 ** -250, 0.0)):
        A, B = rng.uniform(-1.0, 1.0, (2, 500, 3, 3)) * scale + shift
        np.testing.assert_array_equal(triangles_intersect_batch(A, B), _readable(A, B))


def test_near_degenerate_pairs():
    A, B, family = near_degenerate_pairs(3000, seed=5)
    got = triangles_intersect_batch(A, B)
    np.testing.assert_array_equal(got, _readable(A, B))
    # Every family contributes both answers or at least some hits.
    for f in range(len(NEAR_DEGENERATE_FAMILIES)):
        assert got[family == f].any()


def test_constructed_cases_and_their_images():
    A, B, expected = [], [], []
    for other, answer in CASES.values():
        for p in itertools.permutations(range(3)):
            A.append(np.asarray(T, float)[list(p)])
            B.append(np.asarray(other, float))
            expected.append(answer)
            A.append(np.asarray(other, float)[list(p)])
            B.append(np.asarray(T, float))
            expected.append(answer)
    got = triangles_intersect_batch(np.array(A), np.array(B))
    np.testing.assert_array_equal(got, np.array(expected))


def test_degenerate_triangles():
    rng = np.random.default_rng(13)
    n = 1000
    A = rng.integers(-2, 3, (n, 3, 3)).astype(float)
    B = rng.integers(-2, 3, (n, 3, 3)).astype(float)
    # Make a third of the B's segments and a third points.
    B[: n // 3, 2] = B[: n // 3, 0] + 2.0 * (B[: n // 3, 1] - B[: n // 3, 0])
    B[n // 3: 2 * n // 3, 1:] = B[n // 3: 2 * n // 3, :1]
    np.testing.assert_array_equal(triangles_intersect_batch(A, B), _readable(A, B))


def test_certified_answers_are_never_wrong_and_exact_zeros_fall_back():
    rng = np.random.default_rng(14)
    A = rng.integers(-2, 3, (2000, 3, 3)).astype(float)
    B = rng.integers(-2, 3, (2000, 3, 3)).astype(float)
    answer, certain = certified_batch(A, B)
    truth = _readable(A, B)
    np.testing.assert_array_equal(answer[certain], truth[certain])
    assert (~certain).any() and certain.any()


def test_empty_batch():
    got = triangles_intersect_batch(np.zeros((0, 3, 3)), np.zeros((0, 3, 3)))
    assert got.shape == (0,)


def test_bad_input_raises():
    A = np.zeros((2, 3, 3))
    B = np.ones((2, 3, 3))
    B[1, 1, 1] = np.nan
    with pytest.raises(StateError, match="pair 1"):
        triangles_intersect_batch(A, B)
    with pytest.raises(StateError):
        triangles_intersect_batch(A, np.ones((3, 3, 3)))
