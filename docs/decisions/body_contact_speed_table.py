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

    python docs/decisions/body_contact_speed_table.py --narrow [N]
        the narrow phase of one settled step of N cubes (default 40) taken
        apart: the whole stage, the bodies' poses in numpy, the compiled
        query of the step's pairs alone (timeit, best of 5 repeats).
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
    from refsim.studies.bounce_scenes import SETTLE_STEPS

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


def narrow(count: int) -> None:
    import timeit

    import numpy as np

    sys.path.insert(0, "tests/benchmarks")
    from test_bench_dynamics import contact_scene

    from refsim.collision import _numba_contact
    from refsim.collision.bvh_exact import MARGIN_PER_DEVIATION, MARGIN_ROUNDING
    from refsim.dynamics.body_stage import narrow_phase_compiled
    from refsim.dynamics.products import matvec
    from refsim.dynamics.simulation import Simulation
    from refsim.studies.bounce_scenes import SETTLE_STEPS
    from refsim.types import ORTHONORMAL_TOL

    sim = Simulation(contact_scene(count), kernel="compiled")
    sim.advance(SETTLE_STEPS["cubes"])
    seen: list[np.ndarray] = []
    stage = sim._narrow_phase
    sim._narrow_phase = lambda pairs: (seen.append(np.array(pairs)), stage(pairs))[1]
    sim.advance(1)
    if not seen:
        print(f"{count} cubes, settled: no pair of boxes overlaps, no narrow phase")
        return
    pairs = seen[-1].astype(np.int64)
    origin = sim.x - matvec(sim.R, sim.center)
    floats, float_start, ints, int_start, mesh_of = sim._packed_meshes()
    codes = np.empty(len(pairs), dtype=np.int64)

    def best(call) -> float:
        return min(timeit.repeat(call, number=2000, repeat=5)) / 2000 * 1e6

    print(f"{count} cubes, settled, one step's narrow phase ({len(pairs)} pairs):")
    print(f"  the stage: {best(lambda: narrow_phase_compiled(sim, pairs)):.1f} us")
    print(f"  poses (x - R c): {best(lambda: sim.x - matvec(sim.R, sim.center)):.1f} us")
    query = best(lambda: _numba_contact.collide_pairs_numba(
        floats, float_start, ints, int_start, mesh_of, sim.R, origin, pairs, ORTHONORMAL_TOL,
        MARGIN_ROUNDING, MARGIN_PER_DEVIATION, codes))
    print(f"  the compiled query alone: {query:.1f} us")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--narrow"]:
        narrow(*[int(a) for a in sys.argv[2:3]] or [40])
    elif sys.argv[1:2] == ["--stages"]:
        numbers = [int(a) for a in sys.argv[2:]]
        stages(*(numbers + [40, 300][len(numbers):]))
    else:
        for name in sys.argv[1:]:
            bench_table(name)
