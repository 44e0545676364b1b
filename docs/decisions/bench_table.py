"""The step-cost table of compiled-loop.md from a pytest-benchmark JSON file.

    .venv/bin/python -m pytest tests/benchmarks/test_bench_dynamics.py -k test_step \
        --benchmark-only --benchmark-json=dyn.json
    .venv/bin/python docs/decisions/bench_table.py dyn.json

prints one markdown row per scene, rotation and state: the median
microseconds per step of refsim (readable, compiled), pybullet and MuJoCo,
each a round's median divided by its steps per round (``extra_info``), and
refsim's ratios to the faster of pybullet and MuJoCo.
"""

from __future__ import annotations

import json
import sys
from collections import defaultdict


def table(path: str) -> list[str]:
    with open(path) as f:
        data = json.load(f)
    groups: dict[str, dict[str, float]] = defaultdict(dict)
    for bench in data["benchmarks"]:
        info = bench["extra_info"]
        groups[bench["group"]][info["engine"]] = (bench["stats"]["median"]
                                                 / info["steps_per_round"] * 1e6)
    lines = ["| bodies | rotation | state | refsim readable | refsim compiled | pybullet "
             "| MuJoCo | compiled / faster peer | readable / faster peer |",
             "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for group, us in groups.items():
        bodies, rotation, state = group.split(": ", 1)[1].split(", ")
        peer = min(us["pybullet"], us["mujoco"])
        lines.append(
            f"| {bodies} | {rotation.split()[1]} | {state} | {us['refsim-readable']:.1f} "
            f"| {us['refsim-compiled']:.2f} | {us['pybullet']:.2f} | {us['mujoco']:.2f} "
            f"| {us['refsim-compiled'] / peer:.2f} | {us['refsim-readable'] / peer:.0f} |")
    return lines


if __name__ == "__main__":
    print("\n".join(table(sys.argv[1])))
