"""The triangle hierarchy and the body-level broad phase: same answers as the
seed's pairwise tests, the compiled kernel the same as the readable one."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.bundled import models_dir
from refsim.collision import bvh
from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.collision.boxes import (
    triangle_boxes,
    world_vertices,
)
from refsim.collision.seed_levels import triangle_box_pairs
from refsim.errors import StateError
from refsim.kernels import KERNELS
from refsim.models import shapes
from refsim.models.loading import load_model
from refsim.types import random_rotation, rotation_about_axis

SPHERE = load_model(models_dir() / "sphere-2k.ac")
TORUS = load_model(models_dir() / "torus.ac")
STAR = load_model(models_dir() / "star.ac")
IDENTITY = (np.eye(3), np.zeros(3))


def _random_poses(rng, n, spread):
    return [(random_rotation(rng), rng.uniform(-spread, spread, 3)) for _ in range(n)]


@pytest.mark.parametrize("mesh", [SPHERE, TORUS, STAR, shapes.geodesic_sphere(1)],
                         ids=lambda m: m.name)
def test_tree_partitions_the_triangles(mesh):
    tree = bvh.tree_of(mesh)
    leaves = np.flatnonzero(tree.left < 0)
    covered = np.concatenate([tree.order[tree.start[n]:tree.start[n] + tree.count[n]]
                              for n in leaves])
    assert sorted(covered) == list(range(mesh.n_faces))          # each triangle once
    assert (tree.count[leaves] <= bvh.LEAF_SIZE).all() and (tree.count[leaves] > 0).all()
    inner = np.flatnonzero(tree.left >= 0)
    assert (tree.left[inner] > inner).all() and (tree.right[inner] > inner).all()
    # an inner node's triangles are exactly its two children's
    for n in inner:
        a, b = tree.left[n], tree.right[n]
        assert tree.start[a] == tree.start[n]
        assert tree.start[b] == tree.start[a] + tree.count[a]
        assert tree.count[a] + tree.count[b] == tree.count[n]
    assert bvh.tree_of(mesh) is tree                             # built once per mesh


def test_refit_is_the_exact_union_of_triangle_boxes():
    pose = (rotation_about_axis([1, 2, 3], 0.4), np.array([0.3, -1.0, 2.0]))
    world = world_vertices(TORUS, pose)
    tri_lo, tri_hi = triangle_boxes(world, TORUS.faces)
    tree = bvh.tree_of(TORUS)
    lo, hi = bvh.refit(tree, tri_lo, tri_hi)
    assert np.array_equal(lo[0], world.min(axis=0)) and np.array_equal(hi[0], world.max(axis=0))
    for n in range(tree.n_nodes):
        members = tree.order[tree.start[n]:tree.start[n] + tree.count[n]]
        assert np.array_equal(lo[n], tri_lo[members].min(axis=0))
        assert np.array_equal(hi[n], tri_hi[members].max(axis=0))


def test_compiled_prepare_equals_readable_bit_for_bit():
    rng = np.random.default_rng(5)
    for pose in _random_poses(rng, 5, 3.0):
        fast = bvh.prepare_body(TORUS, pose, "compiled")
        slow = bvh.prepare_body(TORUS, pose, "readable")
        for name in ("world", "lo", "hi", "tri_lo", "tri_hi"):
            assert np.array_equal(getattr(fast, name), getattr(slow, name)), name


@pytest.mark.parametrize("mesh_a, mesh_b, spread", [
    (SPHERE, SPHERE, 1.5), (TORUS, TORUS, 1.5), (STAR, TORUS, 1.0), (SPHERE, STAR, 1.2)])
def test_hierarchy_pairs_equal_the_seed_pairs(mesh_a, mesh_b, spread):
    rng = np.random.default_rng(11)
    hits = 0
    for pose_b in _random_poses(rng, 6, spread):
        world_a, world_b = world_vertices(mesh_a, IDENTITY), world_vertices(mesh_b, pose_b)
        seed = triangle_box_pairs(world_a, mesh_a.faces, world_b, mesh_b.faces)
        for kernel in KERNELS:
            pa, pb = (bvh.prepare_body(mesh_a, IDENTITY, kernel),
                      bvh.prepare_body(mesh_b, pose_b, kernel))
            assert np.array_equal(bvh.tree_box_pairs(pa, pb, kernel), seed), kernel
        exact = {kernel: intersecting_pairs(mesh_a, IDENTITY, mesh_b, pose_b, method=method,
                                            kernel=kernel)
                 for kernel in KERNELS for method in ("bvh", "seed")}
        first = next(iter(exact.values()))
        assert all(np.array_equal(first, e) for e in exact.values())
        hits += len(first) > 0
    assert hits >= 2            # the poses do test contact, not only misses


def test_boolean_queries_agree_with_the_pair_lists():
    rng = np.random.default_rng(3)
    for pose_b in _random_poses(rng, 10, 2.2):
        pairs = intersecting_pairs(TORUS, IDENTITY, STAR, pose_b)
        boxes = intersecting_pairs(TORUS, IDENTITY, STAR, pose_b, level="triangle-aabb")
        for method in ("bvh", "seed"):
            for kernel in KERNELS:
                kw = dict(method=method, kernel=kernel)
                assert bodies_collide(TORUS, IDENTITY, STAR, pose_b, **kw) == (len(pairs) > 0)
                assert bodies_collide(TORUS, IDENTITY, STAR, pose_b, level="triangle-aabb",
                                      **kw) == (len(boxes) > 0)


def test_face_touching_cubes_collide_exactly():
    cube = load_model(models_dir() / "cube.ac")
    touching = (np.eye(3), np.array([1.0, 0.0, 0.0]))       # faces at x = 0.5 meet
    apart = (np.eye(3), np.array([1.0 + 2.0 ** -40, 0.0, 0.0]))
    for kernel in KERNELS:
        assert bodies_collide(cube, IDENTITY, cube, touching, kernel=kernel)
        assert not bodies_collide(cube, IDENTITY, cube, apart, kernel=kernel)
        assert len(intersecting_pairs(cube, IDENTITY, cube, touching, kernel=kernel)) > 0


def test_bad_arguments():
    with pytest.raises(ValueError, match="level"):
        bodies_collide(STAR, IDENTITY, STAR, IDENTITY, level="obb")
    with pytest.raises(ValueError, match="level"):
        intersecting_pairs(STAR, IDENTITY, STAR, IDENTITY, level="aabb")
    with pytest.raises(ValueError, match="method"):
        intersecting_pairs(STAR, IDENTITY, STAR, IDENTITY, method="rapid")
    with pytest.raises(ValueError, match="kernel"):
        intersecting_pairs(STAR, IDENTITY, STAR, IDENTITY, kernel="cuda")
    with pytest.raises(StateError, match="pose_b"):
        bodies_collide(STAR, IDENTITY, STAR, (np.eye(3), np.array([np.nan, 0, 0])))
    with pytest.raises(StateError, match="orthonormal"):
        intersecting_pairs(STAR, IDENTITY, STAR, (2 * np.eye(3), np.zeros(3)))
