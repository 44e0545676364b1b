"""The readable step with its contact solve and torque-free rotation on
numpy arrays ("arrays", as before) and on Python floats ("floats",
refsim.kernels.python_floats), alternating in one process: seconds of
``Simulation(scene, kernel="readable").run(n)``, median of the runs, and
whether the two give the same bits (state, frames and events).

    python docs/decisions/readable_floats_ab.py [ROUNDS]

Used in docs/decisions/readable-floats.md. ROUNDS (default 5) runs of each
scene per variant."""

from __future__ import annotations

import statistics
import sys
import time

from refsim import kernels
from refsim.dynamics import impulse, rotation_impulse
from refsim.dynamics.simulation import Simulation
from refsim.scenes.loader import load_scene, scene_from_dict
from refsim.studies.bounce_scenes import cubes_scene

#: each variant: what the two pairs' readable side is
VARIANTS = {
    "arrays": (impulse.solve_contacts_python, rotation_impulse.free_rotation_steps),
    "floats": (impulse.solve_contacts_readable, rotation_impulse.free_rotation_steps_readable),
}


def long_box_at_the_walls():
    """A spinning long box thrown at the walls, then tumbling on the floor."""
    return scene_from_dict({
        "world": {"half_size": 2.0, "restitution": 0.7, "friction": 0.3},
        "integration": {"solver": "euler", "step": 1e-3, "duration": 10.0},
        "collision": {"level": "none"},
        "dynamics": {"rotation": "impulse"},
        "body": [{"name": "body", "model": "long-box.ac", "position": [0.0, 0.5, 0.0],
                  "velocity": [3.0, -2.0, 1.5], "angular_velocity": [2.0, -4.0, 6.0]}]})


SCENES = {
    "long box at the walls, 1500 steps": (long_box_at_the_walls, 1500),
    "40 cubes, impulse, rk4, 2500 steps": (
        lambda: cubes_scene(40, "impulse", seed=4, solver="rk4"), 2500),
    "spinning-cube.toml, 2000 steps": (lambda: load_scene("spinning-cube.toml"), 2000),
    "mixed.toml, 2000 steps": (lambda: load_scene("mixed.toml"), 2000),
}


def run(scene, steps: int, variant: str) -> tuple[float, Simulation]:
    kernels.CONTACT_IMPULSES._readable, kernels.FREE_ROTATION_STEPS._readable = \
        VARIANTS[variant]
    sim = Simulation(scene, kernel="readable")
    sim.record()
    start = time.perf_counter()
    sim.run(steps)
    return time.perf_counter() - start, sim


def same(a: Simulation, b: Simulation) -> bool:
    ta, tb = a.trajectory(), b.trajectory()
    return (all(getattr(ta, k).tobytes() == getattr(tb, k).tobytes()
                for k in ("t", "position", "velocity", "angular_velocity", "orientation"))
            and ta.events == tb.events)


def main(rounds: int) -> None:
    print("| scene | arrays (s) | floats (s) | ratio | same bits |")
    print("| --- | ---: | ---: | ---: | --- |")
    for name, (make, steps) in SCENES.items():
        scene = make()
        seconds: dict[str, list[float]] = {v: [] for v in VARIANTS}
        alike = True
        for _ in range(rounds):
            sims = {}
            for variant in VARIANTS:
                elapsed, sims[variant] = run(scene, steps, variant)
                seconds[variant].append(elapsed)
            alike = alike and same(sims["arrays"], sims["floats"])
        old, new = (statistics.median(seconds[v]) for v in VARIANTS)
        print(f"| {name} | {old:.2f} | {new:.2f} | {new / old:.2f} | {alike} |", flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
