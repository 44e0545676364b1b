"""The particle system's Euler step fused into one compiled loop (S10), for
the optional extra ``fast``.

numpy's Euler step makes about fifteen passes over the state arrays (copy v,
the drag product, gravity, two scaled adds, six wall comparisons and their
masked updates); at a million particles each pass streams 24 MB, so the step
runs at a quarter of the machine's streaming rate. This loop reads each
particle's position and velocity once and writes them once.

Same arithmetic, operation for operation, as
:meth:`refsim.particles.system.ParticleSystem.step` with the Euler tableau
(b = 1, so ``h * b`` is ``h`` exactly) and
:func:`refsim.dynamics.walls.wall_response_points_inplace`: the drag product
``v * (-k/m)`` (quadratic: ``v * (|v| * (-k/m))`` with ``|v|`` summed
``(vx vx + vy vy) + vz vz``), gravity subtracted from the y component,
``x + v h`` and ``v + a h``, then for axis 0, 1, 2 the low wall and then
the high wall. Particles do not interact, so taking them one at a time gives
the same bits as taking each operation over all of them
(tests/particles/test_fused_step.py checks it). No fast-math: each operation
is rounded once.

This module imports numba at import time; import it only when the compiled
step is chosen.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def euler_step_fused(x, v, h, gravity, rate, quadratic, walls, half_size, restitution,
                     k_friction, at_wall):
    """Mirrors :meth:`refsim.particles.system.ParticleSystem.step` with the
    Euler tableau: :func:`refsim.dynamics.forces.acceleration_into`, the
    solver's update and :func:`refsim.dynamics.walls.wall_response_points_inplace`
    (``at_wall``: the wall speed "wall", else the seed's literal one).

    One Euler step of all particles, in place; returns the wall hits."""
    n = x.shape[0]
    bounces = 0
    for i in range(n):
        vx, vy, vz = v[i, 0], v[i, 1], v[i, 2]
        if quadratic:
            s = np.sqrt((vx * vx + vy * vy) + vz * vz) * (-rate)
            ax, ay, az = vx * s, vy * s, vz * s
        else:
            ax, ay, az = vx * (-rate), vy * (-rate), vz * (-rate)
        ay = ay - gravity
        px, py, pz = x[i, 0] + vx * h, x[i, 1] + vy * h, x[i, 2] + vz * h
        ux, uy, uz = vx + ax * h, vy + ay * h, vz + az * h
        if walls and not (-half_size <= px <= half_size and -half_size <= py <= half_size
                          and -half_size <= pz <= half_size):
            # rare: the particle is beyond a wall (or not finite); the walls in
            # the order of wall_response_inplace
            p = np.array([px, py, pz])
            u = np.array([ux, uy, uz])
            bounces += _walls(p, u, half_size, restitution, k_friction, gravity, at_wall)
            px, py, pz = p[0], p[1], p[2]
            ux, uy, uz = u[0], u[1], u[2]
        x[i, 0], x[i, 1], x[i, 2] = px, py, pz
        v[i, 0], v[i, 1], v[i, 2] = ux, uy, uz
    return bounces


@numba.njit(cache=True)
def _walls(p, u, half_size, restitution, k_friction, gravity, at_wall):
    """Axis 0, 1, 2; the low wall, then the high one (strict comparisons);
    the speed at the wall as :func:`refsim.dynamics.walls.wall_speed` writes it."""
    bounces = 0
    for axis in range(3):
        a_k = -gravity if axis == 1 else 0.0
        for side in range(2):
            wall = -half_size if side == 0 else half_size
            beyond = p[axis] < wall if side == 0 else p[axis] > wall
            if beyond:
                if at_wall:
                    squared = u[axis] * u[axis] + 2.0 * a_k * (wall - p[axis])
                    u[axis] = np.copysign(np.sqrt(max(squared, 0.0)), u[axis])
                p[axis] = wall
                u[axis] = u[axis] * -restitution
                for lateral in range(3):
                    if lateral != axis:
                        u[lateral] = u[lateral] * k_friction
                bounces += 1
    return bounces
