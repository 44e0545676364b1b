"""Collision of a body's box with the surrounding world cube (seed S3).

The seed ("Translational Collision Response with Walls of Axis-Aligned
Surrounding World Cube"): "Using the current axis-aligned bounding box that
surrounds the object, we simply handle each component (or dimension)
separately as a one dimensional interval overlap problem. If the box extends
beyond the world cube in a particular dimension, we push it back to the wall
only along that axis". This module is the detection half: per axis, the
interval ``[lo_k, hi_k]`` of the body's box against the cube's
``[cube_lo_k, cube_hi_k]``, and by how much each wall is crossed. The response
(S7) uses :attr:`WallCrossings.correction` to push back along the axis.

"Extends beyond" is strict: a box touching a wall (penetration exactly 0)
crosses nothing. The depths are plain differences of the coordinates, so a
penetration of one ulp is reported as such.

Reference: the interval (min-max) test is the one-dimensional case of the
AABB overlap test, e.g. C. Ericson, *Real-Time Collision Detection*, 2005,
section 4.2 (AABB-AABB intersection). Cost: O(1), six subtractions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from refsim.errors import StateError


@dataclass(frozen=True)
class WallCrossings:
    """Which walls of the world cube a box crosses, and how deep.

    Attributes
    ----------
    below : ndarray, shape (3,)
        ``cube_lo - lo``: how far the box reaches past the low wall on each
        axis; > 0 when that wall is crossed.
    above : ndarray, shape (3,)
        ``hi - cube_hi``: how far the box reaches past the high wall; > 0 when
        crossed.
    """

    below: np.ndarray
    above: np.ndarray

    @property
    def crossed(self) -> np.ndarray:
        """(3, 2) bool: ``[k, 0]`` the low wall of axis k, ``[k, 1]`` the high."""
        return np.stack([self.below > 0.0, self.above > 0.0], axis=1)

    @property
    def any(self) -> bool:
        """Whether any wall is crossed."""
        return bool(self.crossed.any())

    @property
    def correction(self) -> np.ndarray:
        """(3,) translation that brings the box back inside, axis by axis.

        ``+below`` on an axis whose low wall is crossed, ``-above`` on one
        whose high wall is; 0 elsewhere. A box wider than the cube can cross
        both walls of an axis; no push fixes that, and the correction then
        centres the box on that axis (``(below - above) / 2``, the cube's
        centre minus the box's).
        """
        push = np.where(self.below > 0.0, self.below, 0.0) - np.where(
            self.above > 0.0, self.above, 0.0)
        both = (self.below > 0.0) & (self.above > 0.0)
        return np.where(both, 0.5 * (self.below - self.above), push)


def world_cube_test(lo, hi, half_size: float | None = None, *, cube_lo=None,
                    cube_hi=None) -> WallCrossings:
    """Test a box ``[lo, hi]`` against the world cube, one axis at a time.

    Parameters
    ----------
    lo, hi : array_like, shape (3,)
        The body's world box, ``lo <= hi``.
    half_size : float, optional
        The cube is ``[-half_size, half_size]^3`` (the scene's
        ``world.half_size``). Give either this or ``cube_lo`` and ``cube_hi``.
    cube_lo, cube_hi : array_like, shape (3,), optional
        A cube (box) not centred at the origin.

    Returns
    -------
    WallCrossings
        Per axis, the depth past the low and the high wall (> 0 when crossed).

    Raises
    ------
    StateError
        Wrong shapes, non-finite values, ``lo > hi`` or an empty cube.
    """
    if half_size is not None:
        if cube_lo is not None or cube_hi is not None:
            raise StateError("world cube: give half_size or cube_lo/cube_hi, not both")
        if not (np.isfinite(half_size) and half_size > 0.0):
            raise StateError(f"world cube: half_size must be finite and > 0, got {half_size}")
        cube_hi = np.full(3, float(half_size))
        cube_lo = -cube_hi
    elif cube_lo is None or cube_hi is None:
        raise StateError("world cube: give half_size or both cube_lo and cube_hi")
    lo, hi, cube_lo, cube_hi = (_vector(a, name) for a, name in (
        (lo, "lo"), (hi, "hi"), (cube_lo, "cube_lo"), (cube_hi, "cube_hi")))
    if (lo > hi).any():
        raise StateError(f"world cube: box has lo > hi ({lo} > {hi})")
    if (cube_lo >= cube_hi).any():
        raise StateError(f"world cube: empty cube ({cube_lo}, {cube_hi})")
    # Each axis is a one-dimensional interval problem (the seed's words).
    below = cube_lo - lo
    above = hi - cube_hi
    return WallCrossings(below=_readonly(below), above=_readonly(above))


def _vector(value, name: str) -> np.ndarray:
    array = np.asarray(value, dtype=np.float64)
    if array.shape != (3,):
        raise StateError(f"world cube: {name} must have shape (3,), got {array.shape}")
    if not np.isfinite(array).all():
        raise StateError(f"world cube: {name} has a non-finite value")
    return array


def _readonly(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array
