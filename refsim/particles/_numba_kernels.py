"""The particle system's step fused into one compiled loop (S10): every
solver, many steps per call, one pass over memory per call.

Why: numpy's step makes one pass over the state-sized arrays per operation
(RK4: about seventy, counting stage states, products, sums, the forces and
the six wall tests), so at a million particles it runs at a few percent of
the machine's streaming rate. Here each particle's stages live in registers:
the state is read once and written once per call, however many stages and
steps the call takes.

Same arithmetic, operation for operation, as
:meth:`refsim.particles.system.ParticleSystem.step` with the readable kernel,
that is :func:`refsim.solvers.explicit_rk.rk_step_into` over
:func:`refsim.dynamics.forces.acceleration_into`, then
:func:`refsim.dynamics.walls.wall_response_points_inplace`:

- the stage state's velocity is ``(h a_i,i-1) k_i-1 + v`` (rk_step_into's
  first term, ``K * (h a) + Y``). The stage state's position is never read
  (the forces depend on velocity only), so it is not formed;
- the stage derivative is ``(u, a(u))``: linear drag ``u * (-k/m)``,
  quadratic ``u * (|u| (-k/m))`` with ``|u|^2 = (ux ux + uy uy) + uz uz``;
  then gravity subtracted from the y component;
- the update adds ``k_i (h b_i)`` to the state in stage order, skipping zero
  weights, first to the position (with ``k_i``'s velocity part, the stage
  velocity), then to the velocity;
- then the walls: axis 0, 1, 2, the low wall and then the high wall, strict
  comparisons, the speed at the wall as :func:`refsim.dynamics.walls.wall_speed`
  writes it.

Particles do not interact, so taking them one at a time (and a block of them
through several steps before the next block) gives the same bits as taking
each operation over all of them; tests/particles/test_fused_step.py checks it
for every solver. No fast-math: each operation is rounded once, and LLVM does
not contract a multiply and an add into an FMA without it.

The kernels walk the (N, 3) arrays flat, 3 N numbers, so that the compiler
vectorizes them; gravity is subtracted from every component as the pattern
``(0, g, 0)``, and ``a - 0.0`` is ``a`` to the bit for every float
(``-0.0 - 0.0 = -0.0``). Quadratic drag couples a particle's three
components through ``|u|``, so its loop takes a particle at a time (the
compiler vectorizes that loop too, square root included).

The tableaux: every stage evaluated at ``y + h a_i,i-1 k_i-1`` (only the
subdiagonal of ``A`` nonzero), with 1, 2 or 4 stages: the seed's five
solvers and its literal RK4 reading.
:func:`refsim.particles.system.fused_tableau` says whether a tableau is of
that shape and gives its coefficients. docs/decisions/particles-fused-step.md
records the layouts tried and the measurements.

This module imports numba at import time; import it only when the compiled
step is chosen.
"""

from __future__ import annotations

import numba
import numpy as np

#: Particles per block. A block is taken through all the steps of a call
#: before the next block; its state (48 bytes a particle) stays in the
#: first-level cache meanwhile.
BLOCK = 512


@numba.njit(cache=True)
def rk_steps_fused(x, v, steps, stages, hA, hb, b_used, gravity, rate, quadratic, walls,
                   half_size, restitution, k_friction, at_wall):
    """Mirrors :meth:`refsim.particles.system.ParticleSystem.step` with the
    readable kernel (``rk_step_into`` over ``acceleration_into``, then
    ``wall_response_points_inplace``), ``steps`` times, in place.

    Parameters
    ----------
    x, v : numpy.ndarray
        (N, 3) float64, C-contiguous: positions and velocities.
    steps : int
    stages : int
        ``s``, 1, 2 or 4.
    hA : numpy.ndarray
        (s,) ``h * A[i, i-1]`` (entry 0 unused), each product rounded once
        as the readable step rounds it.
    hb, b_used : numpy.ndarray
        (s,) ``h * b[i]`` and ``b[i] != 0``.
    gravity, rate : float
        ``g`` and the drag rate ``k / m``.
    quadratic, walls, at_wall : bool
        Quadratic drag; the wall response on; the speed at the wall
        (``wall_speed="wall"``) rather than the seed's literal one.
    half_size, restitution, k_friction : float
        The cube, ``e`` and ``1 - friction``.

    Returns
    -------
    (bounces, non_finite) : (int, int)
        The (particle, wall) bounces, and the number of components of the
        final state that are not finite (what ``ParticleSystem.run``
        checks, counted here without another pass over memory).
    """
    n = x.shape[0]
    flat_x = x.reshape(3 * n)
    flat_v = v.reshape(3 * n)
    # gravity as the pattern (0, g, 0) over a block's flat components
    g = np.zeros(3 * BLOCK)
    for k in range(1, 3 * BLOCK, 3):
        g[k] = gravity
    bounces = 0
    non_finite = 0
    for start in range(0, n, BLOCK):
        stop = min(start + BLOCK, n)
        # the block's components, flat; slices starting at 0 let the
        # compiler vectorize the loops over them
        xb = flat_x[3 * start:3 * stop]
        vb = flat_v[3 * start:3 * stop]
        for _ in range(steps):
            # the stage count as a constant in each call, for the compiler
            if quadratic and stages == 1:
                _quadratic_block(xb, vb, 1, hA, hb, b_used, gravity, rate)
            elif quadratic and stages == 2:
                _quadratic_block(xb, vb, 2, hA, hb, b_used, gravity, rate)
            elif quadratic:
                _quadratic_block(xb, vb, 4, hA, hb, b_used, gravity, rate)
            elif stages == 1:
                _linear_block(xb, vb, g, 1, hA, hb, b_used, rate)
            elif stages == 2:
                _linear_block(xb, vb, g, 2, hA, hb, b_used, rate)
            else:
                _linear_block(xb, vb, g, 4, hA, hb, b_used, rate)
            if walls and _beyond(xb, half_size):
                bounces += _walls_block(x, v, start, stop, half_size, restitution, k_friction,
                                        gravity, at_wall)
        # the block's final state, checked while it is in cache: c - c is
        # 0.0 for a finite c and NaN for an infinite or NaN one
        for k in range(xb.shape[0]):
            non_finite += (xb[k] - xb[k] != 0.0) | (vb[k] - vb[k] != 0.0)
    return bounces, non_finite


@numba.njit(cache=True, inline="always")
def _linear_block(xb, vb, g, stages, hA, hb, b_used, rate):
    """Linear drag: one step of a block's flat components ``xb``, ``vb``
    (positions, velocities); ``g`` the gravity pattern ``(0, g, 0, 0, g, 0, ...)``.

    ``stages`` is a constant where this is inlined (1, 2 or 4), so the
    compiler unrolls the stage loop and vectorizes the loop over components.
    """
    for k in range(xb.shape[0]):
        vk, gk = vb[k], g[k]
        xk, wk = xb[k], vk
        u = vk                                # the stage velocity: v at stage 1
        kv = 0.0                              # the stage acceleration
        for j in range(stages):
            if j > 0:
                u = kv * hA[j] + vk
            kv = u * -rate - gk
            if b_used[j]:
                xk = xk + u * hb[j]
                wk = wk + kv * hb[j]
        xb[k] = xk
        vb[k] = wk


@numba.njit(cache=True, inline="always")
def _quadratic_block(xb, vb, stages, hA, hb, b_used, gravity, rate):
    """Quadratic drag: one step of a block's flat components ``xb``, ``vb``,
    a particle (three components, coupled through ``|u|``) at a time;
    ``stages`` a constant as in :func:`_linear_block`."""
    for i in range(xb.shape[0] // 3):
        # (a loop over i, not over p in steps of 3: the compiler vectorizes
        # only the former)
        p = 3 * i
        vx, vy, vz = vb[p], vb[p + 1], vb[p + 2]
        px, py, pz = xb[p], xb[p + 1], xb[p + 2]
        wx, wy, wz = vx, vy, vz
        ux, uy, uz = vx, vy, vz
        kx = ky = kz = 0.0
        for j in range(stages):
            if j > 0:
                a = hA[j]
                ux, uy, uz = kx * a + vx, ky * a + vy, kz * a + vz
            s = np.sqrt((ux * ux + uy * uy) + uz * uz) * -rate
            kx, ky, kz = ux * s, uy * s - gravity, uz * s
            if b_used[j]:
                b = hb[j]
                px, py, pz = px + ux * b, py + uy * b, pz + uz * b
                wx, wy, wz = wx + kx * b, wy + ky * b, wz + kz * b
        xb[p], xb[p + 1], xb[p + 2] = px, py, pz
        vb[p], vb[p + 1], vb[p + 2] = wx, wy, wz


@numba.njit(cache=True, inline="always")
def _beyond(xb, half_size):
    """Whether a block's flat positions ``xb`` have a component beyond the
    cube: a count in one vectorized pass over the block in cache, so that the
    usual answer, none, is cheap (a NaN is beyond nothing, as in the readable
    wall response)."""
    count = 0
    for k in range(xb.shape[0]):
        count += (xb[k] < -half_size) | (xb[k] > half_size)
    return count > 0


@numba.njit(cache=True)
def _walls_block(x, v, start, stop, half_size, restitution, k_friction, gravity, at_wall):
    """The wall response of particles ``start:stop``, one by one: axis 0, 1,
    2, the low wall, then the high one, as
    :func:`refsim.dynamics.walls.wall_response_points_inplace` takes them
    over all particles. Returns the bounces."""
    bounces = 0
    for i in range(start, stop):
        for axis in range(3):
            a_k = -gravity if axis == 1 else 0.0
            for side in range(2):
                wall = -half_size if side == 0 else half_size
                hit = x[i, axis] < wall if side == 0 else x[i, axis] > wall
                if hit:
                    if at_wall:
                        squared = v[i, axis] * v[i, axis] + 2.0 * a_k * (wall - x[i, axis])
                        v[i, axis] = np.copysign(np.sqrt(max(squared, 0.0)), v[i, axis])
                    x[i, axis] = wall
                    v[i, axis] = v[i, axis] * -restitution
                    for lateral in range(3):
                        if lateral != axis:
                            v[i, lateral] = v[i, lateral] * k_friction
                    bounces += 1
    return bounces


@numba.njit(cache=True)
def advance_time(t, h, steps):
    """Mirrors the readable step's ``self.t += h`` (ParticleSystem.step),
    ``steps`` times: the same sum, rounded after each step."""
    for _ in range(steps):
        t = t + h
    return t
