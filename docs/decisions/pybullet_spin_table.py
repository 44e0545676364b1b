"""pybullet's rigid checks without and with the adapter's spinning friction:
each check's status and the spinning cube's figures
(docs/decisions/pybullet-spinning-friction.md).

    .venv/bin/python docs/decisions/pybullet_spin_table.py
"""

from __future__ import annotations

import json

from refsim.oracles.pybullet_adapter import engine

from refsim.conformance.expected import shipped_expected_failures
from refsim.conformance.runner import check_engine

for spinning in (False, True):
    result = check_engine(engine(spinning_friction=spinning), cases=20, seed=1, only="rigid",
                          expected_failures=shipped_expected_failures("pybullet")).to_dict()
    print(f"spinning_friction={spinning}")
    for c in result["checks"]:
        print(f"  {c['check']:16s} {c['status']:9s} {json.dumps(c.get('measured'))[:300]}")
