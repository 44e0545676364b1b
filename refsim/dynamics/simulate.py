"""Running a scene whole: :func:`simulate` steps a
:class:`~refsim.dynamics.simulation.Simulation` of it to its duration and
returns the :class:`~refsim.dynamics.trajectory.Trajectory`, with a frame
every ``every`` steps (:func:`default_every`: at most about ``MAX_FRAMES``).
"""

from __future__ import annotations

import contextlib
import math
from dataclasses import replace

from refsim.dynamics.simulation import Simulation, check_scene
from refsim.dynamics.start import LOOP, start_kernel
from refsim.dynamics.trajectory import Trajectory
from refsim.errors import check_count, check_number
from refsim.solvers.integrate import whole_steps
from refsim.storage.frames import FrameSink, MemorySink, frame_count

#: At most about this many frames by default (``every`` is chosen so).
MAX_FRAMES = 1000


def default_every(n_steps: int) -> int:
    """The frame stride that keeps at most about ``MAX_FRAMES`` frames."""
    return max(1, math.ceil(n_steps / MAX_FRAMES))


def with_duration(scene, duration: float | None):
    """``scene`` run for ``duration`` seconds instead of its
    ``integration.duration`` (unchanged when ``duration`` is None); refused
    (StateError) unless it is a whole number of the scene's steps, before
    any work."""
    if duration is None:
        return scene
    duration = check_number("duration", duration)
    whole_steps(duration, scene.integration.step)
    return replace(scene, integration=replace(scene.integration, duration=duration))


def simulate(scene, *, every: int | None = None, duration: float | None = None,
             wall_speed: str | None = None, boxes: str = "auto",
             sink: FrameSink | None = None, kernel: str | None = None) -> Trajectory:
    """Run ``scene`` and return its trajectory.

    Parameters
    ----------
    scene : refsim.Scene
    every : int, optional
        Record a frame every ``every`` steps (and the initial state); default
        :func:`default_every` (at most about 1000 frames).
    duration : float, optional
        Override ``integration.duration`` (seconds).
    wall_speed, boxes : str, optional
        See :class:`Simulation` (``wall_speed``: default the scene's
        ``world.wall_speed``).
    sink : refsim.storage.frames.FrameSink, optional
        Where the frames go as they are computed. Default: a
        :class:`refsim.storage.frames.MemorySink` sized for the run's frames, and the
        trajectory holds numpy arrays. ``refsim run`` passes a
        :class:`refsim.storage.frames.SpillSink`, so that memory does not grow with
        the steps; the trajectory's frames are then views of its files, to be
        saved before the sink closes. Both give the same frames, bit for bit.
    kernel : {"readable", "compiled"}, optional
        See :class:`Simulation`. The default runs the compiled loop, or the
        readable step when numba's cache does not hold the loop yet and the
        run is short (:func:`refsim.dynamics.start.start_kernel`): the same
        frames either way.

    Raises
    ------
    DivergenceError
        With the frames so far in ``partial``.
    StateError, ArgumentTypeError
        A ``duration`` that is not a whole number (>= 1) of steps; an
        ``every`` that is not an integer >= 1.
    """
    check_scene(scene)
    scene = with_duration(scene, duration)
    n_steps = scene.integration.n_steps
    every = default_every(n_steps) if every is None else check_count("every", every, 1)
    if sink is None:
        # the initial state, every every-th step, and the last step
        sink = MemorySink(capacity=frame_count(n_steps, every))
    charge: contextlib.AbstractContextManager = contextlib.nullcontext()
    if kernel is None:
        # a short run on a cold numba cache runs readable (the same frames)
        kernel = start_kernel(scene, n_steps, wall_speed=wall_speed, boxes=boxes)
        if kernel == "readable":
            charge = LOOP.charged()
    sim = Simulation(scene, wall_speed=wall_speed, boxes=boxes, sink=sink, kernel=kernel)
    with charge:
        sim.record()
        sim.run(n_steps, every=every)
        if sim.steps % every:
            sim.record()                              # always end on the last state
    traj = sim.trajectory()
    traj.settings["every"] = every
    return traj
