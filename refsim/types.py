"""Shared value types: poses and the helpers that check and apply them.

A pose is a pair ``(rotation, translation)``: a (3, 3) orthonormal matrix whose
columns are the body's axes in world coordinates, and a (3,) translation. A
point ``p`` in body space is at ``rotation @ p + translation`` in world space
(docs/design.md, Conventions).
"""

from __future__ import annotations

import numpy as np

from refsim.errors import StateError, as_numbers

Pose = tuple[np.ndarray, np.ndarray]

#: How far ``R.T @ R`` may be from the identity before a rotation is rejected.
#: Rotations built from float64 trigonometry or an integrator that
#: re-orthonormalizes are within ~1e-15; 1e-6 admits rotations read from text
#: with a handful of digits while still catching a scale or shear by mistake.
ORTHONORMAL_TOL = 1e-6

IDENTITY_POSE: Pose = (np.eye(3), np.zeros(3))

_EYE = np.eye(3)


def as_pose(pose, *, what: str = "pose") -> Pose:
    """Check a pose and return it as two C-contiguous float64 arrays (a
    transposed rotation, or a translation cut from a column of a 4x4
    matrix, is copied: a compiled kernel then meets one memory layout and
    compiles once).

    Raises
    ------
    StateError
        When the shapes are wrong, a value is not finite, or the rotation is
        not orthonormal within ``ORTHONORMAL_TOL``.
    ArgumentTypeError
        When an entry is not a real number (a string such as ``'0'``, which
        numpy would otherwise read as the number, a complex number, None).
    """
    try:
        rotation, translation = pose
    except (TypeError, ValueError):
        raise StateError(f"{what}: expected (rotation, translation)") from None
    rotation = as_numbers(f"{what} rotation", rotation)
    translation = as_numbers(f"{what} translation", translation)
    if not rotation.flags.c_contiguous:
        rotation = np.ascontiguousarray(rotation)
    if not translation.flags.c_contiguous:
        translation = np.ascontiguousarray(translation)
    if rotation.shape != (3, 3) or translation.shape != (3,):
        raise StateError(f"{what}: expected shapes (3, 3) and (3,), got "
                         f"{rotation.shape} and {translation.shape}")
    # Entries of an orthonormal matrix are at most 1 in magnitude; checking
    # that first rejects NaN (which fails every comparison), infinities and
    # huge values before the Gram product, which then cannot overflow. The
    # message is chosen only on failure.
    ok = np.abs(rotation).max() <= 1.0 + ORTHONORMAL_TOL
    if ok:
        ok = np.abs(rotation.T @ rotation - _EYE).max() <= ORTHONORMAL_TOL
    if not (ok and np.isfinite(translation).all()):
        if not (np.isfinite(rotation).all() and np.isfinite(translation).all()):
            raise StateError(f"{what}: non-finite value")
        raise StateError(f"{what}: rotation is not orthonormal")
    return rotation, translation


def unit_exponent(values) -> int:
    """The exponent ``e`` with ``max |values| * 2**-e`` in ``[0.5, 1)``; for
    all zeros -1075, below the exponent of every nonzero float64, so that
    the largest of several exponents is that of the largest nonzero value.

    Geometry is invariant under a uniform change of scale, and multiplying by
    a power of two is exact in binary floating point (barring underflow of
    values far below the largest). Computing volumes, cross products, convex
    hulls and inertia on ``values * 2**-e`` and scaling the result back by the
    matching power (``2**(3e)`` for a volume) therefore keeps every
    intermediate far from overflow and underflow, for coordinates anywhere in
    float64's range; a result that is itself beyond float64 becomes inf, as
    IEEE arithmetic rounds it.
    """
    largest = float(np.abs(values).max(initial=0.0))
    if largest == 0.0:
        return -1075
    return int(np.frexp(largest)[1])


def transform_points(points: np.ndarray, pose: Pose) -> np.ndarray:
    """World coordinates (n, 3) of body-space ``points`` (n, 3) under ``pose``.

    Coordinate ``k`` of each point is ``((R[k, 0] x + R[k, 1] y) + R[k, 2] z) + t[k]``,
    each product and sum rounded once, in that order: the one transform
    arithmetic of every box and kernel in refsim
    (:mod:`refsim.bounds.aabb_linear`). ``points @ R.T`` is not used: BLAS
    picks its kernel, and with it fused multiply-adds and a summation order,
    per processor, so its last bit depends on the machine.
    """
    rotation, translation = pose
    p = np.asarray(points, dtype=np.float64)
    x, y, z = p[:, 0:1], p[:, 1:2], p[:, 2:3]
    return ((rotation[:, 0] * x + rotation[:, 1] * y) + rotation[:, 2] * z) + translation


def rotation_about_axis(axis, angle: float) -> np.ndarray:
    """The rotation by ``angle`` radians about ``axis`` (Rodrigues' formula).

    ``R = c I + s [k]x + (1 - c) k k^T`` for the unit axis ``k``, written out
    entry by entry (no BLAS: the same bits on every machine).
    """
    axis = np.asarray(axis, dtype=np.float64)
    if axis.shape != (3,) or not np.isfinite(axis).all():
        raise StateError("rotation axis must be 3 finite numbers")
    scale = np.abs(axis).max()
    if scale == 0.0:
        raise StateError("rotation axis has zero length")
    a = axis / scale                                  # no overflow or underflow in |a|^2
    norm = np.sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
    x, y, z = a / norm
    c, s = np.cos(angle), np.sin(angle)
    C = 1.0 - c
    return np.array([[c + C * x * x, C * x * y - s * z, C * x * z + s * y],
                     [C * y * x + s * z, c + C * y * y, C * y * z - s * x],
                     [C * z * x - s * y, C * z * y + s * x, c + C * z * z]])


def quaternion_to_rotation(q) -> np.ndarray:
    """The rotation (3, 3) of the unit quaternion ``q = (w, x, y, z)``, entry by entry."""
    w, x, y, z = q
    return np.array([
        [1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)],
        [2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)],
        [2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)]])


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A rotation drawn uniformly from SO(3).

    A normalized 4-vector of independent standard normals is a unit
    quaternion uniform on the 3-sphere, and so a uniform rotation (K. Shoemake,
    "Uniform random rotations", Graphics Gems III, 1992). Plain arithmetic
    throughout, so a seed gives the same rotation on every machine (a QR
    factorization would not: LAPACK's result depends on the processor).
    """
    g = rng.standard_normal(4)
    norm = np.sqrt(((g[0] * g[0] + g[1] * g[1]) + g[2] * g[2]) + g[3] * g[3])
    return quaternion_to_rotation(g / norm)
