"""Benchmarks of issue 26's target: what a new mesh costs before its first
answer, by refsim and by python-fcl in the same run.

- ``test_tree_build``: the trees a query needs, built for a new mesh. For
  refsim's default level, "exact", that is the exact level's FrameTree
  (least-volume split and oriented node boxes) and its packed arrays
  (``bvh_exact.pack_frame_tree``, as the query keeps them:
  ``bvh_exact._kernel_arrays``); level "triangle-aabb" needs the
  least-area tree instead (``bvh.tree_of``, ``-k aabb``). FCL: a
  ``BVHModel`` (OBBRSS) built from the arrays (beginModel, addSubModel,
  endModel). The readable build runs on the meshes of at most 2048 faces.
- ``test_first_query``: a new mesh's first boolean query against itself at
  an overlapping pose, from the arrays: the ``refsim.Mesh`` (weld, checks),
  its trees and the query; FCL builds its model, two collision objects and
  collides.

Meshes: trimesh icospheres of subdivisions 0 to 6 (20 to 81920 faces),
tori of 2048, 20000 and 200000 faces, and the bundled meshes. Each round
of ``test_tree_build`` builds for a new ``refsim.Mesh`` (made in the
round's setup, not timed: the trees alone). Compiled kernels are
compiled before timing (numba's cache); the cold compile is measured on
its own (docs/decisions/tree-build.md). No speed is asserted: each
benchmark checks its answer, and the build the readable one's.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import trimesh
from refsim.oracles.fcl_adapter import FCLOracle

from refsim.bundled import models_dir
from refsim.collision import bvh, bvh_exact
from refsim.collision.bodies import bodies_collide
from refsim.models.loading import load_model
from refsim.models.mesh import Mesh

#: Largest mesh the readable build is timed on (it takes seconds beyond).
READABLE_FACES = 2048


@functools.cache
def _arrays(name: str) -> tuple[np.ndarray, np.ndarray]:
    if name.startswith("icosphere-"):
        mesh = trimesh.creation.icosphere(subdivisions=int(name.split("-")[1]))
    elif name.startswith("torus-"):
        sections = {"torus-2048": (32, 32), "torus-20000": (200, 50),
                    "torus-200000": (400, 250)}[name]
        mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3,
                                      major_sections=sections[0], minor_sections=sections[1])
    else:
        model = load_model(models_dir() / name)
        return model.vertices, model.faces
    return (np.ascontiguousarray(mesh.vertices, dtype=np.float64),
            np.ascontiguousarray(mesh.faces, dtype=np.int64))


MESHES = ([f"icosphere-{s}" for s in range(7)] + ["torus-2048", "torus-20000", "torus-200000"]
          + sorted(p.name for p in models_dir().glob("*.ac")))


def _rounds(name: str, engine: str = "") -> int:
    """Fewer rounds for the long builds (up to about a second each)."""
    faces = len(_arrays(name)[1])
    if engine == "refsim-readable":
        return 3 if faces > 300 else 10
    return 5 if faces > 50000 else 15 if faces > 5000 else 40


def _fresh(name: str) -> Mesh:
    return Mesh(*_arrays(name))


def _fcl_model(fcl, vertices, faces):
    model = fcl.BVHModel()
    model.beginModel(len(vertices), len(faces))
    model.addSubModel(vertices, faces)
    model.endModel()
    return model


@pytest.fixture
def fcl(oracle):
    return oracle(FCLOracle).fcl


def _refsim_build(level: str, kernel: str):
    """The trees a query at ``level`` builds for a new mesh (what
    ``bodies_collide`` would build on its first call), by ``kernel``."""
    if level == "exact":
        def build(mesh):
            frame = bvh_exact.frame_tree_of(mesh, kernel)
            bvh_exact._kernel_arrays(mesh)          # what the query takes, kept
            return frame.tree
    else:
        def build(mesh):
            return bvh.tree_of(mesh, kernel)
    return build


def _face_count(name: str) -> int:
    """Faces of mesh ``name`` without generating it (an icosphere of s
    subdivisions has 20 4^s; a torus of m x n sections 2 m n)."""
    if name.startswith("icosphere-"):
        return 20 * 4 ** int(name.split("-")[1])
    if name.startswith("torus-"):
        return int(name.split("-")[1])
    return len(load_model(models_dir() / name).faces)


#: Without timing (make test's --benchmark-disable, each benchmark run once
#: to check its answers) the meshes stop here: the two largest, 82k and
#: 200k faces, take 20 s of the suite and check nothing the others do not.
SMOKE_FACES = 20480


def pytest_generate_tests(metafunc):
    """The meshes of this run: all when timing, up to SMOKE_FACES otherwise."""
    timing = not metafunc.config.getoption("benchmark_disable", False)
    meshes = [n for n in MESHES if timing or _face_count(n) <= SMOKE_FACES]
    if metafunc.function.__name__ == "test_tree_build":
        metafunc.parametrize("engine, level, name", _build_cases(meshes))
    elif metafunc.function.__name__ == "test_first_query":
        metafunc.parametrize("name", meshes)


def _build_cases(meshes):
    """(engine, level, mesh) of every build timed: refsim's compiled build at
    both levels; its readable one up to READABLE_FACES faces; FCL's once per
    mesh (its BVHModel serves every query), as level "exact"."""
    cases = []
    for name in meshes:
        faces = _face_count(name)
        for level in ("exact", "aabb"):
            cases.append(("refsim-compiled", level, name))
            if faces <= READABLE_FACES:
                cases.append(("refsim-readable", level, name))
        cases.append(("fcl", "exact", name))
    return cases


def test_tree_build(benchmark, fcl, name, level, engine):
    vertices, faces = _arrays(name)
    benchmark.group = f"tree build: {name} ({len(faces)} faces)"
    benchmark.name = f"{engine} {level}" if engine != "fcl" else "fcl BVHModel"
    rounds = _rounds(name, engine)
    if engine == "fcl":
        faces32 = np.ascontiguousarray(faces, dtype=np.int32)
        model = benchmark.pedantic(_fcl_model, args=(fcl, vertices, faces32), rounds=rounds,
                                   iterations=1, warmup_rounds=1)
        assert model.num_tries_() == len(faces)
        return
    kernel = engine.removeprefix("refsim-")
    build = _refsim_build(level, kernel)
    build(_fresh(name))                            # compile outside the timing
    tree = benchmark.pedantic(build, setup=lambda: ((_fresh(name),), {}), rounds=rounds,
                              iterations=1)
    reference = _refsim_build(level, "readable" if len(faces) <= READABLE_FACES
                              else "compiled")(_fresh(name))
    for got, expected in zip((tree.left, tree.right, tree.start, tree.count, tree.order),
                             (reference.left, reference.right, reference.start,
                              reference.count, reference.order), strict=True):
        assert np.array_equal(got, expected)
    assert np.array_equal(np.sort(tree.order), np.arange(len(faces)))


#: The second body's offset, as a fraction of the mesh's extent along x:
#: the two copies overlap.
OFFSET = 0.5


@pytest.mark.parametrize("engine", ["refsim", "fcl"])
def test_first_query(benchmark, fcl, name, engine):
    vertices, faces = _arrays(name)
    benchmark.group = f"first query: {name} ({len(faces)} faces)"
    shift = OFFSET * float(np.ptp(vertices[:, 0]))
    pose_a = (np.eye(3), np.zeros(3))
    pose_b = (np.eye(3), np.array([shift, 0.0, 0.0]))
    rounds = _rounds(name)
    if engine == "fcl":
        faces32 = np.ascontiguousarray(faces, dtype=np.int32)

        def query():
            model = _fcl_model(fcl, vertices, faces32)
            a = fcl.CollisionObject(model, fcl.Transform(*pose_a))
            b = fcl.CollisionObject(model, fcl.Transform(*pose_b))
            return fcl.collide(a, b, fcl.CollisionRequest(), fcl.CollisionResult()) > 0

        answer = benchmark.pedantic(query, rounds=rounds, iterations=1, warmup_rounds=1)
    else:
        # from the arrays, as FCL's: the Mesh (welding, checks) is part of
        # what a new mesh costs before its first answer
        bodies_collide(_fresh(name), pose_a, _fresh(name), pose_b)   # compile outside

        def query():
            mesh = Mesh(vertices, faces)
            return bodies_collide(mesh, pose_a, mesh, pose_b)

        answer = benchmark.pedantic(query, rounds=rounds, iterations=1, warmup_rounds=1)
    assert answer is True
