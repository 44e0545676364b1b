"""refsim's boxes and mesh facts against trimesh (oracles/trimesh_adapter.py)."""

from __future__ import annotations

import numpy as np
import pytest
from refsim.oracles.trimesh_adapter import (
    TrimeshOracle,
    bounds_tolerance,
    pose_matrix,
    trimesh_skips_transform,
)

from refsim.bounds.aabb_incremental import IncrementalAABB
from refsim.bounds.aabb_linear import aabb_linear
from refsim.models import shapes
from refsim.studies.bounds import perturbed_sphere
from refsim.types import random_rotation

pytestmark = pytest.mark.oracle

MESHES = [shapes.box((1.0, 2.0, 3.0)), shapes.tetrahedron(), shapes.icosahedron(),
          shapes.geodesic_sphere(10), shapes.torus(), shapes.l_beam(), shapes.star_prism(),
          perturbed_sphere(5, 0.05, seed=2)]
IDS = [m.name for m in MESHES]

#: Relative agreement of volume and centre of mass: both are sums over the
#: same triangles in a different order and formulation (refsim: tetrahedra
#: from the vertex average; trimesh: Eberly's integrals), so they agree to
#: rounding, a few ulps times the number of triangles.
MASS_RTOL = 1e-12


@pytest.mark.parametrize("mesh", MESHES, ids=IDS)
def test_scan_equals_trimesh_bounds_within_arithmetic_tolerance(oracle, mesh):
    trimesh = oracle(TrimeshOracle)
    rng = np.random.default_rng(1)
    worst = 0.0
    for _ in range(50):
        pose = (random_rotation(rng), rng.uniform(-5.0, 5.0, 3))
        lo, hi = aabb_linear(mesh, pose)
        t_lo, t_hi = trimesh.transformed_bounds(mesh.vertices, mesh.faces, pose)
        tol = bounds_tolerance(mesh.vertices, pose)
        difference = np.maximum(np.abs(lo - t_lo), np.abs(hi - t_hi))
        assert (difference <= tol).all()
        worst = max(worst, float((difference / tol).max()))
    print(f"{mesh.name}: largest difference {worst:.3f} of the tolerance")


@pytest.mark.parametrize("mesh", MESHES[:4], ids=IDS[:4])
def test_incremental_equals_trimesh_bounds_within_arithmetic_tolerance(oracle, mesh):
    trimesh = oracle(TrimeshOracle)
    tracker = IncrementalAABB(mesh)
    rng = np.random.default_rng(2)
    for _ in range(30):
        pose = (random_rotation(rng), rng.uniform(-5.0, 5.0, 3))
        lo, hi = tracker.update(pose)
        t_lo, t_hi = trimesh.transformed_bounds(mesh.vertices, mesh.faces, pose)
        tol = bounds_tolerance(mesh.vertices, pose)
        assert (np.abs(lo - t_lo) <= tol).all() and (np.abs(hi - t_hi) <= tol).all()


def test_trimesh_skips_near_identity_transforms(oracle):
    # The adapter's documented convention: a translation of 1e-9 is ignored.
    trimesh = oracle(TrimeshOracle)
    mesh = shapes.box()
    pose = (np.eye(3), np.array([1e-9, 0.0, 0.0]))
    assert trimesh_skips_transform(pose)
    t_lo, _ = trimesh.transformed_bounds(mesh.vertices, mesh.faces, pose)
    lo, _ = aabb_linear(mesh, pose)
    assert t_lo[0] == -0.5 and lo[0] == -0.5 + 1e-9


def test_pose_matrix_is_homogeneous():
    rotation = random_rotation(np.random.default_rng(3))
    matrix = pose_matrix((rotation, np.array([1.0, 2.0, 3.0])))
    assert np.array_equal(matrix[:3, :3], rotation)
    assert matrix[:3, 3].tolist() == [1.0, 2.0, 3.0] and matrix[3].tolist() == [0, 0, 0, 1]


@pytest.mark.parametrize("mesh", MESHES, ids=IDS)
def test_convexity_agrees_with_trimesh(oracle, mesh):
    trimesh = oracle(TrimeshOracle)
    assert mesh.is_convex == trimesh.is_convex(mesh.vertices, mesh.faces)


@pytest.mark.parametrize("mesh", MESHES, ids=IDS)
def test_volume_and_centre_of_mass_agree_with_trimesh(oracle, mesh):
    trimesh = oracle(TrimeshOracle)
    volume = trimesh.volume(mesh.vertices, mesh.faces)
    assert mesh.volume == pytest.approx(volume, rel=MASS_RTOL)
    size = float(np.linalg.norm(np.ptp(mesh.vertices, axis=0)))
    centre = trimesh.center_mass(mesh.vertices, mesh.faces)
    assert np.abs(mesh.centroid_volume - centre).max() <= MASS_RTOL * size
