"""The sweep benchmarks return their numbers (times asserted only as times)."""

from __future__ import annotations

import math

from refsim.studies.sweep import measure_sweep_speed
from refsim.sweep.examples import trivial


def test_the_in_process_row_is_the_reference():
    speed = measure_sweep_speed(tasks=2, duration=0.01, trivial_tasks=3, repeats=1,
                                backends=("inprocess",))
    (row,) = speed.backends
    assert (row.backend, row.workers, row.speedup) == ("inprocess", None, 1.0)
    assert speed.tasks == 2 and speed.trivial == 3 and speed.task_seconds > 0
    assert row.bench_seconds > 0 and row.trivial_seconds > 0 and math.isfinite(row.per_task_seconds)
    assert math.isfinite(speed.store_per_task_seconds)


def test_the_trivial_task_returns_its_seed():
    assert trivial(seed=12) == 12
