"""Node pairs the readable exact traversal visits (``bvh_exact.descend``)
over trees built by candidate split rules, on the generated family of
tests/benchmarks/test_bench_mesh_family.py (every mesh and pose) and the
configurations of docs/decisions/query-fixed-cost.md's split table.

    .venv/bin/python docs/decisions/split_rule_trials.py RULE [TIE [SMALL]]

RULE: ``least-volume`` (the rule before its tie-break), ``obb-area`` (the
least total oriented-box area of the halves), ``volume-then-area`` (among
the axes within TIE of the least volume, default 0.1, the least area, each
half's box along the half's own principal axes: with TIE 0.1 the rule
bvh_exact.least_volume_split kept until the node-frame split),
``node-frame-volume-then-area`` (the same with every half's box along the
node's principal axes in a node of at most SMALL triangles, default
bvh_exact.SMALL_NODE: with TIE 0.1 and the default, the rule kept in
bvh_exact.least_volume_split; with SMALL 0 every half is measured in its
own frame, the rule before, and with SMALL above the largest mesh every
half in its node's frame). Prints ``rule | case | node pairs``,
one line a case. The trees are built by the readable build with the rule
(seconds a mesh).
"""

from __future__ import annotations

import functools
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from refsim.bundled import models_dir  # noqa: E402
from refsim.collision import bvh, bvh_exact  # noqa: E402
from refsim.models.loading import load_model  # noqa: E402
from refsim.models.mesh import Mesh  # noqa: E402
from refsim.studies.levels import SPEED_CONFIGURATIONS  # noqa: E402
from tests.benchmarks import test_bench_mesh_family as family  # noqa: E402


def _halves(triangles, members, mid):
    """The node's points and its members ranked along each principal axis."""
    points = triangles[members]
    axes = bvh_exact.principal_axes(points.reshape(-1, 3))
    centroids = bvh_exact.project(points.mean(axis=1), axes)
    for axis in range(3):
        ranked = np.lexsort((members, centroids[:, axis]))
        yield (ranked, bvh_exact.box_sides(points[ranked[:mid]].reshape(-1, 3)),
               bvh_exact.box_sides(points[ranked[mid:]].reshape(-1, 3)))


def least_volume(triangles, members, mid):
    best, best_volume = None, np.inf
    for ranked, first, second in _halves(triangles, members, mid):
        volume = float(np.prod(first)) + float(np.prod(second))
        if volume < best_volume:
            best, best_volume = ranked, volume
    return members[best]


def obb_area(triangles, members, mid):
    best, best_area = None, np.inf
    for ranked, first, second in _halves(triangles, members, mid):
        area = bvh_exact.box_area(first) + bvh_exact.box_area(second)
        if area < best_area:
            best, best_area = ranked, area
    return members[best]


def volume_then_area(tie):
    def split(triangles, members, mid):
        rows = [(float(np.prod(f)) + float(np.prod(s)),
                 bvh_exact.box_area(f) + bvh_exact.box_area(s), r)
                for r, f, s in _halves(triangles, members, mid)]
        least = min(volume for volume, _, _ in rows)
        best = None
        for volume, area, ranked in rows:
            if volume <= least * (1.0 + tie) and (best is None or area < best[0]):
                best = (area, ranked)
        return members[best[1]]
    return split


def _cases():
    cases = []
    for name in family.MESHES:
        for kind in (*family.POSES, "linked"):
            if kind != "linked" or name in family.LINKED:
                cases.append((f"{name} {kind}", name, name, family.IDENTITY,
                              family._pose(name, kind)))
    turn_x = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    cases.append(("torus-linked", "torus.ac", "torus.ac", family.IDENTITY,
                  (turn_x, np.array([1.0, 0.0, 0.0]))))
    cases.append(("cube-on-sphere", "sphere-2k.ac", "cube.ac", family.IDENTITY,
                  (np.eye(3), np.array([0.0, 1.5, 0.0]))))
    for c in SPEED_CONFIGURATIONS:
        configuration = c.as_configuration()
        (mesh_a, mesh_b), (pose_a, pose_b) = configuration.meshes(), configuration.poses()
        cases.append((f"{c.model}-{c.kind}", Path(mesh_a.source).name,
                      Path(mesh_b.source).name, pose_a, pose_b))
    return cases


def _arrays(name):
    if name.endswith(".ac") and name not in family.MESHES:
        model = load_model(models_dir() / name)
        return model.vertices, model.faces
    return family._arrays(name)


def main(rule_name: str, tie: float = 0.1, small: int = bvh_exact.SMALL_NODE) -> None:
    rule = {"least-volume": least_volume, "obb-area": obb_area,
            "volume-then-area": volume_then_area(tie),
            "node-frame-volume-then-area": functools.partial(bvh_exact.least_volume_split,
                                                             tie=tie, small=small)}[rule_name]
    meshes: dict[str, Mesh] = {}
    for label, name_a, name_b, pose_a, pose_b in _cases():
        for name in (name_a, name_b):
            if name not in meshes:
                mesh = Mesh(*_arrays(name))
                tree = bvh.build_tree(mesh.vertices, mesh.faces, split=rule)
                mesh.derived("frame_topology", lambda m, tree=tree: tree)
                meshes[name] = mesh
        visits = bvh_exact.descend(meshes[name_a], pose_a, meshes[name_b], pose_b,
                                   kernel="readable")[1]
        print(f"{rule_name} | {label} | {visits}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], *(float(x) for x in sys.argv[2:3]), *(int(x) for x in sys.argv[3:4]))
