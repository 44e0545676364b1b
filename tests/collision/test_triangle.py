"""The readable exact triangle-triangle test (refsim.collision.triangle).

Every case has exactly representable coordinates, so its answer is known
without rounding; each is checked both ways round, under all vertex orders,
and under exact rigid motions (axis permutations and sign flips).
"""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest

import refsim
from refsim.collision.triangle import (
    point_in_triangle,
    point_set,
    segment_intersects_triangle,
    segments_intersect,
    triangles_intersect,
    triangles_intersect_float,
)
from refsim.errors import StateError

# The reference triangle: in the plane z = 0, legs along x and y.
T = ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0))

CASES = {
    # name: (other triangle, expected)
    "shared vertex": (((0, 0, 0), (-1, 0, 1), (0, -1, 1)), True),
    "shared edge, folded": (((0, 0, 0), (1, 0, 0), (0, -1, 1)), True),
    "shared edge, coplanar, other side": (((0, 0, 0), (1, 0, 0), (0.5, -1, 0)), True),
    "vertex on the face": (((0.25, 0.25, 0), (1, 1, 1), (0, 1, 1)), True),
    "vertex on an edge": (((0.5, 0, 0), (1, -1, 1), (0, -1, 1)), True),
    "vertex on an edge from above": (((0.5, 0.5, 0), (1, 1, 1), (2, 1, 1)), True),
    "edge crossing an edge": (((0.5, -0.5, 0), (0.5, 0.5, 0), (0.5, 0, 1)), True),
    "edge crossing an edge, perpendicular plane": (((0.25, -1, 0), (0.25, 1, 0), (0.25, 0, 1)),
                                                   True),
    "edge touching an edge end-on": (((0.5, -1, 1), (0.5, -1, -1), (0.5, -0.5, 0)), False),
    "piercing": (((0.25, 0.25, -1), (0.25, 0.25, 1), (2, 2, 2)), True),
    "piercing through both": (((0.25, -1, -1), (0.25, 2, -1), (0.25, 0.25, 1)), True),
    "coplanar overlap": (((0.5, 0.5, 0), (-0.5, 0.5, 0), (0.5, -0.5, 0)), True),
    "coplanar containment": (((0.125, 0.125, 0), (0.25, 0.125, 0), (0.125, 0.25, 0)), True),
    "coplanar containing": (((-1, -1, 0), (4, -1, 0), (-1, 4, 0)), True),
    "coplanar disjoint": (((2, 2, 0), (3, 2, 0), (2, 3, 0)), False),
    "coplanar disjoint, near the hypotenuse": (((1, 0.5, 0), (0.5, 1, 0), (1, 1, 0)), False),
    "coplanar touching at a vertex": (((1, 0, 0), (2, 0, 0), (1, 1, 0)), True),
    "coplanar vertex on an edge": (((0.5, 0.5, 0), (1, 1, 0), (2, 0.5, 0)), True),
    "coplanar touching along an edge": (((0, 0, 0), (0, 1, 0), (-1, 0.5, 0)), True),
    "coplanar sharing part of an edge": (((0.25, 0, 0), (2, 0, 0), (1, -1, 0)), True),
    "parallel planes": (((0, 0, 1), (1, 0, 1), (0, 1, 1)), False),
    "parallel planes, one ulp apart": (((0, 0, 2.0 ** -1074), (1, 0, 2.0 ** -1074),
                                        (0, 1, 2.0 ** -1074)), False),
    "disjoint": (((5, 5, 5), (6, 5, 5), (5, 6, 5)), False),
    "plane crossed outside the triangle": (((2, 2, -1), (2, 2, 1), (3, 2, 0)), False),
    "just above the face": (((0.25, 0.25, 2.0 ** -60), (1, 1, 1), (0, 1, 1)), False),
    # Degenerate triangles (zero area), answered as the point sets they are.
    "point on the face": (((0.25, 0.25, 0),) * 3, True),
    "point at a vertex": (((1, 0, 0),) * 3, True),
    "point off the face": (((0.25, 0.25, 2.0 ** -1000),) * 3, False),
    "point beyond the hypotenuse": (((0.5, 0.5 + 2.0 ** -53, 0),) * 3, False),
    "segment piercing": (((0.25, 0.25, -1), (0.25, 0.25, 1), (0.25, 0.25, 0.5)), True),
    "segment with a repeated vertex, piercing": (((0.25, 0.25, -1), (0.25, 0.25, -1),
                                                  (0.25, 0.25, 1)), True),
    "segment in the plane, crossing": (((0.5, -1, 0), (0.5, 1, 0), (0.5, 0, 0)), True),
    "segment in the plane, outside": (((2, -1, 0), (2, 1, 0), (2, 0, 0)), False),
    "segment missing the face": (((0.75, 0.75, -1), (0.75, 0.75, 1), (0.75, 0.75, 0)), False),
}


def _rigid_images(t):
    """t under the 48 exact rigid motions (axis permutations, sign flips)."""
    t = np.asarray(t, dtype=np.float64)
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            yield t[:, perm] * np.array(signs)


@pytest.mark.parametrize("name", list(CASES))
def test_known_case(name):
    other, expected = CASES[name]
    assert triangles_intersect(T, other) is expected
    assert triangles_intersect(other, T) is expected


@pytest.mark.parametrize("name", list(CASES))
def test_known_case_any_vertex_order(name):
    other, expected = CASES[name]
    for p in itertools.permutations(T):
        for q in itertools.permutations(other):
            assert triangles_intersect(p, q) is expected


@pytest.mark.parametrize("name", list(CASES))
def test_known_case_under_exact_rigid_motions(name):
    other, expected = CASES[name]
    both = np.concatenate([np.asarray(T, float), np.asarray(other, float)])
    for image in _rigid_images(both):
        assert triangles_intersect(image[:3], image[3:]) is expected
        # A power-of-two scale is exact; so is a translation where no
        # coordinate rounds (checked in rationals), which excludes the cases
        # built on offsets far below an ulp of the translation.
        shift = np.array([1024.0, -0.5, 3.0])
        moved = image * 8.0 + shift
        exact = all(Fraction(m) == Fraction(x) * 8 + Fraction(s)
                    for row, mrow in zip(image, moved, strict=True)
                    for x, m, s in zip(row, mrow, shift, strict=True))
        scaled = image * 8.0
        assert triangles_intersect(scaled[:3], scaled[3:]) is expected
        if exact:
            assert triangles_intersect(moved[:3], moved[3:]) is expected


def test_public_name():
    assert refsim.triangles_intersect is triangles_intersect
    assert refsim.triangles_intersect(T, CASES["piercing"][0]) is True


def test_point_set_classification():
    assert point_set(T)[0] == "triangle"
    assert point_set(((0, 0, 0), (2, 2, 2), (1, 1, 1))) == ("segment", ((0, 0, 0), (2, 2, 2)))
    assert point_set(((3, 1, 2),) * 3) == ("point", ((3, 1, 2),))
    # Nearly collinear is still a triangle: exact, not a tolerance.
    assert point_set(((0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (2.0, 2.0, 2.0 + 2.0 ** -51)))[0] \
        == "triangle"


def test_helpers():
    assert segment_intersects_triangle((0.25, 0.25, -1.0), (0.25, 0.25, 0.0), T)
    assert not segment_intersects_triangle((0.25, 0.25, -1.0), (0.25, 0.25, -0.5), T)
    assert point_in_triangle((0.0, 0.5, 0.0), T)
    assert not point_in_triangle((0.0, 0.5, 2.0 ** -80), T)
    # skew segments
    assert not segments_intersect((0, 0, 0), (1, 0, 0), (0.5, -1, 1), (0.5, 1, 1))
    # crossing segments, collinear overlapping, collinear disjoint, points
    assert segments_intersect((0, 0, 0), (1, 1, 1), (1, 0, 0), (0, 1, 1))
    assert segments_intersect((0, 0, 0), (2, 2, 2), (1, 1, 1), (3, 3, 3))
    assert not segments_intersect((0, 0, 0), (1, 1, 1), (2, 2, 2), (3, 3, 3))
    assert segments_intersect((1, 1, 1), (1, 1, 1), (0, 0, 0), (2, 2, 2))
    assert not segments_intersect((1, 1, 1), (1, 1, 1), (1, 1, 2), (1, 1, 2))


def test_segment_vs_segment_degenerate_triangles():
    seg1 = ((0, 0, 0), (2, 0, 0), (1, 0, 0))
    seg2 = ((1, -1, 0), (1, 1, 0), (1, 1, 0))
    seg3 = ((1, -1, 1), (1, 1, 1), (1, 0, 1))
    assert triangles_intersect(seg1, seg2) is True
    assert triangles_intersect(seg1, seg3) is False
    assert triangles_intersect(((1, 0, 0),) * 3, seg1) is True
    assert triangles_intersect(((1, 0, 0),) * 3, ((1, 0, 0),) * 3) is True
    assert triangles_intersect(((1, 0, 0),) * 3, ((1, 0, 2.0 ** -52),) * 3) is False


def test_tiny_and_huge_coordinates_take_the_exact_path():
    # Outside the filter's range the exact arithmetic answers alone.
    for scale in (2.0 ** -1000, 2.0 ** 900):
        for name in ("piercing", "coplanar disjoint", "vertex on an edge", "just above the face"):
            other, expected = CASES[name]
            a = np.asarray(T) * scale
            b = np.asarray(other, dtype=np.float64) * scale
            assert triangles_intersect(a, b) is expected, (scale, name)


@pytest.mark.parametrize("bad", [float("nan"), float("inf")])
def test_non_finite_raises(bad):
    other = np.array(CASES["piercing"][0], dtype=np.float64)
    other[1, 2] = bad
    with pytest.raises(StateError):
        triangles_intersect(T, other)
    with pytest.raises(StateError):
        triangles_intersect(other, T)


def test_wrong_shape_raises():
    with pytest.raises(StateError):
        triangles_intersect(T, [[0, 0, 0], [1, 1, 1]])


def test_float_variant_agrees_on_exactly_representable_cases():
    # Small dyadic coordinates: every float determinant is exact, so the
    # unfiltered variant (kept for claim C4) must agree here.
    for other, expected in CASES.values():
        if all(abs(x) >= 2.0 ** -60 or x == 0 for row in other for x in row):
            assert triangles_intersect_float(T, other) is expected


def test_helpers_check_their_input():
    huge = 2.0 ** 1000
    t = ((0.0, 0.0, 0.0), (huge, 0.0, 0.0), (0.0, huge, 0.0))
    assert segment_intersects_triangle((1.0, 1.0, -huge), (1.0, 1.0, huge), t)
    assert not segment_intersects_triangle((1.0, 1.0, 2.0 ** -1000), (1.0, 1.0, huge), t)
    assert point_in_triangle((2.0 ** -1074, 0.0, 0.0), t)
    with pytest.raises(StateError):
        point_in_triangle((float("nan"), 0.0, 0.0), t)
    with pytest.raises(StateError):
        segments_intersect((0, 0, 0), (1, 1), (0, 0, 0), (1, 1, 1))
