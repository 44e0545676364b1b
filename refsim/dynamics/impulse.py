"""Collision impulses with mass, inertia and Coulomb friction (the corrected
contact model, used by ``rotation = "impulse"`` at the walls and by
``body_response = "impulse"`` between bodies).

What: body A touches body B (B may be static: a wall, ``m_inv = 0``,
``I_inv = 0``) at contact points ``p_i`` with a common unit normal ``n``
pointing from B into A. With ``r_a = p - x_a``, ``r_b = p - x_b`` (from each
centre of mass) the relative velocity of the contact point is

    v_rel = (v_a + w_a x r_a) - (v_b + w_b x r_b),   v_n = v_rel . n.

An impulse ``P`` at ``p`` (``+P`` on A, ``-P`` on B) changes it by ``K P``
with the collision matrix ``K = (1/m_a + 1/m_b) E - [r_a]x I_a^-1 [r_a]x -
[r_b]x I_b^-1 [r_b]x``; along a unit direction ``d`` its effective inverse
mass is ``K_d = d . K d = 1/m_a + 1/m_b + d . ((I_a^-1 (r_a x d)) x r_a +
(I_b^-1 (r_b x d)) x r_b)`` (Baraff 2001, eq. 8-18; Mirtich 1996, 3.3).

The solve, per collision, in two phases (Catto's sequential impulses with
accumulated clamping, box2d-lite ``Arbiter::ApplyImpulse``; restitution by
Poisson's hypothesis, Mirtich 1996 section 3.4):

1. compression: for a few Gauss-Seidel sweeps over the contacts, the normal
   impulse that brings ``v_n`` to 0, accumulated and clamped to ``P_n >= 0``
   (contacts push, never pull); then the friction impulse that brings the
   tangential velocity to 0, accumulated and clamped to the Coulomb cone
   ``|P_t| <= mu P_n``;
2. restitution: each contact that approached faster than
   ``RESTITUTION_THRESHOLD`` gets a further ``e P_n`` along n, scaled down
   if need be so that the collision as a whole adds no kinetic energy
   (Poisson's hypothesis with friction at several contacts can add some;
   the kernel tracks the energy change of every partial impulse exactly
   from the velocities and the inverse inertia);
3. friction through restitution: when phase 2 gave an impulse, the
   friction sweeps run again in the cone of the whole impact, ``|P_t| <= mu
   (P_n + lam e P_n)``, so that friction acts over the whole impact as
   Coulomb's law has it (a ball sliding throughout loses ``mu (1 + e)
   |v_n|`` of lateral speed; Stronge, *Impact Mechanics*, 2000, ch. 3-5).

Every partial impulse of phase 1 removes kinetic energy: an impulse
``lambda (-v_d / K_d) d`` with ``0 <= lambda <= 1`` changes the energy by
``-(v_d^2 / K_d)(lambda - lambda^2 / 2) <= 0``. At a single contact phase 2
gives back ``e^2`` of the normal part of what phase 1 took, so the energy
never increases for ``e <= 1`` (for several contacts the same holds at
convergence of phase 1). Momentum: every impulse acts with ``+P`` on A and
``-P`` on B at the same point, so linear momentum and angular momentum
about any fixed point are conserved (``(x_a + r_a) x P - (x_b + r_b) x P =
0``).

Coulomb coefficient. DEVIATION: ``world.friction`` is, in the seed, the
fraction of lateral speed removed at a bounce (kFriction = 1 - friction);
here it is read as the Coulomb coefficient ``mu`` (the same number, a
different law). The seed itself says its lateral friction "should normally
be proportional to the normal component of the incident velocity", which is
what the cone ``|P_t| <= mu P_n`` does.

Seed section: the correction of S8 and S9 (claims C11, C12).

References: B. Mirtich, *Impulse-based Dynamic Simulation of Rigid Body
Systems*, PhD thesis, UC Berkeley 1996, chapter 3; D. Baraff, "Rigid Body
Simulation", SIGGRAPH 2001 course notes, section 8 ("Collision response");
E. Catto, box2d-lite (2006), ``Arbiter.cpp`` (accumulated impulses).

Cost: O(iterations x contacts) scalar operations. The kernel is plain loops
over float64 arrays; numba compiles the same function when installed (the
DESIGN's "per-contact loops" case); the plain Python function is kept as
:func:`solve_contacts_python` and tested against the compiled one.
"""

from __future__ import annotations

import math

import numpy as np

from refsim.dynamics.products import jitable
from refsim.kernels import CONTACT_IMPULSES, ISLAND_IMPULSES, compile_kernel, python_floats

#: Sweeps of phase 1. Gauss-Seidel over the four corners of a face landing
#: flat converges linearly: the cube's bounce speed is off by 2e-3 (relative)
#: after 8 sweeps, 6e-6 after 16 and 1e-11 after 32 (measured in
#: tests/dynamics/test_impulse.py). The compiled kernel makes 32 cheap.
ITERATIONS = 32

#: Contacts approaching slower than this (m/s) get no restitution. Without it
#: a body resting under gravity bounces by ``e g h`` every step and never
#: settles; box2d uses 1 m/s (its ``b2_velocityThreshold``). A bounce of
#: 0.05 m/s rises 0.13 mm, far below anything a scene of metre-sized bodies
#: shows, and far above ``g h`` = 0.01 m/s at the default step.
RESTITUTION_THRESHOLD = 0.05




@jitable
def _cross(a0, a1, a2, b0, b1, b2):
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@jitable
def _matvec(M, x0, x1, x2):
    return (M[0, 0] * x0 + M[0, 1] * x1 + M[0, 2] * x2,
            M[1, 0] * x0 + M[1, 1] * x1 + M[1, 2] * x2,
            M[2, 0] * x0 + M[2, 1] * x1 + M[2, 2] * x2)


@jitable
def _relative_velocity(i, r_a, r_b, v_a, w_a, v_b, w_b):
    """v_rel at contact i: (v_a + w_a x r_a) - (v_b + w_b x r_b); B static
    (``r_b is None``): v_a + w_a x r_a."""
    ca = _cross(w_a[0], w_a[1], w_a[2], r_a[i, 0], r_a[i, 1], r_a[i, 2])
    if r_b is None:
        return v_a[0] + ca[0], v_a[1] + ca[1], v_a[2] + ca[2]
    cb = _cross(w_b[0], w_b[1], w_b[2], r_b[i, 0], r_b[i, 1], r_b[i, 2])
    return (v_a[0] + ca[0] - v_b[0] - cb[0], v_a[1] + ca[1] - v_b[1] - cb[1],
            v_a[2] + ca[2] - v_b[2] - cb[2])


@jitable
def _angular_inverse_mass(i, d0, d1, d2, r, I_inv):
    """d . ((I^-1 (r x d)) x r) = (r x d) . I^-1 (r x d) at contact i."""
    c = _cross(r[i, 0], r[i, 1], r[i, 2], d0, d1, d2)
    q = _matvec(I_inv, c[0], c[1], c[2])
    return c[0] * q[0] + c[1] * q[1] + c[2] * q[2]


@jitable
def _effective_inverse_mass(i, d0, d1, d2, r_a, r_b, m_inv_a, I_inv_a, m_inv_b, I_inv_b):
    """K_d = 1/m_a + 1/m_b + d . ((I_a^-1 (r_a x d)) x r_a + (I_b^-1 (r_b x d)) x r_b);
    B static (``r_b is None``): without B's angular term."""
    k = m_inv_a + m_inv_b
    k += _angular_inverse_mass(i, d0, d1, d2, r_a, I_inv_a)
    if r_b is not None:
        k += _angular_inverse_mass(i, d0, d1, d2, r_b, I_inv_b)
    return k


@jitable
def _apply(i, P0, P1, P2, r_a, r_b, m_inv_a, I_inv_a, m_inv_b, I_inv_b, v_a, w_a, v_b, w_b):
    """+P on A, -P on B at contact i: v += P / m, w += I^-1 (r x P).

    Returns the change of kinetic energy, from the velocities before:
    ``P . v + |P|^2 / (2 m) + w . (r x P) + (r x P) . I^-1 (r x P) / 2``
    for A, the same with -P for B (no inertia tensor needed, only its
    inverse); nothing for a static B (``r_b is None``)."""
    dE = 0.0
    c = _cross(r_a[i, 0], r_a[i, 1], r_a[i, 2], P0, P1, P2)
    q = _matvec(I_inv_a, c[0], c[1], c[2])
    dE += (P0 * v_a[0] + P1 * v_a[1] + P2 * v_a[2]
           + 0.5 * m_inv_a * (P0 * P0 + P1 * P1 + P2 * P2)
           + w_a[0] * c[0] + w_a[1] * c[1] + w_a[2] * c[2]
           + 0.5 * (c[0] * q[0] + c[1] * q[1] + c[2] * q[2]))
    v_a[0] += m_inv_a * P0
    v_a[1] += m_inv_a * P1
    v_a[2] += m_inv_a * P2
    w_a[0] += q[0]
    w_a[1] += q[1]
    w_a[2] += q[2]
    if r_b is None:
        return dE
    c = _cross(r_b[i, 0], r_b[i, 1], r_b[i, 2], P0, P1, P2)
    q = _matvec(I_inv_b, c[0], c[1], c[2])
    dE += (-(P0 * v_b[0] + P1 * v_b[1] + P2 * v_b[2])
           + 0.5 * m_inv_b * (P0 * P0 + P1 * P1 + P2 * P2)
           - (w_b[0] * c[0] + w_b[1] * c[1] + w_b[2] * c[2])
           + 0.5 * (c[0] * q[0] + c[1] * q[1] + c[2] * q[2]))
    v_b[0] -= m_inv_b * P0
    v_b[1] -= m_inv_b * P1
    v_b[2] -= m_inv_b * P2
    w_b[0] -= q[0]
    w_b[1] -= q[1]
    w_b[2] -= q[2]
    return dE


@jitable
def _friction(i, mu, r_a, r_b, n0, n1, n2, m_inv_a, I_inv_a, m_inv_b, I_inv_b, v_a, w_a,
              v_b, w_b, P):
    """The friction impulse at contact i that stops its sliding, accumulated
    in ``P[i, 1:4]`` and clamped to the Coulomb cone ``|P_t| <= mu P[i, 0]``
    (the normal impulse so far); applied in place. Returns ``(moved, dE)``:
    whether it changed P, and the kinetic energy it changed (<= 0)."""
    vr = _relative_velocity(i, r_a, r_b, v_a, w_a, v_b, w_b)
    vn = vr[0] * n0 + vr[1] * n1 + vr[2] * n2
    t0, t1, t2 = vr[0] - vn * n0, vr[1] - vn * n1, vr[2] - vn * n2
    speed = math.sqrt(t0 * t0 + t1 * t1 + t2 * t2)
    if speed == 0.0:
        return False, 0.0
    d0, d1, d2 = t0 / speed, t1 / speed, t2 / speed
    Kt = _effective_inverse_mass(i, d0, d1, d2, r_a, r_b, m_inv_a, I_inv_a,
                                 m_inv_b, I_inv_b)
    jt = -speed / Kt                                 # stops the sliding along d
    q0, q1, q2 = P[i, 1] + jt * d0, P[i, 2] + jt * d1, P[i, 3] + jt * d2
    size = math.sqrt(q0 * q0 + q1 * q1 + q2 * q2)
    limit = mu * P[i, 0]                             # Coulomb: |P_t| <= mu P_n
    if size > limit:
        scale = limit / size
        q0, q1, q2 = q0 * scale, q1 * scale, q2 * scale
    dP0, dP1, dP2 = q0 - P[i, 1], q1 - P[i, 2], q2 - P[i, 3]
    moved = dP0 != 0.0 or dP1 != 0.0 or dP2 != 0.0
    P[i, 1], P[i, 2], P[i, 3] = q0, q1, q2
    return moved, _apply(i, dP0, dP1, dP2, r_a, r_b, m_inv_a, I_inv_a, m_inv_b, I_inv_b,
                         v_a, w_a, v_b, w_b)


def solve_contacts_python(r_a, r_b, n, m_inv_a, I_inv_a, v_a, w_a, m_inv_b, I_inv_b, v_b,
                          w_b, e, mu, threshold, iterations, P):
    """The contact solve (see the module docstring), in place.

    Parameters
    ----------
    r_a, r_b : (c, 3) float64
        Contact points relative to A's and B's centres of mass.
    n : (3,) unit normal from B into A.
    m_inv_a, m_inv_b : float; I_inv_a, I_inv_b : (3, 3) world-frame inverse
        inertia (zeros for a body whose rotation is off).
    v_a, w_a, v_b, w_b : (3,) float64, updated in place.
    A static B (a wall): ``r_b``, ``I_inv_b``, ``v_b`` and ``w_b`` None and
    ``m_inv_b = 0``. B's terms are then left out, which gives the values
    that zero arrays would (+0.0 everywhere) as long as the impulses are
    finite: with ``m_inv_b``, ``I_inv_b``, ``v_b``, ``w_b`` and ``r_b`` zero,
    B's velocity at the contact is +0 and ``x - (+0) = x`` for every float;
    B's inverse mass terms are +-0
    added to a positive ``K``; B's velocities stay +0 (``+0 - (+-0) =
    +0``); and B's energy terms are +-0 added to ``dE``, which can change
    only the sign of a zero ``dE``, which no result depends on (it enters
    only comparisons and ``1 - lam`` with ``lam = -dE1 / G`` clamped to
    ``[0, 1]``). An infinite impulse would make the zero arrays' B
    velocities NaN (``0 inf``), where None leaves them out: a state the
    simulation's divergence check has stopped before. (Numba compiles the
    ``is None`` branches away.)
    e, mu, threshold : restitution, Coulomb coefficient, restitution threshold.
    iterations : int, sweeps of phase 1.
    P : (c, 4) float64 output: accumulated normal impulse (restitution's
        included) and friction impulse vector of each contact, for the
        caller's bookkeeping (the contact events' impulses).

    Returns
    -------
    int : the number of contacts that approached (v_n < 0) at the start.
    """
    c = r_a.shape[0]
    n0, n1, n2 = n[0], n[1], n[2]
    vn0 = np.empty(c)
    Kn = np.empty(c)
    approaching = _begin(r_a, r_b, n0, n1, n2, m_inv_a, I_inv_a, v_a, w_a, m_inv_b, I_inv_b,
                         v_b, w_b, vn0, Kn, P)
    if approaching == 0:
        return 0
    # Phase 1, compression. A sweep whose every increment is exactly zero
    # changed no value, so each later sweep would start from the same
    # numbers and change none either: the solve stops there, with the
    # values all ``iterations`` sweeps give.
    dE1 = 0.0
    for _ in range(iterations):
        moved, dE1 = _compression_sweep(r_a, r_b, n0, n1, n2, m_inv_a, I_inv_a, v_a, w_a,
                                        m_inv_b, I_inv_b, v_b, w_b, mu, Kn, P, dE1)
        if not moved:
            break
    _restitution(r_a, r_b, n0, n1, n2, m_inv_a, I_inv_a, v_a, w_a, m_inv_b, I_inv_b, v_b, w_b,
                 e, mu, threshold, iterations, vn0, P, dE1)
    return approaching


@jitable
def _begin(r_a, r_b, n0, n1, n2, m_inv_a, I_inv_a, v_a, w_a, m_inv_b, I_inv_b, v_b, w_b,
           vn0, Kn, P):
    """Each contact's approach speed ``vn0`` and effective inverse mass
    along n ``Kn``; ``P`` zeroed. Returns how many approach (v_n < 0)."""
    approaching = 0
    for i in range(r_a.shape[0]):
        vr = _relative_velocity(i, r_a, r_b, v_a, w_a, v_b, w_b)
        vn0[i] = vr[0] * n0 + vr[1] * n1 + vr[2] * n2
        Kn[i] = _effective_inverse_mass(i, n0, n1, n2, r_a, r_b, m_inv_a, I_inv_a,
                                        m_inv_b, I_inv_b)
        if vn0[i] < 0.0:
            approaching += 1
        P[i, 0] = 0.0
        P[i, 1] = 0.0
        P[i, 2] = 0.0
        P[i, 3] = 0.0
    return approaching


@jitable
def _compression_sweep(r_a, r_b, n0, n1, n2, m_inv_a, I_inv_a, v_a, w_a, m_inv_b, I_inv_b,
                       v_b, w_b, mu, Kn, P, dE1):
    """One Gauss-Seidel sweep of phase 1 over the contacts: at each, the
    normal impulse that brings v_n to 0, accumulated and clamped to
    ``P_n >= 0``, then friction in the cone ``|P_t| <= mu P_n`` of the
    normal impulse so far. Returns ``(moved, dE1)``: whether any impulse
    changed, and ``dE1`` plus the kinetic energy the sweep changed, summed
    contact by contact."""
    moved = False
    for i in range(r_a.shape[0]):
        vr = _relative_velocity(i, r_a, r_b, v_a, w_a, v_b, w_b)
        vn = vr[0] * n0 + vr[1] * n1 + vr[2] * n2
        Pn = max(P[i, 0] - vn / Kn[i], 0.0)           # accumulated, clamped
        dPn = Pn - P[i, 0]
        moved = moved or dPn != 0.0
        P[i, 0] = Pn
        dE1 += _apply(i, dPn * n0, dPn * n1, dPn * n2, r_a, r_b, m_inv_a, I_inv_a,
                      m_inv_b, I_inv_b, v_a, w_a, v_b, w_b)
        slid, dE = _friction(i, mu, r_a, r_b, n0, n1, n2, m_inv_a, I_inv_a, m_inv_b,
                             I_inv_b, v_a, w_a, v_b, w_b, P)
        moved = moved or slid
        dE1 += dE
    return moved, dE1


@jitable
def _restitution(r_a, r_b, n0, n1, n2, m_inv_a, I_inv_a, v_a, w_a, m_inv_b, I_inv_b, v_b,
                 w_b, e, mu, threshold, iterations, vn0, P, dE1):
    """Phases 2 and 3 (module docstring) for the contacts whose compression
    impulses ``P`` phase 1 left, ``dE1`` the energy phase 1 changed."""
    c = r_a.shape[0]
    # Phase 2, restitution (Poisson): e times the compression impulse,
    # limited so that the collision as a whole adds no energy.
    # DEVIATION (D8): at several contacts with friction, Poisson's
    # restitution can add energy. Its energy change is
    # dE2(lam) = lam G + lam^2 Q for a fraction lam of the impulses, with
    # G = sum_i e P_n,i v_n,i (velocities at the end of phase 1) and
    # Q = dE2(1) - G >= 0; when dE1 + dE2(1) > 0, lam is the root of
    # dE1 + lam G + lam^2 Q = 0 in [0, 1] and the excess is taken back.
    G = 0.0
    for i in range(c):
        if vn0[i] < -threshold and P[i, 0] > 0.0:
            vr = _relative_velocity(i, r_a, r_b, v_a, w_a, v_b, w_b)
            G += e * P[i, 0] * (vr[0] * n0 + vr[1] * n1 + vr[2] * n2)
    dE2 = 0.0
    restituted = False
    for i in range(c):
        if vn0[i] < -threshold and P[i, 0] > 0.0:
            restituted = True
            j = e * P[i, 0]
            dE2 += _apply(i, j * n0, j * n1, j * n2, r_a, r_b, m_inv_a, I_inv_a,
                          m_inv_b, I_inv_b, v_a, w_a, v_b, w_b)
    lam = 1.0
    if dE1 + dE2 > 0.0:
        Q = max(dE2 - G, 0.0)
        if Q > 0.0:
            lam = (-G + math.sqrt(max(G * G - 4.0 * Q * dE1, 0.0))) / (2.0 * Q)
        else:
            lam = -dE1 / G if G > 0.0 else 0.0
        lam = min(max(lam, 0.0), 1.0)
        for i in range(c):
            if vn0[i] < -threshold and P[i, 0] > 0.0:
                j = -(1.0 - lam) * e * P[i, 0]
                _apply(i, j * n0, j * n1, j * n2, r_a, r_b, m_inv_a, I_inv_a, m_inv_b,
                       I_inv_b, v_a, w_a, v_b, w_b)
    # The normal impulse of each contact now includes the restitution
    # impulse lam e P_n (what the caller reads in P, and phase 3's cone).
    for i in range(c):
        if vn0[i] < -threshold and P[i, 0] > 0.0:
            P[i, 0] = P[i, 0] + lam * e * P[i, 0]
    if not restituted or mu == 0.0:
        return
    # Phase 3, friction through restitution: Coulomb's cone is that of the
    # whole impact, |P_t| <= mu (1 + lam e) P_n; the friction sweeps of
    # phase 1 run again in it. A contact that slid throughout takes
    # mu (1 + e) P_n of friction in all, Coulomb's law over the impact
    # (Stronge 2000, ch. 3-5); one that stuck in compression stays stuck.
    # Each friction impulse removes energy, so the energy bound of phase 2
    # still holds.
    for _ in range(iterations):
        moved = False
        for i in range(c):
            slid, dE = _friction(i, mu, r_a, r_b, n0, n1, n2, m_inv_a, I_inv_a, m_inv_b,
                                 I_inv_b, v_a, w_a, v_b, w_b, P)
            moved = moved or slid
        if not moved:
            break


def solve_island_python(starts, body_a, body_b, r_a, r_b, normals, m_inv, I_inv, v, w,
                        e, mu, threshold, iterations, P):
    """The contact solve of several contact sets at once, in place: the
    contact sets of one step (a stack on the floor: the floor's contacts
    with the lower body, the two bodies' contacts), so that each impulse is
    answered by the others within the step, as a resting contact needs (a
    lower body pressed down off its centre is held by the floor under that
    side, instead of turning and walking away). The simulation passes all
    of a step's body contacts as one solve, whether or not they share
    bodies: sets that share none converge each on its own, but share the
    count of sweeps.

    Phase 1 runs its Gauss-Seidel sweeps over every contact of every set,
    until a sweep changes nothing or ``iterations`` sweeps; phases 2 and 3
    then run set by set, each with the energy its own phase 1 changed
    (module docstring). A single set gives what :func:`solve_contacts_python`
    gives.

    Parameters
    ----------
    starts : (S + 1,) int64
        Set s holds contacts ``starts[s]:starts[s + 1]``.
    body_a, body_b : (S,) int64
        The rows of A and B of each set in the body arrays; a wall is B
        with a row of zeros (no mass, no inertia, at rest; the values are
        those of :func:`solve_contacts_python` with B None, see there).
    r_a, r_b : (C, 3) float64
        Contact points from A's and B's centres of mass (zeros for a wall).
    normals : (S, 3) float64
        Each set's unit normal from B into A.
    m_inv : (N,); I_inv : (N, 3, 3); v, w : (N, 3) float64
        Inverse masses, world-frame inverse inertia, and velocities of the
        bodies (the velocities updated in place).
    e, mu : (S,) float64
        Each set's restitution and Coulomb coefficient (a body's with a
        wall, a pair's: :meth:`refsim.Scene.coefficients`).
    threshold, iterations : as :func:`solve_contacts_python`.
    P : (C, 4) float64 output, as there.

    Returns
    -------
    int : the number of contacts that approached at the start.
    """
    S = starts.shape[0] - 1
    C = r_a.shape[0]
    vn0 = np.empty(C)
    Kn = np.empty(C)
    dE1 = np.zeros(S)
    approaching = 0
    for s in range(S):
        lo, hi, a, b = starts[s], starts[s + 1], body_a[s], body_b[s]
        approaching += _begin(r_a[lo:hi], r_b[lo:hi], normals[s, 0], normals[s, 1],
                              normals[s, 2], m_inv[a], I_inv[a], v[a], w[a], m_inv[b],
                              I_inv[b], v[b], w[b], vn0[lo:hi], Kn[lo:hi], P[lo:hi])
    if approaching == 0:
        return 0
    for _ in range(iterations):
        moved = False
        for s in range(S):
            lo, hi, a, b = starts[s], starts[s + 1], body_a[s], body_b[s]
            changed, dE1[s] = _compression_sweep(
                r_a[lo:hi], r_b[lo:hi], normals[s, 0], normals[s, 1], normals[s, 2], m_inv[a],
                I_inv[a], v[a], w[a], m_inv[b], I_inv[b], v[b], w[b], mu[s], Kn[lo:hi],
                P[lo:hi], dE1[s])
            moved = moved or changed
        if not moved:
            break
    for s in range(S):
        lo, hi, a, b = starts[s], starts[s + 1], body_a[s], body_b[s]
        _restitution(r_a[lo:hi], r_b[lo:hi], normals[s, 0], normals[s, 1], normals[s, 2],
                     m_inv[a], I_inv[a], v[a], w[a], m_inv[b], I_inv[b], v[b], w[b], e[s],
                     mu[s], threshold, iterations, vn0[lo:hi], P[lo:hi], dE1[s])
    return approaching


def solve_island_compiled(*args):
    """:func:`solve_island_python` compiled by numba as it stands."""
    return compile_kernel(solve_island_python)(*args)


def solve_island(*args, kernel: str | None = None):
    """:func:`solve_island_python` on the chosen kernel (:mod:`refsim.kernels`)."""
    return ISLAND_IMPULSES(kernel)(*args)


def solve_contacts_readable(*args):
    """:func:`solve_contacts_python` run by the interpreter on Python floats
    (:func:`refsim.kernels.python_floats`): the same bits, sooner
    (docs/decisions/readable-floats.md)."""
    return solve_contacts_python(*python_floats(args))


def solve_contacts_compiled(*args):
    """:func:`solve_contacts_python` compiled by numba as it stands (the same
    source; compiled on first use, then cached on disk)."""
    return compile_kernel(solve_contacts_python)(*args)


def solve_contacts(*args, kernel: str | None = None):
    """:func:`solve_contacts_python` on the chosen kernel (:mod:`refsim.kernels`)."""
    return CONTACT_IMPULSES(kernel)(*args)


#: Entries of a contact's impulse record (:func:`contact_sum_python`): the
#: impulse vector (3), the normal impulses' sum, and the sum of each contact
#: point (3) weighted by its normal impulse.
IMPULSE_RECORD = 7


def contact_sum_python(P, n, r_a, x_a, out):
    """Add what one contact set did to body A to ``out`` (:data:`IMPULSE_RECORD`,),
    in place: the impulses ``sum_i (P_n,i n + P_t,i)`` (``P`` (c, 4) of
    :func:`solve_contacts_python`, ``n`` the normal into A), the normal
    impulses' sum, and ``sum_i P_n,i (x_a + r_a,i)``, the points weighted by
    their normal impulses (``x_a`` A's centre of mass, ``r_a`` (c, 3) the
    contacts from it). Plain loops, summed in contact order, so the compiled
    loop gets the same bits (it compiles this function as it stands)."""
    for i in range(P.shape[0]):
        for j in range(3):
            out[j] += P[i, 0] * n[j] + P[i, 1 + j]
        out[3] += P[i, 0]
        for j in range(3):
            out[4 + j] += P[i, 0] * (x_a[j] + r_a[i, j])


def impulse_and_point(record) -> tuple[tuple | None, tuple | None]:
    """``(impulse, point)`` of a record of :func:`contact_sum_python`, as an
    :class:`refsim.dynamics.trajectory.Event` holds them: None where no
    impulse acted, and no point without a normal impulse."""
    if record is None or not any(record[:4]):
        return None, None
    impulse = (float(record[0]), float(record[1]), float(record[2]))
    if not record[3] > 0.0:
        return impulse, None
    return impulse, (float(record[4] / record[3]), float(record[5] / record[3]),
                     float(record[6] / record[3]))


def wall_impulses(r_a, n, inv_mass: float, I_inv, v, w, restitution: float,
                  friction: float, threshold: float = RESTITUTION_THRESHOLD, *,
                  kernel: str | None = None) -> np.ndarray:
    """Impulses of one body against a wall at contacts ``r_a`` (k, 3) (from
    its centre of mass), wall normal ``n`` (into the body); ``v``, ``w`` (3,)
    updated in place; ``friction`` is Coulomb's mu, ``threshold`` the
    restitution threshold (m/s). The wall is body B of the solve: static (no
    mass, no inertia, at rest), passed as None. Returns the (k, 4) impulses."""
    r_a = np.ascontiguousarray(r_a, dtype=np.float64)
    P = np.empty((len(r_a), 4))
    solve_contacts(r_a, None, n, inv_mass, I_inv, v, w, 0.0, None, None, None, restitution,
                   friction, threshold, ITERATIONS, P, kernel=kernel)
    return P
