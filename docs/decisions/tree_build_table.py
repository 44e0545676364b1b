"""The tables of tree-build.md from a pytest-benchmark JSON file.

    .venv/bin/python -m pytest tests/benchmarks/test_bench_tree_build.py \
        --benchmark-only -p no:randomly --benchmark-json=tree.json
    .venv/bin/python docs/decisions/tree_build_table.py tree.json

prints two markdown tables (a run of some of the benchmarks, ``-k``,
leaves the others' cells or rows out), one row per mesh: the median milliseconds of a
new mesh's tree build (refsim's compiled and readable builds for the exact
level, the compiled one for the triangle-aabb level, FCL's BVHModel) with
the compiled builds' ratios to FCL; and of its first boolean query, trees
included, against FCL's build and query.
"""

from __future__ import annotations

import json
import re
import sys
from collections import defaultdict


def _medians(path: str):
    with open(path) as f:
        data = json.load(f)
    builds: dict[str, dict[str, float]] = defaultdict(dict)
    queries: dict[str, dict[str, float]] = defaultdict(dict)
    faces: dict[str, int] = {}
    for bench in data["benchmarks"]:
        params, median = bench["params"], bench["stats"]["median"] * 1e3
        faces[params["name"]] = int(re.search(r"\((\d+) faces\)", bench["group"]).group(1))
        if bench["group"].startswith("tree build"):
            builds[params["name"]][f"{params['engine']} {params['level']}"] = median
        else:
            queries[params["name"]][params["engine"]] = median
    return builds, queries, faces


def _ms(value: float | None) -> str:
    if value is None:
        return ""
    return f"{value:.3g}" if value < 100 else f"{value:.0f}"


def _ratio(value: float | None, reference: float) -> str:
    return "" if value is None else f"{value / reference:.2f}"


def tables(path: str) -> list[str]:
    builds, queries, faces = _medians(path)
    order = sorted(builds, key=lambda name: (not name.endswith(".ac"), faces[name], name))
    lines = ["| mesh | faces | FCL BVHModel | refsim compiled, exact | ratio "
             "| refsim compiled, triangle-aabb | ratio | refsim readable, exact |",
             "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for name in order:
        ms = builds[name]
        fcl = ms["fcl exact"]
        exact, aabb = ms["refsim-compiled exact"], ms.get("refsim-compiled aabb")
        lines.append(f"| {name} | {faces[name]} | {_ms(fcl)} | {_ms(exact)} | {exact / fcl:.2f} "
                     f"| {_ms(aabb)} | {_ratio(aabb, fcl)} "
                     f"| {_ms(ms.get('refsim-readable exact'))} |")
    lines += ["", "| mesh | faces | FCL build + collide | refsim first bodies_collide | ratio |",
              "| --- | ---: | ---: | ---: | ---: |"]
    for name in (n for n in order if n in queries):
        ms = queries[name]
        lines.append(f"| {name} | {faces[name]} | {_ms(ms['fcl'])} | {_ms(ms['refsim'])} "
                     f"| {ms['refsim'] / ms['fcl']:.2f} |")
    return lines


if __name__ == "__main__":
    print("\n".join(tables(sys.argv[1])))
