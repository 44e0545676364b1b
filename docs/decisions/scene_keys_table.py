"""The textbook problems the scene keys pose (refsim.dynamics.loads), on
refsim's corrected model and the rigid-body oracles: an incline (a floor
under a tilted gravity), a constant torque and force on a free body, a ball
on a fixed table with a pair's restitution, the restitution threshold
(docs/decisions/scene-keys.md).

    python docs/decisions/scene_keys_table.py [--step H ...] [MODULE:FACTORY ...]

Without engines: refsim's corrected model, pybullet, MuJoCo; steps 1e-3
and 5e-4 s. The scenes are the tests' (tests/dynamics/test_loads.py).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
from refsim.oracles import OracleUnavailable

from refsim.engines import load_engine
from refsim.errors import SceneError

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "dynamics"))
from test_loads import ball_on_table, free_body, incline  # noqa: E402  (the tests' scenes)

ENGINES = ("refsim.engines.refsim_engines:corrected", "refsim.oracles.pybullet_adapter:engine",
           "refsim.oracles.mujoco_adapter:engine")
G = 9.81
#: The free body: 2 kg, 1 x 0.6 x 0.3, torque 0.5 N m about z, force 1 N along x.
I_Z = 2.0 * (1.0 + 0.36) / 12.0
#: The ball's centre at rest on the table (table top -4, radius 0.25).
REST = -3.75


def slide(angle_deg: float, mu: float) -> float:
    """Coulomb's distance from rest in 1 s down an incline, 0 when it sticks."""
    a = math.radians(angle_deg)
    return max(0.0, G * (math.sin(a) - mu * math.cos(a)) / 2.0)


def incline_run(engine, angle: float, mu: float, h: float) -> tuple[float, float]:
    """Distance along x in 1 s, and the largest lift of the block off its
    resting height (m)."""
    tr = engine.simulate(incline(angle, mu, h))
    y = np.asarray(tr.position)[:, 0, 1]
    return (float(tr.position[-1, 0, 0] - tr.position[0, 0, 0]), float(y.max() - y[0]))


def apex_heights(trajectory) -> list[float]:
    """The ball's apexes above its resting height: where its vertical
    velocity turns from up to down (the drop's start is no apex)."""
    v = np.asarray(trajectory.velocity)[:, 1, 1]
    y = np.asarray(trajectory.position)[:, 1, 1]
    return [float(y[i] - REST) for i in range(1, len(v)) if v[i - 1] > 0.0 >= v[i]]


def impact_ratio(trajectory) -> float:
    """``-v' / v`` of the ball at its first impact: the vertical speed just
    after it turns upward over the speed the step before (e above the
    threshold, 0 below)."""
    v = np.asarray(trajectory.velocity)[:, 1, 1]
    falling = int(np.argmax(v < 0.0))
    turn = falling + int(np.argmax(v[falling:] >= 0.0))
    return float(-v[turn] / v[turn - 1])


def measure(engine, h: float) -> dict[str, str]:
    """One column of the table: every quantity's value as printed."""
    out: dict[str, str] = {}
    for angle, mu in ((30.0, 0.3), (50.0, 1.0)):
        d, lift = incline_run(engine, angle, mu, h)
        exact = slide(angle, mu)
        out[f"slide {angle:g} {mu:g}"] = f"{d:.4f} ({(d - exact) / exact:+.1%})"
        out[f"lift {angle:g} {mu:g}"] = f"{lift * 1e3:.2f}"
    for angle, mu in ((10.0, 0.3), (50.0, 1.5)):
        d, _ = incline_run(engine, angle, mu, h)
        out[f"creep {angle:g} {mu:g}"] = f"{abs(d) * 1e3:.3f}"
    tr = engine.simulate(free_body(h))
    w = np.asarray(tr.angular_velocity)[-1, 0]
    x = np.asarray(tr.position)[-1, 0]
    out["w_z"] = f"{w[2]:.6f} ({w[2] / (0.5 / I_Z) - 1.0:+.1e})"
    out["x"] = f"{x[0]:.6f} ({x[0] / 0.25 - 1.0:+.1e})"
    tr = engine.simulate(ball_on_table(h), every=1)
    heights = [2.0] + apex_heights(tr)
    out["apex ratios"] = ", ".join(f"{b / a:.4f}" for a, b in zip(heights, heights[1:],
                                                                   strict=False))
    table = np.asarray(tr.position)[:, 0]
    out["table"] = f"{np.abs(table - table[0]).max():.1e}"
    for threshold, key in ((None, "apex unset"), (0.5, "apex 0.5")):
        try:
            tr = engine.simulate(ball_on_table(h, threshold=threshold, drop=0.005,
                                               duration=0.1), every=1)
        except SceneError as exc:
            out[key] = f"refused ({exc.key})"
            continue
        out[key] = f"{impact_ratio(tr):.4f}"
    return out


ROWS = (
    ("slide 30 0.3", "incline 30 deg, mu 0.3: distance in 1 s (m)", f"{slide(30, 0.3):.4f}"),
    ("lift 30 0.3", "  largest lift off the floor (mm)", "0"),
    ("slide 50 1", "incline 50 deg, mu 1.0: distance in 1 s (m)", f"{slide(50, 1.0):.4f}"),
    ("lift 50 1", "  largest lift off the floor (mm)", "0"),
    ("creep 10 0.3", "incline 10 deg, mu 0.3 (sticks): creep in 1 s (mm)", "0"),
    ("creep 50 1.5", "incline 50 deg, mu 1.5 (sticks): creep in 1 s (mm)", "0"),
    ("w_z", "free body: w_z at 1 s (rad/s)", f"{0.5 / I_Z:.6f}"),
    ("x", "free body: x at 1 s (m)", "0.250000"),
    ("apex ratios", "ball on fixed table, pair e = 0.5: apex ratios", "0.25"),
    ("table", "  largest table motion (m)", "0"),
    ("apex unset", "5 mm drop (0.31 m/s), threshold unset: -v'/v at impact", "0.5"),
    ("apex 0.5", "5 mm drop, threshold 0.5 m/s: -v'/v at impact", "0"),
)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("engines", nargs="*", default=ENGINES)
    parser.add_argument("--step", type=float, action="append")
    args = parser.parse_args()
    engines = []
    for spec in args.engines:
        try:
            engine = load_engine(spec)
            engines.append((engine.name, engine))
        except OracleUnavailable as exc:
            print(f"{spec}: not run: {exc}")
    for h in args.step or (1e-3, 5e-4):
        columns = [measure(engine, h) for _, engine in engines]
        print(f"\nh = {h:g} s\n")
        print("| quantity | closed form | " + " | ".join(n for n, _ in engines) + " |")
        print("| --- | --- |" + " --- |" * len(engines))
        for key, label, exact in ROWS:
            print(f"| {label} | {exact} | " + " | ".join(c[key] for c in columns) + " |")


if __name__ == "__main__":
    main()
