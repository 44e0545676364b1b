"""Bounce times of the kit's drops against free fall (docs/decisions/bounce-timing.md).

    python docs/decisions/bounce_time_table.py [--steps H ...] [--solver S]

Each drop of the conformance kit (``drop-*``) runs on refsim's corrected
model at each step; the first three bounces' instants are read by
extrapolating the arc after each bounce back to the floor (the height of
the lowest vertex) and compared with t_1 = sqrt(2 H / g), t_(k+1) = t_k +
2 e^k t_1. Printed: each bounce's error in steps (h).
"""

from __future__ import annotations

import argparse
import math
from dataclasses import replace

import numpy as np

import refsim
from refsim.conformance import cases_rigid as R

G = 9.81
CORRECTED = {"rotation": "impulse", "body_response": "impulse", "wall_response": "impulse"}


def bounce_errors(scene: R.RigidScene, step: float, solver: str) -> list[float]:
    scene = R.with_step(scene, step)
    integration = replace(scene.scene.integration, solver=solver)
    posed = replace(scene.scene, integration=integration,
                    dynamics=replace(scene.scene.dynamics, **CORRECTED))
    tr = refsim.simulate(posed, every=1)
    t, vy = np.asarray(tr.t), np.asarray(tr.velocity)[:, 0, 1]
    y = R.lowest_height(scene, tr)
    e = posed.world.restitution
    t1 = math.sqrt(2.0 * y[0] / G)
    up = np.flatnonzero((vy[:-1] < 0.0) & (vy[1:] > 0.0)) + 1
    errors = []
    for k, i in enumerate(up[:3]):
        exact = t1 + sum(2.0 * e ** j * t1 for j in range(1, k + 1))
        s = (-vy[i] + math.sqrt(vy[i] ** 2 + 2.0 * G * max(y[i], 0.0))) / G
        errors.append((t[i] - s - exact) / step)
    return errors


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--steps", type=float, nargs="*", default=[2e-3, 1e-3, 5e-4])
    parser.add_argument("--solver", default="rk4")
    args = parser.parse_args()
    drops = [s for s in R.rigid_scenes() if s.name.startswith("drop-")]
    print(f"solver {args.solver}; error of bounces 1-3 in steps (h)\n")
    print("| drop | h | bounce 1 | bounce 2 | bounce 3 |\n| --- | --- | --- | --- | --- |")
    for scene in drops:
        for step in args.steps:
            cells = " | ".join(f"{e:+.2g}" for e in bounce_errors(scene, step, args.solver))
            print(f"| {scene.name} | {step:g} | {cells} |")


if __name__ == "__main__":
    main()
