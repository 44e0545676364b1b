"""The kit's body-contact problems (rigid.off_centre, rigid.stack) on
engines: the strike's velocities and spins against the impulse solution, and
how far the stacks' vertices travel in 2 s (docs/decisions/body-contact.md).

    python docs/decisions/body_contact_table.py [--step H] [MODULE:FACTORY ...]

Without engines: refsim's corrected and seed models, pybullet, MuJoCo.
"""

from __future__ import annotations

import argparse
from dataclasses import replace

import numpy as np
from refsim.oracles import OracleUnavailable

from refsim.conformance import cases_rigid as R
from refsim.engines import load_engine

ENGINES = ("refsim.engines.refsim_engines:corrected", "refsim.engines.refsim_engines:seed",
           "refsim.oracles.pybullet_adapter:engine", "refsim.oracles.mujoco_adapter:engine")

#: The stacks run as long as the textbook target (the kit runs them 1 s).
STACK_SECONDS = 2.0


def _with(scene: R.RigidScene, step: float, duration: float | None = None) -> R.RigidScene:
    integration = replace(scene.scene.integration, step=step,
                          duration=duration or scene.scene.integration.duration)
    return replace(scene, scene=replace(scene.scene, integration=integration))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("engines", nargs="*", default=ENGINES)
    parser.add_argument("--step", type=float, default=1e-3)
    args = parser.parse_args()
    cases = R.rigid_cases()
    strikes = [_with(s, args.step) for s in cases.of_kind("strike")]
    stacks = [_with(s, args.step, STACK_SECONDS) for s in cases.of_kind("stack")]
    print(f"h = {args.step:g} s")
    print("| engine | strike | rod v_y (m/s) | rod w_z (rad/s) | ball v_y (m/s) | ball |w| "
          "(rad/s) | L drift |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    travel_rows = []
    for spec in args.engines:
        try:
            engine = load_engine(spec)
        except OracleUnavailable as exc:
            print(f"| {spec} | not run: {exc} | | | | | |")
            continue
        for scene in strikes:
            answer = R.strike_answer(scene)
            trajectory = engine.simulate(scene.scene)
            v = np.asarray(trajectory.velocity)[-1]
            w = np.asarray(trajectory.angular_velocity)[-1]
            L = R.angular_momentum(scene, trajectory)
            drift = float(np.abs(L - L[0]).max() / np.abs(L[0]).max())
            print(f"| {spec} | {scene.name} | {v[0, 1]:.4f} ({answer['rod_velocity']:.4f}) "
                  f"| {w[0, 2]:.4f} ({answer['rod_spin']:.4f}) "
                  f"| {v[1, 1]:.4f} ({answer['ball_velocity']:.4f}) "
                  f"| {np.sqrt((w[1] ** 2).sum()):.3g} | {drift:.1e} |")
        travel_rows.append((spec, [R.largest_vertex_travel(s, engine.simulate(s.scene))
                                   for s in stacks]))
    print(f"\nLargest vertex travel in {STACK_SECONDS:g} s (m)\n")
    print("| engine | " + " | ".join(s.name for s in stacks) + " |")
    print("| --- |" + " --- |" * len(stacks))
    for spec, travels in travel_rows:
        print(f"| {spec} | " + " | ".join(f"{t:.2e}" for t in travels) + " |")


if __name__ == "__main__":
    main()
