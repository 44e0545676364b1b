"""Benchmarks of the box updates (claim C1): linear scan vs incremental, both
kernels, at 1 degree per frame about a fixed axis, on spheres of 180, 2000
(the seed's size) and 20480 triangles; trimesh's transformed bounds on the
2000-triangle sphere as the oracle engine's figure in the same run.

Run: ``pytest tests/benchmarks/test_bench_aabb.py --benchmark-only``.
Each benchmark times one update; the pose advances by one frame per call and
wraps after a full turn (360 frames), so the tracker always sees coherent
motion. Under ``--benchmark-disable`` (``make test``) each runs once.
The per-update figures for the report come from
``refsim.studies.bounds.measure_update_cost``; these are the same calls.
"""

from __future__ import annotations

import itertools

import pytest
from refsim.oracles import OracleUnavailable
from refsim.oracles.trimesh_adapter import TrimeshOracle

from refsim.models import shapes
from refsim.studies.bounds import make_method, pose_sequence
from refsim.types import as_pose

FREQUENCIES = {180: 3, 2000: 10, 20480: 32}  # triangles -> geodesic frequency
METHODS = ["scan-numpy", "scan-numba", "incremental-python", "incremental-numba"]
POSES = [as_pose(p) for p in pose_sequence(360, "coherent", degrees_per_frame=1.0, seed=0)]


def _method_or_skip(mesh, method):
    tracker = make_method(mesh, method)
    tracker.update_unchecked(*POSES[0])  # the tracker's first scan; numba's compile
    return tracker


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("triangles", sorted(FREQUENCIES))
def test_bench_aabb_update(benchmark, triangles, method):
    mesh = shapes.geodesic_sphere(FREQUENCIES[triangles])
    tracker = _method_or_skip(mesh, method)
    frames = itertools.cycle(POSES[1:] + POSES[:1])
    update = tracker.update_unchecked

    def one_frame():
        return update(*next(frames))

    benchmark.group = f"aabb update, {triangles} triangles, 1 deg/frame"
    lo, hi = benchmark(one_frame)
    assert (lo < hi).all()


@pytest.mark.parametrize("method", ["scan-numpy", "incremental-numba"])
def test_bench_aabb_public_update_with_pose_check(benchmark, method):
    # The public call, pose validation (as_pose) included, on the seed's size.
    mesh = shapes.geodesic_sphere(10)
    tracker = _method_or_skip(mesh, method)
    frames = itertools.cycle(POSES[1:] + POSES[:1])
    benchmark.group = "aabb public update, 2000 triangles, 1 deg/frame"
    lo, hi = benchmark(lambda: tracker.update(next(frames)))
    assert (lo < hi).all()


def test_bench_trimesh_bounds_2000(benchmark):
    # The oracle engine on the same mesh and poses: build, transform, bounds.
    try:
        oracle = TrimeshOracle()
    except OracleUnavailable as exc:
        pytest.skip(str(exc))
    mesh = shapes.geodesic_sphere(10)
    frames = itertools.cycle(POSES)
    benchmark.group = "aabb update, 2000 triangles, 1 deg/frame"
    lo, hi = benchmark(lambda: oracle.aabb(mesh.vertices, next(frames)))
    assert (lo < hi).all()
