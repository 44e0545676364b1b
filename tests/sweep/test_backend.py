"""The same seeded tasks give the same results, bit for bit and in task
order, in-process, on two local processes and on a Dask cluster of two
worker processes started apart from the test."""

from __future__ import annotations

import pytest

from refsim.sweep import Task, run_sweep
from refsim.sweep.examples import bounce
from refsim.sweep.records import encode
from tests.sweep import tasks

#: Short runs of the bundled bounce scene: a real refsim task on every backend.
BOUNCE_SECONDS = 0.2


def seeded_sweep() -> list[Task]:
    sweep = [Task(f"draws-{i}", tasks.draws, {"n": 16 + i}) for i in range(6)]
    sweep += [Task(f"bounce-{i}", bounce, {"scene": "bounce.toml", "duration": BOUNCE_SECONDS})
              for i in range(2)]
    return sweep


@pytest.fixture(scope="module")
def in_process():
    return run_sweep(seeded_sweep(), seed=11, progress=False)


def test_in_process_results_are_the_seeded_values(in_process):
    assert in_process.ok
    first = in_process.values[6]
    assert first["t"] == pytest.approx(BOUNCE_SECONDS)
    assert first["wall_hits"] == 0 and first["lowest"] == first["height"][0]
    assert first["lift"] != in_process.values[7]["lift"]          # each task its own seed


def test_two_local_processes_give_the_same_bits(in_process):
    result = run_sweep(seeded_sweep(), backend="processes", workers=2, seed=11, progress=False)
    assert encode(result.values) == encode(in_process.values)
    assert [r.key for r in result.results] == [r.key for r in in_process.results]
    assert result.backend == "processes"


def test_a_dask_cluster_gives_the_same_bits(in_process, dask_scheduler):
    result = run_sweep(seeded_sweep(), backend="dask", scheduler=dask_scheduler, seed=11,
                       progress=False)
    assert encode(result.values) == encode(in_process.values)
    assert [r.attempts for r in result.results] == [1] * len(result.results)
