"""Wall response of point masses in the world cube (S7 applied to S10).

What: after each solver step, for each axis separately, a particle beyond a
wall is pushed back onto it along that axis only; that velocity component is
flipped and scaled by the restitution ``e``, and the two lateral components
are scaled by ``kFriction = 1 - friction``. The seed's words: "If the box
extends beyond the world cube in a particular dimension, we push it back to
the wall only along that axis and flip the velocity; restitution and
frictional forces are applied here as a dampening on the normal and lateral
components of the flipped velocity respectively." For a point the "box" is
the point itself.

The seed flips the velocity whenever the particle is beyond the wall, without
asking whether it still moves outward; so does this code. A particle on the
wall (``x == -half_size``) is inside.

Seed section: S7 (and S5, "Restitution", "Lateral Friction").

Reference: the reflection ``v' = v_t - e v_n`` is the Newton restitution law,
e.g. B. Mirtich, *Impulse-based Dynamic Simulation of Rigid Body Systems*,
PhD thesis, UC Berkeley 1996, chapter 3 (for the frictionless normal
part); the tangential scaling is the seed's simplification.

Cost: O(N) comparisons per axis and wall (the in-place kernel first checks
the whole array's min and max and stops there when nothing is beyond); the plain kernel adds O(hits)
updates, the in-place one O(N) masked updates for each wall that was hit
(no allocation).

:func:`wall_response` is the plain kernel (returns new arrays);
:func:`wall_response_inplace` is the particle system's fast path, doing the
same arithmetic in place with preallocated masks.
"""

from __future__ import annotations

import numpy as np

_LATERAL = ((1, 2), (0, 2), (0, 1))        # the two other axes of each axis


def wall_response(x: np.ndarray, v: np.ndarray, half_size: float, restitution: float,
                  friction: float) -> tuple[np.ndarray, np.ndarray, int]:
    """Positions and velocities (N, 3) after the wall response, and the number
    of (particle, wall) bounces handled."""
    x = x.copy()
    v = v.copy()
    bounces = 0
    for axis in range(3):
        for wall in (-half_size, half_size):
            beyond = x[:, axis] < wall if wall < 0 else x[:, axis] > wall
            for i in np.flatnonzero(beyond):
                x[i, axis] = wall                           # push back along this axis only
                v[i, axis] = -restitution * v[i, axis]      # flip, damp the normal part
                for lateral in _LATERAL[axis]:
                    v[i, lateral] = (1.0 - friction) * v[i, lateral]   # kFriction
                bounces += 1
    return x, v, bounces


def wall_response_inplace(x: np.ndarray, v: np.ndarray, half_size: float, restitution: float,
                          friction: float, beyond: np.ndarray) -> int:
    """:func:`wall_response` on ``x`` and ``v`` in place; ``beyond`` is a (N,)
    bool scratch array. Returns the number of bounces."""
    # Two contiguous reductions decide "no particle beyond any wall" (the
    # usual case) at a third of the cost of the six strided column tests.
    if x.min() >= -half_size and x.max() <= half_size:
        return 0
    bounces = 0
    k_friction = 1.0 - friction
    for axis in range(3):
        for wall in (-half_size, half_size):
            if wall < 0:
                np.less(x[:, axis], wall, out=beyond)
            else:
                np.greater(x[:, axis], wall, out=beyond)
            if not beyond.any():
                continue
            # Masked in-place ufuncs: no index arrays, no O(hits) temporaries.
            np.copyto(x[:, axis], wall, where=beyond)
            np.multiply(v[:, axis], -restitution, out=v[:, axis], where=beyond)
            for lateral in _LATERAL[axis]:
                np.multiply(v[:, lateral], k_friction, out=v[:, lateral], where=beyond)
            bounces += int(np.count_nonzero(beyond))
    return bounces
