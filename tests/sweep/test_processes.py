"""Local processes: a killed worker costs a retry, not the sweep; Ctrl-C
stops the workers and leaves only whole results."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil

from refsim.sweep import Task, run_sweep
from refsim.sweep.records import encode
from tests.helpers import new_workers
from tests.sweep import tasks

ROOT = Path(__file__).resolve().parents[2]

#: Bounded waits for the interrupted subprocess (its start includes spawning workers).
WAIT_SECONDS = 60.0


def sweep_with_a_killer(marker: Path) -> list[Task]:
    sweep = [Task(f"d{i}", tasks.draws, {"n": 8 + i}) for i in range(6)]
    sweep[3] = Task("d3", tasks.die_once, {"marker": str(marker), "n": 11})
    return sweep


def test_a_killed_worker_costs_a_retry_and_the_results_are_undisturbed(tmp_path):
    marker = tmp_path / "killed"
    result = run_sweep(sweep_with_a_killer(marker), backend="processes", workers=2, seed=5,
                       progress=False)
    assert marker.exists()                             # it did die once
    assert result.ok
    undisturbed = run_sweep(sweep_with_a_killer(marker), seed=5, progress=False)
    assert encode(result.values) == encode(undisturbed.values)
    attempts = {r.key: r.attempts for r in result.results}
    assert attempts["d3"] == 2 and max(attempts.values()) == 2
    assert undisturbed.results[3].attempts == 1


def test_a_task_that_always_kills_its_worker_fails_after_its_retries(tmp_path):
    sweep = [Task("ok-0", tasks.draws), Task("dies", tasks.die_always), Task("ok-1", tasks.draws)]
    result = run_sweep(sweep, backend="processes", workers=2, retries=1, progress=False)
    assert [r.status for r in result.results] == ["done", "failed", "done"]
    assert result.results[1].attempts == 2
    assert result.failures["dies"].startswith("worker process died")
    assert result.failures["dies"].endswith("gave up after 2 attempts")


SCRIPT = """
import sys
from refsim.sweep import Task, run_sweep
from tests.helpers import new_workers
from tests.sweep import tasks

if __name__ == "__main__":
    markers, store = sys.argv[1], sys.argv[2]
    sweep = [Task(f"c{i}", tasks.counted, {"marker_dir": markers, "key": f"c{i}", "pause": 0.15})
             for i in range(16)]
    run_sweep(sweep, backend="processes", workers=2, store=store, progress=False)
"""


def _wait_for(condition, what: str) -> None:
    deadline = time.monotonic() + WAIT_SECONDS
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.02)


def test_ctrl_c_stops_the_workers_and_the_sweep_resumes(tmp_path):
    markers, store = tmp_path / "markers", tmp_path / "store"
    markers.mkdir()
    script = tmp_path / "interrupted.py"
    script.write_text(SCRIPT)
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    process = subprocess.Popen([sys.executable, str(script), str(markers), str(store)], env=env,
                               cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        results = store / "results"
        _wait_for(lambda: results.is_dir() and len(list(results.glob("*.json"))) >= 3,
                  "three stored results")
        workers = psutil.Process(process.pid).children(recursive=True)
        assert len(workers) >= 2
        process.send_signal(signal.SIGINT)
        _, err = process.communicate(timeout=WAIT_SECONDS)
    finally:
        process.kill()
        process.wait(WAIT_SECONDS)
    assert process.returncode != 0 and b"KeyboardInterrupt" in err
    gone, alive = psutil.wait_procs(workers, timeout=WAIT_SECONDS)
    assert not [p for p in alive if p.status() != psutil.STATUS_ZOMBIE]
    assert not list(store.rglob("*.tmp"))
    stored = len(list((store / "results").glob("*.json")))
    assert 3 <= stored < 16
    before = tasks.executions(markers)

    sweep = [Task(f"c{i}", tasks.counted, {"marker_dir": str(markers), "key": f"c{i}",
                                           "pause": 0.15}) for i in range(16)]
    result = run_sweep(sweep, store=store, progress=False)
    assert result.ok and sum(r.resumed for r in result.results) == stored
    after = tasks.executions(markers)
    ran_again = {key for key in after if after[key] > before.get(key, 0)}
    assert ran_again == {r.key for r in result.results if not r.resumed}
    assert all(after[key] - before.get(key, 0) == 1 for key in ran_again)


def test_a_cancel_event_stops_a_sweep_run_in_another_thread(tmp_path):
    """A sweep in a thread that Ctrl-C does not reach (the report's) stops
    when its ``cancel`` event is set: its workers are terminated mid-task,
    and it raises SweepCancelled, long before the tasks would have ended."""
    import threading

    from refsim.sweep import SweepCancelled

    markers = tmp_path / "markers"
    markers.mkdir()
    sweep = [Task(f"c{i}", tasks.counted, {"marker_dir": str(markers), "key": f"c{i}",
                                           "pause": 300.0}) for i in range(4)]
    cancel = threading.Event()
    raised: list[BaseException] = []

    def run() -> None:
        try:
            run_sweep(sweep, backend="processes", workers=2, progress=False, cancel=cancel)
        except BaseException as exc:  # noqa: BLE001 - the test reads it
            raised.append(exc)

    me = psutil.Process()
    before = {p.pid for p in me.children(recursive=True)}   # e.g. a Dask fixture's
    thread = threading.Thread(target=run)
    thread.start()
    _wait_for(lambda: len(new_workers(me, before)) >= 2, "two workers")
    workers = new_workers(me, before)
    start = time.monotonic()
    cancel.set()
    thread.join(WAIT_SECONDS)
    assert not thread.is_alive() and time.monotonic() - start < 30.0
    assert len(raised) == 1 and isinstance(raised[0], SweepCancelled)
    assert "0 of 4 tasks done" in str(raised[0])
    _, alive = psutil.wait_procs(workers, timeout=WAIT_SECONDS)
    assert not [p for p in alive if p.status() != psutil.STATUS_ZOMBIE]
    assert tasks.executions(markers) == {}
