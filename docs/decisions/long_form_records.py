"""The bounce studies' records before and after they became long-form: the
same numbers, one row per case and engine instead of one wide row per case.

    python docs/decisions/long_form_records.py BEFORE/results.json AFTER/results.json

BEFORE is a report made before the change (its dynamics records have
``refsim_*``, ``pybullet_*`` and ``seed_speed_*`` fields), AFTER one made
after it. The script rewrites BEFORE's five wide records (``apex_ratios``,
``oblique``, ``rest``, ``energy``, ``step_cost``) and the cost study's
points into the long form, field by field as listed in :data:`RENAMED`,
then compares the whole file with AFTER as ``compare_results.py`` does
(every non-timing value; the environment and timings left out).

It prints each differing path and two counts: the values the long form has
and the wide form never recorded (:data:`NEW_FIELDS`: refsim's spin after an
oblique bounce, the apex times and spin of the seed's wall speed), and every
other difference. Exit status 0 when the second count is 0.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from compare_results import differences  # noqa: E402

ANALYTIC, REFSIM, SEED, ORACLE = "analytic", "refsim", "refsim-seed-wall-speed", "pybullet"

#: How each wide field maps to a long-form row: {record: {engine: {long field:
#: wide field}}}; a long field absent from the mapping is one the wide
#: record did not have.
RENAMED = {
    "apex_ratios": {
        ANALYTIC: {"heights": "analytic_heights", "times": "analytic_times",
                   "ratio": "analytic_ratio", "first_ratio": "analytic_ratio"},
        REFSIM: {"heights": "refsim_heights", "times": "refsim_times", "ratio": "refsim_ratio",
                 "first_ratio": "refsim_first_ratio", "error": "refsim_error",
                 "max_spin": "refsim_max_spin"},
        SEED: {"heights": "seed_speed_heights", "ratio": "seed_speed_ratio",
               "first_ratio": "seed_speed_first_ratio", "error": "seed_speed_error"},
        ORACLE: {"heights": "pybullet_heights", "times": "pybullet_times",
                 "ratio": "pybullet_ratio", "first_ratio": "pybullet_first_ratio",
                 "error": "pybullet_error", "max_spin": "pybullet_max_spin"},
    },
    "oblique": {REFSIM: {"lateral": "refsim"},
                ORACLE: {"lateral": "pybullet", "spin": "pybullet_spin"}},
    "rest": {ANALYTIC: {"settle": "analytic_settle", "bounces": "analytic_bounces"},
             REFSIM: {"settle": "refsim_settle", "bounces": "refsim_bounces"},
             ORACLE: {"settle": "pybullet_settle", "bounces": "pybullet_bounces"}},
    "energy": {ANALYTIC: {"t": "t", "height": "analytic_height", "energy": "analytic_energy"},
               REFSIM: {"t": "t", "height": "refsim_height", "energy": "refsim_energy"},
               ORACLE: {"t": "t", "height": "pybullet_height", "energy": "pybullet_energy"}},
    "step_cost": {REFSIM: {"seconds": "refsim_seconds",
                           "stage_seconds": "refsim_stage_seconds"},
                  ORACLE: {"seconds": "pybullet_seconds"}},
}
#: Values the analytic row has by definition (its error and spin).
FIXED = {("apex_ratios", ANALYTIC): {"error": 0.0, "max_spin": 0.0},
         ("step_cost", ORACLE): {"stage_seconds": {}}}
#: The case fields of each record (kept on every row).
CASE = {"apex_ratios": ("body", "rotation", "e", "step", "solver"),
        "oblique": ("body", "rotation", "e", "friction", "v_t", "v_n", "seed_analytic",
                    "coulomb_point", "coulomb_ball", "ball_slides"),
        "rest": ("body", "e", "zeno"),
        "energy": ("body", "e"),
        "step_cost": ("bodies", "rotation", "warmup", "steps", "repeats")}
#: (record, field) the long form records and the wide one did not.
NEW_FIELDS = {("apex_ratios", "times"), ("apex_ratios", "max_spin"), ("oblique", "spin")}


def long_form(record: str, wide_rows: list[dict]) -> list[dict]:
    """``wide_rows`` of ``record`` rewritten one row per case and engine."""
    rows = []
    for wide in wide_rows:
        for engine, fields in RENAMED[record].items():
            row = {f: wide[f] for f in CASE[record]} | {"engine": engine}
            row |= {new: wide[old] for new, old in fields.items()}
            row |= FIXED.get((record, engine), {})
            rows.append(row)
    return rows


def rewrite(results: dict) -> dict:
    """BEFORE's results with the dynamics records in the long form."""
    records = results["sections"]["dynamics"]["results"]
    for record in RENAMED:
        wide = records[record]
        records[record] = long_form(record, [wide] if record == "energy" else wide)
    for point in records["cost"]["points"]:
        if point["solver"] == "rk4, seed wall speed":
            point["engine"] = SEED
    return results


def main(argv: list[str]) -> int:
    before, after = (json.loads(Path(p).read_text()) for p in argv[:2])
    patterns = [tuple(p) for p in before.get("timing_paths", []) + after.get("timing_paths", [])]
    new = other = 0
    for path, a, b in differences(rewrite(before), after, patterns):
        record = path[3] if len(path) > 3 and path[:3] == ("sections", "dynamics", "results") \
            else None
        if a == "<absent>" and (record, path[-1]) in NEW_FIELDS:
            new += 1
            continue
        other += 1
        print(f"{'/'.join(map(str, path))}: {json.dumps(a)[:160]} -> {json.dumps(b)[:160]}")
    print(f"{new} values the wide records did not have; {other} other differing "
          "non-timing paths")
    return 1 if other else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
