"""The trials behind query-fixed-cost.md.

    .venv/bin/python docs/decisions/query_cost_trials.py calls
    .venv/bin/python docs/decisions/query_cost_trials.py splits
    .venv/bin/python docs/decisions/query_cost_trials.py table before.json after.json

``calls`` times what a compiled query pays around its work: numba's
dispatch per argument (writable and read-only arrays, floats), boxing what
it returns, reshaping a slice, allocating per-query arrays, packing two
poses into one array in Python, and reading an unset environment variable
(best of 9 repeats, nanoseconds a call).
``splits`` counts the node pairs the readable exact traversal visits on the
benchmark poses over the least-area tree and the least-volume tree.
``table`` prints the refsim/FCL medians and ratios of one or more JSON
files (say, before and after a change) of

    .venv/bin/python -m pytest tests/benchmarks/test_bench_collision.py \
        -k "fixed_cost or test_boolean or test_all_pairs or touching" \
        --benchmark-only -p no:randomly --benchmark-json=before.json
"""

from __future__ import annotations

import json
import os
import sys
import timeit
from collections import defaultdict

import numpy as np


def best_ns(call, number: int = 20000) -> float:
    return min(timeit.repeat(call, number=number, repeat=9)) / number * 1e9


def calls() -> None:
    import numba

    def kernel_of(n):
        names = ", ".join(f"x{i}" for i in range(n))
        namespace: dict = {}
        exec(f"def f({names}):\n    return 0\n", namespace)
        return numba.njit(namespace["f"])

    writable = [np.zeros((100, 3)) for _ in range(21)]
    frozen = [a.copy() for a in writable]
    for a in frozen:
        a.flags.writeable = False
    floats = [1.0] * 21
    print("arguments | writable arrays | read-only arrays | floats (ns a call)")
    for n in (0, 1, 2, 4, 8, 16, 21):
        f = kernel_of(n)
        row = []
        for args in (writable[:n], frozen[:n], floats[:n]):
            f(*args)
            row.append(best_ns(lambda f=f, args=args: f(*args)))
        print(f"{n} | " + " | ".join(f"{t:.0f}" for t in row))

    pairs = np.zeros((10, 2), dtype=np.int64)
    returns = {
        "an int": numba.njit(lambda a: 0),
        "one array": numba.njit(lambda a: a[:0]),
        "(int, array, array)": numba.njit(lambda a: (0, a[:0], a[:0])),
    }
    for label, f in returns.items():
        f(pairs)
        print(f"returning {label}: {best_ns(lambda f=f: f(pairs)):.0f} ns")

    @numba.njit
    def reshape_eight(x):
        total = 0.0
        for k in range(8):
            total += x[k:k + 9].reshape((3, 3))[1, 1]
        return total

    @numba.njit
    def slice_eight(x):
        total = 0.0
        for k in range(8):
            total += x[k:k + 9][4]
        return total

    x = np.arange(20.0)
    for f in (reshape_eight, slice_eight):
        f(x)
        print(f"{f.__name__}: {best_ns(lambda f=f: f(x)):.0f} ns")

    @numba.njit
    def many_arrays(nv, nf, nn):          # the per-query arrays, one allocation each
        arrays = (np.empty((nn, 12)), np.empty((nv, 3)), np.empty((nv, 3)),
                  np.empty((nf, 6)), np.empty((nf, 6)), np.empty((nn, 6)),
                  np.empty((nn, 6)), np.empty((3, 3)), np.empty((3, 3)),
                  np.empty((3, 3)), np.empty(3), np.empty(3), np.empty(3))
        flags = (np.zeros(nv, np.bool_), np.zeros(nv, np.bool_), np.zeros(nf, np.bool_),
                 np.zeros(nf, np.bool_), np.zeros(nn, np.bool_), np.zeros(nn, np.bool_))
        return len(arrays) + len(flags)

    @numba.njit
    def two_blocks(nv, nf, nn):           # carved out of one float and one flag array
        block = np.empty(12 + 12 * nn + 6 * nv + 12 * nf + 12 * nn)
        flags = np.zeros(2 * nv + 2 * nf + 3 * nn, np.bool_)
        return block.shape[0] + flags.shape[0]

    for f in (many_arrays, two_blocks):
        f(1002, 2000, 1023)
        print(f"{f.__name__} (2k-triangle meshes): "
              f"{best_ns(lambda f=f: f(1002, 2000, 1023)):.0f} ns")

    rotation, translation = np.eye(3), np.zeros(3)
    pair = np.empty(24)

    def by_slices():
        pair[:9], pair[9:12] = rotation.ravel(), translation
        pair[12:21], pair[21:] = rotation.ravel(), translation

    print(f"two poses packed into one array by slices: {best_ns(by_slices):.0f} ns, by "
          f"np.concatenate: {best_ns(lambda: np.concatenate((rotation.ravel(), translation, rotation.ravel(), translation))):.0f} ns")  # noqa: E501

    from refsim.kernels import KERNELS_ENV, _environment_kernel

    os.environ.pop(KERNELS_ENV, None)
    print(f"os.environ.get of an unset variable: "
          f"{best_ns(lambda: os.environ.get(KERNELS_ENV)):.0f} ns")
    print(f"refsim.kernels._environment_kernel: {best_ns(_environment_kernel):.0f} ns")


def splits() -> None:
    from refsim.bundled import models_dir
    from refsim.collision import bvh_exact
    from refsim.collision.bvh import tree_of
    from refsim.models.loading import load_model
    from refsim.studies.levels import SPEED_CONFIGURATIONS

    identity = (np.eye(3), np.zeros(3))
    turn_x = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    poses = {"torus-linked": ("torus.ac", "torus.ac", identity,
                              (turn_x, np.array([1.0, 0.0, 0.0]))),
             "cube-on-sphere": ("sphere-2k.ac", "cube.ac", identity,
                                (np.eye(3), np.array([0.0, 1.5, 0.0])))}
    for c in SPEED_CONFIGURATIONS:
        configuration = c.as_configuration()
        (mesh_a, mesh_b), (pose_a, pose_b) = configuration.meshes(), configuration.poses()
        poses[f"{c.model}-{c.kind}"] = (mesh_a.source, mesh_b.source, pose_a, pose_b)
    print("pose | least-area tree | least-volume tree (node pairs visited)")
    for name, (model_a, model_b, pose_a, pose_b) in poses.items():
        counts = []
        for split in ("area", "volume"):
            mesh_a, mesh_b = (load_model(models_dir() / model) for model in (model_a, model_b))
            if split == "area":                     # the triangle-aabb level's tree
                for mesh in (mesh_a, mesh_b):
                    mesh.derived("frame_topology", tree_of)
            counts.append(bvh_exact.descend(mesh_a, pose_a, mesh_b, pose_b)[1])
        print(f"{name} | {counts[0]} | {counts[1]}")


def medians(path: str) -> dict[str, dict[str, float]]:
    """Median microseconds of each benchmark group, by engine."""
    with open(path) as f:
        data = json.load(f)
    groups: dict[str, dict[str, float]] = defaultdict(dict)
    for bench in data["benchmarks"]:
        groups[bench["group"]][bench["params"]["engine"]] = bench["stats"]["median"] * 1e6
    return groups


def table(*paths: str) -> None:
    """One row a benchmark group: refsim, FCL and their ratio from each JSON
    file in turn (before, after)."""
    runs = [medians(path) for path in paths]
    print("| query | configuration |" + " refsim (us) | FCL (us) | ratio |" * len(runs))
    print("| --- | --- |" + " ---: | ---: | ---: |" * len(runs))
    for group in runs[0]:
        query, configuration = group.split(": ", 1)
        cells = []
        for run in runs:
            us = run[group]
            refsim_us, fcl_us = us["refsim-bvh"], us.get("fcl-posed", us.get("fcl"))
            cells.append(f" {refsim_us:.1f} | {fcl_us:.1f} | {refsim_us / fcl_us:.2f} |")
        print(f"| {query} | {configuration} |" + "".join(cells))


if __name__ == "__main__":
    {"calls": calls, "splits": splits, "table": table}[sys.argv[1]](*sys.argv[2:])
