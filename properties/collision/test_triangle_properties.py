"""Laws of the exact triangle-triangle test (refsim.collision.triangle).

Symmetry, invariance under vertex order and under exact rigid motions, known
answers of constructed contacts, and equality of the batch and readable
kernels. Constructed pairs use dyadic coordinates so every motion is exact:
a law that fails is a bug, never rounding.
"""

from __future__ import annotations

import itertools

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from properties.collision.strategies import (
    constructed_contact_pairs,
    exact_rigid_motions,
    triangle_pairs,
)
from refsim.collision.predicates import in_filter_range
from refsim.collision.triangle import as_triangle, point_set, triangles_intersect
from refsim.collision.triangle_batch import triangles_intersect_batch


@given(triangle_pairs())
def test_symmetric(pair):
    a, b = pair
    assert triangles_intersect(a, b) == triangles_intersect(b, a)


@given(constructed_contact_pairs())
def test_symmetric_on_contacts(case):
    a, b, _ = case
    assert triangles_intersect(a, b) == triangles_intersect(b, a)


@given(constructed_contact_pairs())
def test_constructed_contacts_touch(case):
    a, b, kind = case
    if kind != "coplanar":
        assert triangles_intersect(a, b) is True


@given(st.one_of(triangle_pairs(), constructed_contact_pairs().map(lambda c: c[:2])))
def test_invariant_under_vertex_order(pair):
    a, b = pair
    expected = triangles_intersect(a, b)
    for p in itertools.permutations(range(3)):
        for q in itertools.permutations(range(3)):
            assert triangles_intersect(a[list(p)], b[list(q)]) == expected


@given(constructed_contact_pairs(), exact_rigid_motions())
def test_invariant_under_exact_rigid_motions(case, motion):
    a, b, _ = case
    assert triangles_intersect(motion(a), motion(b)) == triangles_intersect(a, b)


@given(triangle_pairs(), st.permutations([0, 1, 2]),
       st.tuples(*[st.sampled_from([-1.0, 1.0])] * 3), st.integers(-40, 40))
def test_generic_pairs_invariant_under_exact_motions(pair, perm, signs, k):
    # Permuting axes, flipping signs and scaling by 2**k are exact for any
    # floats away from underflow and overflow (|k| <= 40 keeps them away).
    a, b = pair
    s = np.array(signs) * 2.0 ** k
    expected = triangles_intersect(a, b)
    assert triangles_intersect(a[:, perm] * s, b[:, perm] * s) == expected


@given(triangle_pairs(), st.integers(3, 6))
def test_far_apart_never_intersect(pair, k):
    # The box of each triangle lies in [-2, 2]^3; a shift by 2**k >= 8 separates them.
    a, b = pair
    assert triangles_intersect(a, b + 2.0 ** k) is False


@given(st.lists(st.one_of(triangle_pairs(), constructed_contact_pairs().map(lambda c: c[:2])),
                min_size=1, max_size=40))
def test_batch_equals_readable(pairs):
    A = np.array([p[0] for p in pairs])
    B = np.array([p[1] for p in pairs])
    expected = np.array([triangles_intersect(a, b) for a, b in pairs])
    np.testing.assert_array_equal(triangles_intersect_batch(A, B), expected)


@given(st.lists(st.one_of(triangle_pairs(), constructed_contact_pairs().map(lambda c: c[:2])),
                min_size=1, max_size=40))
def test_numba_equals_readable(pairs):
    from refsim.collision.triangle_numba import triangles_intersect_numba

    A = np.array([p[0] for p in pairs])
    B = np.array([p[1] for p in pairs])
    expected = np.array([triangles_intersect(a, b) for a, b in pairs])
    np.testing.assert_array_equal(triangles_intersect_numba(A, B), expected)


@given(st.lists(st.one_of(triangle_pairs(), constructed_contact_pairs().map(lambda c: c[:2])),
                min_size=1, max_size=40))
def test_compiled_exact_stage_equals_readable(pairs):
    # The stage behind the numba filter (refsim.collision._numba_exact), alone:
    # every pair it decides is answered as the readable test answers it.
    from refsim.collision.triangle_numba import compiled_exact_kernels

    A = np.array([p[0] for p in pairs], dtype=np.float64)
    B = np.array([p[1] for p in pairs], dtype=np.float64)
    expected = np.array([triangles_intersect(a, b) for a, b in pairs])
    answer, decided = compiled_exact_kernels().intersect_batch(A, B)
    np.testing.assert_array_equal(answer[decided], expected[decided])
    # It decides exactly the pairs of two triangles of positive area with
    # coordinates in the filter's range.
    takes = [in_filter_range(np.concatenate([a, b]).ravel().tolist())
             and point_set(as_triangle(a))[0] == point_set(as_triangle(b))[0] == "triangle"
             for a, b in zip(A, B, strict=True)]
    np.testing.assert_array_equal(decided, np.array(takes))
