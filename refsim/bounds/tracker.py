"""Choosing a box update per body: the scene option ``collision.aabb`` (seed S2).

The seed tracks convex bodies incrementally and scans non-convex ones
("Non-convex objects are supported in this simulation by using the
brute-force linear AABB update"). ``make_aabb_tracker`` makes that choice once
per body, and the simulation loop then calls ``update(pose)`` on whichever
object it got. Cost: O(1) to choose (``mesh.is_convex`` is cached on the mesh).
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from refsim.bounds.aabb_incremental import IncrementalAABB
from refsim.bounds.aabb_linear import LinearAABB
from refsim.errors import check_option
from refsim.models.mesh import Mesh, require_mesh
from refsim.types import Pose

AABB_MODES = ("linear", "incremental", "auto")


class AABBTracker(Protocol):
    """What the simulation loop needs from a box update (the counters are
    read-only: a plain attribute or a property)."""

    @property
    def method(self) -> str: ...        # "linear" or "incremental"

    @property
    def visits(self) -> int: ...        # vertices examined by the last update

    @property
    def evaluations(self) -> int: ...   # rotated coordinates computed by the last update

    def update(self, pose: Pose) -> tuple[np.ndarray, np.ndarray]: ...

    def update_unchecked(self, rotation: np.ndarray,
                         translation: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...


def make_aabb_tracker(mesh: Mesh, mode: str = "auto", *, kernel: str | None = None
                      ) -> AABBTracker:
    """A box updater for ``mesh``.

    Parameters
    ----------
    mode : {"linear", "incremental", "auto"}
        "auto": incremental for a convex mesh, the linear scan otherwise (the
        seed's rule). "incremental" on a non-convex mesh raises ModelError.
    kernel : str, optional
        "readable" or "compiled" (:mod:`refsim.kernels`); default compiled
        where numba works.
    """
    check_option("aabb mode", mode, AABB_MODES)
    require_mesh(mesh)
    if mode == "auto":
        mode = "incremental" if mesh.is_convex else "linear"
    if mode == "incremental":
        return IncrementalAABB(mesh, kernel=kernel)
    return LinearAABB(mesh, kernel=kernel)
