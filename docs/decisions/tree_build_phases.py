"""Where a new mesh's compiled exact-level build spends its time, phase by
phase (docs/decisions/tree-build.md, third round): each phase of the build
as it was before the one compiled call (scaling, column copies, the
topology's ``build_tree``, the vertex copies, ``frame_boxes``, the
FrameTree's links and the packing), then the whole build as the query
makes it now, and, for the one compiled call, its own time and its parts
called alone. This thread's CPU time (``time.thread_time_ns``), medians.

    .venv/bin/python docs/decisions/tree_build_phases.py cube.ac icosphere-5 torus-200000
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from refsim.collision import bvh, bvh_exact  # noqa: E402
from refsim.models.mesh import Mesh  # noqa: E402
from tests.benchmarks import test_bench_tree_build as bench  # noqa: E402


def _timed(function) -> float:
    start = time.thread_time_ns()
    function()
    return (time.thread_time_ns() - start) / 1e6


def _phases(mesh: Mesh, nb) -> dict[str, float]:
    out: dict[str, float] = {}
    box: dict = {}
    steps = [
        ("scale", lambda: box.update(tri=bvh.scaled_triangles(mesh.vertices, mesh.faces))),
        ("columns", lambda: box.update(cols=[np.ascontiguousarray(box["tri"][:, :, j]).ravel()
                                             for j in range(3)])),
        ("build_tree", lambda: box.update(tree=bvh.TriangleTree(
            *nb.build_tree(*box["cols"], bvh.LEAF_SIZE, nb.LEAST_VOLUME)))),
        ("vertex copies", lambda: box.update(
            v=[np.array(mesh.vertices[:, j]) for j in range(3)],
            f=np.array(mesh.faces, dtype=np.int64, order="C"))),
        ("frame_boxes", lambda: box.update(boxes=nb.frame_boxes(
            *box["v"], box["f"], box["tree"].left, box["tree"].right, box["tree"].start,
            box["tree"].count, box["tree"].order))),
        ("links", lambda: box.update(frame=bvh_exact.FrameTree(
            box["tree"], np.ascontiguousarray(np.column_stack(
                [box["tree"].left, box["tree"].right, box["tree"].start,
                 box["tree"].count]).astype(np.int64)),
            box["boxes"][0], float(np.abs(mesh.vertices).max()), float(box["boxes"][1])))),
        ("packing", lambda: (np.concatenate([[box["frame"].reach, box["frame"].axes_deviation],
                                             mesh.vertices.ravel(), box["frame"].boxes.ravel()]),
                             np.concatenate([[mesh.n_vertices, mesh.n_faces,
                                              box["tree"].n_nodes], mesh.faces.ravel(),
                                             box["frame"].links.ravel(), box["tree"].order]))),
    ]
    for name, step in steps:
        out[name] = _timed(step)
    return out


def _build_new(build, vertices, faces) -> float:
    mesh = Mesh(vertices, faces)                 # made outside the timing
    return _timed(lambda: build(mesh))


def _report(name: str, nb) -> None:
    vertices, faces = bench._arrays(name)
    mesh = Mesh(vertices, faces)
    v, f = mesh.vertices, mesh.faces
    rounds = 5 if len(faces) > 50000 else 15 if len(faces) > 5000 else 1001
    build = bench._refsim_build("exact", "compiled")
    build(Mesh(vertices, faces))
    parts = [_phases(mesh, nb) for _ in range(rounds)]
    whole = [_build_new(build, vertices, faces) for _ in range(rounds)]
    tx, ty, tz, _ = nb.scaled_columns(v, f)
    one = {
        "frame_tree_arrays": [_timed(lambda: nb.frame_tree_arrays(v, f, bvh.LEAF_SIZE))
                              for _ in range(rounds)],
        "scaled_columns": [_timed(lambda: nb.scaled_columns(v, f)) for _ in range(rounds)],
        "build_tree": [_timed(lambda: nb.build_tree(tx, ty, tz, bvh.LEAF_SIZE, nb.LEAST_VOLUME))
                       for _ in range(rounds)],
    }
    print(f"{name} ({len(faces)} faces), ms:")
    print("  before's phases: " + ", ".join(
        f"{key} {np.median([p[key] for p in parts]):.4g}" for key in parts[0]))
    print(f"  whole build now (frame_tree_of + _kernel_arrays): {np.median(whole):.4g}")
    print("  " + ", ".join(f"{key} {np.median(t):.4g}" for key, t in one.items()))


def main(names: list[str]) -> None:
    nb = bvh.build_kernels()
    for name in names:
        _report(name, nb)


if __name__ == "__main__":
    main(sys.argv[1:] or ["cube.ac", "icosphere-1", "icosphere-5", "torus-200000"])
