"""The broad phase (seed S4 test 1): the sort and sweep gives the seed's
all-pairs answer, on either kernel, on every axis."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.collision.broad_phase import (
    overlapping_pairs,
    overlapping_pairs_all,
    overlapping_pairs_sweep,
)
from refsim.kernels import KERNELS


@pytest.mark.parametrize("kernel", KERNELS)
def test_same_pairs_as_all_pairs_on_integer_boxes(kernel):
    # integer corners: many exact touches and ties, which count as overlaps
    rng = np.random.default_rng(7)
    for _ in range(300):
        n = int(rng.integers(0, 25))
        lo = rng.integers(-5, 5, (n, 3)).astype(float)
        hi = lo + rng.integers(0, 4, (n, 3))
        assert np.array_equal(overlapping_pairs(lo, hi, kernel=kernel),
                              overlapping_pairs_all(lo, hi))


def test_every_sweep_axis_gives_the_same_pairs():
    rng = np.random.default_rng(2)
    for n in (0, 1, 2, 7, 40):
        lo = rng.integers(-5, 5, (n, 3)).astype(float)
        hi = lo + rng.integers(0, 4, (n, 3))
        expected = overlapping_pairs_all(lo, hi)
        for axis in range(3):
            assert np.array_equal(overlapping_pairs_sweep(lo, hi, axis), expected)


@pytest.mark.parametrize("kernel", KERNELS)
def test_no_boxes_or_one_box(kernel):
    assert overlapping_pairs(np.empty((0, 3)), np.empty((0, 3)), kernel=kernel).shape == (0, 2)
    assert overlapping_pairs(np.zeros((1, 3)), np.ones((1, 3)), kernel=kernel).shape == (0, 2)
