"""Adapters to the independent engines refsim is checked against.

One module per engine; each converts conventions (units, frames, float32,
semantics) inside itself and nowhere else. The engines are optional
dependencies (``pip install 'refsim[oracles]'``): an adapter imports its engine
only when used and raises :class:`OracleUnavailable` if it is missing. Tests
turn that into a skip that names the reason (``require`` in tests/conftest.py).
"""

from __future__ import annotations

import importlib

#: What ``pip`` installs for the oracles (pyproject.toml's ``oracles`` extra).
INSTALL_HINT = "pip install 'refsim[oracles]'"


class OracleUnavailable(RuntimeError):
    """The engine behind an oracle is not installed or cannot run here."""


def import_engine(module: str, package: str):
    """Import an engine's module or raise :class:`OracleUnavailable`.

    ``package`` is the PyPI name to tell the user (e.g. ``python-fcl`` for
    module ``fcl``).
    """
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise OracleUnavailable(
            f"oracle engine {package!r} is not installed "
            f"({INSTALL_HINT}): {exc}") from None


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
