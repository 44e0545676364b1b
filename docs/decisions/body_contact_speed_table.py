"""The figures of body-contact-speed.md.

    python docs/decisions/body_contact_speed_table.py BENCH.json [BENCH.json ...]
        per-step medians of the body-contact benchmark (tests/benchmarks/
        test_bench_dynamics.py::test_body_contact_step), one table per file;
        make the JSON with
        pytest tests/benchmarks/test_bench_dynamics.py -k body_contact -n 0 \\
            --benchmark-json=BENCH.json

    python docs/decisions/body_contact_speed_table.py --stages [N] [STEPS]
        where a step's time goes, refsim compiled: N cubes (default 40) of
        the benchmark's scene after SETTLE_STEPS steps, then STEPS (default
        300) steps one call each; the median step and each stage's mean
        (Simulation.stage_seconds; "loop" is the compiled loop's steps).
"""

from __future__ import annotations

import json
import statistics
import sys
import time


def bench_table(path: str) -> None:
    with open(path, encoding="utf-8") as f:
        runs = json.load(f)["benchmarks"]
    rows: dict[str, dict[str, float]] = {}
    for run in runs:
        if not run["group"].startswith("body-contact step"):
            continue
        per_step = run["stats"]["median"] / run["extra_info"]["steps_per_round"]
        rows.setdefault(run["group"].split(": ", 1)[1], {})[run["extra_info"]["engine"]] = per_step
    print(f"{path}\n")
    print("| scene | refsim compiled (us) | pybullet (us) | MuJoCo (us) | refsim / faster peer |")
    print("| --- | --- | --- | --- | --- |")
    for scene, engines in rows.items():
        refsim, peers = engines.get("refsim-compiled"), [engines.get(k) for k in ("pybullet",
                                                                                     "mujoco")]
        faster = min(p for p in peers if p is not None) if any(peers) else None
        cells = [f"{engines[k] * 1e6:.0f}" if k in engines else "-"
                 for k in ("refsim-compiled", "pybullet", "mujoco")]
        ratio = f"{refsim / faster:.1f}" if refsim and faster else "-"
        print(f"| {scene} | {' | '.join(cells)} | {ratio} |")
    print()


def stages(count: int, steps: int) -> None:
    sys.path.insert(0, "tests/benchmarks")
    from test_bench_dynamics import contact_scene

    from refsim.dynamics.simulation import Simulation
    from refsim.studies.bounce import SETTLE_STEPS

    sim = Simulation(contact_scene(count), kernel="compiled")
    sim.advance(SETTLE_STEPS["cubes"])
    before, loop_before, times = dict(sim.stage_seconds), sim.loop_seconds, []
    for _ in range(steps):
        start = time.perf_counter()
        sim.advance(1)
        times.append(time.perf_counter() - start)
    after = sim.stage_seconds
    print(f"{count} cubes, settled: median step {statistics.median(times) * 1e6:.0f} us")
    for stage, seconds in after.items():
        print(f"  {stage}: {(seconds - before.get(stage, 0.0)) / steps * 1e6:.0f} us per step")
    print(f"  loop: {(sim.loop_seconds - loop_before) / steps * 1e6:.0f} us per step")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--stages"]:
        numbers = [int(a) for a in sys.argv[2:]]
        stages(*(numbers + [40, 300][len(numbers):]))
    else:
        for name in sys.argv[1:]:
            bench_table(name)
