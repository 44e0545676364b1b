"""Adapters to the independent engines refsim is checked against.

One module per engine; each converts conventions (units, frames, float32,
semantics) inside itself and nowhere else. The engines are optional
dependencies (``pip install 'refsim[oracles]'``; coal has an extra of its
own, ``pip install 'refsim[coal]'``): an adapter imports its engine only
when used and raises :class:`OracleUnavailable` if it is missing. Tests
turn that into a skip that names the reason (``require`` in tests/conftest.py).
"""

from __future__ import annotations

import contextlib
import importlib
import os
import sys

#: What ``pip`` installs for the oracles (pyproject.toml's ``oracles`` extra).
INSTALL_HINT = "pip install 'refsim[oracles]'"
def install_hint(engines) -> str:
    """The ``pip`` command that installs the packages of the named shipped
    engines (:func:`refsim.engines.registry.install_hint`)."""
    from refsim.engines.registry import install_hint as hint

    return hint(engines)


class OracleUnavailable(RuntimeError):
    """The engine behind an oracle is not installed or cannot run here."""


def import_engine(module: str, package: str, install: str = INSTALL_HINT):
    """Import an engine's module or raise :class:`OracleUnavailable`.

    ``package`` is the PyPI name to tell the user (e.g. ``python-fcl`` for
    module ``fcl``); ``install`` the command that brings it, if not the
    ``oracles`` extra's.
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise OracleUnavailable(
            f"oracle engine {package!r} is not installed "
            f"({install}): {exc}") from None


@contextlib.contextmanager
def c_banner_dropped(banner: str):
    """Standard output and error (file descriptors 1 and 2) captured for the
    block, then put back with what was written to them, less the lines that
    start with ``banner``: for an engine whose C code prints a banner as it
    loads (pybullet's build time, to standard output or error depending on
    its build), which would otherwise land in the output of ``refsim
    report`` or ``conform --all``. Anything else written meanwhile (a
    warning) still reaches its stream, after the block."""
    with contextlib.ExitStack() as stack:
        for fd, stream in ((1, sys.stdout), (2, sys.stderr)):
            stack.enter_context(_fd_filtered(fd, stream, banner.encode()))
        yield


@contextlib.contextmanager
def _fd_filtered(fd: int, stream, banner: bytes):
    """Descriptor ``fd`` into a temporary file for the block; then restored,
    and the file's lines that do not start with ``banner`` written to it."""
    import tempfile

    try:
        saved = os.dup(fd)
    except OSError:                     # no such descriptor: nothing to capture
        yield
        return
    with tempfile.TemporaryFile() as captured:
        try:
            if stream is not None:
                stream.flush()          # what Python buffered goes out before the swap
            os.dup2(captured.fileno(), fd)
            yield
        finally:
            if stream is not None:
                stream.flush()
            _flush_c_stdio()            # what C buffered goes into the file
            os.dup2(saved, fd)
            os.close(saved)
            captured.seek(0)
            kept = b"".join(line for line in captured.read().splitlines(keepends=True)
                            if not line.startswith(banner))
            if kept:
                os.write(fd, kept)


def _flush_c_stdio() -> None:
    """C's ``fflush(NULL)``, where the C library can be loaded."""
    import ctypes

    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):    # no C library to call (Windows)
        pass


#: The six walls by name, in the order the rigid adapters report contacts.
WALL_ORDER = ("x-", "x+", "y-", "y+", "z-", "z+")


def rotation_of_quaternion(quat_wxyz):
    """The rotation matrix (3, 3) of a quaternion ``(w, x, y, z)`` that an
    engine keeps nearly unit, normalised first. In Python floats (numpy's
    scalars cost more, and the rigid-body adapters read it after every
    step), the norm summed in a fixed order, not by a BLAS dot, whose
    order depends on the processor."""
    import math

    import numpy as np

    from refsim.types import quaternion_to_rotation

    w, x, y, z = np.asarray(quat_wxyz, dtype=np.float64).tolist()
    norm = math.sqrt(((w * w + x * x) + y * y) + z * z)
    return quaternion_to_rotation((w / norm, x / norm, y / norm, z / norm))


def run_recorded(adapter, scene, every: int, wall_contacts, settings: dict):
    """The loop of a rigid-body adapter whose ``load(scene)`` has run:
    ``adapter.step()`` for the scene's steps, ``adapter.state()`` recorded
    at the start, every ``every`` steps and at the last, and an event for
    each (body index, wall name) of ``wall_contacts()`` (the contacts after
    a step) that was not there after the step before. Returns
    :func:`trajectory_of_frames` with ``settings``; "step" is the time in
    ``adapter.step`` (the engine and the drag forces)."""
    import time

    from refsim.dynamics.trajectory import Event

    h = scene.integration.step
    n = scene.integration.n_steps
    names = tuple(b.name for b in scene.bodies)
    frames = [adapter.state()]
    times = [0.0]
    events = []
    touching: set = set()
    stepping = 0.0
    start = time.perf_counter()
    for k in range(1, n + 1):
        before = time.perf_counter()
        adapter.step()
        stepping += time.perf_counter() - before
        now = wall_contacts()
        for i, wall in sorted(now - touching, key=lambda iw: (iw[0], WALL_ORDER.index(iw[1]))):
            events.append(Event("wall", k, k * h, names[i], wall))
        touching = now
        if k % every == 0 or k == n:
            frames.append(adapter.state())
            times.append(k * h)
    return trajectory_of_frames(frames, times, names, events, stepping,
                                time.perf_counter() - start, settings)


def seconds_per_step(adapter, steps: int, warmup: int = 0) -> float:
    """Mean seconds of ``adapter.step()`` over ``steps`` steps after
    ``warmup`` untimed ones, reading no state (a loaded rigid adapter)."""
    import time

    for _ in range(warmup):
        adapter.step()
    start = time.perf_counter()
    for _ in range(steps):
        adapter.step()
    return (time.perf_counter() - start) / steps


def trajectory_of_frames(frames, times, names, events, step_seconds: float,
                         total_seconds: float, settings: dict):
    """A :class:`refsim.dynamics.trajectory.Trajectory` from an engine's
    recorded frames, each ``(x, v, w, R)`` arrays (B, 3) or (B, 3, 3), the
    way the rigid-body adapters (pybullet, MuJoCo) record them: two stages,
    the engine's steps and the recording."""
    import numpy as np

    from refsim.dynamics.trajectory import Trajectory

    x, v, w, r = (np.stack([f[i] for f in frames]) for i in range(4))
    return Trajectory(t=np.asarray(times), position=x, velocity=v, angular_velocity=w,
                      orientation=r, names=names, events=events, stages=("step", "record"),
                      stage_seconds={"step": step_seconds,
                                     "record": total_seconds - step_seconds},
                      settings=settings)
