"""Benchmarks of issue 26's "queries on any mesh": the boolean query on a
generated family of meshes, not hand-picked poses, by refsim (compiled, trees
built before timing) and python-fcl with the poses set per query
(``PosedFCL``: a simulation loop's use), in one run.

Meshes (each against a copy of itself): trimesh's icospheres (320 and 1280
faces), tori of 1024 faces about their z axis and of 2048 about a tilted
one, a capsule, a cylinder, a box, the convex hull of 60 random points, a
noisy icosphere (5 % radial noise), and the bundled sphere-2k and torus.
Poses, seeded per mesh: the second body turned at random and placed
``apart`` (the centres 2.4 radii apart: the bounding spheres clear),
``near`` (the centres 0.95 of the sum of the radii apart: boxes overlap,
surfaces mostly apart) or ``deep`` (0.3 of a radius apart); the tori also
``linked``, as two links of a chain. Each benchmark checks its answer
against refsim's exact one (FCL's float answer may differ only where the
exact answer is a touch, which these poses avoid).

Read the ratios (refsim's median over FCL's, per mesh and pose) from one
run: docs/decisions/mesh-family-queries.md has the table and the command. No
speed is asserted.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
import trimesh
from refsim.oracles.fcl_adapter import FCLOracle

from refsim.bundled import models_dir
from refsim.collision.bodies import bodies_collide
from refsim.models.loading import load_model
from refsim.models.mesh import Mesh
from refsim.types import rotation_about_axis
from tests.benchmarks.test_bench_collision import PosedFCL

MESHES = ("icosphere-2", "icosphere-3", "torus-z-1024", "torus-tilted-2048", "capsule",
          "cylinder", "box", "hull-60", "blob-1280", "sphere-2k.ac", "torus.ac")
POSES = ("apart", "near", "deep")
LINKED = ("torus-z-1024", "torus-tilted-2048", "torus.ac")


def _arrays(name: str):
    rng = np.random.default_rng([7, MESHES.index(name)])
    if name.endswith(".ac"):
        model = load_model(models_dir() / name)
        return model.vertices, model.faces
    if name.startswith("icosphere-"):
        mesh = trimesh.creation.icosphere(subdivisions=int(name.split("-")[1]))
    elif name == "torus-z-1024":
        mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3,
                                      major_sections=32, minor_sections=16)
    elif name == "torus-tilted-2048":
        mesh = trimesh.creation.torus(major_radius=1.0, minor_radius=0.25,
                                      major_sections=64, minor_sections=16)
        turn = np.eye(4)
        turn[:3, :3] = rotation_about_axis(np.array([1.0, 2.0, 0.5]), 0.7)
        mesh.apply_transform(turn)
    elif name == "capsule":
        mesh = trimesh.creation.capsule(height=1.0, radius=0.4, count=[24, 24])
    elif name == "cylinder":
        mesh = trimesh.creation.cylinder(radius=0.5, height=1.5, sections=48)
    elif name == "box":
        mesh = trimesh.creation.box(extents=[1.0, 0.6, 0.3])
    elif name == "hull-60":
        mesh = trimesh.convex.convex_hull(rng.normal(size=(60, 3)))
    elif name == "blob-1280":
        mesh = trimesh.creation.icosphere(subdivisions=3)
        mesh.vertices *= 1.0 + 0.05 * rng.standard_normal((len(mesh.vertices), 1))
    else:
        raise KeyError(name)
    return (np.ascontiguousarray(mesh.vertices, dtype=np.float64),
            np.ascontiguousarray(mesh.faces, dtype=np.int64))


@functools.cache
def _mesh(name: str) -> Mesh:
    return Mesh(*_arrays(name))


def _pose(name: str, kind: str):
    """The second body's pose (the first at the identity), seeded by mesh and kind."""
    mesh = _mesh(name)
    rng = np.random.default_rng([11, MESHES.index(name), (*POSES, "linked").index(kind)])
    centre = mesh.vertices.mean(axis=0)
    radius = float(np.linalg.norm(mesh.vertices - centre, axis=1).max())
    if kind == "linked":
        # a chain's next link: turned a quarter about x, one major radius along x
        R = rotation_about_axis(np.array([1.0, 0.0, 0.0]), np.pi / 2)
        return R, np.array([1.0, 0.0, 0.0])
    axis = rng.normal(size=3)
    R = rotation_about_axis(axis, float(rng.uniform(0.0, np.pi)))
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    reach = {"apart": 2.4, "near": 1.9, "deep": 0.3}[kind] * radius
    # place the second body's centre at the first's plus reach along direction
    t = centre + reach * direction - R @ centre
    return R, t


CASES = [(m, p) for m in MESHES for p in POSES] + [(m, "linked") for m in LINKED]
IDENTITY = (np.eye(3), np.zeros(3))


@pytest.fixture
def fcl(oracle):
    return oracle(FCLOracle)


@pytest.mark.parametrize("name, kind", CASES, ids=[f"{m}-{p}" for m, p in CASES])
@pytest.mark.parametrize("engine", ["refsim", "fcl-posed"])
def test_boolean_on_the_family(benchmark, fcl, name, kind, engine):
    mesh = _mesh(name)
    pose = _pose(name, kind)
    truth = bodies_collide(mesh, IDENTITY, mesh, pose)      # trees built here, untimed
    benchmark.group = f"family boolean: {name} {kind}"
    if engine == "fcl-posed":
        posed = PosedFCL(fcl, mesh, mesh)
        answer = benchmark(posed.collide, IDENTITY, pose)
    else:
        answer = benchmark(bodies_collide, mesh, IDENTITY, mesh, pose)
    assert answer == truth
    if kind == "apart":
        assert truth is False
    if kind == "deep":
        assert truth is True
