"""Body-body response: the seed's exchange (S8) and the corrected geometry."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.dynamics.body_response import (
    SEPARATION_SLOP,
    contact_geometry,
    exchange_velocities_seed,
    separate_bodies,
)


def test_equal_masses_exchange_velocities_head_on():
    va, vb, hit = exchange_velocities_seed([-1.0, 0, 0], [1.0, 0, 0], [1.5, 0, 0], [-1.0, 0, 0])
    assert hit
    assert np.array_equal(va, [-1.0, 0, 0]) and np.array_equal(vb, [1.5, 0, 0])


def test_exchange_is_of_the_normal_components_only():
    va, vb, hit = exchange_velocities_seed([0, 0, 0], [1.0, 0, 0], [2.0, 1.0, 0], [0, -1.0, 3.0])
    assert hit
    assert np.array_equal(va, [0.0, 1.0, 0]) and np.array_equal(vb, [2.0, -1.0, 3.0])


def test_separating_bodies_keep_their_velocities():
    va, vb, hit = exchange_velocities_seed([-1.0, 0, 0], [1.0, 0, 0], [-1.0, 0, 0], [0.5, 0, 0])
    assert not hit
    assert np.array_equal(va, [-1.0, 0, 0]) and np.array_equal(vb, [0.5, 0, 0])


def test_exchange_is_elastic_not_inelastic():
    # The seed's "perfectly inelastic" exchange conserves kinetic energy (e = 1).
    rng = np.random.default_rng(3)
    for _ in range(50):
        ca, cb, va, vb = rng.normal(size=(4, 3))
        va2, vb2, _ = exchange_velocities_seed(ca, cb, va, vb)
        assert np.isclose(va2 @ va2 + vb2 @ vb2, va @ va + vb @ vb, rtol=1e-12)
        assert np.allclose(va2 + vb2, va + vb, atol=1e-12)


def _cube(center):
    corners = np.array([[x, y, z] for x in (-0.5, 0.5) for y in (-0.5, 0.5)
                        for z in (-0.5, 0.5)])
    return corners + center


def test_face_contact_normal_depth_and_separation():
    a, b = _cube([0.3, 0.9, 0.0]), _cube([0.0, 0.0, 0.0])    # a sits 0.1 into b, offset
    g = contact_geometry(a, b, [0.3, 0.9, 0.0], [0.0, 0.0, 0.0], np.eye(3), np.eye(3))
    assert np.allclose(g.n, [0.0, 1.0, 0.0])                 # not the oblique centroid line
    assert np.isclose(g.depth, 0.1)
    dx_a, dx_b = separate_bodies(g, 1.0, 1.0)
    assert np.allclose(dx_a, [0, 0.05 + 0.5 * SEPARATION_SLOP * g.extent, 0])
    assert np.allclose(dx_a, -dx_b)
    gap = ((a + dx_a) @ g.n).min() - ((b + dx_b) @ g.n).max()
    assert gap > 0.0                                          # disjoint: no interpenetration


def test_coincident_centroids_take_the_normal_from_the_bodies_axes():
    # The centroid line has zero length and is skipped; the body axes remain.
    a, b = _cube([0.0, 0.0, 0.0]), 0.5 * _cube([0.0, 0.0, 0.0])
    g = contact_geometry(a, b, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], np.eye(3), np.eye(3))
    assert np.array_equal(g.n, [1.0, 0.0, 0.0])     # the first of the tied axes: A's x
    assert g.depth == 0.75                                     # 0.25 + 0.5, exact in binary


def test_no_candidate_axis_raises_a_clear_error():
    # Coincident centroids and zero orientation axes: every candidate has
    # zero length. This used to fail with "cannot unpack non-iterable NoneType".
    a, b = _cube([0.0, 0.0, 0.0]), _cube([0.0, 0.0, 0.0])
    zero = np.zeros((3, 3))
    with pytest.raises(ValueError, match="every candidate axis has zero length"):
        contact_geometry(a, b, [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], zero, zero)
