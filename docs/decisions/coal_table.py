"""coal on the conformance kit's cases, disagreement by disagreement, and
coal's world box against the exact one (docs/decisions/coal.md).

    python docs/decisions/coal_table.py [CASES [SEED]]

Default: 200 cases, seed 0 (``refsim conform``'s). The first table splits
each geometric check's disagreements by family, by direction (coal says
"intersect" where the truth is apart, or the reverse) and by whether the
gap is within the rounding bound; the second measures
``CollisionObject.computeAABB`` on the kit's box cases, the reason the
adapter offers no ``aabb``.
"""

from __future__ import annotations

import sys
from collections import Counter

import numpy as np
from refsim.oracles.coal_adapter import CoalEngine

from refsim.conformance.cases_boxes import box_cases
from refsim.conformance.checks_geometry import (
    check_aabb_encloses,
    check_aabb_tight,
    classify_collide,
    classify_pairs,
    classify_triangles,
)
from refsim.conformance.registry import build_cases


def _row(check: str, found: list, cases: int, extra: str = "") -> str:
    """A table row of ``found``: (family, direction, class at tolerance 0, gap)."""
    families = Counter(f for f, _, _, _ in found)
    directions = Counter(d for _, d, _, _ in found)
    beyond = sum(1 for _, _, kind, _ in found if kind == "bug")
    largest = max((gap for _, _, _, gap in found), default=0.0)
    return (f"| {check} | {len(found)} of {cases} | "
            f"{', '.join(f'{f} {n}' for f, n in sorted(families.items()))} | "
            f"{', '.join(f'{d} {n}' for d, n in sorted(directions.items()))}{extra} | "
            f"{beyond} | {largest:.2g} |")


def disagreements(engine: CoalEngine, cases: int, seed: int) -> None:
    sets = build_cases(("triangles", "poses"), cases, seed)
    triangles = []
    for p in sets["triangles"].pairs:
        got = engine.triangles_intersect(p.a, p.b)
        if got != p.truth:
            verdict = classify_triangles(p.a, p.b, 0.0)      # "bug": beyond the rounding bound
            triangles.append((p.family, "false intersect" if got else "false apart",
                              verdict["class"], verdict["gap_metres"]))
    pairs, collide, extra, missing = [], [], 0, 0
    for c in sets["poses"].cases:
        args = (c.mesh_a.vertices, c.mesh_a.faces, c.pose_a,
                c.mesh_b.vertices, c.mesh_b.faces, c.pose_b)
        got = engine.intersecting_pairs(*args)
        truth = {tuple(r) for r in np.asarray(c.truth).tolist()}
        answer = {tuple(r) for r in got.tolist()}
        if truth != answer:
            verdict = classify_pairs(c, got, 0.0)
            extra, missing = extra + len(answer - truth), missing + len(truth - answer)
            pairs.append((c.family, "extra pairs" if answer > truth else "pairs missed",
                          verdict["class"], verdict["gap_metres"]))
        hit = engine.bodies_collide(*args)
        if hit != bool(truth):
            verdict = classify_collide(c, hit, 0.0)
            collide.append((c.family, "false collide" if hit else "false apart",
                            verdict["class"], verdict.get("gap_metres", 0.0)))
    print(f"coal against the exact answers, {cases} cases, seed {seed}:\n")
    print("| check | disagree | by family | direction | beyond rounding | largest gap, m |")
    print("| --- | --- | --- | --- | --- | --- |")
    print(_row("triangles.agreement", triangles, cases))
    print(_row("pairs.agreement", pairs, cases,
               f" ({extra} face pairs extra, {missing} missed)"))
    print(_row("collide.agreement", collide, cases))


class _WorldBoxes:
    """coal's world box of a posed point cloud as an ``aabb`` engine, for
    this measurement only (the adapter does not offer it)."""

    name = "coal computeAABB"

    def __init__(self, lib):
        self.coal = lib

    def aabb(self, vertices, pose):
        model = self.coal.BVHModelOBBRSS()
        model.beginModel(0, len(vertices))
        model.addVertices(np.ascontiguousarray(vertices, dtype=np.float64))
        model.endModel()
        posed = self.coal.CollisionObject(model, self.coal.Transform3s(*pose))
        posed.computeAABB()
        box = posed.getAABB()
        return np.array(box.min_), np.array(box.max_)


def boxes(engine: CoalEngine, cases: int, seed: int) -> None:
    boxes_engine = _WorldBoxes(engine.coal)
    case_set = box_cases(cases, seed)
    print(f"\ncoal's CollisionObject.computeAABB on the kit's box cases ({cases}, seed {seed}):\n")
    print("| check | failed | largest excess, m |")
    print("| --- | --- | --- |")
    for check in (check_aabb_encloses, check_aabb_tight):
        result = check(boxes_engine, case_set)
        print(f"| aabb.{result.check} | {result.failed} of {result.cases} | "
              f"{result.measured['largest_excess_metres']:.3g} |")
    ratio = 0.0
    for c in case_set.cases:
        lo, hi = boxes_engine.aabb(c.vertices, c.pose)
        rotation, translation = c.pose
        world = c.vertices @ rotation.T + translation
        half = (c.vertices.max(axis=0) - c.vertices.min(axis=0)).max() / 2
        if half > 0:
            excess = max((world.min(axis=0) - lo).max(), (hi - world.max(axis=0)).max())
            ratio = max(ratio, excess / half)
    print(f"\nlargest excess over the largest half-extent: {ratio:.3f} "
          f"(bound 4/sqrt(3) = {4 / 3 ** 0.5:.3f})")


if __name__ == "__main__":
    cases = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    seed = int(sys.argv[2]) if len(sys.argv) > 2 else 0
    coal = CoalEngine()
    disagreements(coal, cases, seed)
    boxes(coal, cases, seed)
