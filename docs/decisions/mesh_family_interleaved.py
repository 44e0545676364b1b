"""The boolean query on the generated family (tests/benchmarks/test_bench_mesh_family.py's
meshes and poses), refsim against python-fcl with poses set per query, timed
in alternating blocks in one process: on a shared, loaded machine this
reads the two engines under the same load, where pytest-benchmark times
one engine's rounds and then the other's.

    .venv/bin/python docs/decisions/mesh_family_interleaved.py [mesh ...]

Per case: blocks of BLOCK calls, refsim's block then FCL's, ROUNDS times;
each block's CPU time of this thread (``time.thread_time``, which leaves
out the time the thread waits for a core) over BLOCK; the medians of the
blocks and their ratio. Prints a markdown table and the distribution of
the ratios. Trees are built before timing; every answer is checked against
refsim's exact one.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from refsim.oracles.fcl_adapter import FCLOracle  # noqa: E402

from refsim.collision.bodies import bodies_collide  # noqa: E402
from tests.benchmarks import test_bench_mesh_family as family  # noqa: E402
from tests.benchmarks.test_bench_collision import PosedFCL  # noqa: E402

BLOCK, ROUNDS = 200, 15


def _block(call, *args) -> float:
    start = time.thread_time()
    for _ in range(BLOCK):
        call(*args)
    return (time.thread_time() - start) / BLOCK * 1e6


def main(names: list[str]) -> None:
    oracle = FCLOracle()
    rows = []
    for name, kind in family.CASES:
        if names and name not in names:
            continue
        mesh, pose = family._mesh(name), family._pose(name, kind)
        truth = bodies_collide(mesh, family.IDENTITY, mesh, pose)
        posed = PosedFCL(oracle, mesh, mesh)
        assert posed.collide(family.IDENTITY, pose) == truth
        ours, theirs = [], []
        for _ in range(ROUNDS):
            ours.append(_block(bodies_collide, mesh, family.IDENTITY, mesh, pose))
            theirs.append(_block(posed.collide, family.IDENTITY, pose))
        rows.append((name, kind, float(np.median(ours)), float(np.median(theirs))))
    rows.sort(key=lambda r: r[2] / r[3])
    print("| mesh | pose | refsim (us) | FCL, poses set per query (us) | ratio |")
    print("| --- | --- | ---: | ---: | ---: |")
    for name, kind, a, b in rows:
        print(f"| {name} | {kind} | {a:.2f} | {b:.2f} | {a / b:.2f} |")
    ratios = np.array([a / b for _, _, a, b in rows])
    q1, median, q3 = np.percentile(ratios, [25, 50, 75])
    print(f"\n{len(ratios)} cases: median ratio {median:.2f}, quartiles {q1:.2f} and {q3:.2f}, "
          f"best {ratios.min():.2f}, worst {ratios.max():.2f}; "
          f"at or under 1.0: {int((ratios <= 1.0).sum())}")


if __name__ == "__main__":
    main(sys.argv[1:])
