"""Drake (refsim.oracles.drake_adapter) on the kit's textbook problems, beside
pybullet in the same run (docs/decisions/drake.md).

    python docs/decisions/drake_table.py [MODULE:FACTORY ...]
    python docs/decisions/drake_table.py --approximation similar [MODULE:FACTORY ...]
    python docs/decisions/drake_table.py --dissipation

Without arguments: Drake's point contact, Drake's hydroelastic contact,
pybullet. Prints, per engine: the drops' first-bounce restitution
(``sqrt`` of the first apex over the drop height) and the kit's apex ratio;
the oblique impacts' lateral velocity and spin once the contact is over
(the first frame out of contact; ``oblique-e0`` at its end) against
Coulomb's; a cube sliding at 2 m/s (mu 0.5) against ``mu g``; the spinning
cube's time to rest; the resting cube's deepest penetration; the free
brick; the strike; the stacks' travel in 0.5 s; and the wall-clock per step
(mean over the kit's scenes run here, record included).

``--dissipation``: Drake's restitution at ``d = 0`` per contact steps ``N``,
and the dissipation ``d v0`` measured on Drake against the continuous
Hunt-Crossley law's (its exact inversion, and Hunt and Crossley's ``3 (1 -
e) / 2``), each with the restitution Drake gives it.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
from refsim.oracles import OracleUnavailable

from refsim.conformance import cases_rigid as R
from refsim.conformance import checks_rigid as C
from refsim.engines import load_engine

ENGINES = ("refsim.oracles.drake_adapter:engine",
           "refsim.oracles.drake_adapter:engine_hydroelastic",
           "refsim.oracles.pybullet_adapter:engine")

SLIDE_SPEED = 2.0
SLIDE_MU = 0.5


def lowest(scene, trajectory, i: int = 0) -> np.ndarray:
    """Height of body ``i``'s lowest vertex above the floor, per frame."""
    body = scene.bodies[i]
    v = np.asarray(scene.mesh(body).vertices, dtype=np.float64) * body.scale
    y = np.asarray(trajectory.position)[:, i, 1, None] + np.einsum(
        "fj,vj->fv", np.asarray(trajectory.orientation)[:, i, 1, :], v)
    return y.min(axis=1) + scene.world.half_size


def slide_scene():
    """The cube face down on the floor, sliding at SLIDE_SPEED along x."""
    return R._bodies_scene([{"name": "cube", "model": R.CUBE,
                             "position": [0.0, -R.HALF_SIZE + 0.5, 0.0],
                             "velocity": [SLIDE_SPEED, 0.0, 0.0]}],
                           R.GRAVITY, 0.5, SLIDE_MU, 0.6)


def main(specs, **drake_settings) -> None:
    """The tables for each engine; ``drake_settings`` (e.g.
    ``approximation="similar"``) go to the Drake factories."""
    cases = R.rigid_cases()
    for spec in specs:
        try:
            engine = load_engine(spec, **(drake_settings if "drake_adapter" in spec else {}))
        except OracleUnavailable as exc:
            print(f"{spec}: not run: {exc}")
            continue
        print(f"## {spec}\n")
        steps, seconds = 0, 0.0

        def run(scene, engine=engine):
            nonlocal steps, seconds
            start = time.perf_counter()
            trajectory = engine.simulate(scene)
            seconds += time.perf_counter() - start
            steps += scene.integration.n_steps
            return trajectory

        print("| drop | first-bounce e (scene e) | apex ratio (e^2) |")
        print("| --- | --- | --- |")
        for case in cases.of_kind("drop"):
            tr = run(case.scene)
            ratio, heights = R.apex_ratio(case, tr)
            first = math.sqrt(heights[1] / heights[0]) if len(heights) > 1 else math.nan
            print(f"| {case.name} | {first:.3f} ({case.e}) | {ratio:.3f} ({case.e ** 2:.3f}) |")

        print("\n| oblique | lateral v after the contact (Coulomb) | spin (Coulomb) |")
        print("| --- | --- | --- |")
        for case in cases.of_kind("oblique"):
            tr = run(case.scene)
            _, v_t, w_z = R.oblique_answer(case)
            low = lowest(case.scene, tr)
            touching = np.flatnonzero(low <= 1e-9)
            k = len(low) - 1
            if case.e > 0 and len(touching):
                after = touching[touching > touching[0]]
                gaps = np.flatnonzero(np.diff(touching) > 1)
                k = int(touching[gaps[0]] + 1) if len(gaps) else int(touching[-1] + 1)
                del after
            v = np.asarray(tr.velocity)[k, 0, 0]
            w = np.asarray(tr.angular_velocity)[k, 0, 2]
            print(f"| {case.name} | {v:.4f} ({v_t:.4f}) at t = {tr.t[k]:.3f} s "
                  f"| {w:.3f} ({w_z:.3f}) |")

        scene = slide_scene()
        tr = run(scene)
        vx = np.asarray(tr.velocity)[:, 0, 0]
        t = np.asarray(tr.t)
        window = (vx < 0.9 * SLIDE_SPEED) & (vx > 0.1 * SLIDE_SPEED)
        decel = -np.polyfit(t[window], vx[window], 1)[0]
        stop = t[np.argmax(vx < 1e-3)]
        print(f"\nsliding cube, {SLIDE_SPEED} m/s, mu {SLIDE_MU}: deceleration {decel:.3f} "
              f"m/s^2 (mu g = {SLIDE_MU * R.GRAVITY:.3f}), stopped at {stop:.3f} s "
              f"({SLIDE_SPEED / (SLIDE_MU * R.GRAVITY):.3f})")

        for case in cases.of_kind("spin"):
            tr = run(case.scene)
            speed = np.linalg.norm(np.asarray(tr.angular_velocity)[:, 0], axis=1)
            below = np.flatnonzero(speed < C.SPIN_REST_FRACTION * R.SPIN)
            when = f"{tr.t[below[0]]:.3f} s" if len(below) else "never"
            print(f"spinning cube: below 1 % of its spin at {when} "
                  f"(kit's limit {C.spin_rest_time(case):.3f} s)")
        for case in cases.of_kind("rest"):
            tr = run(case.scene)
            low = lowest(case.scene, tr)
            w = np.linalg.norm(np.asarray(tr.angular_velocity)[:, 0], axis=1).max()
            drift = np.abs(np.asarray(tr.position)[-1, 0] - np.asarray(tr.position)[0, 0])
            print(f"resting cube: deepest {-low.min():.2e} m (kit allows "
                  f"{C.REST_PENETRATION_STEPS * R.GRAVITY * R.STEP ** 2:.2e}), largest |w| "
                  f"{w:.3f} rad/s, moved {drift.max():.2e} m in {tr.t[-1]:.1f} s")
        for case in cases.of_kind("free"):
            tr = run(case.scene)
            L = R.angular_momentum(case, tr)
            _, _, inertia = R._body(R._model(case))
            m = case.scene.bodies[0].mass
            w = np.asarray(tr.angular_velocity)[:, 0]
            rot = np.asarray(tr.orientation)[:, 0]
            w_b = np.einsum("fji,fj->fi", rot, w)
            energy = 0.5 * m * np.einsum("fi,ij,fj->f", w_b, inertia, w_b)
            print(f"free brick: energy {energy[-1] / energy[0] - 1:+.2e}, |L| "
                  f"{np.linalg.norm(L[-1]) / np.linalg.norm(L[0]) - 1:+.2e} over "
                  f"{tr.t[-1]:.0f} s")
        for case in cases.of_kind("strike"):
            tr = run(case.scene)
            answer = R.strike_answer(case)
            rod_v = np.asarray(tr.velocity)[-1, 0, 1]
            ball_v = np.asarray(tr.velocity)[-1, 1, 1]
            print(f"{case.name}: rod v_y {rod_v:.4f} ({answer['rod_velocity']:.4f}), ball v_y "
                  f"{ball_v:.4f} ({answer['ball_velocity']:.4f})")
        for case in cases.of_kind("stack"):
            tr = run(case.scene)
            print(f"{case.name}: largest vertex travel {R.largest_vertex_travel(case, tr):.2e} m "
                  f"in {tr.t[-1]:.1f} s (kit allows {C.STACK_TRAVEL:.1e})")
        print(f"\nwall-clock: {1e6 * seconds / steps:.0f} us per step over {steps} steps\n")


def continuous_restitution(dv: float) -> float:
    """Restitution of the continuous impact ``x'' = -x (1 + dv x')_+``."""
    from scipy.integrate import solve_ivp

    def leaves(_, y):
        return y[0]

    leaves.terminal = True          # type: ignore[attr-defined]
    leaves.direction = -1           # type: ignore[attr-defined]
    run = solve_ivp(lambda _, y: [y[1], -y[0] * max(0.0, 1.0 + dv * y[1])], (0.0, 100.0),
                    [0.0, 1.0], events=leaves, rtol=1e-10, atol=1e-12, first_step=1e-6)
    return float(-run.y_events[0][0][1])


def dissipation() -> None:
    from refsim.oracles.drake_adapter import DrakeSettings, drake_dv, drake_restitution
    from scipy.optimize import brentq

    print("| contact steps N | restitution at d = 0 |")
    print("| --- | --- |")
    for n in (2, 4, 8, 10, 16, 20, 30, 100):
        print(f"| {n} | {drake_restitution(0.0, float(n)):.3f} |")
    steps = DrakeSettings().contact_steps
    print(f"\nN = {steps:g}\n")
    print("| e | d v0 measured on Drake | continuous law, exact | Drake's e with it "
          "| 3 (1 - e) / 2 | Drake's e with it |")
    print("| --- | --- | --- | --- | --- | --- |")
    for e in (0.5, 0.8):
        exact = brentq(lambda d, e=e: continuous_restitution(d) - e, 1e-6, 10.0)
        hc = 1.5 * (1.0 - e)
        print(f"| {e} | {drake_dv(e, steps):.3f} | {exact:.3f} "
              f"| {drake_restitution(exact, steps):.3f} | {hc:.2f} "
              f"| {drake_restitution(hc, steps):.3f} |")


if __name__ == "__main__":
    args = sys.argv[1:]
    if args == ["--dissipation"]:
        dissipation()
    elif args[:1] == ["--approximation"]:
        main(args[2:] or ENGINES[:1], approximation=args[1])
    else:
        main(args or ENGINES)
