"""Claims C1 and C2 measured: the cost and the convexity need of the incremental box.

C1 (seed): "The linear and incremental approaches were nearly equal in
performance until the size of the models became quite large. The incremental
approach performed noticeably faster on simulations containing 2000 triangles
each." :func:`measure_update_cost` times both updates, per update, over a
sweep of mesh sizes, in coherent motion (a fixed turn per frame about a fixed
axis) and in random jumps, and counts the vertices each examines.

C2 (seed): "an incremental approach requires a convex decomposition of the
model". :func:`measure_incremental_error` runs the tracker on non-convex meshes
anyway and measures how often and by how much its box is too small.

:func:`measure_numba_compile_cost` measures what the compiled kernels cost on
first use, cold and from numba's cache, in fresh interpreters.

Every function takes a seed and returns frozen dataclasses of plain numbers
(tests gate on them; the report draws them). Timings are medians over repeats
of ``time.perf_counter``; they are this machine's, not a law.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np

from refsim.bounds.aabb_incremental import IncrementalAABB
from refsim.bounds.aabb_linear import LinearAABB, aabb_linear
from refsim.kernels import numba_usable
from refsim.models import shapes
from refsim.models.mesh import Mesh
from refsim.studies import TIMED
from refsim.types import as_pose, random_rotation, rotation_about_axis, transform_points

#: The sweep of C1: box (12 triangles), icosahedron (20) and geodesic spheres
#: of 20 f^2 triangles, f = 2 .. 64 (80 .. 81920 triangles).
SWEEP_FREQUENCIES = (2, 3, 5, 7, 10, 16, 23, 32, 45, 64)

METHODS = ("scan-numpy", "scan-numba", "incremental-python", "incremental-numba")


def sweep_meshes(frequencies=SWEEP_FREQUENCIES, *, include_small: bool = True) -> list[Mesh]:
    """The C1 meshes: box, icosahedron, then geodesic spheres (all convex)."""
    meshes = [shapes.box(), shapes.icosahedron()] if include_small else []
    return meshes + [shapes.geodesic_sphere(f) for f in frequencies]


def perturbed_sphere(frequency: int = 10, amplitude: float = 0.05, seed: int = 0) -> Mesh:
    """A geodesic sphere with each vertex moved radially by ``amplitude * U(-1, 1)``.

    Non-convex for any amplitude large against rounding: bumps and dents are
    local extremes a hill climb can stop at.
    """
    base = shapes.geodesic_sphere(frequency)
    rng = np.random.default_rng(seed)
    radius = 1.0 + amplitude * rng.uniform(-1.0, 1.0, base.n_vertices)
    return Mesh(base.vertices * radius[:, None], base.faces,
                name=f"perturbed-sphere-{frequency}-{amplitude:g}")


def pose_sequence(frames: int, motion: str = "coherent", *, degrees_per_frame: float = 1.0,
                  seed: int = 0) -> list[tuple[np.ndarray, np.ndarray]]:
    """Poses for ``frames`` frames.

    ``"coherent"``: a random start orientation turned by ``degrees_per_frame``
    per frame about one random axis (the seed's simulations, where bodies
    turn a little per step). ``"jump"``: an independent uniformly random
    orientation every frame (no coherence at all). The translation is one
    random vector for all frames (it does not change which vertex is extreme).
    """
    rng = np.random.default_rng(seed)
    start = random_rotation(rng)
    axis = rng.standard_normal(3)
    translation = rng.uniform(-1.0, 1.0, 3)
    if motion == "coherent":
        step = np.radians(degrees_per_frame)
        rotations = [rotation_about_axis(axis, i * step) @ start for i in range(frames)]
    elif motion == "jump":
        rotations = [random_rotation(rng) for _ in range(frames)]
    else:
        raise ValueError(f"motion must be 'coherent' or 'jump', got {motion!r}")
    return [(r, translation.copy()) for r in rotations]


#: The kernel (:mod:`refsim.kernels`) behind each method label's second word.
METHOD_KERNELS = {"numpy": "readable", "python": "readable", "numba": "compiled",
                  "readable": "readable", "compiled": "compiled"}


def make_method(mesh: Mesh, method: str, *, allow_nonconvex: bool = False):
    """The box updater named by ``method`` (one of ``METHODS``: the scan or
    the incremental tracker, on the readable or the compiled kernel)."""
    kind, label = method.split("-")
    kernel = METHOD_KERNELS[label]
    if kind == "scan":
        return LinearAABB(mesh, kernel=kernel)
    return IncrementalAABB(mesh, kernel=kernel, allow_nonconvex=allow_nonconvex)


# -- C1: cost per update ------------------------------------------------------------

@dataclass(frozen=True)
class UpdateCost:
    """One (mesh, motion, method) cell of the C1 sweep.

    ``seconds_per_update`` is the median over repeats of (block time / frames)
    of the unchecked update (the pose check, the same for every method, is
    :attr:`UpdateCostStudy.pose_check_seconds`); ``seconds_by_repeat`` each
    repeat's block time / frames, in order (repeat ``k`` of every method
    times the same poses). ``visits_per_update`` and
    ``evaluations_per_update`` are means over the timed frames, ``max_visits``
    their maximum; the first update (a full scan for the tracker) is not timed
    or counted.
    """

    mesh: str
    n_triangles: int
    n_vertices: int
    motion: str
    method: str
    seconds_per_update: float = field(metadata=TIMED)
    visits_per_update: float
    max_visits: int
    evaluations_per_update: float
    seconds_by_repeat: tuple[float, ...] = field(default=(), metadata=TIMED)


@dataclass(frozen=True)
class UpdateCostStudy:
    """The C1 sweep.

    ``crossovers[(motion, incremental, scan)]`` is the smallest triangle count
    of the sweep from which ``incremental`` is faster than ``scan`` at that
    size and every larger one (None if never). ``speedups`` gives, per the same
    key, the list of (n_triangles, scan seconds / incremental seconds);
    ``speedup_repeats`` the list of (n_triangles, the ratio of each repeat's
    times), whose spread is the ratio's run-to-run spread.
    """

    rows: tuple[UpdateCost, ...]
    degrees_per_frame: float
    frames: int
    repeats: int
    seed: int
    pose_check_seconds: float = field(metadata=TIMED)
    crossovers: dict = field(default_factory=dict, metadata=TIMED)
    speedups: dict = field(default_factory=dict, metadata=TIMED)
    speedup_repeats: dict = field(default_factory=dict, metadata=TIMED)

    def row(self, mesh: str, motion: str, method: str) -> UpdateCost:
        for r in self.rows:
            if (r.mesh, r.motion, r.method) == (mesh, motion, method):
                return r
        raise KeyError((mesh, motion, method))


def measure_update_cost(meshes=None, *, motions=("coherent", "jump"), methods=None,
                        frames: int = 200, repeats: int = 5,
                        degrees_per_frame: float = 1.0, seed: int = 0) -> UpdateCostStudy:
    """Cost of the linear scan and the incremental update per update (claim C1).

    Parameters
    ----------
    meshes : list of Mesh, optional
        Default :func:`sweep_meshes` (12 to 81920 triangles).
    motions : tuple of {"coherent", "jump"}
    methods : tuple of str, optional
        Subset of ``METHODS``; default all that are available (the numba
        ones need the extra ``fast``).
    frames, repeats : int
        Each repeat times ``frames`` consecutive updates; the pose sequence
        continues across repeats (``frames * repeats + 1`` poses).
    degrees_per_frame : float
        The turn per frame of the coherent motion.
    """
    if meshes is None:
        meshes = sweep_meshes()
    if methods is None:
        methods = METHODS if numba_usable() else ("scan-numpy", "incremental-python")
    rows = []
    for motion in motions:
        poses = [as_pose(p) for p in pose_sequence(
            frames * repeats + 1, motion, degrees_per_frame=degrees_per_frame, seed=seed)]
        for mesh in meshes:
            for method in methods:
                rows.append(_time_method(mesh, method, motion, poses, frames, repeats))
    study = UpdateCostStudy(rows=tuple(rows), degrees_per_frame=degrees_per_frame,
                            frames=frames, repeats=repeats, seed=seed,
                            pose_check_seconds=_time_pose_check(poses[0]))
    _fill_crossovers(study, meshes, motions, methods)
    return study


def _time_method(mesh, method, motion, poses, frames, repeats) -> UpdateCost:
    tracker = make_method(mesh, method)
    update = tracker.update_unchecked
    update(*poses[0])  # the tracker's initial full scan (and numba's compile)
    block_times = []
    for rep in range(repeats):
        block = poses[1 + rep * frames: 1 + (rep + 1) * frames]
        start = time.perf_counter()
        for rotation, translation in block:
            update(rotation, translation)
        block_times.append((time.perf_counter() - start) / frames)
    # The counts, from an untimed replay of the same poses on a twin (reading
    # the counters inside the timed loop would add to the time).
    twin = make_method(mesh, method)
    twin.update_unchecked(*poses[0])
    visits, evaluations = [], []
    for rotation, translation in poses[1:frames * repeats + 1]:
        twin.update_unchecked(rotation, translation)
        visits.append(twin.visits)
        evaluations.append(twin.evaluations)
    return UpdateCost(mesh=mesh.name, n_triangles=mesh.n_faces, n_vertices=mesh.n_vertices,
                      motion=motion, method=method,
                      seconds_per_update=statistics.median(block_times),
                      visits_per_update=float(np.mean(visits)), max_visits=int(max(visits)),
                      evaluations_per_update=float(np.mean(evaluations)),
                      seconds_by_repeat=tuple(block_times))


def _time_pose_check(pose, repeats: int = 2000) -> float:
    start = time.perf_counter()
    for _ in range(repeats):
        as_pose(pose)
    return (time.perf_counter() - start) / repeats


def _fill_crossovers(study, meshes, motions, methods):
    sizes = sorted({m.n_faces for m in meshes})
    by_size = {m.n_faces: m.name for m in meshes}
    for motion in motions:
        for inc in (m for m in methods if m.startswith("incremental")):
            for scan in (m for m in methods if m.startswith("scan")):
                ratios, repeats = [], []
                for s in sizes:
                    r_scan = study.row(by_size[s], motion, scan)
                    r_inc = study.row(by_size[s], motion, inc)
                    ratios.append((s, r_scan.seconds_per_update / r_inc.seconds_per_update))
                    repeats.append((s, tuple(a / b for a, b in zip(
                        r_scan.seconds_by_repeat, r_inc.seconds_by_repeat, strict=True))))
                crossover = None
                for i, (s, _) in enumerate(ratios):
                    if all(r > 1.0 for _, r in ratios[i:]):
                        crossover = s
                        break
                study.crossovers[(motion, inc, scan)] = crossover
                study.speedups[(motion, inc, scan)] = ratios
                study.speedup_repeats[(motion, inc, scan)] = repeats


# -- C2: error on non-convex meshes ----------------------------------------------------

@dataclass(frozen=True)
class IncrementalError:
    """How wrong the incremental box is on one mesh (claim C2).

    ``frames`` updates are compared with the linear scan (the first update, a
    full scan in both, is excluded). ``wrong_fraction``: frames whose box
    differs at all; ``wrong_side_fraction``: of the ``6 * frames`` box sides,
    the fraction that differ. The deficit of a frame is the largest, over the
    six sides, of (scan side - incremental side, outward) divided by the
    scan box's extent on that axis; it is >= 0 always (the tracker's extremes
    are real vertices, so its box lies inside the true one).
    ``max_deficit`` is over all frames, ``median_deficit`` over wrong frames
    only (0 when none is wrong).
    """

    mesh: str
    n_triangles: int
    convex: bool
    motion: str
    frames: int
    wrong_frames: int
    wrong_fraction: float
    wrong_side_fraction: float
    max_deficit: float
    median_deficit: float
    visits_per_update: float


def default_error_meshes() -> list[Mesh]:
    """The C2 meshes: torus, L-beam, star prism, perturbed spheres, and a
    convex sphere as the control."""
    return [shapes.torus(), shapes.l_beam(), shapes.star_prism(),
            perturbed_sphere(10, 0.01, seed=1), perturbed_sphere(10, 0.05, seed=1),
            perturbed_sphere(23, 0.01, seed=1), shapes.geodesic_sphere(10)]


def measure_incremental_error(meshes=None, *, motion: str = "coherent", frames: int = 720,
                              degrees_per_frame: float = 1.0, seed: int = 0,
                              kernel: str | None = None) -> list[IncrementalError]:
    """Run the tracker on (non-convex) meshes and compare with the scan (C2)."""
    if meshes is None:
        meshes = default_error_meshes()
    poses = [as_pose(p) for p in pose_sequence(frames + 1, motion,
                                               degrees_per_frame=degrees_per_frame, seed=seed)]
    results = []
    for mesh in meshes:
        tracker = IncrementalAABB(mesh, kernel=kernel, allow_nonconvex=True)
        scan = LinearAABB(mesh)
        tracker.update_unchecked(*poses[0])
        deficit_list: list[float] = []
        wrong_sides = 0
        visits: list[int] = []
        for rotation, translation in poses[1:]:
            lo_i, hi_i = tracker.update_unchecked(rotation, translation)
            lo_s, hi_s = scan.update_unchecked(rotation, translation)
            extent = hi_s - lo_s
            outward = np.concatenate([(lo_i - lo_s) / extent, (hi_s - hi_i) / extent])
            wrong_sides += int((outward != 0.0).sum())
            deficit_list.append(float(outward.max()))
            visits.append(tracker.visits)
        deficits = np.array(deficit_list)
        wrong = deficits[deficits != 0.0]
        results.append(IncrementalError(
            mesh=mesh.name, n_triangles=mesh.n_faces, convex=bool(mesh.is_convex),
            motion=motion, frames=frames, wrong_frames=int(len(wrong)),
            wrong_fraction=len(wrong) / frames, wrong_side_fraction=wrong_sides / (6 * frames),
            max_deficit=float(deficits.max()),
            median_deficit=float(np.median(wrong)) if len(wrong) else 0.0,
            visits_per_update=float(np.mean(visits))))
    return results


# -- numba's first-call cost ------------------------------------------------------------

@dataclass(frozen=True)
class CompileCost:
    """What the numba kernels cost on first use, in seconds, in a fresh process.

    ``import_numba``: ``import numba``. ``cold_first_call``: the first tracker
    update pair (initial scan + a walk) and the first compiled scan with an
    empty cache (compiles and writes the cache). ``cached_first_call``: the
    same in a second fresh process that loads the cache. ``steady_call``: one
    later tracker update (2000-triangle sphere, 1 degree per frame).
    """

    import_numba: float = field(metadata=TIMED)
    cold_first_call: float = field(metadata=TIMED)
    cached_first_call: float = field(metadata=TIMED)
    steady_call: float = field(metadata=TIMED)


_COMPILE_PROBE = r"""
import json, time
t0 = time.perf_counter()
import numba  # noqa: F401
t1 = time.perf_counter()
import numpy as np
from refsim.bounds.aabb_incremental import IncrementalAABB
from refsim.bounds.aabb_linear import aabb_linear
from refsim.models.shapes import geodesic_sphere
from refsim.types import rotation_about_axis
mesh = geodesic_sphere(10)
tracker = IncrementalAABB(mesh, kernel="compiled")
poses = [(rotation_about_axis([1.0, 2.0, 3.0], np.radians(i)), np.zeros(3)) for i in range(50)]
t2 = time.perf_counter()
tracker.update(poses[0]); tracker.update(poses[1])
aabb_linear(mesh, poses[0], kernel="compiled")
t3 = time.perf_counter()
steady = []
for pose in poses[2:]:
    s = time.perf_counter(); tracker.update(pose); steady.append(time.perf_counter() - s)
steady.sort()
print(json.dumps({"import": t1 - t0, "first": t3 - t2, "steady": steady[len(steady) // 2]}))
"""


def measure_numba_compile_cost() -> CompileCost:
    """First-call cost of the numba kernels, cold and cached (two fresh processes)."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        runs = []
        for _ in range(2):
            out = subprocess.run([sys.executable, "-c", _COMPILE_PROBE], env=env,
                                 capture_output=True, text=True, check=True)
            runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
    return CompileCost(import_numba=runs[0]["import"], cold_first_call=runs[0]["first"],
                       cached_first_call=runs[1]["first"], steady_call=runs[1]["steady"])


# -- one command per figure ---------------------------------------------------------------

# -- agreement: incremental against scan, scan against trimesh ------------------------

@dataclass(frozen=True)
class BoundsAgreement:
    """How the boxes agree on one mesh over random poses.

    ``incremental_exact``: poses where the incremental box equals the scan's
    bit for bit (convex meshes only, None otherwise; the poses are random
    jumps, the hardest case for the walk). ``trimesh_bitwise``: poses where
    trimesh's box equals the scan's bit for bit; ``trimesh_within``: poses
    within the arithmetic bound :func:`bounds_tolerance`;
    ``max_difference_over_tolerance``: the largest difference seen as a
    fraction of that bound.
    """

    mesh: str
    n_triangles: int
    poses: int
    incremental_exact: int | None
    trimesh_bitwise: int
    trimesh_within: int
    max_difference_over_tolerance: float


#: How far two float64 evaluations of a world coordinate ``(R v + t)_k`` may
#: differ, in units of ``u * (sum_j |R_kj v_j| + |t_k|)`` (u = 2**-53). Each
#: is the exact value rounded through at most four operations (refsim: three
#: for ``r_k`` plus the translation; an engine with a homogeneous 4x4: a
#: length-4 dot product, fused or not), so each is within ``gamma_4 ~ 4u`` of
#: exact and the two within 8u; 16 doubles that for a rotation orthonormal
#: only to ``refsim.types.ORTHONORMAL_TOL``.
BOUNDS_ARITHMETIC_ULPS = 16.0


def bounds_tolerance(vertices, pose) -> np.ndarray:
    """(3,) per-axis bound on the difference of two boxes computed in
    float64 from the same vertices and pose by different arithmetic:
    ``BOUNDS_ARITHMETIC_ULPS * u * (max_v sum_j |R_kj v_j| + |t_k|)``.

    An engine that does not apply the pose as given (trimesh skips one within
    1e-8 of the identity) is outside this bound.
    """
    rotation, translation = (np.asarray(a, dtype=np.float64) for a in pose)
    vertices = np.abs(np.asarray(vertices, dtype=np.float64))
    size = transform_points(vertices, (np.abs(rotation), np.zeros(3))).max(axis=0)
    return BOUNDS_ARITHMETIC_ULPS * 2.0 ** -53 * (size + np.abs(translation))


def measure_bounds_agreement(engine, meshes=None, *, poses: int = 200, seed: int = 0):
    """Agreement counts of refsim's boxes with an ``aabb`` engine
    (:mod:`refsim.engines`) on random poses of the bundled-style meshes
    (list of :class:`BoundsAgreement`)."""
    meshes = meshes or [shapes.box(), shapes.icosahedron(), shapes.geodesic_sphere(10),
                        shapes.torus(), shapes.l_beam()]
    rows = []
    for mesh in meshes:
        rng = np.random.default_rng(seed)
        sequence = [(random_rotation(rng), rng.uniform(-3.0, 3.0, 3)) for _ in range(poses)]
        tracker = IncrementalAABB(mesh) if mesh.is_convex else None
        exact = bitwise = within = 0
        worst = 0.0
        for pose in sequence:
            lo, hi = aabb_linear(mesh, pose)
            if tracker is not None:
                ilo, ihi = tracker.update(pose)
                exact += bool(np.array_equal(ilo, lo) and np.array_equal(ihi, hi))
            tlo, thi = engine.aabb(mesh.vertices, pose)
            difference = np.maximum(np.abs(tlo - lo), np.abs(thi - hi))
            tolerance = bounds_tolerance(mesh.vertices, pose)
            bitwise += bool(not difference.any())
            within += bool((difference <= tolerance).all())
            worst = max(worst, float((difference / tolerance).max()))
        rows.append(BoundsAgreement(mesh.name, mesh.n_faces, poses,
                                    exact if tracker is not None else None,
                                    bitwise, within, worst))
    return rows
