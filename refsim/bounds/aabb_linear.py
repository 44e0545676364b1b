"""Axis-aligned bounding box by a linear scan of the transformed vertices (seed S2).

The seed: "This system supports both linear O(n) and incremental O(1)
axis-aligned bounding box update. The problem of finding closest features has
been reduced to finding the 6 extreme points that form a tight-fitting
axis-aligned bounding box." The linear update is the brute-force half of that
sentence: transform every vertex to world space and keep the smallest and the
largest coordinate on each axis. It is exact for any mesh, convex or not, and
is what the seed uses for non-convex bodies.

One arithmetic for every box in refsim
---------------------------------------
The incremental tracker (:mod:`refsim.bounds.aabb_incremental`) must give the
same box as this scan, bit for bit, so both evaluate a world coordinate the
same way. For body-space vertex ``v = (x, y, z)`` and pose ``(R, t)``, the
rotated coordinate on axis ``k`` is

    r_k(v) = (R[k, 0] * x + R[k, 1] * y) + R[k, 2] * z

evaluated left to right with each product and sum rounded once (no fused
multiply-add), and the box side is ``min_v r_k(v) + t_k``. Two consequences:

- ``vertices @ R.T + t`` is *not* used: numpy hands matmul to BLAS, whose
  kernels use fused multiply-adds and their own summation order, so it can
  differ from ``r_k`` in the last bit (tests/bounds/test_aabb_linear.py
  measures how often). Elementwise numpy multiply and add round each
  operation separately, like Python floats and like the numba kernel.
- The translation is added after the minimum: rounding is monotone
  (``a <= b`` implies ``fl(a + t) <= fl(b + t)``), so
  ``min_v fl(r_k(v) + t_k) == fl(min_v r_k(v) + t_k)`` exactly. The box is
  therefore the box of the fully transformed vertices
  (:func:`transform_vertices`), and the tracker only needs ``r_k``: which
  vertex is extreme depends on the orientation alone.

Reference: the brute-force update is the baseline against which J. D. Cohen,
M. C. Lin, D. Manocha, M. K. Ponamgi, "I-COLLIDE: an interactive and exact
collision detection system for large-scale environments", Proc. ACM Symposium
on Interactive 3D Graphics, 1995, set their incrementally resized boxes for
sweep and prune; C. Ericson, *Real-Time Collision Detection*, 2005, section
4.2 (axis-aligned bounding boxes: computing and updating them).

Cost: O(n) per update for n vertices: 9n multiplications and additions and 6n
comparisons. ``kernel="readable"`` vectorizes them with numpy;
``kernel="compiled"`` is the same loop compiled by numba
(:func:`refsim.bounds._numba_kernels.aabb_linear_numba`), the default, and
like for like with the compiled incremental tracker (:mod:`refsim.kernels`).
"""

from __future__ import annotations

import numpy as np

from refsim.kernels import LINEAR_BOX_SCAN, choose_kernel
from refsim.models.mesh import Mesh, require_mesh
from refsim.types import Pose, as_pose, transform_points


def rotated_coordinate(rotation, vertex, k: int) -> float:
    """Rotated coordinate ``r_k(v)`` of one body-space vertex on axis ``k``.

    The single definition of the arithmetic (module docstring); every AABB
    path in refsim reproduces it exactly.
    """
    x, y, z = vertex
    return (rotation[k][0] * x + rotation[k][1] * y) + rotation[k][2] * z


def rotated_coordinates(rotation: np.ndarray, vertices_t: np.ndarray) -> np.ndarray:
    """``r_k(v)`` for every axis and vertex: (3, n) from (3, 3) and (3, n).

    ``vertices_t`` holds the body-space vertices as rows x, y, z (the
    transpose of ``Mesh.vertices``; contiguous is twice as fast). Element
    ``[k, i]`` is ``(R[k, 0] * x_i + R[k, 1] * y_i) + R[k, 2] * z_i``, the same
    operations in the same order as :func:`rotated_coordinate`.
    """
    x, y, z = vertices_t
    return (rotation[:, 0:1] * x + rotation[:, 1:2] * y) + rotation[:, 2:3] * z


def transform_vertices(vertices: np.ndarray, pose: Pose) -> np.ndarray:
    """World coordinates (n, 3) of body-space ``vertices`` (n, 3) with the boxes' arithmetic.

    Equal, bit for bit, to ``rotated_coordinate(R, v, k) + t[k]`` for every
    vertex; every vertex it returns lies inside :func:`aabb_linear`'s box.
    """
    return transform_points(vertices, pose)


def aabb_linear_kernel(vertices_t: np.ndarray, rotation: np.ndarray,
                       translation: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The linear scan on arrays, unchecked: ``(lo, hi)``, each (3,).

    ``vertices_t`` is (3, n) as in :func:`rotated_coordinates`. Step 1: rotate
    every vertex (``r_k``). Step 2: keep the least and the greatest on each
    axis. Step 3: translate the two corners.
    """
    r = rotated_coordinates(rotation, vertices_t)
    return r.min(axis=1) + translation, r.max(axis=1) + translation


def aabb_linear(mesh: Mesh, pose: Pose, *, kernel: str | None = None
                ) -> tuple[np.ndarray, np.ndarray]:
    """World-space axis-aligned box of ``mesh`` under ``pose`` by an O(n) scan.

    Parameters
    ----------
    mesh : Mesh
        Shared-vertex mesh; its ``vertices`` (n, 3) are scanned.
    pose : (rotation (3, 3), translation (3,))
        Checked with :func:`refsim.types.as_pose`.
    kernel : {"readable", "compiled"}, optional
        The vectorized scan or the compiled loop (default where numba works,
        :mod:`refsim.kernels`); identical results.

    Returns
    -------
    lo, hi : ndarray, shape (3,)
        The box corners: ``lo[k] = min_v r_k(v) + t_k``, ``hi`` likewise.
    """
    require_mesh(mesh)
    scan = LINEAR_BOX_SCAN(kernel)
    rotation, translation = as_pose(pose)
    # (the readable scan gives the same bits on a copy: elementwise, and
    # minima and maxima do not round)
    return scan(np.ascontiguousarray(mesh.vertices.T), rotation, translation)


class LinearAABB:
    """The linear scan behind the same ``update(pose)`` interface as the tracker.

    Stateless: ``visits`` is ``n`` (every vertex is examined) and
    ``evaluations`` is ``3 n`` (one coordinate per vertex and axis).
    """

    method = "linear"

    def __init__(self, mesh: Mesh, *, kernel: str | None = None):
        require_mesh(mesh)
        kernel = choose_kernel(kernel)
        self.mesh = mesh
        self.kernel = kernel
        n = mesh.n_vertices
        self.visits, self.evaluations = n, 3 * n  # the same for every update
        self._vertices_t = np.ascontiguousarray(mesh.vertices.T)  # (3, n), once
        self._scan = LINEAR_BOX_SCAN.pick(kernel)

    def update(self, pose: Pose) -> tuple[np.ndarray, np.ndarray]:
        """The box ``(lo, hi)`` of the mesh under ``pose``, each (3,)."""
        rotation, translation = as_pose(pose)
        return self.update_unchecked(rotation, translation)

    def update_unchecked(self, rotation: np.ndarray, translation: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`update` without the pose check, for a loop whose poses are
        known to be finite float64 (3, 3) orthonormal and (3,) (the check
        costs more than the compiled update itself)."""
        return self._scan(self._vertices_t, rotation, translation)
