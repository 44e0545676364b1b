"""The compiled loop's seconds per step in two checkouts, alternating fresh
processes (the trial of compiled-loop.md, "The loop as the readable outline").

    python docs/decisions/loop_outline_ab.py BEFORE_CHECKOUT AFTER_CHECKOUT ROUNDS

Each checkout is imported through ``PYTHONPATH`` (its own numba cache: run
each once first to compile). Each round times, in a fresh process per
checkout, ``Simulation.advance(2000)`` after 200 warm-up steps on the step
benchmark's scenes (1, 10 and 40 cubes and the 2000-triangle sphere, each
rotation model; refsim.studies.bounce_scenes.bench_scene), the fastest of three
runs. Prints the median microseconds per step of each side and the median
over the rounds of each scene's after/before ratio.
"""

from __future__ import annotations

import ast
import os
import statistics
import subprocess
import sys

TIMER = r"""
import time
from refsim.dynamics.simulation import Simulation
from refsim.studies.bounce_scenes import bench_scene
out = {}
for bodies in ("1 cube", "10 cubes", "40 cubes", "sphere-2k"):
    for rotation in ("off", "seed", "impulse"):
        scene, _ = bench_scene(bodies, rotation)
        best = float("inf")
        for _ in range(3):
            sim = Simulation(scene, kernel="compiled")
            sim.advance(200)
            start = time.perf_counter()
            sim.advance(2000)
            best = min(best, (time.perf_counter() - start) / 2000)
        out[(bodies, rotation)] = best
print(repr(out))
"""


def time_checkout(path: str) -> dict:
    env = {**os.environ, "PYTHONPATH": os.path.abspath(path)}
    out = subprocess.run([sys.executable, "-c", TIMER], cwd=path, env=env, check=True,
                         capture_output=True, text=True).stdout
    return ast.literal_eval(out.strip().splitlines()[-1])


def main(before: str, after: str, rounds: int) -> None:
    runs: dict[str, list[dict]] = {"before": [], "after": []}
    for _ in range(rounds):
        runs["before"].append(time_checkout(before))
        runs["after"].append(time_checkout(after))
    print("| scene | before (us) | after (us) | median of the rounds' ratios |")
    print("| --- | ---: | ---: | ---: |")
    for key in runs["before"][0]:
        b = statistics.median(r[key] for r in runs["before"])
        a = statistics.median(r[key] for r in runs["after"])
        ratio = statistics.median(x[key] / y[key] for x, y in zip(runs["after"],
                                                                   runs["before"], strict=True))
        print(f"| {key[0]}, rotation {key[1]} | {1e6 * b:.3f} | {1e6 * a:.3f} | {ratio:.3f} |")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], int(sys.argv[3]))
