"""Two textbook problems outside the kit, on engines (docs/decisions/body-contact.md):

- elastic tumbling: a body (the brick, or the l-beam whose centre of mass is
  off its origin) dropped spinning at (1, 3, 2) rad/s from 2.17 m in the
  closed cube, e = 1, mu = 0, 10 s: the mechanical energy should stay;
- sliding to rolling: the sphere-2k ball set sliding at 3 m/s on the floor
  without spin, mu = 0.3, e = 0.5: it decelerates at mu g until rolling,
  at t = 2 v0 / (7 mu g) for a solid ball.

    python docs/decisions/tumble_slide_table.py [--step H] [MODULE:FACTORY ...]
"""

from __future__ import annotations

import argparse

import numpy as np
from refsim.oracles import OracleUnavailable

from refsim.conformance import cases_rigid as R
from refsim.engines import load_engine
from refsim.scenes.loader import scene_from_dict

ENGINES = ("refsim.engines.refsim_engines:corrected", "refsim.oracles.pybullet_adapter:engine",
           "refsim.oracles.mujoco_adapter:engine")


def tumble(model: str, step: float) -> R.RigidScene:
    scene = scene_from_dict({
        "world": {"half_size": 5.0, "gravity": 9.81, "restitution": 1.0, "friction": 0.0},
        "integration": {"solver": "rk4", "step": step, "duration": 10.0},
        "collision": {"level": "aabb"},
        "body": [{"model": model, "position": [0.0, -2.0, 0.0],
                  "angular_velocity": [1.0, 3.0, 2.0]}]})
    return R.RigidScene(f"tumble-{model}", "drop", scene, 1.0)


def slide(step: float) -> R.RigidScene:
    vertices = R._body(R.SPHERE)[0]
    scene = scene_from_dict({
        "world": {"half_size": 5.0, "gravity": 9.81, "restitution": 0.5, "friction": 0.3},
        "integration": {"solver": "rk4", "step": step, "duration": 1.5},
        "collision": {"level": "aabb"},
        "body": [{"model": R.SPHERE, "position": [0.0, -5.0 - vertices[:, 1].min(), 0.0],
                  "velocity": [3.0, 0.0, 0.0]}]})
    return R.RigidScene("slide", "slide", scene, 0.5, 0.3)


def deceleration(scene: R.RigidScene, trajectory) -> tuple[float, float]:
    """(deceleration over mu g while sliding, time the slip ends)."""
    vertices, center, _ = R._body(R.SPHERE)
    radius = float(center[1] - vertices[:, 1].min())
    t = np.asarray(trajectory.t)
    v = np.asarray(trajectory.velocity)[:, 0]
    w = np.asarray(trajectory.angular_velocity)[:, 0]
    slip = v[:, 0] + w[:, 2] * radius                  # the contact point's speed
    sliding = np.flatnonzero(slip > 0.05 * 3.0)
    end = float(t[sliding[-1]]) if len(sliding) else 0.0
    window = (t > 0.02) & (t < end - 0.02)
    slope = np.polyfit(t[window], v[window, 0], 1)[0]
    return -slope / (0.3 * R.GRAVITY), end


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("engines", nargs="*", default=ENGINES)
    parser.add_argument("--step", type=float, default=1e-3)
    args = parser.parse_args()
    print(f"h = {args.step:g} s; closed form: energy kept, deceleration 1 mu g, "
          f"rolling from {2 * 3.0 / (7 * 0.3 * R.GRAVITY):.3f} s")
    print("| engine | brick energy drift | l-beam energy drift | sliding deceleration / mu g "
          "| slip ends (s) |")
    print("| --- | --- | --- | --- | --- |")
    for spec in args.engines:
        try:
            engine = load_engine(spec)
        except OracleUnavailable as exc:
            print(f"| {spec} | not run: {exc} | | | |")
            continue
        drifts = []
        for model in ("brick.ac", "l-beam.ac"):
            scene = tumble(model, args.step)
            energy = R.energy(scene, engine.simulate(scene.scene))
            drifts.append(float((energy[-1] - energy[0]) / energy[0]))
        scene = slide(args.step)
        ratio, end = deceleration(scene, engine.simulate(scene.scene))
        print(f"| {spec} | {drifts[0]:+.2%} | {drifts[1]:+.2%} | {ratio:.3f} | {end:.3f} |")


if __name__ == "__main__":
    main()
