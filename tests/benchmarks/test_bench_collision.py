"""Benchmarks of issue 4's targets: all intersecting triangle pairs of two
2000-triangle meshes (sphere pair, torus pair) in three configurations
(separated with overlapping boxes, grazing, deep), by refsim's hierarchy
("bvh", compiled), the seed's pairwise levels ("seed"), and python-fcl, in
one run; and the boolean query against FCL's. Issue 16's touching
configurations (cubes face to face, a cube resting on a sphere), where the
exact stage answers every candidate pair, against FCL with the poses set per
query (``-k touching``); and both queries in every configuration, with
bodies apart too, against FCL with the poses set per query (``-k
fixed_cost``).

Read the ratios from the medians of one ``make bench`` run; the same figures,
with the ratios computed, come from
``refsim study collision-speed`` (the report's collision
section). No speed is asserted; each benchmark checks its answer instead.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from refsim.oracles.fcl_adapter import MAX_CONTACTS, FCLOracle

import refsim
from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.studies.levels import SPEED_CONFIGURATIONS

CASES = {f"{c.model}-{c.kind}": c.as_configuration() for c in SPEED_CONFIGURATIONS}

#: Issue 16's further configurations, where a query is mostly its fixed cost:
#: (model, pose of the second body; the first at the identity, exact answer).
_TURN_X = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
APART = {
    # spheres of radius 1, 10 apart: the root boxes are apart
    "sphere-2k-far": ("sphere-2k.ac", (np.eye(3), np.array([10.0, 0.0, 0.0]))),
    # 2.05 apart along x: boxes [-1, 1] and [1.05, 3.05], apart by 0.05
    "sphere-2k-boxes-apart-close": ("sphere-2k.ac", (np.eye(3), np.array([2.05, 0.0, 0.0]))),
    # two tori linked like a chain (centre circles of radius 1 in the xz and
    # xy planes, 1 apart at the closest; tubes 0.35): boxes overlap, no contact
    "torus-linked": ("torus.ac", (_TURN_X, np.array([1.0, 0.0, 0.0]))),
}


#: Issue 16's touching configurations (cubes face to face, a cube resting on
#: the sphere), where nearly every candidate pair is exactly touching and the
#: float filter certifies none: the exact stage answers them all.
TOUCHING = [name for name, config in CASES.items() if config.kind == "touching"]


class PosedFCL:
    """FCL as a simulation loop uses it: the two collision objects built once,
    both poses set before every query (setTransform), then ``collide``."""

    def __init__(self, adapter, mesh_a, mesh_b):
        self.fcl = fcl = adapter.fcl
        self.a = fcl.CollisionObject(adapter._models.get(mesh_a.vertices, mesh_a.faces))
        self.b = fcl.CollisionObject(adapter._models.get(mesh_b.vertices, mesh_b.faces))
        self.request = fcl.CollisionRequest()

    def collide(self, pose_a, pose_b) -> bool:
        fcl = self.fcl
        self.a.setTransform(fcl.Transform(*pose_a))
        self.b.setTransform(fcl.Transform(*pose_b))
        return fcl.collide(self.a, self.b, self.request, fcl.CollisionResult()) > 0

    def contacts(self, pose_a, pose_b) -> list[tuple[int, int]]:
        """The face pairs of FCL's contacts as it reports them (contacts
        enabled, as the adapter's ``intersecting_pairs`` asks), with the
        objects built once: the timed part of FCL's all-pairs query. Sorting
        them and merging repeats (:func:`unique_pairs`) is numpy work in
        Python here, left out of FCL's time; refsim's time includes its own."""
        fcl = self.fcl
        self.a.setTransform(fcl.Transform(*pose_a))
        self.b.setTransform(fcl.Transform(*pose_b))
        request = fcl.CollisionRequest(num_max_contacts=MAX_CONTACTS, enable_contact=True)
        result = fcl.CollisionResult()
        fcl.collide(self.a, self.b, request, result)
        return [(c.b1, c.b2) for c in result.contacts]


def unique_pairs(contacts) -> np.ndarray:
    """(k, 2) int64, the distinct face pairs of :meth:`PosedFCL.contacts`, sorted."""
    return np.unique(np.array(contacts, dtype=np.int64).reshape(-1, 2), axis=0)


@pytest.mark.parametrize("name", TOUCHING)
@pytest.mark.parametrize("query", ["boolean", "all pairs"])
@pytest.mark.parametrize("engine", ["refsim-bvh", "fcl-posed"])
def test_touching(benchmark, fcl, name, query, engine):
    mesh_a, pose_a, mesh_b, pose_b, expected = _setup(name)
    benchmark.group = f"touching, poses set per query: {name}, {query}"
    if engine == "fcl-posed":
        posed = PosedFCL(fcl, mesh_a, mesh_b)
        query_fn = posed.collide if query == "boolean" else posed.contacts
    else:
        query_fn = bodies_collide if query == "boolean" else intersecting_pairs
        query_fn = functools.partial(query_fn, mesh_a, mesh_b=mesh_b)
    run = lambda: query_fn(pose_a=pose_a, pose_b=pose_b)  # noqa: E731
    run()                                     # compile / build the trees outside the timing
    answer = benchmark(run)
    assert len(expected) > 0
    if query == "boolean":
        assert answer is True
    else:
        if engine == "fcl-posed":
            answer = unique_pairs(answer)
        assert np.array_equal(answer, expected)   # FCL included: the same pairs here


def _posed_case(name):
    """Meshes, poses and the exact pairs of an APART or CASES configuration."""
    if name in APART:
        model, pose_b = APART[name]
        mesh_a = mesh_b = refsim.load_model(model)
        pose_a = (np.eye(3), np.zeros(3))
        expected = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, method="seed")
        assert len(expected) == 0
        return mesh_a, pose_a, mesh_b, pose_b, expected
    return _setup(name)


@pytest.mark.parametrize("name", list(APART) + list(CASES))
@pytest.mark.parametrize("query", ["boolean", "all pairs"])
@pytest.mark.parametrize("engine", ["refsim-bvh", "fcl-posed"])
def test_fixed_cost(benchmark, fcl, name, query, engine):
    # FCL as a simulation loop asks it (PosedFCL: objects built once, both
    # poses set per query), without the adapter's own work (its mesh cache
    # lookup, and sorting the pairs) that test_boolean and test_all_pairs time
    mesh_a, pose_a, mesh_b, pose_b, expected = _posed_case(name)
    benchmark.group = f"{query}, poses set per query: {name}"
    boolean = query == "boolean"
    if engine == "fcl-posed":
        posed = PosedFCL(fcl, mesh_a, mesh_b)
        run = functools.partial(posed.collide if boolean else posed.contacts, pose_a, pose_b)
    else:
        run = functools.partial(bodies_collide if boolean else intersecting_pairs,
                                mesh_a, pose_a, mesh_b, pose_b)
    run()                                     # compile / build the trees outside the timing
    answer = benchmark(run)
    if boolean:
        assert answer == (len(expected) > 0)
    else:
        answer = unique_pairs(answer) if engine == "fcl-posed" else answer
        assert np.array_equal(answer, expected)   # FCL included: the same pairs


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
