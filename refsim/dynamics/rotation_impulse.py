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

Cost: O(B) per step (a few (B, 3, 3) products); O(n) per wall contact for
the vertices, plus the contact solve.
"""

from __future__ import annotations

import numpy as np


def rotation_exp(theta: np.ndarray) -> np.ndarray:
    """``exp([theta]x)`` for rotation vectors ``theta`` (B, 3): (B, 3, 3).

    Rodrigues: ``cos(a) E + sin(a) K + (1 - cos(a)) k k^T`` with
    ``a = |theta|``, ``k = theta / a``, ``K = [k]x``; written as
    ``cos(a) E + s [theta]x + c theta theta^T`` with ``s = sin(a)/a``,
    ``c = (1 - cos(a))/a^2``, whose series are used below ``a = 1e-4``
    (where the truncation error, ``a^4/120``, is below 1e-18).
    """
    a2 = np.einsum("ij,ij->i", theta, theta)
    small = a2 < 1e-8
    a = np.sqrt(np.where(small, 1.0, a2))
    s = np.where(small, 1.0 - a2 / 6.0, np.sin(a) / a)
    c = np.where(small, 0.5 - a2 / 24.0, (1.0 - np.cos(a)) / (a * a))
    cos_a = np.where(small, 1.0 - 0.5 * a2, np.cos(a))
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
    """``R I_body R^T`` for all bodies: (B, 3, 3), (B, 3, 3) -> (B, 3, 3)."""
    return R @ I_body @ R.transpose(0, 2, 1)


def _matvec(M: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("bij,bj->bi", M, x)


def _matTvec(M: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.einsum("bji,bj->bi", M, x)


def orientation_step_exact(R: np.ndarray, w: np.ndarray, h: float, I_body: np.ndarray,
                           I_body_inv: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One torque-free step of all bodies: ``(R', w')`` (see the module docstring)."""
    L = _matvec(R, _matvec(I_body, _matTvec(R, w)))                  # R I_body R^T w
    R_next = rotation_exp(h * w) @ R
    w_next = _matvec(R_next, _matvec(I_body_inv, _matTvec(R_next, L)))
    return R_next, w_next


def wall_contacts(world_vertices: np.ndarray, axis: int, wall: float, low_wall: bool
                  ) -> np.ndarray:
    """Indices of the vertices past the wall ``x_axis = wall`` (strictly)."""
    column = world_vertices[:, axis]
    return np.flatnonzero(column < wall if low_wall else column > wall)
