"""Laws of the body-body collision hierarchy (refsim.collision.bodies, seed S4).

For random poses of small bundled models (generic, and axis-aligned with
exact touching contacts): the levels nest (exact pairs are triangle-aabb
pairs), every coarser level is conservative, the hierarchy ("bvh") finds the
same pairs as the seed's pairwise path for both kernels, and FCL's face
pairs differ from refsim's only where a float engine may (classified;
no "bug").
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from refsim.oracles import OracleUnavailable

from properties.collision.strategies import posed_model_pairs
from refsim.collision import bvh_exact
from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.collision.boxes import world_vertices
from refsim.studies.triangles import classify_disagreement


def as_set(pairs) -> set:
    return set(map(tuple, np.asarray(pairs).reshape(-1, 2).tolist()))


@given(posed_model_pairs())
def test_exact_pairs_are_triangle_aabb_pairs(case):
    mesh_a, pose_a, mesh_b, pose_b, _ = case
    exact = as_set(intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, level="exact"))
    boxes = as_set(intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, level="triangle-aabb"))
    assert exact <= boxes


@given(posed_model_pairs())
def test_coarser_levels_are_conservative(case):
    mesh_a, pose_a, mesh_b, pose_b, _ = case
    if bodies_collide(mesh_a, pose_a, mesh_b, pose_b, level="exact"):
        for level in ("sphere", "aabb", "triangle-aabb"):
            assert bodies_collide(mesh_a, pose_a, mesh_b, pose_b, level=level), level


@given(posed_model_pairs())
def test_boolean_query_matches_pairs(case):
    mesh_a, pose_a, mesh_b, pose_b, _ = case
    for level in ("triangle-aabb", "exact"):
        pairs = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, level=level)
        assert bodies_collide(mesh_a, pose_a, mesh_b, pose_b, level=level) == (len(pairs) > 0)


@given(posed_model_pairs())
def test_the_boolean_query_stops_at_an_intersecting_pair(case):
    """The compiled boolean query's early exit (bvh_exact's FIRST_HIT, the
    exact stage answering each pair the filter leaves open as it is met):
    the pair it stops at is one of the all-pairs query's, and it finds one
    exactly when that query finds any (unless pairs are left undecided for
    the readable kernel, which these models' coordinates never need)."""
    mesh_a, pose_a, mesh_b, pose_b, _ = case
    pairs = as_set(intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, kernel="compiled"))
    found, undecided = bvh_exact.query_compiled(mesh_a, pose_a, mesh_b, pose_b,
                                                bvh_exact.FIRST_HIT)
    assert len(undecided) == 0
    assert len(found) == (1 if pairs else 0) and as_set(found) <= pairs
    assert bodies_collide(mesh_a, pose_a, mesh_b, pose_b, kernel="compiled") == bool(pairs)


@pytest.mark.parametrize("kernel", ["compiled", "readable"])
@given(case=posed_model_pairs())
def test_bvh_equals_seed_path(kernel, case):
    mesh_a, pose_a, mesh_b, pose_b, _ = case
    for level in ("triangle-aabb", "exact"):
        bvh = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, level=level, method="bvh",
                                 kernel=kernel)
        seed = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, level=level, method="seed",
                                  kernel=kernel)
        np.testing.assert_array_equal(bvh, seed)
        assert bodies_collide(mesh_a, pose_a, mesh_b, pose_b, level=level, method="bvh",
                              kernel=kernel) == bodies_collide(
            mesh_a, pose_a, mesh_b, pose_b, level=level, method="seed", kernel=kernel)


_FCL = []


def fcl_oracle():
    if not _FCL:
        try:
            from refsim.oracles.fcl_adapter import FCLOracle
            _FCL.append(FCLOracle())
        except OracleUnavailable as exc:
            pytest.skip(str(exc))
    return _FCL[0]


@pytest.mark.oracle
@given(posed_model_pairs())
def test_fcl_pairs_differ_only_where_floats_may(case):
    fcl = fcl_oracle()
    mesh_a, pose_a, mesh_b, pose_b, label = case
    ours = as_set(intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b))
    theirs = as_set(fcl.intersecting_pairs(mesh_a.vertices, mesh_a.faces, pose_a,
                                           mesh_b.vertices, mesh_b.faces, pose_b))
    world_a, world_b = world_vertices(mesh_a, pose_a), world_vertices(mesh_b, pose_b)
    for i, j in ours ^ theirs:
        kind = classify_disagreement(world_a[mesh_a.faces[i]], world_b[mesh_b.faces[j]])
        assert kind != "bug", (label, i, j, (i, j) in ours)
