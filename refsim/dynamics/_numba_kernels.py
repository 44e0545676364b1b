"""The compiled simulation loop: many steps of :meth:`Simulation.step
<refsim.dynamics.simulation.Simulation.step>` in one numba call.

Why: the readable step is a few dozen numpy calls, whose interpreter cost
does not depend on the number of bodies, while a step of a few cubes is a
few hundred floating-point operations (docs/decisions/compiled-loop.md
measures both). Compiling each stage separately leaves
the calls between them; this kernel runs the whole loop, K steps per call,
for the common choices, and hands the rest back to the readable step.

What it runs (one step, the stages of the readable outline, same order):

1. integrate    the scene's explicit Runge-Kutta tableau (any of the five
                solvers) on ``y = (x, v)`` with gravity and linear or
                quadratic drag: :func:`refsim.solvers.explicit_rk.rk_step`
                with :func:`refsim.dynamics.forces.translational_rhs`;
2. rotation     none (``rotation = "off"``), the seed's Euler step of the
                axes with Gram-Schmidt
                (:func:`refsim.dynamics.rotation_seed.axes_step_seed`,
                compiled from its own source),
                or the corrected free-body splitting step
                (:func:`refsim.dynamics.rotation_impulse.free_rotation_step`,
                compiled from its own source);
3. check        the energy bound, conservatively (below);
4. bounds       the linear scan of a body's vertices
                (:func:`refsim.dynamics.boxes.boxes_loops`), or the
                incremental walk for the bodies the readable step gives a
                tracker (:meth:`Simulation._bounds`): the same boxes, bit
                for bit, either way (``Simulation``'s ``boxes`` option);
5. walls        :func:`refsim.bounds.world_cube.world_cube_test`'s correction,
                then the seed's response,
                :func:`refsim.dynamics.walls.wall_response_seed`, after S9's
                spin change :meth:`Simulation._wall_spin_seed` (contact vertex
                :func:`~refsim.dynamics.rotation_seed.contact_vertex_seed`,
                :func:`~refsim.dynamics.rotation_seed.contact_spin_seed`)
                with the seed's rotation; or the corrected impulses,
                :meth:`Simulation._wall_impulse` (the vertices past the wall,
                found without testing the groups of vertices that cannot
                be past it,
                :func:`refsim.dynamics._numba_walls.vertices_past_wall`;
                push-back, speed at the wall, and the contact solve
                :func:`refsim.dynamics.impulse.solve_contacts_python`
                compiled from its own source, the wall static);
6. broad-phase  every pair of boxes, in the sorted order of
                :func:`refsim.collision.broad_phase.overlapping_pairs_sweep`;
8. response     at level "aabb", the seed's exchange,
                :func:`refsim.dynamics.body_response.exchange_velocities_seed`;
                any other level or body response: stages 7 and 8 in Python
                between two calls (``STOP_BODY_STAGE`` below).

Each is written in the readable function's operations and order (each
product and sum rounded once, no fused multiply-add: numba compiles without
fast-math), so the loop and the readable step agree bit for bit;
tests/dynamics/test_compiled_loop.py checks whole trajectories.

Hand-back. The kernel returns to Python before a step is whole when

- ``STOP_BODY_STAGE``: a pair of boxes overlaps and the scene's level or
  body response is not the seed's exchange at level "aabb"
  (``BODY_HAND_BACK``). Stages 1-6 of the step are done and kept; the
  step's pairs are in ``pairs``, and, with the corrected wall response,
  the wall contacts its island solve needs in ``wall_r`` and ``wall_at``
  and the wall impulse records in ``impulse_now``. The step's contacts and
  events are not noted yet and it is not counted:
  :meth:`refsim.dynamics.compiled_loop.CompiledLoop.body_stage` runs the
  narrow phase and body response of :mod:`refsim.dynamics.body_stage` (the
  readable step's own, with their compiled kernels), then
  :func:`finish_body_step` notes and counts the step, and the loop is
  called again. The exact query, the contact points and the island solve
  stay out of this kernel: compiled into it, they made its first compile
  take several times as long (docs/decisions/body-contact-speed.md);
- ``STOP_READABLE``: the energy bound is above half the divergence limit,
  or not finite. The state is restored to the start of that step, and the
  caller takes it with the readable step, which decides (and raises
  DivergenceError where it must);
- ``STOP_EVENTS``: the event buffer cannot hold another step's events
  (the state is that of the last whole step).

The energy check is conservative: the readable check sums with ``einsum``,
whose order differs, so the kernel hands back at half the limit instead of
deciding at the limit; a state that far beyond its scale is a divergence in
all but name, and the readable step then decides exactly.

Events: the kernel keeps the previous step's contacts as flags, ``walls``
(B, 6) (axis k, low wall at 2k, high wall at 2k + 1) and ``bodies`` (B, B)
(pair i < j at [i, j]), and writes one row ``(step, kind, i, j)`` per
contact that began (``step`` the simulation's step count before it; kind 0:
wall 2k or 2k + 1; kind 1: body j), after the rows still pending; the
caller sorts a step's rows by names as :meth:`Simulation._note_events` does.

Arguments: :func:`advance`, the entry from Python, takes three flat arrays
and views them as the forty-odd arrays of :func:`_steps`, the loop itself
(:mod:`refsim.dynamics.loop_layout` says why and how), and counts the steps
and event rows of the call in them before it returns.

Seed sections: S2, S3, S5-S9 (as the readable stages), and their
correction (the corrected rotation model and wall impulses).

Cost per step: O(s B) for s solver stages, O(sum of vertices) for the boxes
(and per wall contact of the corrected model, for the vertices past the
wall: O(leaves + the vertices of the leaves near the wall), plus the
contact solve),
O(B^2) box tests for the broad phase (all pairs, compiled; cheaper than the
sort below a few hundred bodies).

This module imports numba at import time; import it only when the compiled
kernels are chosen.
"""

from __future__ import annotations

import numba
import numpy as np
from numba.core import types
from numba.extending import intrinsic

from refsim.bounds._numba_kernels import incremental_update_numba
from refsim.dynamics import loop_layout as slot
from refsim.dynamics._numba_walls import (
    wall_impulse_response,
    wall_speed,
    wall_spin_seed,
    world_inertia,
)
from refsim.dynamics.loop_layout import (
    BODY_EXCHANGE,
    BODY_HAND_BACK,
    BODY_NONE,
    ROTATION_EXACT,
    ROTATION_SEED,
)
from refsim.dynamics.rotation_impulse import free_rotation_step
from refsim.dynamics.rotation_seed import axes_step_seed

#: :func:`refsim.kernels.sources_digest` of the refsim modules this one imports:
#: an edit there must change this line, so that numba renews its cache of
#: this module (tests/test_kernels.py checks it).
SOURCES_DIGEST = "4638f68ea5dcd39a"

#: The kernel took every step it was asked for.
DONE = 0
#: The next step needs the readable step (state restored to its start).
STOP_READABLE = 1
#: The event buffer is nearly full; call again after reading it.
STOP_EVENTS = 2
#: A step's boxes overlap and the scene's body stage is not the loop's:
#: stages 1-6 of the step are done, its pairs are in ``PAIRS``, and Python
#: runs the body stage and ends the step (:func:`finish_body_step`).
STOP_BODY_STAGE = 3



@numba.njit(cache=True, nogil=True)
def advance(n_steps, floats, ints, flags):
    """Mirrors :meth:`refsim.dynamics.simulation.Simulation.step`, up to
    ``n_steps`` times: the compiled loop's entry from Python, which runs
    :func:`_steps` on the arrays packed in ``floats``, ``ints`` and
    ``flags`` (:mod:`refsim.dynamics.loop_layout`: each a view, no copy),
    in place. Before returning it counts what it did in ``COUNTERS``: the
    steps (``C_STEPS``, ``C_LOOP_STEPS``), the event rows written
    (``C_PENDING``; a call appends to rows still pending), and the steps
    it did not take and why (``C_LEFT``, ``C_STOP``). Returns 0 when it took
    every step and there is no event row to read, else 1 (read the
    counters)."""
    counters = _view1(ints, ints, slot.COUNTERS)
    settings = _view1(ints, ints, slot.SETTINGS)
    scalars = _view1(floats, ints, slot.SCALARS)
    done, n_events, stop, n_pairs = _steps(
        n_steps, counters[slot.C_STEPS], counters[slot.C_PENDING],
        scalars[slot.S_H], _view2(floats, ints, slot.HA), _view1(floats, ints, slot.HB),
        scalars[slot.S_GRAVITY], _view1(floats, ints, slot.DRAG_RATE),
        settings[slot.G_QUADRATIC], settings[slot.G_ROTATION_MODE], scalars[slot.S_RESTITUTION],
        scalars[slot.S_FRICTION], settings[slot.G_WALL_SPEED_AT_WALL],
        settings[slot.G_WALL_IMPULSE], scalars[slot.S_THRESHOLD], settings[slot.G_ITERATIONS],
        scalars[slot.S_HALF_SIZE], _view2(floats, ints, slot.VERTICES_T),
        _view1(ints, ints, slot.FIRST_VERTEX), settings[slot.G_CENTRED],
        _view2(floats, ints, slot.CENTER), _view1(floats, ints, slot.LAM),
        _view1(floats, ints, slot.MASS), _view1(floats, ints, slot.INV_MASS),
        _view3(floats, ints, slot.Q), _view2(floats, ints, slot.MOMENTS),
        _view3(floats, ints, slot.I_BODY_INV), scalars[slot.S_ENERGY_LIMIT],
        _view1(ints, ints, slot.LEAF_ORDER), _view1(ints, ints, slot.LEAF_START),
        _view2(floats, ints, slot.LEAF_SPHERES), _view1(ints, ints, slot.FIRST_LEAF),
        settings[slot.G_BODY_MODE],
        # the state and what is read and written
        _view2(floats, ints, slot.X), _view2(floats, ints, slot.V), _view2(floats, ints, slot.W),
        _view3(floats, ints, slot.R), _view2(floats, ints, slot.LO), _view2(floats, ints, slot.HI),
        _view2(flags, ints, slot.WALLS), _view2(flags, ints, slot.BODIES),
        _view2(ints, ints, slot.EVENTS), _view1(ints, ints, slot.TRACKED),
        _view2(ints, ints, slot.TRACKER_ROWS), _view1(floats, ints, slot.TRACKERS_F),
        _view1(ints, ints, slot.TRACKERS_I), _view3(floats, ints, slot.IMPULSE_NOW),
        _view2(floats, ints, slot.EVENT_DATA),
        # scratch
        _view1(floats, ints, slot.Y), _view1(floats, ints, slot.Y_I), _view2(floats, ints, slot.K),
        _view2(floats, ints, slot.X0), _view2(floats, ints, slot.V0), _view2(floats, ints, slot.W0),
        _view3(floats, ints, slot.R0), _view2(floats, ints, slot.A), _view2(floats, ints, slot.E),
        _view1(floats, ints, slot.L), _view1(floats, ints, slot.CORR),
        _view1(ints, ints, slot.PAST), _view2(floats, ints, slot.R_A),
        _view2(floats, ints, slot.P), _view1(floats, ints, slot.N),
        _view2(floats, ints, slot.ORIGIN), _view2(flags, ints, slot.NOW_WALLS),
        _view2(ints, ints, slot.PAIRS), _view2(floats, ints, slot.WALL_R),
        _view3(ints, ints, slot.WALL_AT))
    counters[slot.C_STEPS] += done
    counters[slot.C_LOOP_STEPS] += done
    counters[slot.C_PENDING] = n_events
    counters[slot.C_LEFT] = n_steps - done
    counters[slot.C_STOP] = stop
    counters[slot.C_PAIRS] = n_pairs
    return 0 if done == n_steps and n_events == 0 else 1


# Views of the packed arrays (refsim.dynamics.loop_layout: the header of
# ``ints`` holds each array's offset and shape), made by ``numba.carray``
# from the address of their first element: C-contiguous arrays with the
# shapes and dtypes of separate ones, so the loop compiles to the same
# arithmetic. Not slices and ``reshape``: a reshape checks its strides
# through a C helper, and a slice holds a reference to the flat array,
# which every function it is passed to takes and drops again (an atomic
# operation each time), some tens of nanoseconds per array and call, more
# than a step of one cube for the sixty arrays of a call. These views hold
# none (the flat arrays, the call's arguments, outlive them).

@intrinsic
def _address(typingctx, flat, at):
    """The address of ``flat[at]`` (a C pointer to its dtype), unchecked."""
    def codegen(context, builder, signature, args):
        array = context.make_array(signature.args[0])(context, builder, args[0])
        return builder.gep(array.data, [args[1]])
    return types.CPointer(flat.dtype)(flat, at), codegen


@numba.njit(cache=True, nogil=True)
def _view1(flat, ints, k):
    return numba.carray(_address(flat, ints[4 * k]), ints[4 * k + 1])


@numba.njit(cache=True, nogil=True)
def _view2(flat, ints, k):
    return numba.carray(_address(flat, ints[4 * k]), (ints[4 * k + 1], ints[4 * k + 2]))


@numba.njit(cache=True, nogil=True)
def _view3(flat, ints, k):
    return numba.carray(_address(flat, ints[4 * k]),
                        (ints[4 * k + 1], ints[4 * k + 2], ints[4 * k + 3]))


@numba.njit(cache=True, nogil=True)
def _steps(n_steps, first_step, n_events, h, hA, hb, gravity, drag_rate, quadratic,
           rotation_mode, restitution, friction, wall_speed_at_wall, wall_impulse, threshold,
           iterations, half_size, vertices_t, first_vertex, centred, center, lam, mass,
           inv_mass, Q, moments, I_body_inv, energy_limit, leaf_order, leaf_start,
           leaf_spheres, first_leaf, body_mode,
           x, v, w, R, lo, hi, walls, bodies, events, tracked, tracker_rows, trackers_f,
           trackers_i, impulse_now, event_data,
           y, y_i, K, x0, v0, w0, R0, A, E, L, corr, past, r_a, P, n, origin, now_walls,
           pairs, wall_r, wall_at):
    """Mirrors :meth:`refsim.dynamics.simulation.Simulation.step`, up to
    ``n_steps`` times, in place; returns ``(steps, events, stop, pairs)``
    (module docstring: the readable function of each stage, and the
    hand-back), ``events`` the number of event rows now written, ``pairs``
    the rows of ``pairs`` of a step stopped with ``STOP_BODY_STAGE``
    (:func:`advance` unpacks the arguments).

    Parameters (B bodies, s solver stages; float64 unless said)
    ----------
    first_step : int, the simulation's steps before this call (an event
        row's step is ``first_step`` plus the step of the call, from 0)
    n_events : int, the event rows already written (appended to)
    hA : (s, s) ``h * A`` of the tableau; hb : (s,) ``h * b``
    drag_rate : (B,) ``drag / mass``; quadratic : bool
    rotation_mode : int (``ROTATION_*``)
    wall_speed_at_wall : bool (``wall_speed="wall"``, else the seed's; the
        seed's wall response)
    wall_impulse : bool, the corrected wall response (``wall_response =
        "impulse"``), else the seed's; threshold, iterations: its
        restitution threshold and sweeps (:mod:`refsim.dynamics.impulse`)
    vertices_t : (3, N) every body's body-space vertices, body b's in
        columns ``first_vertex[b]:first_vertex[b + 1]`` (int64 (B + 1,))
    centred : bool, every centroid at its mesh origin (mesh origin = x);
        else the origin is ``x - R c`` for the body-space centroids ``center``
        (B, 3), ``R c`` summed left to right
        (:attr:`Simulation.position`, :func:`refsim.dynamics.products.matvec`)
    lam, mass, inv_mass : (B,) largest principal moment, mass, 1 / mass
    Q, moments : (B, 3, 3), (B, 3) principal axes (mesh frame) and moments
        (:func:`refsim.dynamics.rotation_impulse.principal_frame`)
    I_body_inv : (B, 3, 3) body-space inverse inertia
    leaf_order, leaf_start, leaf_spheres, first_leaf : every body's groups
        of vertices (:func:`refsim.dynamics.compiled_loop.vertex_leaves`,
        laid out by ``CompiledLoop._lay_out_leaves``), for the wall stage of
        the corrected response (:func:`refsim.dynamics._numba_walls.vertices_past_wall`)
    body_mode : int (``BODY_*``)
    x, v, w : (B, 3); R : (B, 3, 3); lo, hi : (B, 3) the state and boxes
    walls : (B, 6) bool; bodies : (B, B) bool (the contacts, read and written)
    events : (capacity, 4) int64
    impulse_now : (B, 6, 7) each body's wall contacts' impulse records of
        the step (:func:`refsim.dynamics.impulse.contact_sum_python`);
        event_data : (capacity, 7), the record of each event's contact
    tracked : (B,) int64, the row of ``tracker_rows`` of a body whose box
        comes from its incremental tracker (the walk of
        :func:`refsim.bounds._numba_kernels.incremental_update_numba`: the
        scan's box on a convex mesh, bit for bit), or -1 (the linear scan)
    tracker_rows : (T, 14) int64, where each tracker's arrays start in the
        flat ``trackers_f`` (float64) and ``trackers_i`` (int64) (``T_*``;
        :class:`refsim.dynamics.compiled_loop.CompiledLoop` lays them out)
    y, y_i, K, x0, v0, w0, R0, A, E, L, corr, past, r_a, P, n, origin, now_walls,
    pairs : scratch: ``y``, ``y_i`` (2 3B,), ``K`` (s, 2 3B) of the solver;
        ``x0``, ``v0``, ``w0``, ``R0`` the state at the start of the step;
        ``A``, ``E`` (3, 3), ``L`` (3,) of the rotation step (``E`` also a
        body's world inverse inertia, ``L`` the velocity a wall impulse
        acts on, ``A`` the turn after a bounce); ``corr`` (3,) a wall correction; the
        wall impulses' vertices past a wall ``past`` (M,) int64, contacts
        ``r_a`` (M, 3), impulses ``P`` (M, 4) and normal ``n`` (3,), M the
        most vertices of a body; ``origin`` (B, 3); ``now_walls`` (B, 6)
        bool; ``pairs`` (max(B (B - 1) / 2, 1), 2) int64
    wall_r, wall_at : with the corrected wall response and ``BODY_HAND_BACK``,
        the step's wall contacts as the readable wall stage leaves them in
        ``Simulation._wall_contacts`` (every vertex past the wall, less the
        centroid, before the push-back): those of body b's wall 2k (low) or
        2k + 1 (high) are rows ``wall_at[b, wall, 0]`` on, ``wall_at[b,
        wall, 1]`` of them (0: none), of ``wall_r`` (3 N, 3) float64, N the
        vertices of all bodies (a body meets at most three walls a step)
    """
    B = x.shape[0]
    s = hb.shape[0]
    d = 3 * B
    per_step = 6 * B + B * (B - 1) // 2
    k_friction = 1.0 - friction
    keep = wall_impulse and body_mode == BODY_HAND_BACK      # the wall contacts, for Python
    for step in range(n_steps):
        if n_events + per_step > events.shape[0]:
            return step, n_events, STOP_EVENTS, 0
        for b in range(B):
            for k in range(3):
                x0[b, k] = x[b, k]
                v0[b, k] = v[b, k]
                w0[b, k] = w[b, k]
                for j in range(3):
                    R0[b, k, j] = R[b, k, j]

        # 1. integrate: rk_step on y = (x, v), f = translational_rhs
        for b in range(B):
            for k in range(3):
                y[3 * b + k] = x[b, k]
                y[d + 3 * b + k] = v[b, k]
        for i in range(s):
            for e in range(2 * d):
                y_i[e] = y[e]
            for j in range(i):
                if hA[i, j] != 0.0:
                    for e in range(2 * d):
                        y_i[e] = y_i[e] + hA[i, j] * K[j, e]
            for b in range(B):
                # acceleration: v (-r) (linear) or v (|v| (-r)) (quadratic), then a_y -= g
                vx, vy, vz = y_i[d + 3 * b], y_i[d + 3 * b + 1], y_i[d + 3 * b + 2]
                factor = -drag_rate[b]
                if quadratic:
                    factor = np.sqrt((vx * vx + vy * vy) + vz * vz) * factor
                K[i, 3 * b] = vx
                K[i, 3 * b + 1] = vy
                K[i, 3 * b + 2] = vz
                K[i, d + 3 * b] = vx * factor
                K[i, d + 3 * b + 1] = vy * factor - gravity
                K[i, d + 3 * b + 2] = vz * factor
        for i in range(s):
            if hb[i] != 0.0:
                for e in range(2 * d):
                    y[e] = y[e] + hb[i] * K[i, e]
        for b in range(B):
            for k in range(3):
                x[b, k] = y[3 * b + k]
                v[b, k] = y[d + 3 * b + k]

        # 2. rotation: the seed's X += h (w x X) for each column, then
        # Gram-Schmidt; or the exact step
        if rotation_mode == ROTATION_EXACT:
            for b in range(B):
                free_rotation_step(R[b], w[b], Q[b], moments[b], h, A, L, E)
        elif rotation_mode == ROTATION_SEED:
            for b in range(B):
                axes_step_seed(R[b], w[b], h, A, R[b])

        # 3. check, conservatively (module docstring)
        total = 0.0
        for b in range(B):
            vv = (v[b, 0] * v[b, 0] + v[b, 1] * v[b, 1]) + v[b, 2] * v[b, 2]
            ww = (w[b, 0] * w[b, 0] + w[b, 1] * w[b, 1]) + w[b, 2] * w[b, 2]
            total += 0.5 * (mass[b] * vv + lam[b] * ww) \
                + mass[b] * gravity * (x[b, 1] + half_size)
        if not (total <= 0.5 * energy_limit):
            _restore(x, v, w, R, x0, v0, w0, R0)
            return step, n_events, STOP_READABLE, 0

        # 4. bounds: the linear scan, r_k = (R_k0 x + R_k1 y) + R_k2 z, + origin
        for b in range(B):
            for k in range(3):
                if centred:
                    origin[b, k] = x[b, k]
                else:
                    origin[b, k] = x[b, k] - ((R[b, k, 0] * center[b, 0]
                                               + R[b, k, 1] * center[b, 1])
                                              + R[b, k, 2] * center[b, 2])
            if tracked[b] >= 0:
                _tracker_update(tracker_rows[tracked[b]], trackers_f, trackers_i, R[b],
                                origin[b], lo[b], hi[b])
                continue
            for k in range(3):
                a0, a1, a2 = R[b, k, 0], R[b, k, 1], R[b, k, 2]
                first = first_vertex[b]
                least = greatest = (a0 * vertices_t[0, first] + a1 * vertices_t[1, first]) \
                    + a2 * vertices_t[2, first]
                for q in range(first + 1, first_vertex[b + 1]):
                    r = (a0 * vertices_t[0, q] + a1 * vertices_t[1, q]) + a2 * vertices_t[2, q]
                    if r < least:
                        least = r
                    if r > greatest:
                        greatest = r
                lo[b, k] = least + origin[b, k]
                hi[b, k] = greatest + origin[b, k]

        # 5. walls (S3, S7; S9's spin first with the seed's rotation; or the
        # corrected impulses)
        kept = np.int64(0)      # int64 at once: a literal 0 compiles wall_impulse_response twice
        for b in range(B):
            for k in range(6):
                now_walls[b, k] = False
                for j in range(7):
                    impulse_now[b, k, j] = 0.0
                if keep:
                    wall_at[b, k, 1] = 0
            beyond = False
            for k in range(3):
                if lo[b, k] < -half_size or hi[b, k] > half_size:
                    beyond = True
            if not beyond:
                continue
            for k in range(3):
                # WallCrossings.correction
                below = -half_size - lo[b, k]
                above = hi[b, k] - half_size
                if below > 0.0 and above > 0.0:
                    corr[k] = 0.5 * (below - above)
                else:
                    corr[k] = (below if below > 0.0 else 0.0) - (above if above > 0.0 else 0.0)
            if wall_impulse:
                world_inertia(R[b], I_body_inv[b], E)
                kept = wall_impulse_response(
                    b, corr, vertices_t, leaf_order, leaf_start, leaf_spheres, first_leaf, x,
                    center, v, w, R, lo, hi, h, half_size, gravity, restitution, friction,
                    threshold, iterations, inv_mass[b], E, past, r_a, P, n, L, A, impulse_now,
                    keep, wall_r, wall_at, kept)
            else:
                if rotation_mode == ROTATION_SEED:
                    wall_spin_seed(b, corr, vertices_t, first_vertex[b], first_vertex[b + 1],
                                   x, center, v, w, R, lo, hi, restitution, friction)
                # wall_response_seed
                for k in range(3):
                    if corr[k] == 0.0:
                        continue
                    x[b, k] += corr[k]
                    v_k = v[b, k]
                    if wall_speed_at_wall:
                        v_k = wall_speed(v_k, -gravity if k == 1 else 0.0, corr[k])
                    v[b, k] = -restitution * v_k
                    for j in range(3):
                        if j != k:
                            v[b, j] = k_friction * v[b, j]
            for k in range(3):
                lo[b, k] += corr[k]
                hi[b, k] += corr[k]
                if corr[k] != 0.0:
                    now_walls[b, 2 * k + (0 if corr[k] > 0.0 else 1)] = True

        # 6. broad phase: every overlapping pair (closed boxes), rows sorted
        n_pairs = 0
        if body_mode != BODY_NONE:
            for i in range(B):
                for j in range(i + 1, B):
                    if (lo[i, 0] <= hi[j, 0] and lo[j, 0] <= hi[i, 0]
                            and lo[i, 1] <= hi[j, 1] and lo[j, 1] <= hi[i, 1]
                            and lo[i, 2] <= hi[j, 2] and lo[j, 2] <= hi[i, 2]):
                        pairs[n_pairs, 0] = i
                        pairs[n_pairs, 1] = j
                        n_pairs += 1
            if n_pairs and body_mode == BODY_HAND_BACK:
                # Python runs the body stage, then finish_body_step commits
                # the step (its flags and events: none written yet)
                return step, n_events, STOP_BODY_STAGE, n_pairs
        # the wall contacts that began (committed only now: a stop above
        # leaves the previous step's flags)
        n_events = _note_wall_onsets(first_step + step, walls, now_walls, impulse_now, events,
                                     event_data, n_events)
        # 8. the seed's exchange (S8) for each pair, in order
        if body_mode == BODY_EXCHANGE:
            for p in range(n_pairs):
                a, c = pairs[p, 0], pairs[p, 1]
                _exchange_seed(a, c, x, v)
        # the body contacts of this step (none when the hand-back mode got
        # here): contacts that ended are cleared, those that began noted
        if body_mode != BODY_NONE:
            q = 0
            for i in range(B):
                for j in range(i + 1, B):
                    now = q < n_pairs and pairs[q, 0] == i and pairs[q, 1] == j
                    if now:
                        q += 1
                        if not bodies[i, j]:
                            events[n_events, 0] = first_step + step
                            events[n_events, 1] = 1
                            events[n_events, 2] = i
                            events[n_events, 3] = j
                            for c in range(7):          # the seed's exchange: no impulse
                                event_data[n_events, c] = 0.0
                            n_events += 1
                    bodies[i, j] = now
    return n_steps, n_events, DONE, 0


#: Columns of ``tracker_rows`` (one row per tracked body): the number of
#: vertices n, then where each of the tracker's arrays starts in the flat
#: float (XYZ, VALUE, TIE) and int (the others) arrays.
T_N, T_XYZ, T_VALUE, T_TIE, T_OFFSETS, T_INDICES, T_INDICES_END, T_EXTREMES, T_STAMP, \
    T_TOUCHED, T_SEEN, T_QUEUE, T_GENERATION, T_COUNTS = range(14)


@numba.njit(cache=True, nogil=True)
def _tracker_update(row, trackers_f, trackers_i, rotation, translation, lo, hi):
    """One incremental box update of a tracked body, its arrays slices of
    the flat ones (the two-dimensional ones made as :func:`_view2` makes
    its views): :func:`incremental_update_numba`, which mirrors
    :meth:`refsim.bounds.aabb_incremental.IncrementalAABB.update`."""
    n = row[T_N]
    f, i = trackers_f, trackers_i
    incremental_update_numba(
        numba.carray(_address(f, row[T_XYZ]), (3, n)),
        i[row[T_OFFSETS]:row[T_OFFSETS] + n + 1],
        i[row[T_INDICES]:row[T_INDICES_END]],
        rotation, translation,
        numba.carray(_address(i, row[T_EXTREMES]), (2, 3)),
        f[row[T_TIE]],
        numba.carray(_address(f, row[T_VALUE]), (3, n)),
        numba.carray(_address(i, row[T_STAMP]), (3, n)),
        i[row[T_TOUCHED]:row[T_TOUCHED] + n],
        i[row[T_SEEN]:row[T_SEEN] + n],
        i[row[T_QUEUE]:row[T_QUEUE] + n],
        i[row[T_GENERATION]:row[T_GENERATION] + 2],
        i[row[T_COUNTS]:row[T_COUNTS] + 2],
        lo, hi)


@numba.njit(cache=True, nogil=True)
def _restore(x, v, w, R, x0, v0, w0, R0):
    """The state at the start of the step (the wall stage's S9 spin changes w)."""
    for b in range(x.shape[0]):
        for k in range(3):
            x[b, k] = x0[b, k]
            v[b, k] = v0[b, k]
            w[b, k] = w0[b, k]
            for j in range(3):
                R[b, k, j] = R0[b, k, j]


@numba.njit(cache=True, nogil=True)
def _exchange_seed(a, b, x, v):
    """Mirrors :func:`refsim.dynamics.body_response.exchange_velocities_seed`
    on ``v[a]``, ``v[b]`` in place (its sums left to right, as
    :mod:`refsim.dynamics.products` writes them)."""
    N0 = x[a, 0] - x[b, 0]
    N1 = x[a, 1] - x[b, 1]
    N2 = x[a, 2] - x[b, 2]
    length = np.sqrt((N0 * N0 + N1 * N1) + N2 * N2)
    if length == 0.0:
        return
    N0 /= length
    N1 /= length
    N2 /= length
    va_n = (v[a, 0] * N0 + v[a, 1] * N1) + v[a, 2] * N2
    vb_n = (v[b, 0] * N0 + v[b, 1] * N1) + v[b, 2] * N2
    if va_n - vb_n >= 0.0:
        return
    da = vb_n - va_n
    db = va_n - vb_n
    v[a, 0] = v[a, 0] + da * N0
    v[a, 1] = v[a, 1] + da * N1
    v[a, 2] = v[a, 2] + da * N2
    v[b, 0] = v[b, 0] + db * N0
    v[b, 1] = v[b, 1] + db * N1
    v[b, 2] = v[b, 2] + db * N2


@numba.njit(cache=True, nogil=True)
def _note_wall_onsets(step, walls, now_walls, impulse_now, events, event_data, n_events):
    """The wall contacts that began in ``step`` (``now_walls[b, k]`` and not
    ``walls[b, k]``) as event rows ``(step, 0, b, k)`` from row ``n_events``
    on, each with its impulse record ``impulse_now[b, k]``; then ``walls``
    becomes ``now_walls``. Returns the new number of rows."""
    for b in range(walls.shape[0]):
        for k in range(6):
            if now_walls[b, k] and not walls[b, k]:
                events[n_events, 0] = step
                events[n_events, 1] = 0
                events[n_events, 2] = b
                events[n_events, 3] = k
                for j in range(7):
                    event_data[n_events, j] = impulse_now[b, k, j]
                n_events += 1
            walls[b, k] = now_walls[b, k]
    return n_events


@numba.njit(cache=True, nogil=True)
def finish_body_step(hits, records, walls, now_walls, bodies, impulse_now, events, event_data,
                     counters):
    """The end of a step the kernel stopped in with ``STOP_BODY_STAGE``,
    after Python ran its body stage: what :func:`_steps` does after its
    broad phase, with the pairs in contact ``hits`` (m, 2) int64 (rows
    ``i < j``, in the order of the broad phase's rows) and ``records`` (m,
    7) the impulse record of each (:func:`refsim.dynamics.impulse.contact_sum_python`,
    zeros where no impulse acted). The wall contacts that began are noted
    with ``impulse_now``'s records (which the body stage's island solve
    added to), then the body contacts; the flags become the step's; the
    step is counted (``C_STEPS``, ``C_LOOP_STEPS``, ``C_BODY_STEPS``; one
    fewer ``C_LEFT``) with its event rows (``C_PENDING``).

    One compiled call, so that a signal handled in Python finds the step
    either not committed (its flags, events and counts those of the step
    before; the caller restores the state) or committed whole."""
    step = counters[slot.C_STEPS]
    n_events = counters[slot.C_PENDING]
    B = walls.shape[0]
    n_events = _note_wall_onsets(step, walls, now_walls, impulse_now, events, event_data,
                                 n_events)
    q = 0
    m = hits.shape[0]
    for i in range(B):
        for j in range(i + 1, B):
            now = q < m and hits[q, 0] == i and hits[q, 1] == j
            if now:
                if not bodies[i, j]:
                    events[n_events, 0] = step
                    events[n_events, 1] = 1
                    events[n_events, 2] = i
                    events[n_events, 3] = j
                    for c in range(7):
                        event_data[n_events, c] = records[q, c]
                    n_events += 1
                q += 1
            bodies[i, j] = now
    counters[slot.C_STEPS] += 1
    counters[slot.C_LOOP_STEPS] += 1
    counters[slot.C_BODY_STEPS] += 1
    counters[slot.C_PENDING] = n_events
    counters[slot.C_LEFT] -= 1
    counters[slot.C_STOP] = DONE
    counters[slot.C_PAIRS] = 0
    return q == m
