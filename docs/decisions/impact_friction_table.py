"""The sphere's oblique impacts of the conformance kit (rigid.oblique_bounce)
on engines: lateral velocity and spin after the impact against Coulomb's
friction over the whole impact (docs/decisions/impact-friction.md).

    python docs/decisions/impact_friction_table.py [MODULE:FACTORY ...]

Without arguments: refsim's corrected and seed models, pybullet, MuJoCo.
"""

from __future__ import annotations

import sys

from refsim.conformance import cases_rigid as R
from refsim.conformance.checks_rigid import check_rigid_oblique_bounce
from refsim.engines import load_engine

ENGINES = ("refsim.engines.refsim_engines:corrected", "refsim.engines.refsim_engines:seed",
           "refsim.oracles.pybullet_adapter:engine", "refsim.oracles.mujoco_adapter:engine")


def main(specs) -> None:
    cases = R.RigidCases(scenes=tuple(R.rigid_cases().of_kind("oblique")))
    print("| engine | impact | v_t after (Coulomb) | error, tolerance | w after (Coulomb) "
          "| error, tolerance |")
    print("| --- | --- | --- | --- | --- | --- |")
    for spec in specs:
        result = check_rigid_oblique_bounce(load_engine(spec), cases)
        for name, m in result.measured.items():
            print(f"| {spec.split(':')[0].split('.')[-1]}:{spec.split(':')[1]} | {name} "
                  f"| {m['lateral_velocity']:.4f} ({m['coulomb']:.4f}) "
                  f"| {m['lateral_velocity'] - m['coulomb']:+.4f}, {m['tolerance']:.4f} "
                  f"| {m['spin']:.3f} ({m['coulomb_spin']:.3f}) "
                  f"| {m['spin'] - m['coulomb_spin']:+.3f}, {m['spin_tolerance']:.3f} |")


if __name__ == "__main__":
    main(sys.argv[1:] or ENGINES)
