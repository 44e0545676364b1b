"""Shared value types: poses and the helpers that check and apply them.

A pose is a pair ``(rotation, translation)``: a (3, 3) orthonormal matrix whose
columns are the body's axes in world coordinates, and a (3,) translation. A
point ``p`` in body space is at ``rotation @ p + translation`` in world space
(DESIGN.md, Conventions).
"""

from __future__ import annotations

import numpy as np

from refsim.errors import StateError

Pose = tuple[np.ndarray, np.ndarray]

#: How far ``R.T @ R`` may be from the identity before a rotation is rejected.
#: Rotations built from float64 trigonometry or an integrator that
#: re-orthonormalizes are within ~1e-15; 1e-6 admits rotations read from text
#: with a handful of digits while still catching a scale or shear by mistake.
ORTHONORMAL_TOL = 1e-6

IDENTITY_POSE: Pose = (np.eye(3), np.zeros(3))

_EYE = np.eye(3)


def as_pose(pose, *, what: str = "pose") -> Pose:
    """Check a pose and return it as two float64 arrays.

    Raises
    ------
    StateError
        When the shapes are wrong, a value is not finite, or the rotation is
        not orthonormal within ``ORTHONORMAL_TOL``.
    """
    try:
        rotation, translation = pose
    except (TypeError, ValueError):
        raise StateError(f"{what}: expected (rotation, translation)") from None
    rotation = np.asarray(rotation, dtype=np.float64)
    translation = np.asarray(translation, dtype=np.float64)
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


def transform_points(points: np.ndarray, pose: Pose) -> np.ndarray:
    """World coordinates of body-space ``points`` (n, 3) under ``pose``."""
    rotation, translation = pose
    return points @ rotation.T + translation


def rotation_about_axis(axis, angle: float) -> np.ndarray:
    """The rotation by ``angle`` radians about ``axis`` (Rodrigues' formula)."""
    axis = np.asarray(axis, dtype=np.float64)
    norm = np.linalg.norm(axis)
    if norm == 0.0:
        raise StateError("rotation axis has zero length")
    x, y, z = axis / norm
    c, s = np.cos(angle), np.sin(angle)
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A rotation drawn uniformly from SO(3) (QR of a Gaussian matrix)."""
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0.0:
        q[:, 0] = -q[:, 0]
    return q
