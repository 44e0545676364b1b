"""Example sweep tasks: a seeded refsim simulation reduced to a few numbers,
and a task that does nothing (the measure of a sweep's own overhead).

:func:`bounce` is what a sweep task looks like: a module-level function that
takes its ``seed`` and plain arguments (a scene by its file name), runs
refsim, and returns a small record. The tests run it on every backend, and
the sweep benchmarks (:mod:`refsim.studies.sweep`) time it.

Cost: one ``refsim.simulate`` of the scene for ``duration`` simulated
seconds, plus loading the scene.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np


def bounce(*, seed: int, scene: str = "bounce.toml", duration: float = 0.2,
           lift: float = 0.5) -> dict:
    """Simulate ``scene`` for ``duration`` s with every body raised by a
    seeded uniform draw in [0, ``lift``) m; report the end of the motion.

    Returns
    -------
    dict
        ``t``: the last frame's time; ``height`` and ``vertical_speed``: each
        body's last y position and y velocity; ``lowest``: the lowest y any
        body reached in a frame; ``wall_hits``: the number of wall events;
        ``lift``: the draws.
    """
    from refsim.dynamics.simulate import simulate
    from refsim.scenes.loader import load_scene

    loaded = load_scene(scene)
    rng = np.random.default_rng(seed)
    lifts = rng.uniform(0.0, lift, size=len(loaded.bodies))
    bodies = tuple(replace(body, position=(body.position[0], body.position[1] + float(dy),
                                           body.position[2]))
                   for body, dy in zip(loaded.bodies, lifts, strict=True))
    trajectory = simulate(replace(loaded, bodies=bodies), duration=duration)
    return {
        "t": float(trajectory.t[-1]),
        "height": trajectory.position[-1, :, 1].tolist(),
        "vertical_speed": trajectory.velocity[-1, :, 1].tolist(),
        "lowest": float(trajectory.position[:, :, 1].min()),
        "wall_hits": sum(event.kind == "wall" for event in trajectory.events),
        "lift": lifts.tolist(),
    }


def trivial(*, seed: int) -> int:
    """A task that does nothing but return its seed: its cost is the sweep's."""
    return seed
