"""The report's entries on bounding boxes (seeds S2 and S3, claims C1 and C2).

The cost of a box update (C1, timed), the incremental box's error on
non-convex meshes (C2), agreement with trimesh, and numba's compile cost
(``refsim study`` only). A quick run sweeps fewer meshes, frames and
repeats.
"""

from __future__ import annotations

from refsim.report.run import Run

#: Quick: meshes up to 32 frequencies of the geodesic sphere (the seed's 2000
#: triangles included), fewer frames and repeats.
BOUNDS_QUICK_FREQUENCIES = (3, 7, 10, 16, 32)


def bounds_cost(run: Run):
    from refsim.studies import bounds

    meshes = bounds.sweep_meshes(BOUNDS_QUICK_FREQUENCIES) if run.quick \
        else bounds.sweep_meshes()
    return bounds.measure_update_cost(meshes, frames=run.size(50, 200),
                                      repeats=run.size(3, 5), seed=run.seed)


def bounds_error(run: Run):
    from refsim.studies import bounds

    return [e for motion in ("coherent", "jump")
            for e in bounds.measure_incremental_error(motion=motion, frames=run.size(180, 720),
                                                      seed=run.seed)]


def bounds_agreement(run: Run):
    from refsim.studies import bounds

    return bounds.measure_bounds_agreement(run.engine("trimesh-mesh"), poses=run.size(50, 200),
                                           seed=run.seed)


def bounds_compile(run: Run):
    from refsim.studies import bounds

    return bounds.measure_numba_compile_cost()
