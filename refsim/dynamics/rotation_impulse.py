"""The corrected rotation model (``rotation = "impulse"``): orientation by the
exact rotation, angular momentum with the body's inertia tensor, and wall
contacts resolved by impulses at every vertex past the wall.

Free motion. The state keeps the angular velocity ``w`` (world frame, rad/s);
over a step the angular momentum ``L = I_world w`` is constant (no torque
acts in flight), with ``I_world = R I_body R^T``. One step:

    L  = R I_body R^T w
    R' = exp(h [w]x) R            (Rodrigues: the exact rotation by angle h|w|)
    w' = R' I_body^-1 R'^T L

``R'`` is a product of rotations, so it stays orthonormal to rounding (no
drift to correct: the tests bound ``max |R^T R - E|`` over a long run). For
a body with isotropic inertia (a cube, a sphere) ``w`` is constant and the
step is exact; otherwise it is the first-order Lie-Euler step of Euler's
equations, conserving L exactly and the kinetic energy to O(h).

DEVIATION from the seed (S9), which steps the axes by Euler
(``X += h w x X``) and uses the identity as inertia.

Wall contacts. When the body's box crosses a wall (the seed's S3 test), the
contacts are all mesh vertices past the wall, with the wall's inward normal
n. The body is pushed back along that axis by the depth of the deepest one
(the seed's push-back, so no interpenetration persists), the normal velocity
is given the speed it had at the wall (energy along the axis, as in
:func:`refsim.dynamics.walls.wall_speed`), and the impulses of
:mod:`refsim.dynamics.impulse` act at the contacts: only on approaching
contacts, with restitution and Coulomb friction. Friction at several
contacts, or at one contact off the axis of spin, gives torques with a
component along n: unlike the seed's model, spin about the normal is damped.

References: D. Baraff, "Rigid Body Simulation", SIGGRAPH 2001 course notes,
sections 2-4 (state ``(x, R, P, L)``, ``I^-1 = R I_body^-1 R^T``); rotation
by the exponential map as in E. Hairer, C. Lubich, G. Wanner, *Geometric
Numerical Integration*, 2nd ed., Springer 2006, section IV.8 (Lie group
methods).

Arithmetic in one order: every sum of products is written out left to
right (:mod:`refsim.dynamics.products`, not ``einsum`` or ``@``, which go
to BLAS or SIMD loops whose order depends on the processor), and sine and
cosine are the C library's, one call per body (:func:`sin_cos`). The
compiled simulation loop (:mod:`refsim.dynamics._numba_kernels`) repeats
these operations in the same order, so the two agree bit for bit, and the
result does not depend on numpy's choice of loops for the processor.

Cost: O(B) per step (a few (B, 3, 3) products, 2 B calls of sine and
cosine); O(n) per wall contact for the vertices, plus the contact solve.
"""

from __future__ import annotations

import math

import numpy as np

from refsim.dynamics.products import dot, matmul, matTvec, matvec

#: Below this ``|theta|^2`` (``|theta| < 1e-4``) :func:`rotation_exp` uses
#: the series of ``sin(a)/a`` and ``(1 - cos(a))/a^2``, whose truncation
#: error there (``a^4/120``) is below 1e-18.
SERIES_BELOW = 1e-8


def sin_cos(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(sin(a), cos(a))`` of (B,) angles, one ``math.sin`` / ``math.cos``
    call per body: the C library's functions, which the compiled loop calls
    too (numpy's own ``np.sin`` / ``np.cos`` may take SIMD loops of their
    own, chosen by the processor, whose last bits differ)."""
    values = a.tolist()
    return (np.array([math.sin(x) for x in values], dtype=np.float64),
            np.array([math.cos(x) for x in values], dtype=np.float64))


def rotation_exp(theta: np.ndarray) -> np.ndarray:
    """``exp([theta]x)`` for rotation vectors ``theta`` (B, 3): (B, 3, 3).

    Rodrigues: ``cos(a) E + sin(a) K + (1 - cos(a)) k k^T`` with
    ``a = |theta|``, ``k = theta / a``, ``K = [k]x``; written as
    ``cos(a) E + s [theta]x + c theta theta^T`` with ``s = sin(a)/a``,
    ``c = (1 - cos(a))/a^2``, whose series are used below ``SERIES_BELOW``.

    Each entry in one order (the compiled loop repeats it):
    ``((c theta_i) theta_j -+ s theta_k) + cos(a)`` (the last term on the
    diagonal only), ``|theta|^2`` summed left to right.
    """
    a2 = dot(theta, theta)
    small = a2 < SERIES_BELOW
    a = np.sqrt(np.where(small, 1.0, a2))
    sin_a, cos_of_a = sin_cos(a)
    s = np.where(small, 1.0 - a2 / 6.0, sin_a / a)
    c = np.where(small, 0.5 - a2 / 24.0, (1.0 - cos_of_a) / (a * a))
    cos_a = np.where(small, 1.0 - 0.5 * a2, cos_of_a)
    out = (c[:, None, None] * theta[:, :, None]) * theta[:, None, :]   # c theta theta^T
    st = s[:, None] * theta
    out[:, 0, 1] -= st[:, 2]
    out[:, 0, 2] += st[:, 1]
    out[:, 1, 2] -= st[:, 0]
    out[:, 1, 0] += st[:, 2]
    out[:, 2, 0] -= st[:, 1]
    out[:, 2, 1] += st[:, 0]
    for k in range(3):
        out[:, k, k] += cos_a
    return out


def world_inertia(R: np.ndarray, I_body: np.ndarray) -> np.ndarray:
    """``(R I_body) R^T`` for all bodies: (B, 3, 3), (B, 3, 3) -> (B, 3, 3),
    each product summed left to right (:func:`refsim.dynamics.products.matmul`)."""
    return matmul(matmul(R, I_body), np.swapaxes(R, -1, -2))


def orientation_step_exact(R: np.ndarray, w: np.ndarray, h: float, I_body: np.ndarray,
                           I_body_inv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One torque-free step of all bodies: ``(R', w')`` (see the module
    docstring); each matrix-vector product a left-to-right sum
    (:mod:`refsim.dynamics.products`), no ``einsum`` or BLAS."""
    L = matvec(R, matvec(I_body, matTvec(R, w)))                  # R (I_body (R^T w))
    R_next = matmul(rotation_exp(h * w), R)
    w_next = matvec(R_next, matvec(I_body_inv, matTvec(R_next, L)))
    return R_next, w_next


def wall_contacts(world_vertices: np.ndarray, axis: int, wall: float, low_wall: bool
                  ) -> np.ndarray:
    """Indices of the vertices past the wall ``x_axis = wall`` (strictly)."""
    column = world_vertices[:, axis]
    return np.flatnonzero(column < wall if low_wall else column > wall)
