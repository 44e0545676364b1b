"""Running a scene for the viewer: in chunks, with progress, cancellable.

The live viewer re-runs the simulation in a worker thread whenever a control
changes, shows the progress, and drops a run that a newer request replaces.
:func:`run_bodies` therefore drives :class:`refsim.Simulation` the way
:func:`refsim.simulate` does (a frame first, then one every ``every`` steps
counted from the start, and the last state), a chunk of steps at a time,
reporting the fraction done between chunks; the frames are the same, bit for
bit (a test checks it). :func:`run_particles` does the same for a
``[particles]`` table with :class:`refsim.ParticleSystem`.

Cost: that of the simulation, plus one call of ``progress`` per chunk.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from refsim.dynamics.simulate import default_every
from refsim.dynamics.simulation import Simulation
from refsim.dynamics.start import start_kernel
from refsim.dynamics.trajectory import Trajectory

#: Steps between two progress reports (and cancellation checks): about a
#: tenth of a second of the slowest bundled scene, so a cancelled run stops
#: promptly and the progress bar moves smoothly.
CHUNK_STEPS = 200

#: Frames kept of a particle scene (each frame is 24 bytes a particle).
PARTICLE_FRAMES = 200


class Cancelled(Exception):
    """The run was replaced by a newer one before it finished."""


def _never() -> bool:
    return False


def _ignore(fraction: float) -> None:
    pass


def run_bodies(scene, *, every: int | None = None,
               progress: Callable[[float], None] = _ignore,
               cancelled: Callable[[], bool] = _never) -> Trajectory:
    """The trajectory of ``scene``'s bodies, as ``refsim.simulate(scene, every=every)``.

    ``progress(fraction)`` is called after each chunk of ``CHUNK_STEPS``
    steps; when ``cancelled()`` becomes true the run stops with
    :class:`Cancelled`. A divergence raises :class:`refsim.DivergenceError`
    with the frames so far in ``partial``, as ``simulate`` does.
    """
    n_steps = scene.integration.n_steps
    every = default_every(n_steps) if every is None else every
    # a short run does not wait for numba's first compile (the same frames)
    sim = Simulation(scene, kernel=start_kernel(scene, n_steps))
    sim.record()
    while sim.steps < n_steps:
        if cancelled():
            raise Cancelled
        sim.run(min(CHUNK_STEPS, n_steps - sim.steps), every=every)
        progress(sim.steps / n_steps)
    if sim.steps % every:
        sim.record()                                  # always end on the last state
    traj = sim.trajectory()
    traj.settings["every"] = every
    return traj


@dataclass(frozen=True)
class ParticleRun:
    """Frames of a particle system: ``t`` (F,), ``position`` (F, N, 3)."""

    t: np.ndarray
    position: np.ndarray
    every: int


def particle_every(n_steps: int) -> int:
    """The stride that keeps at most about ``PARTICLE_FRAMES`` frames."""
    return max(1, math.ceil(n_steps / PARTICLE_FRAMES))


def run_particles(scene, *, every: int | None = None,
                  progress: Callable[[float], None] = _ignore,
                  cancelled: Callable[[], bool] = _never) -> ParticleRun:
    """The particles of ``scene`` (its ``[particles]`` table) for its duration,
    a frame every ``every`` steps (and the first and last)."""
    from refsim.particles.system import ParticleSystem

    n_steps = scene.integration.n_steps
    every = particle_every(n_steps) if every is None else every
    system = ParticleSystem(scene.particles)
    t, xs = [0.0], [system.positions.astype(np.float32)]
    while system.steps < n_steps:
        if cancelled():
            raise Cancelled
        system.run(min(every, n_steps - system.steps))     # DivergenceError: not finite
        t.append(system.steps * scene.particles.step)
        xs.append(system.positions.astype(np.float32))
        progress(system.steps / n_steps)
    return ParticleRun(t=np.array(t), position=np.stack(xs), every=every)
