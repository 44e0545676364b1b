"""Laws of the box updates (seed S2) on random convex meshes and pose sequences.

- The incremental box equals the linear scan's bit for bit, for both kernels,
  in coherent motion and in jumps, from random, identity and signed-permutation
  orientations (exact ties on the coplanar faces of grid hulls).
- The two incremental kernels agree on everything: box, extremes, visits.
- Every transformed vertex lies in the box, and the box is tight (its sides
  are attained by the tracker's extreme vertices).
- The scan equals trimesh's bounds within the arithmetic tolerance.
- On a non-convex mesh the tracker's box may be wrong, but only too small.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from refsim.oracles import OracleUnavailable
from refsim.oracles.trimesh_adapter import (
    TrimeshOracle,
    trimesh_skips_transform,
)

from properties.bounds.strategies import convex_hull_meshes, pose_sequences, rotations
from refsim.bounds.aabb_incremental import IncrementalAABB
from refsim.bounds.aabb_linear import (
    aabb_linear,
    rotated_coordinate,
    rotated_coordinates,
    transform_vertices,
)
from refsim.models import shapes
from refsim.studies.bounds import bounds_tolerance, perturbed_sphere

KERNELS = ["readable", "compiled"]


def _same(a, b) -> bool:
    """Bitwise equality of two boxes (lo, hi)."""
    return all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


@given(mesh=convex_hull_meshes(), sequence=pose_sequences())
def test_incremental_box_equals_scan_bitwise(mesh, sequence):
    _, poses = sequence
    trackers = [IncrementalAABB(mesh, kernel=k) for k in KERNELS]
    for frame, pose in enumerate(poses):
        scan = aabb_linear(mesh, pose)
        assert _same(aabb_linear(mesh, pose, kernel="compiled"), scan)
        for tracker in trackers:
            box = tracker.update(pose)
            assert _same(box, scan), (tracker.kernel, frame, box, scan)


@given(mesh=convex_hull_meshes(), sequence=pose_sequences())
def test_kernels_agree_on_extremes_and_counts(mesh, sequence):
    _, poses = sequence
    python = IncrementalAABB(mesh, kernel="readable")
    numba = IncrementalAABB(mesh, kernel="compiled")
    for pose in poses:
        assert _same(python.update(pose), numba.update(pose))
        assert np.array_equal(python.extremes, numba.extremes)
        assert (python.visits, python.evaluations) == (numba.visits, numba.evaluations)


@given(mesh=convex_hull_meshes(), sequence=pose_sequences(max_frames=10))
def test_box_contains_every_vertex_and_is_tight(mesh, sequence):
    _, poses = sequence
    tracker = IncrementalAABB(mesh, kernel=KERNELS[-1])
    for pose in poses:
        lo, hi = tracker.update(pose)
        world = transform_vertices(mesh.vertices, pose)
        assert (world >= lo).all() and (world <= hi).all()
        # Tight: each side is the coordinate of the extreme vertex found.
        for k in range(3):
            assert world[tracker.extremes[0, k], k] == lo[k]
            assert world[tracker.extremes[1, k], k] == hi[k]


@given(rotation=rotations(),
       vertex=st.lists(st.floats(min_value=-1e3, max_value=1e3), min_size=3, max_size=3))
def test_single_vertex_and_vectorized_arithmetic_agree_bitwise(rotation, vertex):
    # The crux of the bitwise law: the tracker transforms one vertex at a
    # time, the scan all at once; both must round the same operations.
    v = np.array(vertex)
    many = rotated_coordinates(rotation, np.stack([v, -v, 2.0 * v]).T)
    for k in range(3):
        assert rotated_coordinate(rotation, v, k) == many[k, 0]
        assert rotated_coordinate(rotation.tolist(), vertex, k) == many[k, 0]


@given(mesh=convex_hull_meshes(max_points=40), sequence=pose_sequences(max_frames=3))
def test_scan_equals_trimesh_within_arithmetic_tolerance(mesh, sequence):
    try:
        oracle = TrimeshOracle()
    except OracleUnavailable as exc:
        pytest.skip(str(exc))
    _, poses = sequence
    for pose in poses:
        lo, hi = aabb_linear(mesh, pose)
        t_lo, t_hi = oracle.aabb(mesh.vertices, pose)
        if trimesh_skips_transform(pose):
            # trimesh's convention: a transform within 1e-8 of the identity
            # is not applied (oracles/trimesh_adapter.py).
            assert np.array_equal(t_lo, mesh.vertices.min(axis=0))
            continue
        tol = bounds_tolerance(mesh.vertices, pose)
        assert (np.abs(lo - t_lo) <= tol).all() and (np.abs(hi - t_hi) <= tol).all()


_NONCONVEX = [shapes.torus(n_major=16, n_minor=10), shapes.l_beam(), shapes.star_prism(),
              perturbed_sphere(5, 0.05, seed=3)]


@given(index=st.integers(min_value=0, max_value=len(_NONCONVEX) - 1),
       sequence=pose_sequences(max_frames=20))
def test_nonconvex_tracker_box_is_never_too_large(index, sequence):
    # The tracker's extremes are real vertices, so its box lies inside the
    # true one: on a non-convex mesh it can only miss (claim C2), never overreach.
    mesh = _NONCONVEX[index]
    tracker = IncrementalAABB(mesh, kernel=KERNELS[-1], allow_nonconvex=True)
    _, poses = sequence
    for pose in poses:
        lo, hi = tracker.update(pose)
        s_lo, s_hi = aabb_linear(mesh, pose)
        assert (lo >= s_lo).all() and (hi <= s_hi).all()


@given(mesh=convex_hull_meshes(kinds=("grid",), subdivisions=(1, 2)),
       sequence=pose_sequences(motions=("jump",),
                               rotation=rotations(kinds=("identity", "signed-permutation"))))
def test_plateaus_at_axis_aligned_poses_give_the_scan_box(mesh, sequence):
    # Axis-aligned poses of grid hulls put whole faces, with vertices inside
    # them, at one coordinate: exact plateaus. A strict hill climb alone stops
    # inside a plateau that is not the extreme one; the certification step
    # (aabb_incremental, step 2) must carry the walk across.
    _, poses = sequence
    trackers = [IncrementalAABB(mesh, kernel=k) for k in KERNELS]
    for pose in poses:
        scan = aabb_linear(mesh, pose)
        for tracker in trackers:
            assert _same(tracker.update(pose), scan)
