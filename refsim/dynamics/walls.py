"""Translational response to the walls of the world cube (seed S7), for a
body's box and for point masses (the particle system, S10): one law, with
the wall-speed option for both.

The seed: "Using the current axis-aligned bounding box that surrounds the
object, we simply handle each component (or dimension) separately as a one
dimensional interval overlap problem. If the box extends beyond the world
cube in a particular dimension, we push it back to the wall only along that
axis and flip the velocity; restitution and frictional forces are applied
here as a dampening on the normal and lateral components of the flipped
velocity respectively."

So, for each axis k whose wall the box crosses (detection:
:func:`refsim.bounds.world_cube.world_cube_test`):

1. push back: ``x_k += correction_k`` (the box then touches the wall);
2. flip and damp the normal part: ``v_k <- -e v_k`` (``e`` =
   ``world.restitution``);
3. damp the lateral parts: ``v_j <- kFriction v_j`` for the two other axes,
   ``kFriction = 1 - friction`` (``world.friction``).

For a point (a particle) the "box" is the point itself:
:func:`wall_response_points` and its in-place twin
:func:`wall_response_points_inplace` apply the same rule, with the same wall
speed, to N points at once; a point on the wall (``x == -half_size``) is
inside. AMBIGUITY (A8): the velocity is flipped whenever the box (or point)
is beyond the wall, without asking whether it still moves outward (the
seed's words: "push it back ... and flip the velocity").

Energy of the push-back. The push-back is a discretization artefact: the
body reached the wall some time during the step and is found past it by
``delta = |correction_k|``. Moving it back by ``delta`` against gravity adds
``m g delta`` of potential energy while the velocity it keeps is the one it
had at the deeper point, so every bounce would gain about ``m g delta``
(``delta`` up to ``|v| h``: at a 6 m drop with h = 1e-3, apex ratios off by
0.2 % at the first bounce and growing as the bounces get lower).
DEVIATION (D1): the default ``speed="wall"`` therefore gives the normal component the speed the
body had *at the wall*, by energy conservation along that axis over the
distance ``delta``:

    v_k,wall^2 = v_k^2 + 2 a_k correction_k,   a_k = gravity's k component,

keeping its sign (clamped at 0 when the body could not have reached the
deeper point from the wall: resting contact). Then push-back plus bounce
change the mechanical energy by exactly ``(e^2 - 1) m v_k,wall^2 / 2`` on the
normal part (and the lateral damping), as the seed's continuous model says.
``speed="seed"`` keeps the seed's literal velocity, for comparison.

The corrected wall response (``wall_response = "impulse"``, in
:meth:`refsim.dynamics.simulation.Simulation._wall_impulse`) takes its time
of impact from here: :func:`deepest_speed` and :func:`crossing_time` say
when in the step the body reached the wall, and :func:`bounce_advance`
carries a bounce on from that instant to the end of the step (choice D10).

Seed section: S7 (with S5's restitution and lateral friction).

Reference: Newton's restitution law ``v_n' = -e v_n`` as in B. Mirtich,
*Impulse-based Dynamic Simulation of Rigid Body Systems*, PhD thesis, UC
Berkeley 1996, chapter 3; the lateral scaling is the seed's simplification.

Cost: O(1) per crossed wall of a body; for N points O(N) comparisons per
axis and wall (the in-place kernel first checks the whole array's min and
max and stops there when nothing is beyond) plus O(N) masked updates for
each wall that was hit (no allocation).
"""

from __future__ import annotations

import math

import numpy as np

from refsim.dynamics.rotation_impulse import rotation_exp_into
from refsim.errors import check_option

SPEEDS = ("wall", "seed")
_LATERAL = ((1, 2), (0, 2), (0, 1))          # the two other axes of each axis


def wall_speed(v_k: float, a_k: float, correction_k: float) -> float:
    """The normal velocity component at the wall, by energy along the axis.

    ``v_k`` at the penetrated position, ``a_k`` the (constant) acceleration
    along the axis, ``correction_k`` the push-back (signed). From
    ``v_deep^2 = v_wall^2 + 2 a_k (x_deep - x_wall)`` and
    ``x_deep - x_wall = -correction_k``.
    """
    squared = v_k * v_k + 2.0 * a_k * correction_k
    # DEVIATION: clamped at 0 (a body that could not have come from the wall
    # with this speed is in resting contact and keeps none of it).
    return float(np.copysign(np.sqrt(max(squared, 0.0)), v_k))


def deepest_speed(r_a, count, k, low, v, w):
    """The velocity along ``+e_k`` of the deepest of the contacts
    ``r_a[:count]`` (offsets from the centroid; the first of equally deep
    ones): ``v_k + (w x r)_k``, with ``v``, ``w`` (3,) the centroid's
    velocity and the angular velocity. ``low``: the wall is the low one of
    axis ``k``. Written for numba as well: the compiled loop compiles this
    function itself."""
    deepest = 0
    for i in range(1, count):
        if (r_a[i, k] < r_a[deepest, k]) if low else (r_a[i, k] > r_a[deepest, k]):
            deepest = i
    k1 = (k + 1) % 3
    k2 = (k + 2) % 3
    return v[k] + (w[k1] * r_a[deepest, k2] - w[k2] * r_a[deepest, k1])


def crossing_time(u, a_k, correction_k, low, h):
    """How long before the end of the step the body crossed the wall (s,
    in ``[0, h]``): the corrected wall response's time of impact.

    The wall stage finds a body past the wall at the end of a step; it
    reached the wall some time ``tau`` earlier. Its deepest contact crossed
    first; its normal velocity now is ``u`` (:func:`deepest_speed`), and at
    the wall it was ``u_wall`` with ``u^2 = u_wall^2 - 2 a_k correction_k``
    (:func:`wall_speed`: the acceleration ``a_k`` constant over the step, the
    rotation's part of ``u`` taken as constant too). Under constant
    acceleration the distance covered is the mean speed times the time, so
    ``tau = 2 |correction_k| / (|u| + |u_wall|)``, clamped to one step.
    ``tau = 0`` when that contact does not move into the wall (``low``: the
    low wall of the axis, whose normal is ``+e_k``). Written for numba as
    well.
    """
    if (u >= 0.0) if low else (u <= 0.0):
        return 0.0
    squared = u * u + 2.0 * a_k * correction_k
    speed = abs(u) + (math.sqrt(squared) if squared > 0.0 else 0.0)
    tau = 2.0 * abs(correction_k) / speed
    return tau if tau < h else h


def bounce_advance(x, v, v_contact, R, w, dw0, dw1, dw2, E, lo, hi, k, low, a_k, tau):
    """Carry a body that bounced off the wall of axis ``k`` on from the
    instant of the impact to the end of the step, in place.

    The corrected response acts at the wall, on the velocities at the wall
    (:func:`wall_speed`), but at the end of the step: left there, the body
    would restart from the wall ``tau`` (:func:`crossing_time`) late, and
    every bounce would add up to a step's delay to the flight. Had the
    impulse acted at the instant of the crossing, the body would since have
    moved with its new velocities. Under the constant acceleration ``a_k``
    along the normal (nothing along the wall changes it):

    - along the normal, from the wall: ``x_k += v_k tau + a_k tau^2 / 2``
      and ``v_k += a_k tau`` (``v_k`` the velocity after the impulse, at the
      wall), which keeps the energy the impulse left;
    - along the wall, ``x_j += (v_j - v_contact_j) tau``: the change the
      impulse made, for the time it would have acted (``v_contact``: the
      velocity the impulse acted on);
    - the orientation ``R`` (3, 3) turned over ``tau`` with the spin before
      the impact; it is turned on by the change of spin ``dw`` times ``tau``
      (``R <- exp([dw tau]x) R``, first order in ``tau``), and the angular
      velocity ``w`` (3,) with it, so that the spin in the body's frame, and
      with it the rotational energy, is the impulse's. Without this turn the
      contact that was struck lags its rebound, is found past the wall
      again, and its push-back adds energy: an l-beam tumbling with e = 1
      gained 1.2 % in 10 s at h = 1e-3 (0.4 % with the turn).

    A body that would not have left the wall in ``tau`` (an inelastic
    impact, a slow rebound) stays where it is, in contact. The box ``lo``,
    ``hi`` (3,) moves with the body; ``E`` (3, 3) is scratch. Every product
    in one written-out order, for numba as well: the compiled loop compiles
    this function itself.
    """
    s = v[k] * tau + 0.5 * a_k * tau * tau
    if (s <= 0.0) if low else (s >= 0.0):
        return
    for j in range(3):
        if j == k:
            d = s
            v[k] += a_k * tau
        else:
            d = (v[j] - v_contact[j]) * tau
        x[j] += d
        lo[j] += d
        hi[j] += d
    rotation_exp_into(dw0 * tau, dw1 * tau, dw2 * tau, E)
    for j in range(3):                                  # R <- E R, column by column
        r0, r1, r2 = R[0, j], R[1, j], R[2, j]
        for i in range(3):
            R[i, j] = (E[i, 0] * r0 + E[i, 1] * r1) + E[i, 2] * r2
    w0, w1, w2 = w[0], w[1], w[2]
    for i in range(3):                                  # w <- E w
        w[i] = (E[i, 0] * w0 + E[i, 1] * w1) + E[i, 2] * w2


def wall_response_seed(x: np.ndarray, v: np.ndarray, correction: np.ndarray,
                       restitution: float, friction: float, gravity: float = 0.0,
                       speed: str = "wall") -> tuple[np.ndarray, np.ndarray]:
    """The seed's per-axis wall response of one body (S7).

    Parameters
    ----------
    x, v : (3,) arrays
        Position of the body's reference point and its velocity; not modified.
    correction : (3,) array
        :attr:`refsim.bounds.world_cube.WallCrossings.correction`: nonzero on
        each axis whose wall the box crosses.
    restitution, friction : float
        ``world.restitution`` (e) and ``world.friction`` (kFriction = 1 - friction).
    gravity : float
        g, for ``speed="wall"`` (gravity is ``(0, -g, 0)``).
    speed : {"wall", "seed"}
        The normal speed that is flipped: at the wall (default, see the module
        docstring) or the seed's literal one at the penetrated position.

    Returns
    -------
    (x, v) : new (3,) arrays.
    """
    check_option("speed", speed, SPEEDS)
    x = np.array(x, dtype=np.float64)
    v = np.array(v, dtype=np.float64)
    k_friction = 1.0 - friction                              # the seed's kFriction
    for k in np.flatnonzero(correction):
        x[k] += correction[k]                                # 1. push back along this axis only
        v_k = v[k]
        if speed == "wall":
            a_k = -gravity if k == 1 else 0.0
            v_k = wall_speed(v_k, a_k, correction[k])
        v[k] = -restitution * v_k                            # 2. flip, damp the normal part
        for j in _LATERAL[k]:
            v[j] = k_friction * v[j]                         # 3. damp the lateral parts
    return x, v


def wall_name(axis: int, correction_k: float) -> str:
    """``"x-"``, ``"y+"``, ...: the wall a push-back of this sign came from
    (a positive correction pushes away from the low wall)."""
    return "xyz"[axis] + ("-" if correction_k > 0 else "+")


def wall_response_points(x: np.ndarray, v: np.ndarray, half_size: float, restitution: float,
                         friction: float, gravity: float = 0.0, speed: str = "wall"
                         ) -> tuple[np.ndarray, np.ndarray, int]:
    """The per-axis response of N points (N, 3): new positions and velocities,
    and the number of (point, wall) bounces handled. The plain kernel: for
    each axis, the low wall then the high one, each point beyond it pushed
    back onto it, its normal speed (at the wall, or the seed's literal one)
    flipped and damped by ``e``, its lateral speed damped by ``kFriction``."""
    check_option("speed", speed, SPEEDS)
    x = x.copy()
    v = v.copy()
    bounces = 0
    k_friction = 1.0 - friction
    for axis in range(3):
        a_k = -gravity if axis == 1 else 0.0
        for wall in (-half_size, half_size):
            beyond = x[:, axis] < wall if wall < 0 else x[:, axis] > wall
            for i in np.flatnonzero(beyond):
                correction = wall - x[i, axis]
                x[i, axis] = wall                           # push back along this axis only
                v_k = v[i, axis]
                if speed == "wall":
                    v_k = wall_speed(v_k, a_k, correction)
                v[i, axis] = -restitution * v_k             # flip, damp the normal part
                for lateral in _LATERAL[axis]:
                    v[i, lateral] = k_friction * v[i, lateral]   # kFriction
                bounces += 1
    return x, v, bounces


def wall_response_points_inplace(x: np.ndarray, v: np.ndarray, half_size: float,
                                 restitution: float, friction: float, beyond: np.ndarray,
                                 gravity: float = 0.0, speed: str = "wall",
                                 scratch: np.ndarray | None = None) -> int:
    """:func:`wall_response_points` on ``x`` and ``v`` in place: the same
    arithmetic, masked. ``beyond`` is an (N,) bool scratch array, and
    ``scratch`` an (N,) float one (needed for ``speed="wall"``). Returns the
    number of bounces."""
    # Two contiguous reductions decide "no point beyond any wall" (the usual
    # case) at a third of the cost of the six strided column tests.
    if x.min() >= -half_size and x.max() <= half_size:
        return 0
    bounces = 0
    k_friction = 1.0 - friction
    for axis in range(3):
        a_k = -gravity if axis == 1 else 0.0
        for wall in (-half_size, half_size):
            if wall < 0:
                np.less(x[:, axis], wall, out=beyond)
            else:
                np.greater(x[:, axis], wall, out=beyond)
            if not beyond.any():
                continue
            # Masked in-place ufuncs: no index arrays, no O(hits) temporaries.
            v_k = v[:, axis]
            if speed == "wall":
                # wall_speed, masked: copysign(sqrt(max(v^2 + (2 a) (wall - x), 0)), v),
                # the push-back (wall - x) taking x's column until x is set to the wall
                if scratch is None:
                    raise ValueError('wall_response_points_inplace: speed="wall" needs the '
                                     '(N,) float scratch array, got None')
                s, c = scratch, x[:, axis]
                np.multiply(v_k, v_k, out=s, where=beyond)
                np.subtract(wall, c, out=c, where=beyond)
                np.multiply(c, 2.0 * a_k, out=c, where=beyond)
                np.add(s, c, out=s, where=beyond)
                np.maximum(s, 0.0, out=s, where=beyond)
                np.sqrt(s, out=s, where=beyond)
                np.copysign(s, v_k, out=v_k, where=beyond)
            np.copyto(x[:, axis], wall, where=beyond)
            np.multiply(v_k, -restitution, out=v_k, where=beyond)
            for lateral in _LATERAL[axis]:
                np.multiply(v[:, lateral], k_friction, out=v[:, lateral], where=beyond)
            bounces += int(np.count_nonzero(beyond))
    return bounces
