"""The Dask backend: a killed worker costs a retry, on a cluster started
apart (its scheduler reruns the task) and on a local cluster (the sweep
reruns it); an unreachable scheduler is one clear error."""

from __future__ import annotations

import pytest

from refsim.errors import SweepError
from refsim.sweep import Task, dask_cluster, run_sweep
from refsim.sweep.records import encode
from tests.sweep import tasks
from tests.sweep.test_processes import sweep_with_a_killer


def test_a_killed_worker_of_a_separate_cluster_costs_a_retry(tmp_path, dask_scheduler):
    marker = tmp_path / "killed"
    result = run_sweep(sweep_with_a_killer(marker), backend="dask", scheduler=dask_scheduler,
                       seed=5, progress=False)
    assert marker.exists() and result.ok
    undisturbed = run_sweep(sweep_with_a_killer(marker), seed=5, progress=False)
    assert encode(result.values) == encode(undisturbed.values)


def test_a_killed_worker_of_a_local_cluster_is_retried_by_the_sweep(tmp_path):
    marker = tmp_path / "killed"
    result = run_sweep(sweep_with_a_killer(marker), backend="dask", workers=2, seed=5,
                       progress=False)
    assert marker.exists() and result.ok
    undisturbed = run_sweep(sweep_with_a_killer(marker), seed=5, progress=False)
    assert encode(result.values) == encode(undisturbed.values)
    attempts = {r.key: r.attempts for r in result.results}
    assert attempts["d3"] == 2 and max(attempts.values()) == 2


def test_an_unreachable_scheduler_is_one_sweep_error(monkeypatch):
    monkeypatch.setattr(dask_cluster, "CONNECT_SECONDS", 0.5)
    with pytest.raises(SweepError, match="cannot reach the Dask scheduler at tcp://127.0.0.1:9"):
        run_sweep([Task("a", tasks.draws)], backend="dask", scheduler="tcp://127.0.0.1:9",
                  progress=False)
