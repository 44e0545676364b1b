"""The kernel a run starts on: a short run does not wait for a compile.

numba compiles the simulation loop (:mod:`refsim.dynamics._numba_kernels`)
on its first call on a machine and keeps the machine code on disk; that
first compile takes longer than the bundled scenes' whole runs on the
readable kernels (docs/decisions/cold-start.md has the figures). The
readable and compiled kernels give the same results bit for bit
(tests/dynamics/test_compiled_loop.py), so which one a run takes changes
its time only. The loop is a :class:`refsim.kernels.Tier` (:data:`LOOP`):
a process spends at most :data:`LOOP_COMPILE_SECONDS` on readable runs
before it compiles. :func:`start_kernel` picks:

- the default (the compiled loop) when numba already holds the loop's
  machine code for this processor, in memory or in its disk cache, or when
  ``REFSIM_KERNELS`` or ``REFSIM_TIERED_START=0`` chooses, or the loop
  cannot run the scene, or the process has spent its readable budget;
- else "readable" when the run's readable steps, timed on a few of them,
  would take less than the budget left; else the default, and the process
  compiles from then on (also, untimed, for bodies of more than
  :data:`PROBE_FACES` triangles that can meet at a triangle level).

The estimate is the first steps' rate: a scene whose bodies meet only
later (each readable body contact costs far more than a step in flight)
can run readable for longer than the compile would have taken. The probe
looks at the clock every :data:`PROBE_CHUNK` steps, so it can pass
:data:`PROBE_SECONDS` by up to that many steps.

``refsim run``, the viewer's runs (:mod:`refsim.viewer.runs`) and
:func:`refsim.simulate` with its default kernel ask it (a
:class:`refsim.Simulation` made directly keeps the compiled default: how
many steps it will take is not known). A run started readable compiles
nothing, so numba's cache stays empty until a long enough run comes.
"""

from __future__ import annotations

import time

from refsim.errors import RefsimError
from refsim.kernels import Tier

#: About the loop's first compile on a two-core machine, rounded down
#: (docs/decisions/cold-start.md): a run whose readable steps take less
#: starts readable.
LOOP_COMPILE_SECONDS = 25.0

#: The simulation loop as a family of compiled kernels: the process's
#: readable budget before it compiles (:class:`refsim.kernels.Tier`).
LOOP = Tier("simulation loop", ("refsim.dynamics._numba_kernels:advance",),
            compile_seconds=LOOP_COMPILE_SECONDS)

#: The readable steps timed to estimate a run's readable time: at most this
#: many, and no more once this much time has passed.
PROBE_STEPS = 200
PROBE_SECONDS = 0.25
#: Steps between two looks at the clock while timing.
PROBE_CHUNK = 10
#: A scene whose bodies can meet at a triangle level ("triangle-aabb",
#: "exact") is not timed when a body has more triangles than this: the
#: readable build of its triangle hierarchy, on the first contact, can take
#: longer than the compile (seconds for 20 000 triangles), and a probe that
#: met it would pay it before deciding.
PROBE_FACES = 5000


def start_kernel(scene, n_steps: int, *, wall_speed: str | None = None,
                 boxes: str = "auto") -> str | None:
    """"readable" when a run of ``n_steps`` of ``scene`` would end sooner on
    the readable kernels than the readable budget left to :data:`LOOP`;
    else None (the default kernel). Costs a file read when the loop is
    compiled, else up to :data:`PROBE_SECONDS` of readable steps on a copy
    of the run (charged to the budget)."""
    from refsim.collision.bodies import PAIR_LEVELS
    from refsim.dynamics.compiled_loop import loop_support
    from refsim.dynamics.simulation import Simulation

    if not LOOP.readable_first():
        return None
    probe = Simulation(scene, wall_speed=wall_speed, boxes=boxes, kernel="readable")
    if loop_support(probe) is not None:     # stage kernels then, not the loop
        return None
    if (probe.plan.body_body and probe.plan.level in PAIR_LEVELS
            and max(b.mesh.n_faces for b in probe.bodies) > PROBE_FACES):
        return None
    began = time.process_time()                 # CPU time, as LOOP charges it
    try:
        with LOOP.charged():
            while probe.steps < min(PROBE_STEPS, n_steps):
                probe.advance(min(PROBE_CHUNK, n_steps - probe.steps))
                if time.process_time() - began > PROBE_SECONDS:
                    break
    except RefsimError:                      # the run itself will say it
        return None
    per_step = (time.process_time() - began) / max(probe.steps, 1)
    if per_step * n_steps < LOOP.remaining():
        return "readable"
    LOOP.settle()                            # a long run: compile now, and from now on
    return None
