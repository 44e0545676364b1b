"""The table of mesh-family-queries.md from a pytest-benchmark JSON file.

    .venv/bin/python -m pytest tests/benchmarks/test_bench_mesh_family.py \
        --benchmark-only -p no:randomly --benchmark-json=family.json
    .venv/bin/python docs/decisions/mesh_family_table.py family.json

prints one markdown row per mesh and pose, refsim's median over FCL's from
the same run, sorted by that ratio, then the distribution of the ratios.
"""

from __future__ import annotations

import json
import statistics
import sys


def main(path: str) -> None:
    with open(path) as f:
        data = json.load(f)
    medians = {}
    for bench in data["benchmarks"]:
        p = bench["params"]
        medians[(p["name"], p["kind"], p["engine"])] = bench["stats"]["median"] * 1e6
    rows = sorted((medians[(n, k, "refsim")] / medians[(n, k, "fcl-posed")], n, k,
                   medians[(n, k, "refsim")], medians[(n, k, "fcl-posed")])
                  for n, k, e in medians if e == "refsim")
    print("| mesh | pose | refsim (us) | FCL, poses set per query (us) | ratio |")
    print("| --- | --- | ---: | ---: | ---: |")
    for ratio, name, kind, mine, theirs in rows:
        print(f"| {name} | {kind} | {mine:.2f} | {theirs:.2f} | {ratio:.2f} |")
    ratios = [r[0] for r in rows]
    quartiles = statistics.quantiles(ratios, n=4)
    print(f"\n{len(ratios)} cases: median ratio {statistics.median(ratios):.2f}, quartiles "
          f"{quartiles[0]:.2f} and {quartiles[2]:.2f}, best {min(ratios):.2f}, worst "
          f"{max(ratios):.2f}; at or under 1.0: {sum(r <= 1.0 for r in ratios)}")


if __name__ == "__main__":
    main(sys.argv[1])
