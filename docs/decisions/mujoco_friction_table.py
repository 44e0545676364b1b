"""MuJoCo's friction settings on the kit's friction-bearing textbook problems
(docs/decisions/mujoco-friction.md): each variant of
:class:`refsim.oracles.mujoco_adapter.MujocoSettings`, the kit's verdict per
rigid check (with MuJoCo's shipped declarations) and the headline errors
against the closed forms, and a cube sliding to rest at ``mu g`` (outside
the kit: docs/decisions/drake_table.py's scene).

    .venv/bin/python docs/decisions/mujoco_friction_table.py [--step H] [--only NAME ...]

``--step`` runs every rigid scene at that step instead of the kit's 1e-3
(the convergence table); ``--only`` runs the named variants only.
"""

from __future__ import annotations

import argparse
import ast
import math
import sys
from pathlib import Path

import numpy as np
from refsim.oracles.mujoco_adapter import engine

from refsim.conformance import cases_rigid as R
from refsim.conformance import checks_rigid as C
from refsim.conformance.expected import shipped_expected_failures
from refsim.conformance.runner import check_engine

sys.path.insert(0, str(Path(__file__).resolve().parent))
import drake_table  # noqa: E402  (the Drake page's sliding cube and lowest vertex)
from drake_table import SLIDE_MU, SLIDE_SPEED, lowest  # noqa: E402

#: The adapter's settings, one option changed at a time, then combinations.
VARIANTS = {
    "adapter": {},
    "pyramidal": {"cone": "pyramidal"},
    "impratio 10": {"impratio": 10.0},
    "impratio 100": {"impratio": 100.0},
    "noslip 10": {"noslip_iterations": 10},
    "noslip 100": {"noslip_iterations": 100},
    "condim 4": {"condim": 4},
    "condim 6": {"condim": 6},
    "solreffriction = solref": {"solreffriction": (0.0, 0.0)},
    "solreffriction 0.02 1": {"solreffriction": (0.02, 1.0)},
    # outside the brief's values: impratio below 1 (softer friction rows)
    "impratio 0.1": {"impratio": 0.1},
    # combinations
    "condim 4, impratio 100, noslip 100": {"condim": 4, "impratio": 100.0,
                                           "noslip_iterations": 100},
    "solreffriction 0.02 1, noslip 100": {"solreffriction": (0.02, 1.0),
                                          "noslip_iterations": 100},
    "pyramidal, noslip 100": {"cone": "pyramidal", "noslip_iterations": 100},
}

#: The friction-bearing checks first, then the rest of the rigid set.
CHECKS = ("rigid.oblique_bounce", "rigid.spin_to_rest", "rigid.incline",
          "rigid.resting_contact", "rigid.no_spin", "rigid.apex_ratio", "rigid.energy",
          "rigid.determinism", "rigid.free_rotation", "rigid.off_centre", "rigid.stack")





def rise(trajectory) -> float:
    """How far body 0's origin (the cube's centre) rises above its start."""
    y = np.asarray(trajectory.position)[:, 0, 1]
    return float(y.max() - y[0])


def slide_scene(step: float):
    """The Drake page's sliding cube (drake_table.slide_scene) at ``step``."""
    return R.with_step(R.RigidScene("slide-cube", "slide", drake_table.slide_scene(), 0.5,
                                    SLIDE_MU), step).scene


def verdict(check) -> str:
    passed = check.cases - check.failed
    classes = ", ".join(f"{k} {v}" for k, v in sorted(check.classes.items()))
    return f"{check.status} {passed}/{check.cases}" + (f" ({classes})" if classes else "")


def figures(result, cases, mj, step: float) -> dict[str, str]:
    """The headline figures of one variant's run (the checks' ``measured``,
    and the trajectories the checks shared)."""
    out = {}
    oblique = result.check("rigid.oblique_bounce").measured
    for name, m in oblique.items():
        ratio = max(abs(m["lateral_velocity"] - m["coulomb"]) / m["tolerance"],
                    abs(m["spin"] - m["coulomb_spin"]) / m["spin_tolerance"])
        out[name] = (f"v {m['lateral_velocity']:.4f} ({m['coulomb']:.4f}), "
                     f"w {m['spin']:.3f} ({m['coulomb_spin']:.3f}); miss/tol {ratio:.2g}")
    spin_case = cases.of_kind("spin")[0]
    spin = result.check("rigid.spin_to_rest").measured["spin-cube"]
    tr = cases.run(mj, spin_case)
    speed = np.linalg.norm(tr.angular_velocity[:, 0], axis=1)
    t = tr.t
    window = (speed < 0.9 * R.SPIN) & (speed > 0.1 * R.SPIN)
    rate = -np.polyfit(t[window], speed[window], 1)[0] if window.sum() > 2 else math.nan
    # Coulomb's spin-down rate under a uniform pressure: the kit's limit is
    # SPIN_TIME_FACTOR times the time it takes
    coulomb = R.SPIN * C.SPIN_TIME_FACTOR / C.spin_rest_time(spin_case)
    first = spin["first_time_below"]
    out["spin-cube"] = (f"below 1 % at {first if first is None else round(first, 3)} s "
                        f"(Coulomb {R.SPIN / coulomb:.3f}, limit {spin['rest_time_limit']:.3f}); "
                        f"rate {rate:.2f} rad/s^2 ({coulomb:.2f}); "
                        f"hop {1e3 * lowest(spin_case.scene, tr).max():.2f} mm, "
                        f"centre rise {1e3 * rise(tr):.1f} mm")
    rest = result.check("rigid.resting_contact").measured
    out["resting"] = ", ".join(f"{k} deepest {m['deepest']:.2e} m (tol {m['tolerance']:.2e})"
                               for k, m in rest.items())
    incline = result.check("rigid.incline").measured
    for case in cases.of_kind("incline"):
        m = incline[case.name]
        hop = lowest(case.scene, cases.run(mj, case)).max()
        out[case.name] = (f"travel {m['travel_metres']:.4f} m ({m['coulomb_metres']:.4f}), "
                          f"miss {m['miss_metres']:.2e} (tol {m['tolerance_metres']:.2e}); "
                          f"hop {1e3 * hop:.2f} mm")
    no_spin = result.check("rigid.no_spin").measured
    worst = max(no_spin, key=lambda k: no_spin[k]["largest_spin"])
    out["no_spin"] = f"largest spin {no_spin[worst]['largest_spin']:.2e} rad/s ({worst})"
    off = result.check("rigid.off_centre").measured
    out["off_centre"] = ", ".join(f"{k} ball spin {m['ball_spin']:.3f} rad/s, worst miss "
                                  f"{m['largest_miss_of_closing_speed']:.3f}"
                                  for k, m in off.items())
    stack = result.check("rigid.stack").measured
    out["stack"] = ", ".join(f"{m['largest_vertex_travel_metres']:.1e}" for m in stack.values())
    scene = slide_scene(step)
    tr = mj.simulate(scene)
    vx, t = np.asarray(tr.velocity)[:, 0, 0], np.asarray(tr.t)
    window = (vx < 0.9 * SLIDE_SPEED) & (vx > 0.1 * SLIDE_SPEED)
    decel = -np.polyfit(t[window], vx[window], 1)[0]
    travel = float(np.asarray(tr.position)[-1, 0, 0] - np.asarray(tr.position)[0, 0, 0])
    g = SLIDE_MU * R.GRAVITY
    closed = SLIDE_SPEED ** 2 / (2 * g)
    out["slide-cube"] = (f"deceleration {decel:.3f} m/s^2 ({g:.3f}); travel {travel:.4f} m "
                         f"({closed:.4f}, {travel / closed - 1:+.1%}); "
                         f"hop {1e3 * lowest(scene, tr).max():.2f} mm, "
                         f"centre rise {1e3 * rise(tr):.1f} mm")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--step", type=float, default=R.STEP)
    parser.add_argument("--only", nargs="*", default=None)
    parser.add_argument("--set", nargs="*", default=(), metavar="FIELD=VALUE",
                        help="an extra variant from MujocoSettings fields")
    args = parser.parse_args()
    variants = {k: v for k, v in VARIANTS.items() if args.only is None or k in args.only}
    if args.set:
        extra = {}
        for item in args.set:
            key, value = item.split("=", 1)
            extra[key] = ast.literal_eval(value)
        variants[" ".join(args.set)] = extra
    print(f"h = {args.step:g} s\n")
    rows = {}
    for name, settings in variants.items():
        mj = engine(**settings)
        cases = R.RigidCases(scenes=tuple(R.with_step(s, args.step) for s in R.rigid_scenes()))
        result = check_engine(mj, cases=20, seed=1, only="rigid", case_sets={"rigid": cases},
                              expected_failures=shipped_expected_failures("mujoco"))
        rows[name] = ({c: verdict(result.check(c)) for c in CHECKS},
                      figures(result, cases, mj, args.step))
    print("| variant | " + " | ".join(c.removeprefix("rigid.") for c in CHECKS) + " |")
    print("| --- |" + " --- |" * len(CHECKS))
    for name, (verdicts, _) in rows.items():
        print(f"| {name} | " + " | ".join(verdicts[c] for c in CHECKS) + " |")
    for name, (_, figs) in rows.items():
        print(f"\n## {name}: {variants[name] or 'the adapter as shipped'}\n")
        for key, text in figs.items():
            print(f"- {key}: {text}")


if __name__ == "__main__":
    main()
