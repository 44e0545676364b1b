"""Benchmarks of issue 4's targets: all intersecting triangle pairs of two
2000-triangle meshes (sphere pair, torus pair) in three configurations
(separated with overlapping boxes, grazing, deep), by refsim's hierarchy
("bvh", compiled), the seed's pairwise levels ("seed"), and python-fcl, in
one run; and the boolean query against FCL's.

Read the ratios from the medians of one ``make bench`` run; the same figures,
with the ratios computed, come from
``refsim study collision-speed`` (the report's collision
section). No speed is asserted; each benchmark checks its answer instead.
"""

from __future__ import annotations

import numpy as np
import pytest
from refsim.oracles.fcl_adapter import FCLOracle

from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.studies.levels import SPEED_CONFIGURATIONS

CASES = {f"{c.model}-{c.kind}": c.as_configuration() for c in SPEED_CONFIGURATIONS}


@pytest.fixture
def fcl(oracle):
    return oracle(FCLOracle)


def _setup(name):
    config = CASES[name]
    (mesh_a, mesh_b), (pose_a, pose_b) = config.meshes(), config.poses()
    expected = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, method="seed")
    return mesh_a, pose_a, mesh_b, pose_b, expected


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("engine", ["refsim-bvh", "refsim-seed", "fcl"])
def test_all_pairs(benchmark, fcl, name, engine):
    mesh_a, pose_a, mesh_b, pose_b, expected = _setup(name)
    benchmark.group = f"all pairs: {name}"
    if engine == "fcl":
        arrays = (mesh_a.vertices, mesh_a.faces, pose_a, mesh_b.vertices, mesh_b.faces, pose_b)
        query = lambda: fcl.intersecting_pairs(*arrays)  # noqa: E731
    else:
        method = engine.removeprefix("refsim-")
        query = lambda: intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b,  # noqa: E731
                                           method=method)
    query()                                   # compile / build the trees outside the timing
    pairs = benchmark(query)
    assert np.array_equal(pairs, expected)    # FCL included: the same pairs everywhere


@pytest.mark.parametrize("name", list(CASES))
@pytest.mark.parametrize("engine", ["refsim-bvh", "fcl"])
def test_boolean(benchmark, fcl, name, engine):
    mesh_a, pose_a, mesh_b, pose_b, expected = _setup(name)
    benchmark.group = f"boolean: {name}"
    if engine == "fcl":
        arrays = (mesh_a.vertices, mesh_a.faces, pose_a, mesh_b.vertices, mesh_b.faces, pose_b)
        query = lambda: fcl.bodies_collide(*arrays)  # noqa: E731
    else:
        query = lambda: bodies_collide(mesh_a, pose_a, mesh_b, pose_b)  # noqa: E731
    query()
    assert benchmark(query) == (len(expected) > 0)
