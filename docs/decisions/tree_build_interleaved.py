"""A new mesh's exact-level build (what tests/benchmarks/test_bench_tree_build.py
times: ``frame_tree_of`` and the packed arrays the query keeps, compiled) against
python-fcl's ``BVHModel`` build, the two alternating in one process: on a
shared, loaded machine this reads both under the same load.

    .venv/bin/python docs/decisions/tree_build_interleaved.py [mesh ...]

Meshes are the benchmark's (``icosphere-s``, ``torus-n``, bundled ``*.ac``);
by default a set from 12 to 200k faces. Per mesh: ROUNDS rounds of one
refsim build (on a new Mesh made outside the timing) and one FCL build,
each timed by this thread's CPU time (``time.thread_time``); the medians and
their ratio. The Mesh is timed apart (``Mesh(vertices, faces)``: welding and
checks), and the last column is the median of Mesh and trees over FCL's.
Each tree is checked against the first one built.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from refsim.oracles.fcl_adapter import FCLOracle  # noqa: E402

from refsim.models.mesh import Mesh  # noqa: E402
from tests.benchmarks import test_bench_tree_build as bench  # noqa: E402

DEFAULT = ["cube.ac", "icosphere-1", "icosphere-3", "torus.ac", "icosphere-4", "torus-20000",
           "icosphere-5", "icosphere-6", "torus-200000"]


def main(names: list[str]) -> None:
    fcl = FCLOracle().fcl
    print("| mesh | faces | FCL BVHModel (ms) | refsim compiled, exact (ms) | ratio "
          "| refsim Mesh() (ms) | Mesh and trees over FCL |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name in names or DEFAULT:
        vertices, faces = bench._arrays(name)
        faces32 = np.ascontiguousarray(faces, dtype=np.int32)
        rounds = 5 if len(faces) > 50000 else 15 if len(faces) > 5000 else 41
        build = bench._refsim_build("exact", "compiled")
        first = build(Mesh(vertices, faces))
        ours, theirs, meshes = [], [], []
        for _ in range(rounds):
            start = time.thread_time()
            mesh = Mesh(vertices, faces)
            meshes.append(time.thread_time() - start)
            start = time.thread_time()
            tree = build(mesh)
            ours.append(time.thread_time() - start)
            assert np.array_equal(tree.order, first.order)
            start = time.thread_time()
            bench._fcl_model(fcl, vertices, faces32)
            theirs.append(time.thread_time() - start)
        a, b = float(np.median(ours)) * 1e3, float(np.median(theirs)) * 1e3
        c = float(np.median(np.add(ours, meshes))) * 1e3
        print(f"| {name} | {len(faces)} | {b:.3g} | {a:.3g} | {a / b:.2f} "
              f"| {float(np.median(meshes)) * 1e3:.3g} | {c / b:.2f} |", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
