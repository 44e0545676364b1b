"""Laws of ear clipping (refsim.models.triangulate, seed S1) on random
star-shaped polygons (simple by construction: corners sorted by angle about
a point that sees the whole boundary).

For a simple polygon with k corners: k - 2 triangles, every corner used, each
triangle turning the polygon's way, areas summing to the polygon's area.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from properties.models.strategies import star_polygons
from refsim.models.triangulate import ear_clip, ear_clip_reference, newell_normal
from refsim.types import rotation_about_axis

#: The triangles' areas are computed from the same coordinates as the
#: polygon's by sums of a few dozen products of size <= 1; 1e-12 relative is
#: a hundred times the rounding and far below any missing or doubled triangle.
AREA_RTOL = 1e-12


def _laws(p, tri):
    # ear_clip is the reference below 16 corners, the index from there on:
    # both give the reference's triangles (test_ear_index_properties.py).
    assert tri.tolist() == ear_clip_reference(p).tolist()
    k = len(p)
    assert tri.shape == (k - 2, 3)
    assert sorted(set(tri.ravel().tolist())) == list(range(k))
    n = newell_normal(p)
    v = p[tri]
    cross = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    assert (cross @ n >= 0.0).all()
    area = 0.5 * np.linalg.norm(cross, axis=1).sum()
    assert abs(area - 0.5 * np.linalg.norm(n)) <= AREA_RTOL * max(area, 1e-300)


@given(star_polygons())
def test_star_polygons_obey_the_laws(p):
    _laws(p, ear_clip(p))


@given(star_polygons())
def test_reversed_winding_obeys_the_laws(p):
    q = p[::-1].copy()
    _laws(q, ear_clip(q))


@given(star_polygons(), st.floats(-3.0, 3.0), st.sampled_from([[1, 0, 0], [1, 2, 3],
                                                               [0, -1, 5]]))
def test_rotated_polygons_give_the_same_triangles_up_to_rounding(p, angle, axis):
    # Rotation changes the coordinates by rounding only; away from exact
    # collinearity the ears are the same, and the laws hold either way.
    q = p @ rotation_about_axis(axis, angle).T + np.array([2.0, -1.0, 0.5])
    _laws(q, ear_clip(q))
