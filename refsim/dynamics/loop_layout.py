"""Where the compiled loop's arrays sit in the three flat arrays it is
called with (:func:`refsim.dynamics._numba_kernels.advance`), and the
counters it keeps.

Why flat arrays: numba types and unboxes every argument of a call from
Python, some tens of nanoseconds each, and a call with the loop's forty-odd
arrays and numbers cost more than a peer engine's whole step of one body
(docs/decisions/compiled-loop.md, "One step per call"). Packed, a call has
four arguments; inside the kernel each array is a view of its flat array
(a slice and a reshape, no copy), with the same shape, dtype and
C-contiguous layout as before, so the arithmetic and its bits are the same.

Each array has a number below, one numbering for all three flat arrays
(``floats`` float64, ``ints`` int64, ``flags`` bool). The first
``4 * ARRAYS`` entries of ``ints`` are the header: for array ``k``,
``ints[4 k]`` is its offset in its flat array and ``ints[4 k + 1 : 4 k +
4]`` its shape (unused dimensions 1).
:class:`refsim.dynamics.compiled_loop.CompiledLoop` lays them out, the
kernel reads them back. The state ``x``, ``v``, ``w``, ``R``, ``lo``, ``hi``
of the :class:`~refsim.dynamics.simulation.Simulation` and its counters are
views into these arrays too, so a call passes no state of its own.

The counters (``COUNTERS``, int64) are written by the kernel before it
returns, so that the step count and the events a call took are never
behind the state it moved, whatever Python does after the call (a signal
handler that raises as the call returns leaves them consistent; no signal
hold is needed around the call).
"""

from __future__ import annotations

# -- float64 arrays (``floats``) ------------------------------------------------------------
(SCALARS, HA, HB, DRAG_RATE, VERTICES_T, CENTER, LAM, MASS, INV_MASS, Q, MOMENTS,
 I_BODY_INV, LEAF_SPHERES, TRACKERS_F, IMPULSE_NOW, EVENT_DATA,
 X, V, W, R, LO, HI,
 # scratch of the kernel (its values do not carry from one call to the next)
 Y, Y_I, K, X0, V0, W0, R0, A, E, L, CORR, R_A, P, N, ORIGIN,
 # the wall stage's contacts of the step, kept for a body stage run in Python
 WALL_R) = range(38)
# -- int64 arrays (``ints``, after the header) ----------------------------------------------
(SETTINGS, COUNTERS, FIRST_VERTEX, LEAF_ORDER, LEAF_START, FIRST_LEAF, TRACKED,
 TRACKER_ROWS, TRACKERS_I, EVENTS,
 PAST, PAIRS, WALL_AT) = range(38, 51)          # PAST: scratch; PAIRS, WALL_AT: of the step
# -- bool arrays (``flags``) ----------------------------------------------------------------
WALLS, BODIES, NOW_WALLS = range(51, 54)        # NOW_WALLS: of the step
#: How many arrays the header describes.
ARRAYS = 54

#: Body-body modes of the loop (``SETTINGS[G_BODY_MODE]``; chosen by
#: :func:`refsim.dynamics.plan.stage_plan`).
BODY_NONE = 0           # no body-body stage (one body, level "none", response "off")
BODY_EXCHANGE = 1       # level "aabb", the seed's exchange (S8): done in the loop
BODY_HAND_BACK = 2      # any other: a step with an overlapping pair of boxes stops the
                        # kernel after its broad phase (STOP_BODY_STAGE)

#: Rotation models of the loop (``SETTINGS[G_ROTATION_MODE]``: the scene's
#: ``dynamics.rotation``).
ROTATION_OFF = 0
ROTATION_SEED = 1       # S9's Euler step of the axes
ROTATION_EXACT = 2      # "impulse": the exact rotation with angular momentum

#: Entries of ``SCALARS`` (float64).
S_H, S_GRAVITY, S_RESTITUTION, S_FRICTION, S_THRESHOLD, S_HALF_SIZE, S_ENERGY_LIMIT = range(7)
#: Entries of ``SETTINGS`` (int64; the flags 0 or 1).
(G_QUADRATIC, G_ROTATION_MODE, G_WALL_SPEED_AT_WALL, G_WALL_IMPULSE, G_ITERATIONS, G_CENTRED,
 G_BODY_MODE) = range(7)

#: Entries of ``COUNTERS`` (int64). ``C_STEPS``: the simulation's steps
#: (:attr:`Simulation.steps`, also on the readable kernel); ``C_LOOP_STEPS``:
#: those the loop took. ``C_PENDING``: event rows of the kernel's buffer
#: (``EVENTS``, ``EVENT_DATA``) not yet cleared, whose events follow the
#: first ``C_EVENT_BASE`` events of the simulation's list (some of them may
#: be in the list already: ``CompiledLoop.note_events`` adds the others and
#: then clears the rows). ``C_LEFT``, ``C_STOP``: of the last call, the
#: steps it did not take and why (the kernel's ``DONE``, ``STOP_*``).
#: ``C_PAIRS``: the overlapping pairs of boxes (rows of ``PAIRS``) of a step
#: the kernel stopped in with ``STOP_BODY_STAGE``. ``C_BODY_STEPS``: the
#: loop's steps whose body stage ran in Python between two calls of the
#: kernel (:meth:`CompiledLoop.body_stage
#: <refsim.dynamics.compiled_loop.CompiledLoop.body_stage>`), counted in
#: ``C_LOOP_STEPS`` too.
C_STEPS, C_LOOP_STEPS, C_EVENT_BASE, C_PENDING, C_LEFT, C_STOP, C_PAIRS, C_BODY_STEPS = range(8)
COUNTER_COUNT = 8
