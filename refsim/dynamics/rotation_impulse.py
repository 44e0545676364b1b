"""The corrected rotation model (``rotation = "impulse"``): a torque-free
rotation step that keeps angular momentum exactly and energy to within a
bounded O(h^2) oscillation, and wall contacts resolved by impulses at every
vertex past the wall.

Free motion. The state keeps the angular velocity ``w`` (world frame, rad/s)
and the orientation ``R`` (columns: the mesh's axes in the world). Between
contacts the body is a free rigid body: with the principal axes ``Q``
(columns, in the mesh frame) and principal moments ``I_0 <= I_1 <= I_2`` of
its inertia, the principal frame is ``P = R Q``, the angular momentum in it
is ``L = diag(I) P^T w``, and the energy is
``H = L_0^2/(2 I_0) + L_1^2/(2 I_1) + L_2^2/(2 I_2)`` (Euler's equations;
Landau & Lifshitz, *Mechanics*, sections 35-37).

The step splits ``H`` around the middle moment ``I_1``:

    H = |L|^2 / (2 I_1)  +  c_0 L_0^2 / 2  +  c_2 L_2^2 / 2,
    c_i = 1/I_i - 1/I_1,

and each part's flow is a rotation known in closed form:

- the free rotor ``|L|^2/(2 I_1)`` (``|L|`` is a Casimir): ``L`` is constant
  in the body and the body turns about it, ``P <- P exp(t [L / I_1]x)``;
- an axis term ``c_i L_i^2 / 2``: the body turns about its own axis ``i`` by
  ``phi = t c_i L_i``, ``P <- P rot_i(phi)``, while ``L <- rot_i(-phi) L``.

One step is the symmetric (Strang) composition

    axis 0 (h/2), axis 2 (h/2), rotor (h), axis 2 (h/2), axis 0 (h/2),

which is second order, time-reversible and a Poisson map of the rigid body:
every sub-flow keeps the world angular momentum ``P L`` exactly (it rotates
``P`` and ``L`` oppositely), and the energy error stays bounded, O(h^2),
over exponentially long times instead of drifting (E. Hairer, C. Lubich,
G. Wanner, *Geometric Numerical Integration*, 2nd ed., Springer 2006,
section VII.5; the splitting of the free rigid body into integrable parts:
A. Dullweber, B. Leimkuhler, R. McLachlan, "Symplectic splitting methods
for rigid body molecular dynamics", J. Chem. Phys. 107 (1997) 5840; J.
Touma, J. Wisdom, "Lie-Poisson integrators for rigid body dynamics in the
solar system", Astron. J. 107 (1994) 1189). For a symmetric body
(``I_0 = I_1`` or ``I_1 = I_2``) one axis term vanishes and the other
commutes with the rotor, so the step is exact; for a body with equal
moments (a cube, a sphere) it is the exact rotation ``exp(h [w]x)``.

The earlier step of this model, ``R' = exp(h [w]x) R`` with ``w`` then
recomputed from the kept ``L`` (the Lie-Euler method), kept ``L`` but added
energy every step, ``(h^2/2) (w x L) . I^-1 (w x L)`` to leading order, never
negative; a box with three different sides spun near its middle axis gained
16 % in 12 s and flipped too often.

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
sections 2-4 (state ``(x, R, P, L)``, ``I^-1 = R I_body^-1 R^T``).

Arithmetic in one order: every sum of products is written out left to
right (:mod:`refsim.dynamics.products`, not ``einsum`` or ``@``, which go
to BLAS or SIMD loops whose order depends on the processor), and sine and
cosine are the C library's. The free step is one function of plain loops
that the compiled simulation loop (:mod:`refsim.dynamics._numba_kernels`)
compiles from this source (``register_jitable``), so the two agree bit for
bit, and the result does not depend on numpy's choice of loops for the
processor.

Cost: O(B) per step (per body a few 3 x 3 products, five sines and cosines);
O(n) per wall contact for the vertices, plus the contact solve.
"""

from __future__ import annotations

import math

import numpy as np

from refsim.dynamics.products import jitable, matmul, orthonormalize_columns
from refsim.kernels import compile_kernel, python_floats

#: Below this ``|theta|^2`` (``|theta| < 1e-4``) :func:`rotation_exp_into`
#: uses the series of ``sin(a)/a`` and ``(1 - cos(a))/a^2``, whose truncation
#: error there (``a^4/120``) is below 1e-18.
SERIES_BELOW = 1e-8


def principal_frame(I_body: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(Q, moments)`` of a body-space inertia tensor (3, 3): the principal
    axes as the columns of a rotation matrix (det +1) and the moments
    ``Q[:, i] . I_body Q[:, i]``, increasing; by the fixed-order Jacobi
    rotations of :func:`refsim.collision.bvh_exact.symmetric_eigenvectors`,
    so the same bits on every machine. Once per body, at set-up."""
    from refsim.collision.bvh_exact import symmetric_eigenvectors

    Q = symmetric_eigenvectors(I_body.tolist())
    if _det3(Q) < 0.0:
        Q[:, 2] = -Q[:, 2]
    moments = np.empty(3)
    for i in range(3):
        q = Q[:, i].tolist()
        Iq = [(I_body[k, 0] * q[0] + I_body[k, 1] * q[1]) + I_body[k, 2] * q[2]
              for k in range(3)]
        moments[i] = (q[0] * Iq[0] + q[1] * Iq[1]) + q[2] * Iq[2]
    return Q, moments


def _det3(M: np.ndarray) -> float:
    return float(M[0, 0] * (M[1, 1] * M[2, 2] - M[1, 2] * M[2, 1])
                 - M[0, 1] * (M[1, 0] * M[2, 2] - M[1, 2] * M[2, 0])
                 + M[0, 2] * (M[1, 0] * M[2, 1] - M[1, 1] * M[2, 0]))


@jitable
def rotation_exp_into(t0, t1, t2, E):
    """``exp([theta]x)`` of the rotation vector ``theta = (t0, t1, t2)``,
    into E (3, 3).

    Rodrigues: ``cos(a) E + s [theta]x + c theta theta^T`` with
    ``a = |theta|``, ``s = sin(a)/a``, ``c = (1 - cos(a))/a^2``, whose series
    are used below ``SERIES_BELOW``; the C library's sine and cosine
    (``math.sin``, ``math.cos``, which the compiled loop calls too: numpy's
    ``np.sin`` may take SIMD loops whose last bits differ per processor);
    each entry ``(c t_i) t_j -+ s t_k`` (``+ cos(a)`` on the diagonal).
    """
    a2 = (t0 * t0 + t1 * t1) + t2 * t2
    if a2 < SERIES_BELOW:
        s = 1.0 - a2 / 6.0
        c = 0.5 - a2 / 24.0
        cos_a = 1.0 - 0.5 * a2
    else:
        a = math.sqrt(a2)
        s = math.sin(a) / a
        cos_a = math.cos(a)
        c = (1.0 - cos_a) / (a * a)
    ct0, ct1, ct2 = c * t0, c * t1, c * t2
    st0, st1, st2 = s * t0, s * t1, s * t2
    E[0, 0] = ct0 * t0 + cos_a
    E[0, 1] = ct0 * t1 - st2
    E[0, 2] = ct0 * t2 + st1
    E[1, 0] = ct1 * t0 + st2
    E[1, 1] = ct1 * t1 + cos_a
    E[1, 2] = ct1 * t2 - st0
    E[2, 0] = ct2 * t0 - st1
    E[2, 1] = ct2 * t1 + st0
    E[2, 2] = ct2 * t2 + cos_a


@jitable
def _axis_flow(P, L, i, rate):
    """The flow of ``c_i L_i^2 / 2`` for a time t, ``rate = t c_i``, in
    place: the body turns about its principal axis i by ``phi = rate L_i``
    (columns j, k of P, with (i, j, k) cyclic), and L by ``-phi``, so that
    ``P L`` does not change. ``phi = 0`` (a symmetric body) is the identity."""
    phi = rate * L[i]
    if phi == 0.0:
        return
    j = (i + 1) % 3
    k = (i + 2) % 3
    s = math.sin(phi)
    c = math.cos(phi)
    L_j, L_k = L[j], L[k]
    L[j] = c * L_j + s * L_k
    L[k] = c * L_k - s * L_j
    for r in range(3):
        P_j, P_k = P[r, j], P[r, k]
        P[r, j] = c * P_j + s * P_k
        P[r, k] = c * P_k - s * P_j


@jitable
def free_rotation_step(R, w, Q, moments, h, P, L, E):
    """One torque-free step of one body (module docstring), in place.

    Parameters
    ----------
    R : (3, 3) orientation (columns: the mesh's axes in the world)
    w : (3,) angular velocity, world frame, rad/s
    Q : (3, 3) principal axes in the mesh frame (columns, det +1);
        moments : (3,) the principal moments, increasing
        (:func:`principal_frame`)
    h : step, s
    P, E : (3, 3) and L : (3,) scratch

    Every product and sum in one written-out order (no BLAS), so the
    readable and compiled runs agree bit for bit.
    """
    for i in range(3):                                  # P = R Q
        for j in range(3):
            P[i, j] = (R[i, 0] * Q[0, j] + R[i, 1] * Q[1, j]) + R[i, 2] * Q[2, j]
    # Why each step: R = P Q^T and the next step's P = R Q multiply P by
    # Q^T Q, the identity only to rounding (Q is a computed eigenvector
    # matrix), the same factor every step; and L = diag(I) P^T w is read back
    # from w = P (L / I), which keeps L only as far as P^T P = E. Without
    # this, |R^T R - E| grows like the number of steps and the angular
    # momentum drifts like its square; with it, both stay at rounding.
    orthonormalize_columns(P, P)
    for j in range(3):                                  # L = diag(I) P^T w
        L[j] = moments[j] * ((P[0, j] * w[0] + P[1, j] * w[1]) + P[2, j] * w[2])
    I_1 = moments[1]
    half_c0 = 0.5 * h * (1.0 / moments[0] - 1.0 / I_1)
    half_c2 = 0.5 * h * (1.0 / moments[2] - 1.0 / I_1)
    _axis_flow(P, L, 0, half_c0)
    _axis_flow(P, L, 2, half_c2)
    rotation_exp_into((h / I_1) * L[0], (h / I_1) * L[1], (h / I_1) * L[2], E)
    for i in range(3):                                  # P <- P E, row by row
        p0, p1, p2 = P[i, 0], P[i, 1], P[i, 2]
        for j in range(3):
            P[i, j] = (p0 * E[0, j] + p1 * E[1, j]) + p2 * E[2, j]
    _axis_flow(P, L, 2, half_c2)
    _axis_flow(P, L, 0, half_c0)
    W0, W1, W2 = L[0] / moments[0], L[1] / moments[1], L[2] / moments[2]
    for i in range(3):
        w[i] = (P[i, 0] * W0 + P[i, 1] * W1) + P[i, 2] * W2    # w = P (L / I)
        for j in range(3):                                        # R = P Q^T
            R[i, j] = (P[i, 0] * Q[j, 0] + P[i, 1] * Q[j, 1]) + P[i, 2] * Q[j, 2]


@jitable
def free_rotation_steps(R, w, Q, moments, h):
    """:func:`free_rotation_step` of every body: R (B, 3, 3), w (B, 3),
    Q (B, 3, 3), moments (B, 3), in place."""
    P = np.empty((3, 3))
    E = np.empty((3, 3))
    L = np.empty(3)
    for b in range(R.shape[0]):
        free_rotation_step(R[b], w[b], Q[b], moments[b], h, P, L, E)


def free_rotation_steps_readable(R, w, Q, moments, h):
    """:func:`free_rotation_steps` run by the interpreter on Python floats
    (:func:`refsim.kernels.python_floats`), body by body: the same bits,
    sooner (docs/decisions/readable-floats.md)."""
    P, L, E = python_floats((np.empty((3, 3)), np.empty(3), np.empty((3, 3))))
    for b in range(R.shape[0]):
        free_rotation_step(*python_floats((R[b], w[b], Q[b], moments[b], h)), P, L, E)


def free_rotation_steps_compiled(R, w, Q, moments, h):
    """:func:`free_rotation_steps` compiled by numba as it stands (the same
    source; compiled on first use, then cached on disk)."""
    compile_kernel(free_rotation_steps)(R, w, Q, moments, h)


def world_inertia(R: np.ndarray, I_body: np.ndarray) -> np.ndarray:
    """``(R I_body) R^T`` for all bodies: (B, 3, 3), (B, 3, 3) -> (B, 3, 3),
    each product summed left to right (:func:`refsim.dynamics.products.matmul`)."""
    return matmul(matmul(R, I_body), np.swapaxes(R, -1, -2))


#: A vertex past a wall is a contact of an impact when it is at least this
#: fraction as deep as the deepest (:func:`wall_contacts`): it crossed within
#: the first half of the time the deepest has been across, about the same
#: instant. (A body at rest is held by every vertex past the wall.)
WALL_DEEPEST_FRACTION = 0.5


def wall_contacts(world_vertices: np.ndarray, axis: int, wall: float, low_wall: bool
                  ) -> np.ndarray:
    """Indices of the vertices past the wall ``x_axis = wall`` (strictly) by
    at least :data:`WALL_DEEPEST_FRACTION` of the deepest one's depth, in
    index order.

    A contact found after the body crossed the wall began at its deepest
    vertex; those much shallower crossed later in the step. A sphere mesh
    found a step's fall into the floor has its lowest vertex and a ring of
    others past it, and the ring, unevenly placed, turns a frictionless
    sphere that lands straight (docs/decisions/body-contact.md); a face
    landing flat has every vertex of the face equally deep. The corrected wall
    response asks this of an impact only: a body resting on the wall sinks
    about ``g h^2`` a step, so a tilt of a few micro-radians would leave a
    single edge as "deepest", and a cube at rest would rock from edge to
    edge for ever instead of settling."""
    past = past_wall(world_vertices, axis, wall, low_wall)
    if not len(past):
        return past
    column = world_vertices[past, axis]
    depth = wall - column if low_wall else column - wall
    return past[depth >= WALL_DEEPEST_FRACTION * depth.max()]


def past_wall(world_vertices: np.ndarray, axis: int, wall: float, low_wall: bool
              ) -> np.ndarray:
    """Indices of every vertex past the wall ``x_axis = wall`` (strictly)."""
    column = world_vertices[:, axis]
    return np.flatnonzero(column < wall if low_wall else column > wall)
