"""run_sweep in-process: order, failures, seeds, options, resuming a sweep."""

from __future__ import annotations

import sys

import pytest

from refsim.errors import ArgumentTypeError, OptionError, StateError, SweepError
from refsim.sweep import Task, run_sweep, task_seed
from refsim.sweep.records import decode, encode
from tests.sweep import tasks


def test_results_come_in_task_order_with_failures_carrying_their_message():
    sweep = [Task("b", tasks.draws, {"n": 5}), Task("a", tasks.fail, {"message": "no good"}),
             Task("c", tasks.not_plain), Task("d", tasks.draws)]
    result = run_sweep(sweep, seed=3, progress=False)
    assert [r.key for r in result.results] == ["b", "a", "c", "d"]
    assert [r.status for r in result.results] == ["done", "failed", "failed", "done"]
    assert result.failures == {
        "a": "ValueError: no good",
        "c": "TypeError: a set is not a plain record (allowed: None, bool, int, float, str, "
             "lists and tuples, dicts with str keys, numpy scalars and arrays)"}
    assert [r.attempts for r in result.results] == [1, 1, 1, 1]        # raising is not retried
    assert result.values[1] is None and not result.ok
    assert result.values[0] == decode(encode(tasks.draws(seed=task_seed(3, "b"), n=5)))
    assert result.results[0].wall_seconds > 0 and result.backend == "inprocess"


def test_a_failed_result_without_a_message_is_still_a_failure():
    from refsim.sweep.run import SweepResult, TaskResult

    result = SweepResult((TaskResult("a", "failed"),), "inprocess", 0.0)
    assert result.failures == {"a": "no reason given"} and not result.ok


def test_the_progress_line_never_goes_to_stdout(capsys):
    run_sweep([Task("a", tasks.draws)], progress=True)
    assert capsys.readouterr() == ("", "")          # and stderr is no terminal here


def test_an_interrupted_sweep_resumes_without_running_a_task_twice(tmp_path):
    markers, store = tmp_path / "markers", tmp_path / "store"
    markers.mkdir()
    once = str(tmp_path / "interrupted")
    sweep = [Task(f"c{i}", tasks.counted, {"marker_dir": str(markers), "key": f"c{i}",
                                           "interrupt_once": once if i == 4 else None})
             for i in range(8)]
    with pytest.raises(KeyboardInterrupt):
        run_sweep(sweep, store=store, progress=False)
    assert tasks.executions(markers) == {f"c{i}": 1 for i in range(4)}
    assert len(list((store / "results").iterdir())) == 4
    result = run_sweep(sweep, store=store, progress=False)
    assert result.ok
    assert tasks.executions(markers) == {f"c{i}": 1 for i in range(8)}
    assert [r.resumed for r in result.results] == [True] * 4 + [False] * 4
    fresh = run_sweep(sweep, progress=False)               # no store: every task runs
    assert encode(result.values) == encode(fresh.values)
    assert not list(store.rglob("*.tmp"))


def test_a_finished_store_answers_without_starting_a_backend(tmp_path, monkeypatch):
    sweep = [Task("a", tasks.draws)]
    first = run_sweep(sweep, store=tmp_path, progress=False)
    monkeypatch.setitem(sys.modules, "distributed", None)      # dask could not start now
    again = run_sweep(sweep, backend="dask", store=tmp_path, progress=False)
    assert again.values == first.values and again.results[0].resumed


def test_a_store_of_another_task_list_is_refused_before_anything_runs(tmp_path):
    markers = tmp_path / "markers"
    markers.mkdir()
    sweep = [Task("c0", tasks.counted, {"marker_dir": str(markers), "key": "c0"})]
    run_sweep(sweep, store=tmp_path / "s", progress=False)
    with pytest.raises(SweepError, match="another task list.*'c0'"):
        run_sweep(sweep, store=tmp_path / "s", seed=1, progress=False)    # other seeds
    changed = [Task("c0", tasks.counted, {"marker_dir": str(markers), "key": "c0", "pause": 0.1}),
               Task("c1", tasks.counted, {"marker_dir": str(markers), "key": "c1"})]
    with pytest.raises(SweepError, match="another task list.*'c0'"):
        run_sweep(changed, store=tmp_path / "s", progress=False)
    assert tasks.executions(markers) == {"c0": 1}


def test_dask_without_distributed_names_the_package_to_install(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(OptionError, match=r"pip install 'refsim\[sweep\]'"):
        run_sweep([Task("a", tasks.draws)], backend="dask", workers=1, progress=False)


@pytest.mark.parametrize("options, error, phrase", [
    ({"backend": "threads"}, OptionError, "backend must be one of"),
    ({"workers": 2}, OptionError, "'inprocess' runs in this process"),
    ({"backend": "processes", "scheduler": "tcp://127.0.0.1:1"}, OptionError, "dask"),
    ({"backend": "dask", "scheduler": "tcp://127.0.0.1:1", "workers": 2}, OptionError, "not both"),
    ({"backend": "processes", "workers": 0}, StateError, "workers must be at least 1"),
    ({"retries": -1}, StateError, "retries"),
    ({"seed": 1.5}, ArgumentTypeError, "seed"),
])
def test_options_that_do_not_apply_are_refused(options, error, phrase):
    with pytest.raises(error, match=phrase):
        run_sweep([Task("a", tasks.draws)], progress=False, **options)


def test_keys_are_unique_and_tasks_are_tasks():
    with pytest.raises(SweepError, match="two tasks have the key 'a'"):
        run_sweep([Task("a", tasks.draws), Task("a", tasks.draws, {"n": 3})])
    with pytest.raises(ArgumentTypeError, match="Task objects"):
        run_sweep([tasks.draws])
