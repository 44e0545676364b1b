"""Exact, filtered orientation predicates (refsim.collision.predicates)."""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest

from refsim.collision.predicates import (
    FILTER_MAX_ABS,
    FILTER_MIN_ABS,
    orient2d,
    orient2d_exact,
    orient2d_filtered,
    orient2d_float,
    orient3d,
    orient3d_exact,
    orient3d_filtered,
    orient3d_float,
)
from refsim.errors import StateError
from refsim.studies.triangles import measure_filter_fallback


def _fraction_sign3(a, b, c, d):
    """Independent reference: the determinant in Fractions."""
    rows = [[Fraction(x) - Fraction(y) for x, y in zip(p, d, strict=True)] for p in (a, b, c)]
    (a1, a2, a3), (b1, b2, b3), (c1, c2, c3) = rows
    det = a1 * (b2 * c3 - b3 * c2) - a2 * (b1 * c3 - b3 * c1) + a3 * (b1 * c2 - b2 * c1)
    return (det > 0) - (det < 0)


def test_orient3d_convention():
    # a, b, c counter-clockwise seen from +z; d below the plane -> +1 (Shewchuk).
    a, b, c = (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)
    assert orient3d(a, b, c, (0.0, 0.0, -1.0)) == 1
    assert orient3d(a, b, c, (0.0, 0.0, 1.0)) == -1
    assert orient3d(a, b, c, (5.0, -3.0, 0.0)) == 0


def test_orient2d_convention():
    assert orient2d((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)) == 1
    assert orient2d((0.0, 0.0), (0.0, 1.0), (1.0, 0.0)) == -1
    assert orient2d((0.0, 0.0), (1.0, 1.0), (3.0, 3.0)) == 0


def test_orient3d_point_off_plane_by_one_ulp():
    # d is one ulp above the plane z = 1 through three points: the float
    # determinant is tiny, the exact sign is still -1 (above).
    a, b, c = (0.0, 0.0, 1.0), (1.0, 0.0, 1.0), (0.0, 1.0, 1.0)
    d = (0.3, 0.3, np.nextafter(1.0, 2.0))
    assert orient3d(a, b, c, d) == -1
    assert orient3d(a, b, c, (0.3, 0.3, np.nextafter(1.0, 0.0))) == 1


def test_orient3d_matches_fractions_on_near_degenerate_points():
    rng = np.random.default_rng(7)
    fallbacks = 0
    for _ in range(300):
        a, b, c = rng.uniform(-1, 1, (3, 3))
        u, v = rng.uniform(0, 1, 2)
        d = a + u * (b - a) + v * (c - a)   # on the plane, up to rounding
        pts = [tuple(p.tolist()) for p in (a, b, c, d)]
        sign, certified = orient3d_filtered(*pts)
        fallbacks += not certified
        assert sign == _fraction_sign3(*pts)
        assert orient3d_exact(*pts) == _fraction_sign3(*pts)
    # Points "on" the plane up to rounding are what the filter cannot decide.
    assert fallbacks > 200


def test_plain_float_sign_can_be_wrong_where_the_filter_is_not():
    # Kettner et al.'s classic family ("Classroom examples of robustness
    # problems in geometric computations", 2008): a walks over a 40 x 40 grid
    # of ulps near (0.5, 0.5), nearly collinear with b and c. Lifted to 3D
    # with d off the plane z = 0 (d not at the origin, so the differences
    # round too).
    wrong3 = wrong2 = 0
    for i, j in itertools.product(range(40), range(40)):
        a = (0.5 + i * 2.0 ** -53, 0.5 + j * 2.0 ** -53, 0.0)
        b, c, d = (12.0, 12.0, 0.0), (24.0, 24.0, 0.0), (0.1, 0.3, 1.0)
        exact = _fraction_sign3(a, b, c, d)
        assert orient3d(a, b, c, d) == exact
        wrong3 += orient3d_float(a, b, c, d) != exact
        exact2 = orient2d_exact(a[:2], b[:2], c[:2])
        assert orient2d(a[:2], b[:2], c[:2]) == exact2
        wrong2 += orient2d_float(a[:2], b[:2], c[:2]) != exact2
    # Measured: 718 and 778 of the 1600 float signs are wrong.
    assert wrong3 > 100
    assert wrong2 > 100


def test_out_of_filter_range_is_exact():
    tiny = FILTER_MIN_ABS / 4.0
    a, b, c, d = (0.0, 0.0, 0.0), (tiny, 0.0, 0.0), (0.0, tiny, 0.0), (0.0, 0.0, -tiny)
    assert orient3d(a, b, c, d) == 1
    huge = FILTER_MAX_ABS * 4.0
    assert orient3d((0.0, 0.0, 0.0), (huge, 0.0, 0.0), (0.0, huge, 0.0), (1.0, 1.0, 1.0)) == -1
    assert orient2d((0.0, 0.0), (huge, 0.0), (0.0, 1e-300)) == 1


def test_orient2d_filtered_agrees_with_exact():
    rng = np.random.default_rng(3)
    for _ in range(300):
        a, b = rng.uniform(-1, 1, (2, 2))
        c = a + rng.uniform(0, 1) * (b - a)
        pts = [tuple(p.tolist()) for p in (a, b, c)]
        assert orient2d_filtered(*pts)[0] == orient2d_exact(*pts)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_raises(bad):
    with pytest.raises(StateError):
        orient3d((0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, bad))
    with pytest.raises(StateError):
        orient2d((0, 0), (1, bad), (0, 1))


def test_filter_fallback_rates():
    rates = measure_filter_fallback(n=2000, seed=0)
    # Uniform random input: the filter decides essentially everything.
    assert rates.orient3d_random < 0.01
    assert rates.orient2d_random < 0.01
    assert rates.batch_random_pairs < 0.01
    # Points rounded onto a plane or line: mostly undecidable in floats.
    assert rates.orient3d_near_plane > 0.5
    assert rates.orient2d_near_line > 0.3
    # Small integers: exact zeros (coplanar quadruples) always fall back.
    assert 0.0 < rates.orient3d_integer_grid < 0.5
