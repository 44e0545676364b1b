"""Seconds of the exact level's readable query (``intersecting_pairs`` and
``bodies_collide`` with ``kernel="readable"``, trees already built): median
of ROUNDS calls per case, and the node pairs the readable traversal visits
and the pairs it finds (which must not change with its arithmetic).

    python docs/decisions/readable_traversal_time.py [ROUNDS]

Used in docs/decisions/readable-floats.md, run in a checkout of the code
before and after a change (each with its own numba cache)."""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

from refsim.collision import bvh_exact
from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.models.loading import load_model


def turned(angle: float, offset) -> tuple[np.ndarray, np.ndarray]:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), np.asarray(offset, float)


HERE = (np.eye(3), np.zeros(3))
CASES = {
    "sphere-2k, overlapping by a tenth": ("sphere-2k.ac", turned(0.3, [1.9, 0.2, 0.1])),
    "sphere-2k, apart by a tenth": ("sphere-2k.ac", turned(0.3, [2.1, 0.2, 0.1])),
    "torus, linked": ("torus.ac", (np.array([[1.0, 0, 0], [0, 0, -1.0], [0, 1.0, 0]]),
                                   np.array([1.0, 0.0, 0.0]))),
    "cube, corner into face": ("cube.ac", turned(0.7, [0.95, 0.2, 0.1])),
}


def main(rounds: int) -> None:
    print("| case | pairs (ms) | collide (ms) | node pairs visited | pairs found |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for name, (model, pose) in CASES.items():
        mesh = load_model(model)
        bvh_exact.frame_tree_of(mesh, "compiled")                 # built once, not timed
        found = intersecting_pairs(mesh, HERE, mesh, pose, kernel="readable")
        _, visits = bvh_exact.descend(mesh, HERE, mesh, pose)
        times = {"pairs": [], "collide": []}
        for _ in range(rounds):
            start = time.perf_counter()
            intersecting_pairs(mesh, HERE, mesh, pose, kernel="readable")
            times["pairs"].append(time.perf_counter() - start)
            start = time.perf_counter()
            bodies_collide(mesh, HERE, mesh, pose, kernel="readable")
            times["collide"].append(time.perf_counter() - start)
        pairs_ms, collide_ms = (1e3 * statistics.median(times[k]) for k in ("pairs", "collide"))
        print(f"| {name} | {pairs_ms:.1f} | {collide_ms:.1f} | {visits} | {len(found)} |",
              flush=True)


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 7)
