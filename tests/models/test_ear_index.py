"""Indexed ear clipping (refsim.models.ear_index, seed S1): the specification's
triangles, bit for bit, compiled and readable alike, with near-linear work."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from refsim.models import ear_index, polygons
from refsim.models.triangulate import (
    INDEX_MIN_CORNERS,
    ear_clip,
    ear_clip_indexed,
    ear_clip_reference,
    newell_normal,
)
from refsim.studies.ear_clip import measure_ear_clip_work
from refsim.types import rotation_about_axis
from tests.models.test_triangulate import POLYGONS, _l_shape

#: Areas of the family polygons are sums of k products of coordinates <= 1
#: (or <= k for the comb, whose area is ~k): 1e-12 relative is far above the
#: rounding (~k u) and far below one missing triangle (>= 1 / k^2 of the area).
AREA_RTOL = 1e-12


def _xy(*pairs):
    return np.array([(x, y, 0.0) for x, y in pairs], float)


def _existing_test_polygons():
    """Every polygon tests/models/test_triangulate.py and test_ac3d.py clip."""
    out = {}
    for name, (make, _) in POLYGONS.items():
        out[name] = make()
        out[name + " reversed"] = make()[::-1].copy()
    out["three collinear"] = _xy((0, 0), (1, 0), (2, 0), (3, 0), (3, 1), (0, 1))
    out["repeated point"] = _xy((0, 0), (2, 0), (2, 2), (1, 2), (1, 1), (1, 1.5), (1, 1),
                                (0, 2))
    out["tilted far L"] = (_l_shape() @ rotation_about_axis([1.0, 2.0, 3.0], 0.7).T
                           + np.array([1e3, -2e3, 5e2]))
    for perm in ([2, 0, 1], [1, 2, 0]):
        out[f"L in plane {perm}"] = _l_shape()[:, perm]
    for scale in (1e300, 8.5e307, 1e-300, 2e-323):
        out[f"L times {scale}"] = _l_shape() * scale
    out["unit quad"] = _xy((5, 0), (6, 0), (6, 1), (5, 1))
    out["triangle"] = _xy((0, 0), (1, 0), (0, 1))
    out["degenerate line"] = _xy((0, 0), (1, 0), (2, 0), (3, 0), (1.5, 0))
    out["degenerate point"] = np.zeros((4, 3))
    return out


EXISTING = _existing_test_polygons()


@pytest.mark.parametrize("name", sorted(EXISTING))
@pytest.mark.parametrize("kernel", ["compiled", "readable"])
def test_existing_test_polygons_give_the_reference_triangles(name, kernel):
    p = EXISTING[name]
    expected = ear_clip_reference(p)
    got = ear_clip_indexed(p, kernel=kernel)
    assert got.dtype == np.int64
    assert got.tolist() == expected.tolist()
    assert ear_clip(p).tolist() == expected.tolist()


# Sizes at which the reference (O(k^2) in Python) is still quick.
FAMILY_SIZES = [16, 61, 200]


@pytest.mark.parametrize("kind", sorted(polygons.KINDS))
@pytest.mark.parametrize("k", FAMILY_SIZES)
def test_families_give_the_reference_triangles(kind, k):
    p = polygons.KINDS[kind](k)
    expected = ear_clip_reference(p).tolist()
    assert ear_clip_indexed(p).tolist() == expected
    tilted = p @ rotation_about_axis([1.0, 2.0, 3.0], 0.7).T + np.array([0.5, -0.25, 2.0])
    assert ear_clip_indexed(tilted).tolist() == ear_clip_reference(tilted).tolist()


@pytest.mark.parametrize("kind", sorted(polygons.KINDS))
def test_compiled_and_readable_agree_bit_for_bit_with_the_same_work(kind):
    # Same source, two runs: same triangles and the same counters (the tree's
    # sort is stable, so even its shape is the same).
    p = polygons.KINDS[kind](300)
    work_c, work_r = np.zeros(4, np.int64), np.zeros(4, np.int64)
    compiled = ear_clip_indexed(p, kernel="compiled", work=work_c)
    readable = ear_clip_indexed(p, kernel="readable", work=work_r)
    assert compiled.tobytes() == readable.tobytes()
    assert work_c.tolist() == work_r.tolist()


@pytest.mark.parametrize("kind", sorted(polygons.KINDS))
def test_families_obey_the_contract_at_20k_corners(kind):
    p = polygons.KINDS[kind](20_000)
    k = len(p)
    tri = ear_clip(p)
    assert tri.shape == (k - 2, 3)
    assert sorted(set(tri.ravel().tolist())) == list(range(k))
    v = p[tri]
    area2 = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])[:, 2]
    assert (area2 > 0.0).all()  # the polygon's winding; no zero-area triangle
    area = 0.5 * np.linalg.norm(newell_normal(p))
    assert 0.5 * area2.sum() == pytest.approx(area, rel=AREA_RTOL)


def test_below_the_threshold_ear_clip_is_the_reference():
    # Both sides of the threshold agree with the reference ...
    for k in (INDEX_MIN_CORNERS - 1, INDEX_MIN_CORNERS):
        p = polygons.random_star(k, seed=3)
        assert ear_clip(p).tolist() == ear_clip_reference(p).tolist()
    # ... and below it numba is never imported (a fresh interpreter).
    code = ("import sys; from refsim.models import polygons; "
            "from refsim.models.triangulate import ear_clip, INDEX_MIN_CORNERS; "
            "ear_clip(polygons.star(INDEX_MIN_CORNERS - 1)); print('numba' in sys.modules)")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True)
    assert run.stdout.strip() == "False"


# -- the lemma's cases, one polygon each --------------------------------------------------


def test_a_straight_run_on_the_diagonal_blocks_through_the_corner_after_b():
    # Lemma case (ii): the apex 1, where the walk starts, has the triangle
    # (0, 1, 2) whose diagonal 2 -> 0 carries the straight corners 3 and 4.
    # They are not candidates, so only the test of the corner after b (3)
    # sees them. Clipping 1 first would leave a flat polygon; the reference
    # clips 2 first, and so must the index.
    p = _xy((3, 0), (1, 3), (0, 0), (1, 0), (2, 0))
    got = ear_clip_indexed(p)
    assert got.tolist() == ear_clip_reference(p).tolist()
    assert got.tolist() == [[1, 2, 3], [1, 3, 4], [1, 4, 0]]


def test_a_corner_touching_another_edge_is_a_candidate():
    # Two overlapping spikes from (48, -4) towards the centre, the first with
    # collinear corners (39, -3.25), (30, -2.5): the second spike's edges pass
    # through them. A convex corner lying on an ear's edge then blocks it in
    # the reference; only the contact marks make it a candidate here.
    p = _xy((-64, -60), (-64, -60), (-56, -68), (-52, -80), (-12, -52), (16, -60), (32, -60),
            (20, -32), (20, -32), (19, -29), (18, -26), (17, -23), (16.75, -22.25),
            (16.5, -21.5), (16.25, -20.75), (16, -20), (36, -28), (48, -4), (39, -3.25),
            (30, -2.5), (12, -1), (48, -4), (24, -2), (48, -4), (76, -4), (60, 20), (32, 24),
            (32, 44), (40, 64), (-16, 64), (-36, 36), (-68, 56), (-80, 28), (-68, 12))
    assert ear_clip_indexed(p).tolist() == ear_clip_reference(p).tolist()
    xs, ys = np.ascontiguousarray(p[:, 0]), np.ascontiguousarray(p[:, 1])
    marked = ear_index.shared_points(xs, ys)
    assert not marked[19]  # (30, -2.5) is visited once ...
    tree = _tree(xs, ys)
    ear_index.mark_contacts(xs, ys, tree, np.empty(ear_index.STACK_SIZE, np.int64),
                            np.zeros(4, np.int64), marked)
    assert marked[19] and marked[22] and marked[23]  # ... but lies on edge 22 -> 23


def _tree(xs, ys):
    k = len(xs)
    perm, leaf = np.arange(k), np.empty(k, np.int64)
    arrays = [np.empty(2 * k, np.int64) for _ in range(4)]
    boxes = [np.empty(2 * k) for _ in range(4)]
    m = ear_index.build_tree(xs, ys, perm, leaf, *arrays, *boxes, ear_index.LEAF_SIZE)
    return ear_index.CornerTree(perm, leaf, *(a[:m] for a in arrays), *(b[:m] for b in boxes),
                                np.zeros(m, np.int64))


def test_a_bridge_to_a_hole_gives_the_reference_triangles():
    p = polygons.bridged_annulus(40)
    tri = ear_clip_indexed(p)
    assert tri.tolist() == ear_clip_reference(p).tolist()
    v = p[tri]
    area2 = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])[:, 2]
    assert (area2 >= 0.0).all()
    assert 0.5 * area2.sum() == pytest.approx(0.5 * newell_normal(p)[2], rel=AREA_RTOL)


# -- the next ear and the fallback --------------------------------------------------------


def test_fallback_clips_are_the_references():
    # A self-intersecting polygon (edge 1 -> 2 crosses 4 -> 5, and 2 -> 3
    # crosses 8 -> 0) in which no ear is left twice; the fallback then clips
    # the most convex corner, the first from the walk's pointer on ties, as
    # the reference does (outside the contract, the two agree here).
    p = _xy((2, 1), (5, 1), (3, 4), (1, 1), (4, 1), (4, 5), (4, 3), (2, 5), (1, 2))
    work = np.zeros(4, np.int64)
    assert ear_clip_indexed(p, work=work).tolist() == ear_clip_reference(p).tolist()
    assert work[ear_index.FALLBACKS] == 2


def test_most_convex_is_the_first_largest_turn_walking_from_start():
    # The tournament tree against the reference's walk round the ring, on
    # turns with many ties and some corners removed.
    rng = np.random.default_rng(7)
    for _ in range(200):
        k = int(rng.integers(1, 40))
        turn = rng.integers(-2, 3, k).astype(float)
        present = rng.random(k) < 0.7
        present[rng.integers(k)] = True
        size = 1 << (k - 1).bit_length()
        best = np.full(2 * size, -1, np.int64)
        for v in range(k):
            ear_index.tournament_set(turn, best, v, bool(present[v]))
        alive = np.flatnonzero(present)
        start = int(rng.choice(alive))
        walk = [v for v in list(range(start, k)) + list(range(start)) if present[v]]
        expected = walk[0]
        for v in walk[1:]:
            if turn[v] > turn[expected]:
                expected = v
        assert ear_index.most_convex(turn, best, start) == expected


# -- cost: near-linear work --------------------------------------------------------------

#: Work per corner may grow from 1000 to 16 000 corners by at most this
#: factor: log k grows by 1.4, k log k work gives about that; O(k^1.25)
#: would give 2, the reference's O(k^2) 16.
GROWTH_LIMIT = 2.0


@pytest.mark.parametrize("kind", ["circle", "star", "comb"])
def test_work_per_corner_grows_near_linearly(kind):
    small = measure_ear_clip_work(kind, 1000)
    large = measure_ear_clip_work(kind, 16_000)
    print(f"{kind}: work per corner {small.per_corner:.1f} at {small.corners}, "
          f"{large.per_corner:.1f} at {large.corners}")
    assert large.per_corner <= GROWTH_LIMIT * small.per_corner
    # each corner is tested as an ear about three times: once at the start
    # and once as each neighbour of a clipped ear
    assert large.ear_tests == 3 * large.corners - 6
    assert large.fallbacks == 0
