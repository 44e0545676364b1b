"""The measured polygon families (refsim.models.polygons, seed S1): corner
counts, counter-clockwise, no crossing edges, and their areas in closed form."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.errors import OptionError
from refsim.models import polygons
from refsim.models.triangulate import newell_normal
from refsim.studies.ear_clip import measure_ear_clip_seconds, measure_ear_clip_work

#: Shoelace sums of ~100 products of coordinates <= 2 (the comb: <= 100):
#: rounding ~1e-14 relative; any wrong corner changes an area by > 1e-3.
AREA_RTOL = 1e-12


def _regular_area(n, r=1.0):
    return 0.5 * n * r * r * np.sin(2.0 * np.pi / n)


K = 96
AREAS = {
    "circle": _regular_area(K),
    "star": 0.5 * K * 0.35 * np.sin(2.0 * np.pi / K),  # K triangles tip-origin-notch
    "comb": 4 * (K // 4) - 1.0,  # base (2t - 1) x 1 plus t teeth 1 x 2
    "collinear_square": 1.0,
    "spiked_circle": _regular_area(K // 2),  # the spikes have no width
    "bridged_annulus": _regular_area(47) - _regular_area(47, 0.5),  # (96 - 2) / 2 each
}


def _crossing_edges(xy):
    """Pairs of non-adjacent edges that cross properly (O(k^2), for small k)."""
    def orient(a, b, c):
        return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    k, found = len(xy), []
    for i in range(k):
        for j in range(i + 2, k - (i == 0)):
            a, b, c, d = xy[i], xy[(i + 1) % k], xy[j], xy[(j + 1) % k]
            if (orient(a, b, c) * orient(a, b, d) < 0) and (orient(c, d, a) * orient(c, d, b) < 0):
                found.append((i, j))
    return found


@pytest.mark.parametrize("kind", sorted(polygons.KINDS))
def test_each_family_is_a_counter_clockwise_polygon_without_crossings(kind):
    p = polygons.KINDS[kind](K)
    assert p.shape == (K, 3) and (p[:, 2] == 0.0).all()
    assert newell_normal(p)[2] > 0.0
    assert _crossing_edges(p[:, :2]) == []
    if kind in AREAS:
        assert 0.5 * newell_normal(p)[2] == pytest.approx(AREAS[kind], rel=AREA_RTOL)


def test_repeated_points_are_where_the_docstrings_say():
    spiked = polygons.spiked_circle(16)  # 8 base corners, spikes at 0, 2, 4, 6
    assert spiked[0].tolist() == spiked[2].tolist() and spiked[1].tolist() == [0.5, 0.0, 0.0]
    ring = polygons.bridged_annulus(16)  # 7 outline corners, 7 hole corners
    assert ring[0].tolist() == ring[7].tolist() == [1.0, 0.0, 0.0]
    assert ring[8].tolist() == ring[15].tolist() == [0.5, 0.0, 0.0]


def test_measurements_return_counts_and_seconds():
    work = measure_ear_clip_work("star", 200)
    assert work.corners == 200 and work.ear_tests == 3 * 200 - 6 and work.fallbacks == 0
    assert work.per_corner > 3.0
    assert measure_ear_clip_seconds("circle", 100, method="reference", repeats=1) > 0.0
    with pytest.raises(OptionError, match="method"):
        measure_ear_clip_seconds("circle", 100, method="fast")
