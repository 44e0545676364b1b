"""Incremental axis-aligned bounding box by hill climbing (seed S2).

The seed: "This system supports both linear O(n) and incremental O(1)
axis-aligned bounding box update. The problem of finding closest features has
been reduced to finding the 6 extreme points that form a tight-fitting
axis-aligned bounding box", with the vertex neighbours from S1 "for use in the
incremental bounding box update routine", and "Non-convex objects are
supported ... by using the brute-force linear AABB update; an incremental
approach requires a convex decomposition of the model".

Algorithm (after the "dynamically resized" bounding boxes of J. D. Cohen,
M. C. Lin, D. Manocha, M. K. Ponamgi, "I-COLLIDE: an interactive and exact
collision detection system for large-scale environments", ACM Symposium on
Interactive 3D Graphics, 1995, which keep each body's box for sweep and prune
by walking from last frame's extremal vertices; the idea of tracking a
feature by local moves that stay near the previous answer under coherent
motion is M. C. Lin and J. F. Canny, "A fast algorithm for incremental
distance calculation", IEEE ICRA, 1991):

- Keep six extreme vertices: the minimum and the maximum on each world axis.
- On an update, for each of the six, walk the vertex-neighbour graph from
  last frame's extreme vertex, **step 1**: move to the neighbour with the
  largest ``sign * r_k`` while it is strictly larger than the current
  vertex's (steepest ascent; among equal neighbours the lowest index, so the
  two kernels agree). ``r_k`` is the rotated coordinate of
  :func:`refsim.bounds.aabb_linear.rotated_coordinate`, the same arithmetic as
  the linear scan, so the box can be compared with it bit for bit.
- The first update has no previous extremes and initializes by a full scan
  (``visits == n``), exactly the linear scan plus remembering the arg-extremes
  (the lowest index among ties).

Why it is exact on convex meshes: for a linear function on a convex polytope,
a vertex with no better neighbour is a global maximum (the simplex method's
argument: the polytope lies in the cone of the edges leaving any vertex). On a
closed convex triangulated surface, even one with vertices inside flat faces,
the vertices with ``f >= c`` are connected in the edge graph for every ``c``,
so a non-decreasing path always leads to the maximum.

DEVIATION: step 2, certification. Strict ascent alone can stop short in two
ways the seed does not discuss. (a) Plateaus: a face perpendicular to the axis
(exact ties, e.g. a box at an axis-aligned pose) where a vertex inside the face
has no strictly better neighbour although the far side of the plateau has one.
(b) Rounding: ``r_k`` is the exact linear function rounded (error at most
``3u * |v|``, u = 2**-53), so near-ties can show a vertex as a local maximum
when the exact function is not. When step 1 stops, step 2 searches the
near-plateau, the vertices reachable from the current one through vertices
with ``sign * r_k >= best - tie_window``; if any of them is strictly better,
the walk moves to the best (lowest index among ties) and climbs again.
Because the exact level sets are connected, there are exact non-decreasing
paths from the current vertex and from the scan's vertex to the exact
maximum; every vertex on them has a rounded value above
``best - 2 * 3u * |v|``, so with ``tie_window`` larger than that the search
reaches the scan's vertex: the returned coordinate equals the scan's bit for
bit. On a generic mesh in coherent motion no neighbour lies within the window
(the windows are 1e-14 of the body size) and step 2 examines nothing new.

On a non-convex mesh the walk can stop at a local extreme: the box is then
too small. The tracker refuses such meshes unless ``allow_nonconvex=True``,
which exists so the error can be measured (claim C2,
:func:`refsim.studies.bounds.measure_incremental_error`).

Counting: ``visits`` is the number of distinct vertices the last update
examined (computed a rotated coordinate of), over all six walks: ``n`` for the
first update, like the scan. ``evaluations`` counts the coordinates computed
(a vertex examined on two axes counts twice; the scan does ``3 n``).

Cost: O(1) per update under coherent motion when the rotation per frame is
small against the angle between neighbouring vertices (each walk examines the
current vertex and its neighbours, about seven vertices); in general
O(steps * degree) where steps is the number of vertices the extreme moves.
For a sphere-like mesh of n vertices turning by a fixed angle per frame the
steps grow like sqrt(n) once the vertex spacing is below that angle. O(n) for
the first update and for a plateau search over a large flat face.

Kernels: ``kernel="readable"`` is the readable one (below);
``kernel="compiled"`` is the same loops compiled
(:mod:`refsim.bounds._numba_kernels`), the default where numba works
(:mod:`refsim.kernels`). Both give the same boxes, extremes, visits and
evaluations.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from refsim.bounds.aabb_linear import rotated_coordinates
from refsim.errors import ModelError
from refsim.kernels import INCREMENTAL_BOX, choose_kernel
from refsim.models.mesh import Mesh, require_mesh
from refsim.types import Pose, as_pose

#: Width of the near-plateau search (step 2), relative to the largest vertex
#: norm ``|v|``. One rotated coordinate is within ``3u |v|`` of the exact value
#: (u = 2**-53; three rounded operations, rows of R of unit length), so two
#: vertices' exact order can be reversed by at most ``6u |v|``. 64u leaves a
#: factor of ten for a rotation that is orthonormal only to ``ORTHONORMAL_TOL``
#: and for meshes that are convex only to rounding of their vertices, and is
#: still 1e-14 of the body size: far below the spacing of any real mesh's
#: vertices, so step 2 costs nothing in coherent motion.
TIE_WINDOW_RTOL = 64 * 2.0 ** -53


def extreme_vertex_python(start: int, sign: float, r: Callable[[int], float],
                          neighbors: Sequence[Sequence[int]], tie_window: float) -> int:
    """The vertex maximizing ``sign * r(v)`` reached from ``start``.

    Parameters
    ----------
    start : int
        Last frame's extreme vertex.
    sign : float
        +1.0 for the maximum, -1.0 for the minimum (negation is exact).
    r : callable
        ``r(v)``: rotated coordinate of vertex ``v`` on this axis (memoized by
        the caller, which also counts the vertices examined).
    neighbors : sequence of sorted index sequences
        The vertex-neighbour graph.
    tie_window : float
        Width of the near-plateau searched when the ascent stops (step 2).
    """
    current = start
    best = sign * r(current)
    while True:
        # Step 1: steepest ascent, strict improvement only. Neighbours are
        # sorted, so among equally good ones the first (lowest index) wins.
        step_to = -1
        for u in neighbors[current]:
            s = sign * r(u)
            if s > best:
                best, step_to = s, u
        if step_to >= 0:
            current = step_to
            continue
        # Step 2 (DEVIATION, certification): breadth-first over the
        # near-plateau {sign * r >= best - tie_window} around `current`,
        # looking for a strictly better vertex.
        floor = best - tie_window
        seen = {current}
        queue = [current]
        head = 0
        found, found_best = -1, best
        while head < len(queue):
            v = queue[head]
            head += 1
            for u in neighbors[v]:
                if u in seen:
                    continue
                s = sign * r(u)
                if s >= floor:
                    seen.add(u)
                    queue.append(u)
                    if s > found_best or (s == found_best and found >= 0 and u < found):
                        found, found_best = u, s
        if found < 0:
            return current  # certified: nothing better within reach
        current, best = found, found_best


class IncrementalAABB:
    """The seed's incremental box: six extreme vertices kept by hill climbing.

    Parameters
    ----------
    mesh : Mesh
        Must be convex (``mesh.is_convex``) unless ``allow_nonconvex``.
    kernel : {"readable", "compiled"}, optional
        Readable or compiled kernel; default compiled where numba works.
    allow_nonconvex : bool, default False
        Track a non-convex mesh anyway; the box may then be too small (to
        measure claim C2). Never chosen by ``aabb = "auto"``.

    Attributes
    ----------
    extremes : ndarray of int64, shape (2, 3), or None
        ``extremes[0, k]``, ``extremes[1, k]``: the vertices at the minimum and
        the maximum on axis ``k`` after the last update; None before the first.
    visits : int
        Distinct vertices examined by the last update (``n`` for the first).
    evaluations : int
        Rotated coordinates computed by the last update (``3 n`` for the first).

    Raises
    ------
    ModelError
        The mesh is not convex and ``allow_nonconvex`` is False.
    """

    method = "incremental"

    def __init__(self, mesh: Mesh, *, kernel: str | None = None,
                 allow_nonconvex: bool = False):
        require_mesh(mesh)
        kernel = choose_kernel(kernel)
        if not allow_nonconvex and not mesh.is_convex:
            raise ModelError(
                "the incremental AABB update is exact only for convex meshes; use the "
                "linear scan, or IncrementalAABB(mesh, allow_nonconvex=True) to measure "
                "its error", path=mesh.source or mesh.name)
        self.mesh = mesh
        self.kernel = kernel
        self.allow_nonconvex = allow_nonconvex
        radius = float(np.sqrt((mesh.vertices ** 2).sum(axis=1)).max())
        self.tie_window = TIE_WINDOW_RTOL * radius
        n = mesh.n_vertices
        # The state both kernels share: the six extreme vertices (-1: none
        # yet) and the counters of the last update (visits, evaluations).
        self._extremes = np.full((2, 3), -1, np.int64)
        self._counts = np.zeros(2, np.int64)
        self._update = INCREMENTAL_BOX.pick(kernel).__get__(self)   # the bound method
        if kernel == "readable":
            # Plain lists: indexing them is several times faster than numpy
            # scalars, and the kernel reads like the algorithm.
            self._xyz = mesh.vertices.tolist()
            self._neighbors = _neighbor_lists(mesh)
        else:
            from refsim.bounds._numba_kernels import incremental_update_numba

            self._kernel_numba = incremental_update_numba
            self._xyz = np.ascontiguousarray(mesh.vertices.T)
            # Work arrays of the compiled kernel: memoized r_k(v) and the
            # generation stamps that mark which entries belong to this update
            # (so nothing is cleared between updates), the breadth-first
            # queue of step 2, and the two generation counters.
            self._value = np.zeros((3, n))
            self._stamp = np.zeros((3, n), np.int64)
            self._touched = np.zeros(n, np.int64)
            self._seen = np.zeros(n, np.int64)
            self._queue = np.zeros(n, np.int64)
            self._generation = np.zeros(2, np.int64)

    @property
    def extremes(self) -> np.ndarray | None:
        if self._extremes[0, 0] < 0:
            return None
        return self._extremes.copy()

    @property
    def visits(self) -> int:
        return int(self._counts[0])

    @property
    def evaluations(self) -> int:
        return int(self._counts[1])

    def reset(self) -> None:
        """Forget the extremes: the next update scans all vertices again."""
        self._extremes[:] = -1

    def update(self, pose: Pose) -> tuple[np.ndarray, np.ndarray]:
        """The box ``(lo, hi)`` of the mesh under ``pose``, each (3,)."""
        rotation, translation = as_pose(pose)
        return self.update_unchecked(rotation, translation)

    def update_unchecked(self, rotation: np.ndarray, translation: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`update` without the pose check, for a loop whose poses are
        known to be finite float64 (3, 3) orthonormal and (3,) (the check
        costs more than the compiled update itself)."""
        return self._update(rotation, translation)

    # -- the readable kernel -------------------------------------------------------

    def _update_python(self, rotation: np.ndarray, translation: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray]:
        if self._extremes[0, 0] < 0:
            return self._initialize_by_scan(rotation, translation)
        xyz, R = self._xyz, rotation.tolist()
        extremes = self._extremes
        lo, hi = np.empty(3), np.empty(3)
        examined: list[dict[int, float]] = []
        for k in range(3):
            memo: dict[int, float] = {}
            a, b, c = R[k]

            def r(v, a=a, b=b, c=c, memo=memo):
                # The rotated coordinate r_k(v), once per vertex and update.
                value = memo.get(v)
                if value is None:
                    x, y, z = xyz[v]
                    value = memo[v] = (a * x + b * y) + c * z
                return value

            for side, sign in ((0, -1.0), (1, 1.0)):
                extremes[side, k] = extreme_vertex_python(
                    int(extremes[side, k]), sign, r, self._neighbors, self.tie_window)
            lo[k] = r(int(extremes[0, k])) + translation[k]
            hi[k] = r(int(extremes[1, k])) + translation[k]
            examined.append(memo)
        self._counts[:] = len(set().union(*examined)), sum(len(m) for m in examined)
        return lo, hi

    def _initialize_by_scan(self, rotation: np.ndarray, translation: np.ndarray
                            ) -> tuple[np.ndarray, np.ndarray]:
        # The first update: the linear scan, remembering where the extremes are
        # (np.argmin/argmax return the lowest index among ties).
        r = rotated_coordinates(rotation, self.mesh.vertices.T)
        self._extremes[0] = r.argmin(axis=1)
        self._extremes[1] = r.argmax(axis=1)
        n = self.mesh.n_vertices
        self._counts[:] = n, 3 * n
        return r.min(axis=1) + translation, r.max(axis=1) + translation

    # -- the compiled kernel ---------------------------------------------------------

    def _update_numba(self, rotation: np.ndarray, translation: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:
        box = np.empty((2, 3))
        self._kernel_numba(
            self._xyz, self.mesh.neighbor_offsets, self.mesh.neighbor_indices, rotation,
            translation, self._extremes, self.tie_window, self._value, self._stamp,
            self._touched, self._seen, self._queue, self._generation, self._counts,
            box[0], box[1])
        return box[0], box[1]


def _neighbor_lists(mesh: Mesh) -> list[list[int]]:
    o, idx = mesh.neighbor_offsets.tolist(), mesh.neighbor_indices.tolist()
    return [idx[o[i]:o[i + 1]] for i in range(mesh.n_vertices)]
