"""Translational response of a body to the walls of the world cube (seed S7).

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

The particle system does the same to points
(:func:`refsim.particles.walls.wall_response`). AMBIGUITY (A8): as there, the
velocity is flipped whenever the box is beyond the wall, without asking
whether it still moves outward (the seed's words: "push it back ... and flip
the velocity").

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

Seed section: S7 (with S5's restitution and lateral friction).

Reference: Newton's restitution law ``v_n' = -e v_n`` as in B. Mirtich,
*Impulse-based Dynamic Simulation of Rigid Body Systems*, PhD thesis, UC
Berkeley 1996, chapter 3; the lateral scaling is the seed's simplification.

Cost: O(1) per crossed wall.
"""

from __future__ import annotations

import numpy as np

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
    if speed not in SPEEDS:
        raise ValueError(f"speed must be one of {SPEEDS}, got {speed!r}")
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
