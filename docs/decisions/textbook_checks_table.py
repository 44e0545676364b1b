"""The kit's slide, elastic tumble and bounce times on each engine
(docs/decisions/textbook-checks.md): the figures the checks measure, with
the seconds each check took (its scenes' runs included; the bounce times
read the drops' runs, made here by that check).

    python docs/decisions/textbook_checks_table.py [--step H] [--tumble SECONDS]
                                                   [MODULE:FACTORY ...]

``--tumble`` runs the elastic tumble for that long instead of the kit's 5 s.
"""

from __future__ import annotations

import argparse
import time
from dataclasses import replace

from refsim.oracles import OracleUnavailable

from refsim.conformance import cases_rigid as R
from refsim.conformance import checks_rigid as C
from refsim.engines import load_engine
from refsim.solvers.integrate import covering_duration

ENGINES = ("refsim.engines.refsim_engines:corrected", "refsim.engines.refsim_engines:seed",
           "refsim.oracles.pybullet_adapter:engine", "refsim.oracles.mujoco_adapter:engine",
           "refsim.oracles.drake_adapter:engine",
           "refsim.oracles.drake_adapter:engine_hydroelastic")


def scenes(step: float, tumble: float | None) -> tuple:
    chosen = []
    for scene in R.rigid_scenes():
        if scene.kind not in ("slide", "tumble", "drop"):
            continue
        if scene.kind == "tumble" and tumble is not None:
            integration = replace(scene.scene.integration,
                                  duration=covering_duration(tumble, scene.scene.integration.step))
            scene = replace(scene, scene=replace(scene.scene, integration=integration))
        chosen.append(R.with_step(scene, step))
    return tuple(chosen)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("engines", nargs="*", default=ENGINES)
    parser.add_argument("--step", type=float, default=R.STEP)
    parser.add_argument("--tumble", type=float, default=None)
    args = parser.parse_args()
    print(f"h = {args.step:g} s")
    print("| engine | ball: decel / mu g, slip ends (s) | cube: decel / mu g, stops (s), "
          "travel (m) | tumble: energy change, impacts (allowed) | bounce times: worst "
          "miss, steps | seconds: slide, tumble, bounces |")
    print("| --- | --- | --- | --- | --- | --- |")
    for spec in args.engines:
        try:
            engine = load_engine(spec)
        except OracleUnavailable as exc:
            print(f"| {spec} | not run: {exc} | | | | |")
            continue
        cases = R.RigidCases(scenes=scenes(args.step, args.tumble))
        seconds, results = [], []
        for check in (C.check_rigid_slide_to_roll, C.check_rigid_elastic_tumble,
                      C.check_rigid_bounce_times):
            start = time.perf_counter()
            results.append(check(engine, cases))
            seconds.append(time.perf_counter() - start)
        slide, tumble, bounces = (r.measured for r in results)
        ball, box, brick = slide["slide-ball"], slide["slide-box"], tumble["tumble-brick"]
        worst = max((abs(x) for m in bounces.values() for x in m["misses_in_steps"]),
                    default=float("nan"))
        print(f"| {engine.name} | {ball['deceleration_over_mu_g']:.3f}, "
              f"{ball['slip_end_time']:.3f} | {box['deceleration_over_mu_g']:.4f}, "
              f"{box['slip_end_time']:.3f}, {box['distance']:.3f} | "
              f"{brick['largest_energy_change']:.2%}, {brick['impacts']} "
              f"({brick['tolerance']:.1%}) | {worst:.2f} | "
              + ", ".join(f"{s:.1f}" for s in seconds) + " |")
    print(f"closed form: ball {R.slide_answer(cases.scenes[-3])['slip_end_time']:.4f} s; "
          f"cube {R.slide_answer(cases.scenes[-2])['slip_end_time']:.4f} s, "
          f"{R.slide_answer(cases.scenes[-2])['distance']:.4f} m")


if __name__ == "__main__":
    main()
