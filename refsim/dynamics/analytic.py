"""Closed-form answers for a body bouncing on the floor of the world cube.

What: a point mass (or a body that does not rotate) dropped from rest at
height ``h0`` above the floor under gravity ``g``, with the Newton
restitution law ``v_n' = -e v_n`` at each instantaneous bounce and no drag:

- speed at the first impact ``v0 = sqrt(2 g h0)``, time of the first impact
  ``t0 = sqrt(2 h0 / g)``;
- after bounce k (k = 1, 2, ...) the rebound speed is ``e^k v0`` and the apex
  height ``h_k = e^(2k) h0``: successive apexes have the ratio ``e^2``;
- flight k between bounces k and k+1 lasts ``2 e^k v0 / g``; bounce k happens
  at ``t_k = t0 (1 + 2 (e + e^2 + ... + e^(k-1)))
  = t0 (1 + 2 e (1 - e^(k-1)) / (1 - e))``;
- the bounces accumulate (Zeno) at ``t_inf = t0 (1 + 2 e / (1 - e))
  = t0 (1 + e) / (1 - e)``, after infinitely many bounces: the time to rest;
- the mechanical energy above the floor, ``E = m g h0`` before the first
  bounce, is ``e^(2k) m g h0`` after bounce k (a staircase in time).

Lateral velocity after one oblique bounce with normal speed ``v_n`` (into the
wall) and tangential speed ``v_t``:

- the seed's friction (S5, S7): the lateral part of the reflected velocity is
  scaled by ``kFriction = 1 - friction``: ``v_t' = (1 - friction) v_t``,
  whatever the normal speed;
- Coulomb friction with coefficient ``mu`` for a point mass (or a body
  sliding throughout the impact): the tangential impulse is at most ``mu``
  times the normal impulse ``m (1 + e) |v_n|``, so
  ``v_t' = max(v_t - mu (1 + e) |v_n|, 0)`` (sticking stops it at 0).
  A uniform ball that may roll instead reaches rolling (contact point at
  rest) when the friction has taken ``2/7`` of ``v_t``, after which
  ``v_t' = 5/7 v_t``: :func:`lateral_velocity_coulomb_ball` gives that case.

References: the restitution law and its Zeno sequence, e.g. B. Mirtich,
*Impulse-based Dynamic Simulation of Rigid Body Systems*, PhD thesis, UC
Berkeley 1996, ch. 3; the impact with Coulomb friction, W. J. Stronge,
*Impact Mechanics*, Cambridge 2000, ch. 2-3 (the 2/7 for a ball, ch. 5).
Seed sections: S5 (restitution, lateral friction), S7 (wall response).

Cost: O(1) per quantity, O(k) for k bounces.
"""

from __future__ import annotations

import math

import numpy as np


def impact_speed(h0: float, g: float) -> float:
    """``v0 = sqrt(2 g h0)``: speed at the first impact after a drop from rest."""
    return math.sqrt(2.0 * g * h0)


def fall_time(h0: float, g: float) -> float:
    """``t0 = sqrt(2 h0 / g)``: time from release to the first impact."""
    return math.sqrt(2.0 * h0 / g)


def apex_heights(h0: float, e: float, k: int) -> np.ndarray:
    """(k + 1,) apex heights ``h_j = e^(2j) h0`` for j = 0..k (h_0 is the drop height)."""
    return h0 * e ** (2.0 * np.arange(k + 1))


def apex_ratio(e: float) -> float:
    """Ratio of successive apex heights, ``e^2``."""
    return e * e


def bounce_times(h0: float, g: float, e: float, k: int) -> np.ndarray:
    """(k,) times of bounces 1..k: ``t_j = t0 (1 + 2 sum_{i=1}^{j-1} e^i)``."""
    t0 = fall_time(h0, g)
    j = np.arange(1, k + 1)
    if e == 1.0:
        return t0 * (2.0 * j - 1.0)
    return t0 * (1.0 + 2.0 * e * (1.0 - e ** (j - 1.0)) / (1.0 - e))


def apex_times(h0: float, g: float, e: float, k: int) -> np.ndarray:
    """(k,) times of apexes 1..k: bounce j plus ``e^j v0 / g``."""
    t0 = fall_time(h0, g)
    j = np.arange(1, k + 1)
    return bounce_times(h0, g, e, k) + t0 * e ** j


def time_to_rest(h0: float, g: float, e: float) -> float:
    """Zeno time of the bounce sequence: ``t0 (1 + 2 e / (1 - e))`` (inf for e = 1)."""
    if e >= 1.0:
        return math.inf
    return fall_time(h0, g) * (1.0 + 2.0 * e / (1.0 - e))


def bounces_until(e: float, fraction: float) -> int:
    """The first bounce k after which the apex ``e^(2k) h0`` is below
    ``fraction h0`` (0 < fraction < 1, 0 < e < 1)."""
    return max(1, math.ceil(math.log(fraction) / (2.0 * math.log(e)) - 1e-12))


def time_to_settle(h0: float, g: float, e: float, fraction: float) -> float:
    """Time of the bounce after which the apex stays below ``fraction h0``
    (the measurable version of :func:`time_to_rest`, which it approaches as
    ``fraction -> 0``)."""
    return float(bounce_times(h0, g, e, bounces_until(e, fraction))[-1])


def height(t, h0: float, g: float, e: float, max_bounces: int = 200) -> np.ndarray:
    """Height above the touching height at times ``t`` (array), piecewise
    parabolic; 0 after the Zeno time (or after ``max_bounces`` bounces)."""
    t = np.asarray(t, dtype=np.float64)
    t0 = fall_time(h0, g)
    v0 = impact_speed(h0, g)
    y = np.where(t < t0, h0 - 0.5 * g * t * t, 0.0)
    starts = bounce_times(h0, g, e, max_bounces)
    for j, start in enumerate(starts, start=1):
        u = e ** j * v0                              # rebound speed after bounce j
        s = t - start
        inside = (s >= 0.0) & (s < 2.0 * u / g)
        y = np.where(inside, u * s - 0.5 * g * s * s, y)
    return y


def energy(t, h0: float, g: float, e: float, mass: float = 1.0) -> np.ndarray:
    """Mechanical energy (potential above the touching height plus kinetic)
    at times ``t``: ``m g h0 e^(2k)`` after bounce k."""
    t = np.asarray(t, dtype=np.float64)
    count = np.zeros(t.shape)
    for start in bounce_times(h0, g, e, 200):
        count += t >= start
    return mass * g * h0 * e ** (2.0 * count)


def lateral_velocity_seed(v_t: float, friction: float) -> float:
    """The seed's friction: ``v_t' = kFriction v_t``, ``kFriction = 1 - friction``."""
    return (1.0 - friction) * v_t


def lateral_velocity_coulomb(v_t: float, v_n: float, mu: float, e: float) -> float:
    """Coulomb friction on a point mass (sliding case):
    ``v_t' = max(|v_t| - mu (1 + e) |v_n|, 0)`` in the direction of ``v_t``."""
    speed = max(abs(v_t) - mu * (1.0 + e) * abs(v_n), 0.0)
    return math.copysign(speed, v_t)


def lateral_velocity_coulomb_ball(v_t: float, v_n: float, mu: float, e: float) -> float:
    """Coulomb friction on a uniform ball without initial spin: it slides
    (point-mass answer) unless the friction impulse would exceed what brings
    the contact point to rest, in which case it leaves rolling at ``5/7 v_t``."""
    sliding = lateral_velocity_coulomb(v_t, v_n, mu, e)
    rolling = 5.0 / 7.0 * v_t
    return sliding if abs(sliding) >= abs(rolling) else rolling


def sliding_throughout(v_t: float, v_n: float, mu: float, e: float) -> bool:
    """Whether a uniform ball keeps sliding through the whole impact:
    ``mu (1 + e) |v_n| <= 2/7 |v_t|`` (so the point-mass answer holds for it)."""
    return mu * (1.0 + e) * abs(v_n) <= 2.0 / 7.0 * abs(v_t)


def oblique_impact_ball(v_t: float, w: float, v_n: float, mu: float, e: float,
                        radius: float, mass: float, inertia: float) -> tuple[float, float]:
    """A ball (mass ``m``, moment of inertia ``I`` about its centre, contact
    at distance ``radius`` straight below its centre) striking a fixed plane
    with normal speed ``v_n`` (> 0, into the plane), lateral velocity ``v_t``
    and spin ``w`` about the horizontal axis across ``v_t`` (positive when the
    contact point moves with ``v_t``: its slip is ``u = v_t + w radius``),
    Coulomb friction ``mu`` over the whole impact and restitution ``e``.

    The normal impulse ``J_n = m (1 + e) v_n`` passes through the centre and
    does not change the slip, so the slip keeps its direction until friction
    stops it and then stays zero (no reversal of slip for a ball: Stronge,
    *Impact Mechanics*, 2000, section 5.1; Brach, *Mechanical Impact
    Dynamics*, 1991, ch. 5). The friction impulse that stops the slip is
    ``J_stick = |u| / (1/m + radius^2 / I)``; Coulomb allows ``mu J_n``:

    - ``mu J_n >= J_stick``: the ball leaves rolling, ``J_t = J_stick``;
    - else it slides throughout, ``J_t = mu J_n``;

    and with ``J = -sign(u) J_t`` along ``v_t``: ``v_t' = v_t + J / m``,
    ``w' = w + radius J / I``. Returns ``(v_t', w')``.
    """
    u = v_t + w * radius
    j_n = mass * (1.0 + e) * v_n
    j_stick = abs(u) / (1.0 / mass + radius * radius / inertia)
    j_t = min(j_stick, mu * j_n)
    j = -math.copysign(j_t, u) if u != 0.0 else 0.0
    return v_t + j / mass, w + radius * j / inertia
