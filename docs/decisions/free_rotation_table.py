"""The free brick of the conformance kit (rigid.free_rotation) on engines:
flips, flip interval, energy and angular-momentum drift against the closed
form (docs/decisions/free-rotation.md).

    python docs/decisions/free_rotation_table.py [MODULE:FACTORY ...]

Without arguments: refsim's corrected and seed models, pybullet, MuJoCo.
"""

from __future__ import annotations

import sys

from refsim.oracles import OracleUnavailable

from refsim.conformance import cases_rigid as R
from refsim.conformance.checks_rigid import check_rigid_free_rotation
from refsim.engines import load_engine

ENGINES = ("refsim.engines.refsim_engines:corrected", "refsim.engines.refsim_engines:seed",
           "refsim.oracles.pybullet_adapter:engine", "refsim.oracles.mujoco_adapter:engine")


def main(specs) -> None:
    cases = R.RigidCases(scenes=tuple(R.rigid_cases().of_kind("free")))
    print("| engine | flips (closed form) | flip interval, relative error | energy drift "
          "| angular momentum drift |")
    print("| --- | --- | --- | --- | --- |")
    for spec in specs:
        try:
            engine = load_engine(spec)
        except OracleUnavailable as exc:
            print(f"| {spec} | not run: {exc} | | | |")
            continue
        m = check_rigid_free_rotation(engine, cases).measured["free-brick"]
        print(f"| {spec} | {m['flips']} ({m['closed_form_flips']}) | {m['interval_error']:.2e} "
              f"| {m['energy_drift']:.2e} | {m['momentum_drift']:.2e} |")


if __name__ == "__main__":
    main(sys.argv[1:] or ENGINES)
