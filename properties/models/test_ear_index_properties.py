"""Laws of the indexed ear clipping (refsim.models.ear_index, seed S1).

Law 1 (specification): on every polygon, ``ear_clip_indexed`` returns the
triangles of ``ear_clip_reference``, index for index, in the same order:
simple polygons (float stars, the earlier laws' polygons, and lattice stars
with exact orientations), and polygons that touch themselves (collinear runs,
repeated corners, overlapping spikes, bridges to holes).

Law 2 (same source): compiled and run as Python, the kernel gives the same
bytes.

Law 3 (contract): k - 2 triangles, every corner used; for simple polygons
each triangle turns the polygon's way, strictly (no zero-area triangle for
collinear runs), and the areas sum to the polygon's area. Polygons that touch
themselves keep only the signed sum: the specification may cover one side of
a spike and come back over it with a triangle of the other winding.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from properties.models.strategies import (
    bridged_polygons,
    decorated_polygons,
    lattice_star_polygons,
    star_polygons,
)
from refsim.models.triangulate import ear_clip_indexed, ear_clip_reference, newell_normal
from refsim.types import rotation_about_axis

#: Triangle areas and Newell's normal are sums of at most a few hundred
#: products of coordinates (exact for lattice corners, rounded once each for
#: float stars); 1e-12 relative is far above that rounding and far below a
#: missing or doubled triangle (>= 1/1000 of the area here).
AREA_RTOL = 1e-12


def _same_as_reference(p):
    tri = ear_clip_indexed(p)
    assert tri.tolist() == ear_clip_reference(p).tolist()
    return tri


def _contract(p, tri, *, simple, area=None):
    """Law 3; ``area`` is the polygon's exact area when known."""
    k = len(p)
    assert tri.shape == (k - 2, 3)
    assert sorted(set(tri.ravel().tolist())) == list(range(k))
    n = newell_normal(p)
    unit = n / np.linalg.norm(n)
    v = p[tri]
    turn = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0]) @ unit  # twice the signed areas
    if simple:
        assert (turn > 0.0).all()
    polygon = 0.5 * np.linalg.norm(n) if area is None else area
    assert abs(0.5 * turn.sum() - polygon) <= AREA_RTOL * polygon


@given(star_polygons(), st.booleans())
def test_float_stars_give_the_reference_triangles(p, reverse):
    q = p[::-1].copy() if reverse else p
    _contract(q, _same_as_reference(q), simple=True)


@given(star_polygons(), st.floats(-3.0, 3.0), st.sampled_from([[1, 0, 0], [1, 2, 3],
                                                               [0, -1, 5]]))
def test_rotated_float_stars_give_the_reference_triangles(p, angle, axis):
    q = p @ rotation_about_axis(axis, angle).T + np.array([2.0, -1.0, 0.5])
    _same_as_reference(q)


@given(lattice_star_polygons(), st.booleans())
def test_lattice_stars_give_the_reference_triangles(p, reverse):
    q = p[::-1].copy() if reverse else p
    _contract(q, _same_as_reference(q), simple=True)


@given(decorated_polygons())
def test_runs_repeats_and_spikes_give_the_reference_triangles(p):
    _contract(p, _same_as_reference(p), simple=False)


@given(bridged_polygons())
def test_bridges_to_holes_give_the_reference_triangles(polygon):
    p, area = polygon
    _contract(p, _same_as_reference(p), simple=False, area=area)


@given(st.one_of(lattice_star_polygons(), decorated_polygons(),
                 bridged_polygons().map(lambda polygon: polygon[0])))
def test_compiled_and_readable_give_the_same_bytes(p):
    assert (ear_clip_indexed(p, kernel="compiled").tobytes()
            == ear_clip_indexed(p, kernel="readable").tobytes())
