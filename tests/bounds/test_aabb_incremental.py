"""The incremental box (seed S2): exactness, kernels, plateaus, refusal, cost in visits."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from properties.bounds.strategies import midpoint_subdivision
from refsim import kernels
from refsim.bounds.aabb_incremental import (
    IncrementalAABB,
    extreme_vertex_python,
)
from refsim.bounds.aabb_linear import LinearAABB, aabb_linear
from refsim.bounds.tracker import make_aabb_tracker
from refsim.errors import ModelError, RefsimError
from refsim.models import shapes
from refsim.studies import bounds as measure

KERNELS = ["readable", "compiled"]

IDENTITY = (np.eye(3), np.zeros(3))
#: Half turn about x, exact: y -> -y, z -> -z.
HALF_TURN_X = (np.diag([1.0, -1.0, -1.0]), np.zeros(3))


def _same(a, b) -> bool:
    return all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


@pytest.mark.parametrize("kernel", KERNELS)
def test_first_update_is_a_full_scan(kernel):
    mesh = shapes.geodesic_sphere(5)
    tracker = IncrementalAABB(mesh, kernel=kernel)
    assert tracker.extremes is None
    box = tracker.update(IDENTITY)
    assert _same(box, aabb_linear(mesh, IDENTITY))
    assert (tracker.visits, tracker.evaluations) == (mesh.n_vertices, 3 * mesh.n_vertices)
    # The extremes are the lowest-index vertices at the minimum and maximum.
    v = mesh.vertices
    for k in range(3):
        assert tracker.extremes[0, k] == np.flatnonzero(v[:, k] == v[:, k].min())[0]
        assert tracker.extremes[1, k] == np.flatnonzero(v[:, k] == v[:, k].max())[0]


def test_a_transposed_rotation_gives_the_same_box_and_no_second_compile():
    # a rotation given as another's transpose is Fortran-ordered; the pose
    # check copies it to C order, so the compiled kernels meet one layout
    # (numba would otherwise compile each again for the other)
    from refsim.bounds._numba_kernels import aabb_linear_numba, incremental_update_numba
    from refsim.types import as_pose

    homogeneous = np.eye(4)
    homogeneous[:3, :3] = turn = measure.pose_sequence(1, "jump", seed=5)[0][0]
    homogeneous[:3, 3] = [0.5, -1.0, 2.0]
    checked = as_pose((homogeneous[:3, :3].T, homogeneous[:3, 3]))   # both non-contiguous
    assert checked[0].flags.c_contiguous and checked[1].flags.c_contiguous
    assert np.array_equal(checked[0], turn.T) and list(checked[1]) == [0.5, -1.0, 2.0]

    mesh = shapes.geodesic_sphere(5)
    poses = measure.pose_sequence(3, "jump", seed=5)
    c_order = [(np.ascontiguousarray(R), t) for R, t in poses]
    f_order = [(np.asfortranarray(R), t) for R, t in poses]
    assert not f_order[0][0].flags.c_contiguous
    first, second = (IncrementalAABB(mesh, kernel="compiled") for _ in range(2))
    boxes = [(first.update(p), aabb_linear(mesh, p, kernel="compiled")) for p in c_order]
    kernels_before = (len(incremental_update_numba.signatures),
                      len(aabb_linear_numba.signatures))
    for (box, scan), p in zip(boxes, f_order, strict=True):
        assert _same(second.update(p), box) and _same(aabb_linear(mesh, p, kernel="compiled"),
                                                      scan)
    assert (len(incremental_update_numba.signatures),
            len(aabb_linear_numba.signatures)) == kernels_before


@pytest.mark.parametrize("kernel", KERNELS)
@pytest.mark.parametrize("motion", ["coherent", "jump"])
def test_sphere_box_equals_scan_bitwise_over_a_turn(kernel, motion):
    mesh = shapes.geodesic_sphere(10)
    tracker = IncrementalAABB(mesh, kernel=kernel)
    for pose in measure.pose_sequence(200, motion, seed=3):
        assert _same(tracker.update(pose), aabb_linear(mesh, pose))


def test_kernels_agree_on_boxes_extremes_and_counts():
    mesh = shapes.geodesic_sphere(16)
    python = IncrementalAABB(mesh, kernel="readable")
    numba = IncrementalAABB(mesh, kernel="compiled")
    for motion in ("coherent", "jump"):
        for pose in measure.pose_sequence(150, motion, degrees_per_frame=3.0, seed=4):
            assert _same(python.update(pose), numba.update(pose))
            assert np.array_equal(python.extremes, numba.extremes)
            assert (python.visits, python.evaluations) == (numba.visits, numba.evaluations)


def _subdivided_cube():
    # A unit cube with each face cut into 16 triangles by two rounds of
    # midpoint subdivision: vertices at face centres have a flat star.
    return midpoint_subdivision(midpoint_subdivision(shapes.box()))


def test_strict_ascent_alone_stalls_on_a_plateau():
    # The reason for the certification step (DEVIATION in aabb_incremental):
    # the +y face's centre vertex, after a half turn about x, lies on the
    # bottom face; all its neighbours tie with it, so strict ascent stops there.
    mesh = _subdivided_cube()
    centre = int(np.flatnonzero((mesh.vertices == [0.0, 0.5, 0.0]).all(axis=1))[0])
    neighbors = [list(a) for a in mesh.neighbors]
    r_y = mesh.vertices @ HALF_TURN_X[0][1]  # exact: a signed copy of a column

    def strict_ascent(start):
        current = start
        while True:
            better = [u for u in neighbors[current] if r_y[u] > r_y[current]]
            if not better:
                return current
            current = max(better, key=lambda u: (r_y[u], -u))

    assert r_y[strict_ascent(centre)] == -0.5  # stalled at the minimum
    found = extreme_vertex_python(centre, 1.0, lambda v: float(r_y[v]), neighbors, 0.0)
    assert r_y[found] == 0.5  # the certified walk reaches the maximum


@pytest.mark.parametrize("kernel", KERNELS)
def test_tracker_crosses_plateaus_of_a_subdivided_cube(kernel):
    mesh = _subdivided_cube()
    assert mesh.is_convex
    # Put the extremes at face centres: a vertex order where they come first.
    centres = np.flatnonzero((np.abs(mesh.vertices) == 0.5).sum(axis=1) == 1)
    centres = centres[(mesh.vertices[centres] == 0.0).sum(axis=1) == 2]
    order = np.concatenate([centres, np.setdiff1d(np.arange(mesh.n_vertices), centres)])
    mesh = refsim.Mesh(mesh.vertices[order], np.argsort(order)[mesh.faces])
    tracker = IncrementalAABB(mesh, kernel=kernel)
    tracker.update(IDENTITY)
    assert (np.abs(mesh.vertices[tracker.extremes]).sum(axis=2) == 0.5).all()
    for pose in (HALF_TURN_X, IDENTITY, (np.diag([-1.0, -1.0, 1.0]), np.ones(3))):
        assert _same(tracker.update(pose), aabb_linear(mesh, pose))


@pytest.mark.parametrize("mesh", [shapes.torus(), shapes.l_beam(), shapes.star_prism()],
                         ids=lambda m: m.name)
def test_nonconvex_mesh_is_refused_unless_asked(mesh):
    with pytest.raises(ModelError, match="convex"):
        IncrementalAABB(mesh)
    tracker = IncrementalAABB(mesh, allow_nonconvex=True)
    lo, hi = tracker.update(IDENTITY)
    assert _same((lo, hi), aabb_linear(mesh, IDENTITY))  # the first update scans


def test_unknown_kernel_raises():
    with pytest.raises(RefsimError, match="kernel"):
        IncrementalAABB(shapes.box(), kernel="fortran")


def test_reset_makes_the_next_update_a_scan():
    mesh = shapes.geodesic_sphere(3)
    tracker = IncrementalAABB(mesh, kernel=KERNELS[-1])
    tracker.update(IDENTITY)
    tracker.update(IDENTITY)
    assert tracker.visits < mesh.n_vertices
    tracker.reset()
    assert tracker.extremes is None
    tracker.update(IDENTITY)
    assert tracker.visits == mesh.n_vertices


def test_public_names_are_exported():
    assert refsim.IncrementalAABB is IncrementalAABB
    assert refsim.make_aabb_tracker is make_aabb_tracker


def test_auto_mode_is_incremental_for_convex_and_linear_otherwise():
    assert isinstance(make_aabb_tracker(shapes.icosahedron(), "auto"), IncrementalAABB)
    assert isinstance(make_aabb_tracker(shapes.torus(), "auto"), LinearAABB)
    assert isinstance(make_aabb_tracker(shapes.icosahedron(), "linear"), LinearAABB)
    with pytest.raises(ModelError):
        make_aabb_tracker(shapes.torus(), "incremental")
    with pytest.raises(RefsimError, match="mode"):
        make_aabb_tracker(shapes.box(), "sometimes")


def test_both_trackers_give_the_same_boxes():
    mesh = shapes.geodesic_sphere(7)
    incremental, linear = make_aabb_tracker(mesh, "incremental"), make_aabb_tracker(mesh, "linear")
    for pose in measure.pose_sequence(50, "coherent", seed=9):
        assert _same(incremental.update(pose), linear.update(pose))


#: The C1 target: at 1 degree per frame the tracker examines a bounded number
#: of vertices however large the mesh. Each of the six walks examines its
#: vertex and the neighbours (degree <= 6 on these spheres): 42 when no extreme
#: moves; a move adds the new vertex's new neighbours. 96 leaves room for
#: about two moves per walk per frame.
MAX_VISITS_PER_UPDATE = 96


def test_visits_per_update_stay_flat_as_the_mesh_grows():
    # Spheres from 980 to 81920 triangles (n from 492 to 40962 vertices).
    meshes = measure.sweep_meshes((7, 10, 16, 23, 32, 45, 64), include_small=False)
    study = measure.measure_update_cost(meshes, motions=("coherent",),
                                        methods=(f"incremental-{KERNELS[-1]}",),
                                        frames=60, repeats=1, seed=0)
    n = np.array([r.n_vertices for r in study.rows], float)
    visits = np.array([r.visits_per_update for r in study.rows])
    for r in study.rows:
        print(f"{r.n_triangles:6d} triangles: {r.visits_per_update:5.1f} visits/update "
              f"(max {r.max_visits})")
    assert max(r.max_visits for r in study.rows) <= MAX_VISITS_PER_UPDATE
    # Growth against n: the log-log slope. A scan has slope 1; sqrt(n) growth
    # (the walk length once the vertex spacing falls below the turn per
    # frame) would be 0.5. The measured slope is about 0.06.
    slope = np.polyfit(np.log(n), np.log(visits), 1)[0]
    assert slope < 0.15


def test_without_numba_the_readable_kernel_is_the_default(monkeypatch):
    monkeypatch.setattr(kernels, "numba_error", lambda: "ImportError: no numba here")
    monkeypatch.delenv(kernels.KERNELS_ENV, raising=False)
    kernels._warn_readable.cache_clear()      # once per process: another test may have warned
    with pytest.warns(kernels.KernelWarning, match="no numba here"):
        tracker = IncrementalAABB(shapes.icosahedron())
    assert tracker.kernel == "readable"
    assert _same(tracker.update(IDENTITY), aabb_linear(shapes.icosahedron(), IDENTITY))
    with pytest.raises(RefsimError, match="numba"):
        IncrementalAABB(shapes.icosahedron(), kernel="compiled")
    with pytest.raises(RefsimError, match="numba"):
        aabb_linear(shapes.icosahedron(), IDENTITY, kernel="compiled")
