"""The C1/C2 measurements (refsim.studies.bounds): shapes of the results and
the facts the report states. Timings are returned, never asserted."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.models import shapes
from refsim.studies import bounds as measure


def test_perturbed_sphere_is_not_convex_and_keeps_the_sphere_topology():
    mesh = measure.perturbed_sphere(5, 0.05, seed=0)
    base = shapes.geodesic_sphere(5)
    assert not mesh.is_convex and mesh.is_closed
    assert (mesh.n_vertices, mesh.n_faces) == (base.n_vertices, base.n_faces)
    radius = np.linalg.norm(mesh.vertices, axis=1)
    assert (np.abs(radius - 1.0) <= 0.05 + 1e-15).all()


def test_pose_sequences_turn_by_the_requested_angle():
    poses = measure.pose_sequence(10, "coherent", degrees_per_frame=1.0, seed=0)
    r0, r1 = poses[0][0], poses[1][0]
    angle = np.degrees(np.arccos((np.trace(r1 @ r0.T) - 1.0) / 2.0))
    assert angle == pytest.approx(1.0, abs=1e-9)
    with pytest.raises(ValueError):
        measure.pose_sequence(3, "wobble")


def test_update_cost_study_rows_and_crossovers():
    meshes = [shapes.box(), shapes.geodesic_sphere(5)]
    methods = ("scan-numpy", "incremental-python")
    study = measure.measure_update_cost(meshes, methods=methods, frames=5, repeats=2)
    assert len(study.rows) == 2 * len(meshes) * len(methods)
    row = study.row("geodesic-sphere-5", "coherent", "scan-numpy")
    assert row.visits_per_update == row.n_vertices == 252
    assert row.evaluations_per_update == 3 * 252 and row.seconds_per_update > 0.0
    assert set(study.crossovers) == {(m, "incremental-python", "scan-numpy")
                                     for m in ("coherent", "jump")}
    sizes = [n for n, _ in study.speedups[("coherent", "incremental-python", "scan-numpy")]]
    assert sizes == [12, 500]


@pytest.mark.parametrize("scan, incremental, expected", [
    ((1.0, 2.0, 4.0), (2.0, 1.5, 1.0), 500),     # faster from the middle size on
    ((1.0, 2.0, 4.0), (0.5, 3.0, 1.0), 2000),    # faster at 12, slower at 500: not yet
    ((1.0, 2.0, 4.0), (0.5, 1.0, 2.0), 12),      # faster everywhere
    ((1.0, 2.0, 4.0), (2.0, 3.0, 5.0), None),    # never faster
    ((1.0, 2.0, 4.0), (2.0, 2.0, 5.0), None),    # a tie is not faster
])
def test_crossover_is_the_smallest_size_from_which_incremental_stays_faster(
        scan, incremental, expected):
    names = {12: "a", 500: "b", 2000: "c"}
    rows = tuple(measure.UpdateCost(names[n], n, n, "coherent", method, seconds, 1.0, 1, 3.0)
                 for method, times in (("scan-numpy", scan), ("incremental-python", incremental))
                 for n, seconds in zip(names, times, strict=True))
    study = measure.UpdateCostStudy(rows=rows, degrees_per_frame=1.0, frames=1, repeats=1,
                                    seed=0, pose_check_seconds=0.0)
    meshes = [type("M", (), {"n_faces": n, "name": name}) for n, name in names.items()]
    measure._fill_crossovers(study, meshes, ("coherent",), ("scan-numpy", "incremental-python"))
    assert study.crossovers[("coherent", "incremental-python", "scan-numpy")] == expected


def test_incremental_error_on_convex_and_nonconvex_meshes():
    meshes = [shapes.geodesic_sphere(10), measure.perturbed_sphere(10, 0.05, seed=1),
              shapes.torus(), shapes.star_prism()]
    results = {r.mesh: r for r in measure.measure_incremental_error(meshes, frames=180)}
    convex = results["geodesic-sphere-10"]
    assert convex.convex and convex.wrong_frames == 0 and convex.max_deficit == 0.0
    bumpy = results["perturbed-sphere-10-0.05"]
    assert not bumpy.convex and bumpy.wrong_fraction > 0.5
    assert 0.0 < bumpy.median_deficit <= bumpy.max_deficit <= 1.0
    assert results["star"].wrong_fraction > 0.5
    # Convexity is sufficient, not necessary: a height function on a torus of
    # revolution has a single local maximum for almost every direction, and
    # on this torus the walk never went wrong (a measured fact, seed 0).
    torus = results["torus"]
    assert not torus.convex and torus.wrong_frames == 0


def test_numba_compile_cost_is_measured_cold_and_cached():
    cost = measure.measure_numba_compile_cost()
    print(cost)
    # timings vary (and are never asserted against each other here); the
    # measurement must return a finite positive figure for every phase
    for phase in (cost.import_numba, cost.cold_first_call, cost.cached_first_call,
                  cost.steady_call):
        assert 0.0 < phase < 600.0
