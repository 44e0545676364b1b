"""The seed's simplified rotational dynamics (S9), faithful, with its flaw.

The seed's body has a position ``Pos``, a linear velocity ``Vel``, an angular
velocity ``w`` and orientation axes ``X, Y, Z`` (the columns of the
orientation matrix R). Between collisions:

    X += h (w x X),  Y += h (w x Y),  Z += h (w x Z)      (an Euler step)

and ``w`` is constant (identity inertia: "the angular momentum ... just
becomes the angular velocity"). At a contact with a plane of normal N, at
the contact vertex ``Pi`` (object space about the centroid, oriented:
``Pi = R p_i``):

    Vi  = w x Pi + Vel                               velocity of the contact point
    Rvi = -(Vi . N) N  +  (Vi + (-(Vi . N) N))        reflected: normal + lateral part
    Rvi (damped) = kFriction * lateral + kRestitution * normal
    I   = kRestitution * (-(Vi . N) N)                the damped normal part of Rvi
    T   = Pi x I
    w  += T                                           "the torque IS the desired change"

(The seed's "Lateral Component of Rvi = Vi + Normal Component of Rvi" is
``Vi - (Vi . N) N``, the tangential part of Vi.)

Why this cannot damp spin (claim C12). Write ``u = Pi x N``, ``v_n = Vi . N``
(< 0 when the point approaches the plane) and ``e = kRestitution``. Then

    I = -e v_n N,   T = Pi x I = -e v_n u,   w' = w - e v_n u.

(a) T is perpendicular to N (``u . N = 0``), so ``w' . N = w . N``: the spin
about the contact normal (a cube spinning about the vertical on the floor)
is never changed by any contact, however many. Nothing else in the seed's
model acts on w, so that component of w lives forever.

(b) Lateral friction never reaches w: the lateral part of Rvi is damped and
then discarded, since I is only the normal part. A spinning, sliding contact
feels no torque from friction.

(c) Energy. With identity inertia the rotational energy is ``|w|^2 / 2`` and

    |w'|^2 / 2 - |w|^2 / 2 = -e v_n (w . u) + e^2 v_n^2 |u|^2 / 2.

Since ``w . u = w . (Pi x N) = (w x Pi) . N``, the rotational part of the
contact point's normal velocity, write ``v_n = v_rot + v_lin`` with
``v_rot = w . u`` and ``v_lin = Vel . N``. For a contact caused by the
body's fall (``v_lin < 0``, ``|v_lin| >> |v_rot|``) the change is about
``e |v_lin| v_rot + e^2 v_lin^2 |u|^2 / 2``: the second term is positive and
of the order of the translational energy of the fall, so falling contacts
*pump* rotational energy in (whatever the sign of ``v_rot``). The impulse is
not the one that would stop the contact point (which needs ``(1 + e)`` times
the normal velocity divided by the effective mass ``1/m + |u|^2 / I``), it
is applied on top of the translational reflection of S7 that already
reversed Vel (momentum counted twice), and it ignores the mass, so it is
dimensionally a velocity, not an impulse. Only for a purely rotational
contact (``v_lin = 0``) is the component of w along u scaled by
``1 - e |u|^2``, a partial damping, which overshoots when ``e |u|^2 > 2``.

What the simulation then shows (``refsim.studies.dynamics.measure_spin``):
the cube of ``scenes/spinning-cube.toml`` keeps its vertical spin ``w_y``
exactly, the horizontal components are kicked at every bounce and by the
corners that dip below the floor while it slides, and |w| and the rotational
energy do not decay to 0, whereas the corrected model
(:mod:`refsim.dynamics.rotation_impulse`) brings the cube to rest.

Seed section: S9 ("Simplified Rotational Dynamics", "Existing Problems").

Reference for the correct version: D. Baraff, "Rigid Body Simulation",
SIGGRAPH 2001 course notes *Physically Based Modeling*, sections 8-9
(collision impulses with the inertia tensor).

Cost: O(B) per orientation step; O(n) per contact to find the vertex.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from refsim.dynamics.products import jitable, orthonormalize_columns
from refsim.kernels import SEED_ORIENTATION_STEP, compile_kernel


def cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a x b`` for (B, 3) arrays, by components (np.cross costs 10x more
    for small B, from its generality)."""
    out = np.empty_like(b)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def skew_apply(w: np.ndarray, R: np.ndarray) -> np.ndarray:
    """``w x`` each column of R, for all bodies: (B, 3), (B, 3, 3) -> (B, 3, 3)."""
    wx, wy, wz = w[:, 0:1], w[:, 1:2], w[:, 2:3]      # (B, 1): broadcast over columns
    X0, X1, X2 = R[:, 0, :], R[:, 1, :], R[:, 2, :]   # component rows of all three axes
    out = np.empty_like(R)
    out[:, 0, :] = wy * X2 - wz * X1
    out[:, 1, :] = wz * X0 - wx * X2
    out[:, 2, :] = wx * X1 - wy * X0
    return out


def gram_schmidt(R: np.ndarray) -> np.ndarray:
    """Orthonormalize the columns of each (3, 3) in R (B, 3, 3): X normalized, Y
    made orthogonal to X and normalized, Z = X x Y (right-handed). Dot
    products are summed left to right, as in the compiled path."""
    X = R[:, :, 0]
    X = X / np.sqrt((X[:, 0] * X[:, 0] + X[:, 1] * X[:, 1]) + X[:, 2] * X[:, 2])[:, None]
    Y = R[:, :, 1]
    d = (Y[:, 0] * X[:, 0] + Y[:, 1] * X[:, 1]) + Y[:, 2] * X[:, 2]
    Y = Y - d[:, None] * X
    Y = Y / np.sqrt((Y[:, 0] * Y[:, 0] + Y[:, 1] * Y[:, 1]) + Y[:, 2] * Y[:, 2])[:, None]
    out = np.empty_like(R)
    out[:, :, 0] = X
    out[:, :, 1] = Y
    out[:, :, 2] = cross_rows(X, Y)
    return out


def orientation_step_seed(R: np.ndarray, w: np.ndarray, h: float) -> np.ndarray:
    """The seed's Euler step of the axes, ``X += h (w x X)`` for each column,
    for all bodies: R (B, 3, 3), w (B, 3) in rad/s. Returns a new R.

    AMBIGUITY (A2): the seed gives w's magnitude in "revolutions / time", but
    ``dX/dt = w x X`` holds only with w in radians per time; refsim's w is in
    rad/s (docs/design.md, Conventions): what the seed's own formula computes.

    AMBIGUITY: the seed's axes are "normalized and orthogonal", but its Euler
    step is not a rotation: it lengthens every axis by a factor
    ``sqrt(1 + h^2 |w x X|^2 / |X|^2)`` per step (10 % over the 6 s of the
    spinning-cube scene). The formula image that may have said how the seed
    kept them orthonormal is lost; this code re-orthonormalizes after every
    step by Gram-Schmidt (X first), the cheapest way a 1997 program would.
    """
    return gram_schmidt(R + h * skew_apply(w, R))


@jitable
def axes_step_seed(R, w, h, A, out):
    """:func:`orientation_step_seed` of one body: R (3, 3), w (3,), into out
    (3, 3), which may be R itself (A (3, 3) scratch): ``X += h (w x X)`` for
    each column c, then Gram-Schmidt, X first
    (:func:`refsim.dynamics.products.orthonormalize_columns`); the same
    operations in the same order as the vectorised step."""
    wx, wy, wz = w[0], w[1], w[2]
    for c in range(3):
        X0, X1, X2 = R[0, c], R[1, c], R[2, c]
        A[0, c] = X0 + h * (wy * X2 - wz * X1)
        A[1, c] = X1 + h * (wz * X0 - wx * X2)
        A[2, c] = X2 + h * (wx * X1 - wy * X0)
    orthonormalize_columns(A, out)


@jitable
def orientation_step_seed_loops(R: np.ndarray, w: np.ndarray, h: float,
                                out: np.ndarray) -> None:
    """:func:`orientation_step_seed` as loops over the bodies, into ``out``
    (:func:`axes_step_seed` of each; the kernel numba compiles)."""
    A = np.empty((3, 3))
    for b in range(R.shape[0]):
        axes_step_seed(R[b], w[b], h, A, out[b])


def orientation_step_seed_compiled(R: np.ndarray, w: np.ndarray, h: float) -> np.ndarray:
    """Mirrors :func:`orientation_step_seed`: its loops
    (:func:`orientation_step_seed_loops`) compiled by numba, the same bits."""
    out = np.empty_like(R)
    compile_kernel(orientation_step_seed_loops)(np.ascontiguousarray(R),
                                                np.ascontiguousarray(w), float(h), out)
    return out


def orientation_step_seed_kernel(R: np.ndarray, w: np.ndarray, h: float, *,
                                 kernel: str | None = None) -> np.ndarray:
    """:func:`orientation_step_seed` on the chosen kernel (:mod:`refsim.kernels`)."""
    return SEED_ORIENTATION_STEP(kernel)(R, w, h)


@dataclass(frozen=True)
class SeedContact:
    """The seed's quantities at one contact, all world-frame (3,) vectors."""

    Pi: np.ndarray       # contact vertex about the centroid, oriented (R p_i)
    N: np.ndarray        # contact plane normal, pointing into the body
    Vi: np.ndarray       # velocity of the contact point, w x Pi + Vel
    Rvi: np.ndarray      # reflected, damped: kFriction lateral + kRestitution normal
    I: np.ndarray        # impulse "force": the damped normal part of Rvi
    T: np.ndarray        # torque Pi x I, the change of w
    w: np.ndarray        # the angular velocity after the contact


def contact_spin_seed(w: np.ndarray, Vel: np.ndarray, Pi: np.ndarray, N: np.ndarray,
                      restitution: float, friction: float) -> SeedContact:
    """The seed's change of angular velocity at one contact (S9).

    Parameters
    ----------
    w, Vel : (3,)
        Angular velocity (rad/s) and the centroid's velocity before the
        contact (AMBIGUITY: the velocity before S7's flip; the seed computes
        Vi "of the point of contact", i.e. as it hits).
    Pi : (3,)
        Contact vertex relative to the centroid, in world orientation.
    N : (3,)
        Unit normal of the contact plane, pointing into the body (for the
        floor, (0, 1, 0)).
    restitution, friction : float
        kRestitution = ``restitution``; kFriction = ``1 - friction``.
    """
    k_restitution, k_friction = restitution, 1.0 - friction
    Vi = np.cross(w, Pi) + Vel                         # Vi = (w x Pi) + Vel
    normal = -np.dot(Vi, N) * N                        # Normal Component of Rvi = -DOT(Vi,N) * N
    lateral = Vi + normal                              # Lateral Component of Rvi = Vi + Normal
    Rvi = lateral * k_friction + normal * k_restitution
    I = normal * k_restitution                         # the dampened normal component of Rvi
    T = np.cross(Pi, I)                                # T = Pi x I
    # AMBIGUITY: the seed's last formula (an image) is lost. Its words: "The
    # torque IS the desired change in the angular velocity (w), so the angular
    # velocity is immediately changed with an Euler step". "Is the desired
    # change" and "immediately" read as w += T; an Euler step w += h T would
    # make the contact torque h (1e-3) times smaller and leave w practically
    # untouched by contacts. w += T is the reading that lets the seed's
    # author observe anything to debug.
    return SeedContact(Pi=Pi, N=N, Vi=Vi, Rvi=Rvi, I=I, T=T, w=w + T)


def contact_vertex_seed(world_vertices: np.ndarray, axis: int, low_wall: bool) -> int:
    """Index of the seed's contact vertex Pi against a wall: the deepest
    vertex past it (the box's extreme vertex on that side).

    AMBIGUITY: the seed says only "given a point of contact Pi (which is just
    a vertex of the object)". The deepest vertex is the one that defines the
    box face that crossed the wall, the natural choice with an AABB-based
    test. Ties (a face flat on the wall) go to the lowest vertex index
    (numpy's argmin/argmax), deterministic but arbitrary: a flat landing
    gets torque from one corner.
    """
    column = world_vertices[:, axis]
    return int(np.argmin(column) if low_wall else np.argmax(column))
