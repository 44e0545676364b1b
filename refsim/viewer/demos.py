"""Demo replays for the report: the seed's flaws seen beside their corrections.

- :func:`demo_c12`: claim C12, "angular velocity does not damp to rest": the
  cube of ``scenes/spinning-cube.toml`` under the seed's rotation model (S9),
  which keeps it spinning, beside the corrected ``rotation = "impulse"``,
  which brings it to rest. Same scene otherwise.
- :func:`demo_c11`: claim C11, "slow or same-direction bodies
  interpenetrate": the "stack" case of :func:`refsim.studies.dynamics.c11_scene`
  (an icosahedron dropped onto another resting on the floor) under the
  seed's velocity exchange (``body_response = "seed"``, S8), where the top
  body sinks into the bottom one, beside ``"impulse"``, where it does not.
- :func:`demo_wall_bounce`: one wall bounce (``scenes/bounce.toml``, 3 s:
  the drop, the bounce and the rise) by refsim beside the same scene run by
  pybullet (:mod:`refsim.oracles.pybullet_adapter`), or any other rigid
  engine of the registry (:mod:`refsim.engines.registry`) named by
  ``engine``.

Each returns the :class:`~refsim.viewer.replay.ReplayInfo` of the file it
wrote (its size and frame stride). The demos run their simulations; they
state nothing about them (the report's claims do). Run all three with
``python -m refsim.viewer.demos OUT_DIR``.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from refsim.viewer import REPLAY_MAX_BYTES
from refsim.viewer.replay import ReplayInfo, run_from_scene, write_replay

#: How long the wall-bounce demo runs (s): the drop from 2 m (1.1 s), the
#: bounce and the rise to the next apex (0.9 s), and part of the next fall.
BOUNCE_SECONDS = 3.0

#: The C11 case shown, and how long (s): the top body lands at about 0.4 s
#: and, under the seed's exchange, stays inside the bottom one.
C11_CASE = "stack"
C11_SECONDS = 2.0


def _bundled(name: str):
    from refsim.scenes.loader import load_scene

    return load_scene(name)


def _with(scene, **dynamics):
    return replace(scene, dynamics=replace(scene.dynamics, **dynamics))


def _for(scene, duration: float | None):
    if duration is None:
        return scene
    return replace(scene, integration=replace(scene.integration, duration=duration))


def demo_c12(path, *, scene=None, duration: float | None = None,
             max_bytes: int = REPLAY_MAX_BYTES) -> ReplayInfo:
    """C12: the seed's rotation model beside the corrected one (side by side);
    ``duration`` (s) shortens the scene's."""
    from refsim.dynamics.simulate import simulate

    scene = _for(scene or _bundled("spinning-cube.toml"), duration)
    runs = []
    for model, label in (("seed", "rotation = seed (S9): never stops"),
                         ("impulse", "rotation = impulse (corrected)")):
        s = _with(scene, rotation=model)
        runs.append(run_from_scene(label, s, simulate(s)))
    return write_replay(runs, path, max_bytes=max_bytes,
                        title="C12: a spinning cube, the seed's rotation against the "
                              "corrected one")


def demo_c11(path, *, case: str = C11_CASE, duration: float = C11_SECONDS,
             max_bytes: int = REPLAY_MAX_BYTES) -> ReplayInfo:
    """C11: the seed's velocity exchange beside the corrected impulse (side by side)."""
    from refsim.dynamics.simulate import simulate
    from refsim.studies.dynamics import c11_scene

    runs = []
    for response, label in (("seed", "body_response = seed (S8): interpenetrates"),
                            ("impulse", "body_response = impulse (corrected)")):
        s = c11_scene(case, response, duration=duration)
        traj = simulate(s)
        runs.append(run_from_scene(label, s, traj,
                                   settings={"case": case, **traj.settings}))
    return write_replay(runs, path, max_bytes=max_bytes, boxes=True,
                        title=f"C11 ({case}): bodies in slow contact, the seed's velocity "
                              f"exchange against the corrected impulse")


def demo_wall_bounce(path, *, engine: str = "pybullet", scene=None,
                     duration: float = BOUNCE_SECONDS,
                     max_bytes: int = REPLAY_MAX_BYTES) -> ReplayInfo:
    """One wall bounce by refsim beside the same scene run by ``engine``, a
    rigid engine of :data:`refsim.engines.registry.ENGINES` by name
    (default pybullet), shown under its title.

    Raises :class:`refsim.oracles.OracleUnavailable` when that engine is not
    installed, before any simulation runs.
    """
    from refsim.dynamics.simulate import default_every, simulate
    from refsim.engines.registry import build, title

    scene = _for(scene or _bundled("bounce.toml"), duration)
    other = build(engine)
    try:
        external = other.simulate(scene, every=default_every(scene.integration.n_steps))
    finally:
        close = getattr(other, "close", None)
        if close is not None:
            close()
    runs = [run_from_scene("refsim", scene, simulate(scene)),
            run_from_scene(title(engine), scene, external)]
    return write_replay(runs, path, max_bytes=max_bytes,
                        title=f"a wall bounce: refsim beside {title(engine)}")


DEMOS: dict[str, Callable[..., ReplayInfo]] = {
    "c12-spin.html": demo_c12, "c11-interpenetration.html": demo_c11,
    "wall-bounce.html": demo_wall_bounce}


def write_demos(folder, *, max_bytes: int = REPLAY_MAX_BYTES) -> list[ReplayInfo]:
    """All three demo replays into ``folder`` (created if missing)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    return [demo(folder / name, max_bytes=max_bytes) for name, demo in DEMOS.items()]


if __name__ == "__main__":                       # python -m refsim.viewer.demos OUT_DIR
    for info in write_demos(sys.argv[1] if len(sys.argv) > 1 else "."):
        print(info.summary())
