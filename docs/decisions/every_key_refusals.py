"""Every shipped rigid-body engine on a scene that sets every scene key
beyond the seed's world (docs/decisions/every-key.toml): what each poses,
and the one line with which it refuses what it cannot.

    python docs/decisions/every_key_refusals.py

Prints one row per engine: "ran" with the ball's height after 1 s, or the
refusal's line.
"""

from __future__ import annotations

from pathlib import Path

from refsim.oracles import OracleUnavailable

import refsim
from refsim.engines import load_engine
from refsim.engines.registry import SHIPPED
from refsim.errors import SceneError

SCENE = Path(__file__).with_name("every-key.toml")


def main() -> None:
    scene = refsim.load_scene(SCENE)
    for entry in SHIPPED:
        try:
            engine = load_engine(entry.spec)
        except OracleUnavailable as exc:
            print(f"{entry.name:17s} not installed: {exc}")
            continue
        if not hasattr(engine, "simulate"):
            continue
        try:
            trajectory = engine.simulate(scene)
        except SceneError as exc:
            print(f"{entry.name:17s} refuses: {exc}")
            continue
        y = float(trajectory.position[-1, 1, 1])
        print(f"{entry.name:17s} ran: the ball's centre at y = {y:.4f} m after 1 s")


if __name__ == "__main__":
    main()
