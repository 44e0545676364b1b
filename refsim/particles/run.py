"""Running a particle scene and keeping its frames (seed S10), for
``refsim run`` and for anyone who wants the frames of a particle scene.

Cost: O(N) per step; the frames kept are (frames, N, 3) twice, in memory.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from refsim.errors import DivergenceError, SceneError

#: ``refsim run`` stores about this many frames unless ``--every`` says
#: otherwise: enough to replay smoothly, and 200 frames of 10 000 particles
#: are 96 MB of float64.
DEFAULT_FRAMES = 200

#: ``refsim run`` refuses to store more frame data than this (positions and
#: velocities, 48 bytes a particle a frame) and asks for a larger ``--every``:
#: the frames are held in memory until the file is written.
MAX_FRAME_BYTES = 4 * 10**9


def frame_stride(scene, every: int | None) -> tuple[int, int]:
    """``(n_steps, every)`` for a particle scene: the whole number of steps
    in ``integration.duration`` and the stride between stored frames
    (``every``, or about ``DEFAULT_FRAMES`` frames)."""
    from refsim.solvers.integrate import STEP_COUNT_RTOL  # duration / step tolerance

    integration = scene.integration
    ratio = integration.duration / integration.step
    n_steps = round(ratio)
    if abs(ratio - n_steps) > STEP_COUNT_RTOL * max(n_steps, 1):
        raise SceneError(f"duration / step = {ratio:.9g} is not a whole number of steps",
                         scene.path, "integration.duration")
    if every is None:
        every = max(1, math.ceil(n_steps / (DEFAULT_FRAMES - 1)))
    return n_steps, every


@dataclass(frozen=True)
class ParticleFrames:
    """Stored frames of a particle run.

    Attributes
    ----------
    step : numpy.ndarray
        (frames,) int64 step index of each frame (0 is the initial state).
    t : numpy.ndarray
        (frames,) times, ``step * h``.
    position, velocity : numpy.ndarray
        (frames, N, 3) float64.
    """

    step: object
    t: object
    position: object
    velocity: object


def run_particles(config, n_steps: int, every: int) -> ParticleFrames:
    """Run a :class:`~refsim.particles.system.ParticleSystem` from
    ``config.initial_state()`` for ``n_steps`` steps, keeping every
    ``every``-th state and the last one.

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

    h = config.step
    system = ParticleSystem(config)
    steps = [0]
    xs, vs = [system.positions.copy()], [system.velocities.copy()]

    def frames():
        step = np.array(steps, dtype=np.int64)
        return ParticleFrames(step, step * h, np.stack(xs), np.stack(vs))

    while system.steps < n_steps:
        block = min(every, n_steps - system.steps)
        try:
            # Overflow on the way to divergence is expected and detected below,
            # so numpy's warnings would only repeat it.
            with np.errstate(over="ignore", invalid="ignore"):
                system.run(block)
        except DivergenceError:
            first = _first_non_finite_step(config, xs[-1], vs[-1], block)
            step = steps[-1] + first
            raise DivergenceError("particle state is not finite", step=step, time=step * h,
                                  partial=frames()) from None
        steps.append(system.steps)
        xs.append(system.positions.copy())
        vs.append(system.velocities.copy())
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
