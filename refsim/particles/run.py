"""Running a particle scene and keeping its frames (seed S10), for
``refsim run`` and for anyone who wants the frames of a particle scene.

The frames go to a sink (:mod:`refsim.storage.frames`): in memory by default (one
buffer of exactly the run's frames), or spilled to disk as they come, which
``refsim run`` does, so that its memory is the system's state and buffers
plus one frame, whatever the number of steps.

Cost: O(N) per step. Memory: the :class:`~refsim.particles.system.
ParticleSystem` (its state and step buffers), a copy of the last stored
state (48 N bytes, to find the first non-finite step after a divergence),
and what the sink keeps: (frames, N, 3) twice in memory, or one frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from refsim.errors import DivergenceError

#: ``refsim run`` stores about this many frames unless ``--every`` says
#: otherwise: enough to replay smoothly, and 200 frames of 10 000 particles
#: are 96 MB of float64.
DEFAULT_FRAMES = 200

#: Bytes of one particle in one frame: position and velocity, 6 float64.
FRAME_BYTES_PER_PARTICLE = 48

#: Entries of a particle frame, in the order they are written to the .npz.
FRAME_ENTRIES = ("t", "step", "position", "velocity")


def frame_stride(scene, every: int | None) -> tuple[int, int]:
    """``(n_steps, every)`` for a particle scene: the whole number of steps
    in ``integration.duration`` (the loader checked it is one) and the stride
    between stored frames (``every``, or about ``DEFAULT_FRAMES`` frames)."""
    n_steps = scene.integration.n_steps
    if every is None:
        every = max(1, math.ceil(n_steps / (DEFAULT_FRAMES - 1)))
    return n_steps, every


@dataclass(frozen=True)
class ParticleFrames:
    """Stored frames of a particle run: numpy arrays, or, from a run with a
    :class:`refsim.storage.frames.SpillSink`, :class:`refsim.storage.frames.SpilledArray`
    views of its files (valid while it is open).

    Attributes
    ----------
    step : numpy.ndarray
        (frames,) int64 step index of each frame (0 is the initial state).
    t : numpy.ndarray
        (frames,) times, ``step * h``.
    position, velocity : numpy.ndarray
        (frames, N, 3) float64.
    """

    # numpy arrays or SpilledArrays: both index and have a length
    step: Any
    t: Any
    position: Any
    velocity: Any


def run_particles(config, n_steps: int, every: int, *, sink=None) -> ParticleFrames:
    """Run a :class:`~refsim.particles.system.ParticleSystem` from
    ``config.initial_state()`` for ``n_steps`` steps, keeping every
    ``every``-th state and the last one.

    Parameters
    ----------
    config : ParticleConfig
    n_steps, every : int
    sink : refsim.storage.frames.FrameSink, optional
        Where the frames go (``t``, ``step``, ``position``, ``velocity``).
        Default: a :class:`refsim.storage.frames.MemorySink` of exactly the run's
        frames, and the result holds numpy arrays. With a
        :class:`refsim.storage.frames.SpillSink` the result holds views of its
        files (valid while it is open); the frames are the same, bit for bit.

    Raises
    ------
    DivergenceError
        The state became non-finite. ``step`` and ``time`` are those of the
        first non-finite step (the system checks once per stored frame; the
        frame interval that failed is replayed step by step from its start,
        which reproduces the same arithmetic bit for bit). ``partial`` holds
        the frames stored before it.
    """
    import numpy as np

    from refsim.particles.system import ParticleSystem
    from refsim.storage.frames import MemorySink, frame_count

    h = config.step
    if sink is None:
        sink = MemorySink(capacity=frame_count(n_steps, every))
    system = ParticleSystem(config)
    # the last stored state, where a failed interval is replayed from
    x_last, v_last = system.positions.copy(), system.velocities.copy()

    def store():
        # t as step * h, the same product, element by element, as the
        # vectorized ``step * h`` of (frames,) steps
        step = np.int64(system.steps)
        sink.append({"t": step * h, "step": step, "position": system.positions,
                     "velocity": system.velocities})

    def frames():
        a = sink.arrays()
        return ParticleFrames(a["step"], a["t"], a["position"], a["velocity"])

    store()
    while system.steps < n_steps:
        block = min(every, n_steps - system.steps)
        last_step = system.steps
        try:
            # Overflow on the way to divergence is expected and detected below,
            # so numpy's warnings would only repeat it.
            with np.errstate(over="ignore", invalid="ignore"):
                system.run(block)
        except DivergenceError:
            first = _first_non_finite_step(config, x_last, v_last, block)
            step = last_step + first
            raise DivergenceError("particle state is not finite", step=step, time=step * h,
                                  partial=frames()) from None
        store()
        np.copyto(x_last, system.positions)
        np.copyto(v_last, system.velocities)
    return frames()


def _first_non_finite_step(config, x, v, block: int) -> int:
    """Steps from the state ``(x, v)`` until it is first non-finite (at most ``block``)."""
    import numpy as np

    from refsim.particles.system import ParticleSystem

    system = ParticleSystem(config, positions=x, velocities=v)
    for i in range(1, block + 1):
        with np.errstate(over="ignore", invalid="ignore"):
            system.step()
        if not np.isfinite(system.state).all():
            return i
    return block
