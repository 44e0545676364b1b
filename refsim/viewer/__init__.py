"""Seeing a simulation: a live viewer in the browser and standalone replays
(seed S12, "interactive graphics"; for refsim, a replay viewer).

- ``refsim view SCENE.toml`` / :func:`refsim.view`: the scene's bodies moving
  in 3D (y up) inside the world cube, with play, pause, step, scrub and speed;
  controls for the solver, step size, collision level, box update, rotation
  model and body response that re-run the simulation in a worker thread;
  overlays for the bodies' boxes, contacting triangle pairs, wall-hit normals
  and impulses, and an energy chart (:mod:`refsim.viewer.live`).
- ``refsim replay RUN.npz ... -o replay.html`` /
  :func:`refsim.viewer.replay.write_replay`: recorded trajectories side by
  side or overlaid, in one HTML file that plays from ``file://`` with no
  network (:mod:`refsim.viewer.replay`); :mod:`refsim.viewer.demos` writes
  the replays of claims C11 and C12 and of a wall bounce beside pybullet.

The viewer is a view layer (docs/design.md, Architecture): it imports the
algorithms and runs simulations, and computes no verdicts. What it draws
beyond the recorded poses (boxes, contacting triangles, wall impulses,
energy) comes from refsim's own functions, in :mod:`refsim.viewer.overlays`.

Why viser (https://viser.studio, MIT): one Python package whose client (a
three.js/React application) ships inside the wheel as one bundled HTML
file, so it runs with no network and no JavaScript build of our own; GUI
controls (dropdowns, numbers, sliders, buttons, a uPlot chart) call back into
Python, which is where the simulation lives; and its scene serializer writes
the same scene, with a player (play/pause, scrub, speed, scene tree), into a
standalone HTML file, which is exactly a replay. The alternatives weighed:
a hand-written three.js page (a JavaScript client and a websocket protocol
to own, and a bundled three.js to vendor); notebook widgets (pythreejs, k3d:
no standalone command, and replays only inside Jupyter); desktop renderers
(Open3D, pyvista/VTK: large native dependencies, a window rather than a
browser, and no file to share); matplotlib animations (no interactivity,
slow 3D). The costs of viser, accepted: about 0.8 MB of client in every
replay file, and a dependency that is optional (the ``viewer`` extra), so
that refsim's algorithms never need it.
"""

from __future__ import annotations

__all__ = ["view"]

#: The default size budget of a replay page (``refsim replay --max-bytes``):
#: about six times viser's client, room for a few thousand frames of a few bodies.
REPLAY_MAX_BYTES = 5_000_000


#: The modules of the package, imported on first use (``refsim.viewer.replay``).
_MODULES = ("demos", "draw", "live", "overlays", "replay", "runs", "server")


def __getattr__(name: str):
    import importlib

    if name == "view":
        return importlib.import_module("refsim.viewer.live").view
    if name in _MODULES:
        return importlib.import_module(f"refsim.viewer.{name}")
    raise AttributeError(f"module 'refsim.viewer' has no attribute {name!r}")
