"""The vectorized sort and sweep gives the seed's all-pairs answer."""

from __future__ import annotations

import numpy as np

from refsim.collision.boxes import overlapping_pairs_all
from refsim.dynamics.broad_phase import overlapping_pairs


def test_same_pairs_as_all_pairs_on_integer_boxes():
    # integer corners: many exact touches and ties, which count as overlaps
    rng = np.random.default_rng(7)
    for _ in range(300):
        n = int(rng.integers(0, 25))
        lo = rng.integers(-5, 5, (n, 3)).astype(float)
        hi = lo + rng.integers(0, 4, (n, 3))
        assert np.array_equal(overlapping_pairs(lo, hi), overlapping_pairs_all(lo, hi))


def test_no_boxes_or_one_box():
    assert overlapping_pairs(np.empty((0, 3)), np.empty((0, 3))).shape == (0, 2)
    assert overlapping_pairs(np.zeros((1, 3)), np.ones((1, 3))).shape == (0, 2)


def test_compiled_sweep_matches_numpy_sweep():
    from refsim.dynamics.broad_phase import overlapping_pairs_compiled, overlapping_pairs_loops

    rng = np.random.default_rng(8)
    for _ in range(200):
        n = int(rng.integers(0, 40))
        lo = rng.integers(-6, 6, (n, 3)).astype(float)
        hi = lo + rng.integers(0, 4, (n, 3))
        expected = overlapping_pairs(lo, hi)
        assert np.array_equal(overlapping_pairs_compiled(lo, hi), expected)
        assert np.array_equal(overlapping_pairs_loops(lo, hi), expected)
