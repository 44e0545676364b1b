"""``run_sweep``: run every task once on a backend, keep what arrives.

The loop, as an outline:

1. check      the tasks (keys unique), derive each task's seed from its key;
2. resume     open the store, if any; a task with a stored result is done;
3. submit     the waiting tasks in order, keeping ``backend.slots`` in flight;
4. collect    each outcome as it arrives: a result is stored at once (so an
              interruption loses no finished work); an exception is the
              task's answer (failed, with its one-line message, not retried);
              a lost worker costs the task an attempt;
5. retry      a task whose worker died, up to ``retries`` more times, each
              time *alone*: when a worker dies, every call it held is lost
              with it, and the one that killed it cannot be told from the
              ones beside it; run alone, a task that dies again is charged
              alone, and an innocent neighbour simply succeeds (at the cost
              of one extra attempt, which ``attempts`` shows);
6. return     every task's result in task order.

Ctrl-C (or any error in the loop, such as a full disk, or the caller's
``cancel`` event, for a sweep run in another thread than the one Ctrl-C
reaches) stops the backend at once (running calls cancelled, local workers
terminated) and propagates; every result stored before it stays, whole.
The result files are written by this process only, never by a worker.

Retries are decided here for every backend, so that ``retries`` means the
same everywhere (a Dask scheduler refsim did not start may also retry on its
own: see :mod:`refsim.sweep.dask_cluster`).

Cost: the tasks' own, divided among the workers, plus a per-task overhead
(the backend's, and one small fsync'd file per result with a store).
"""

from __future__ import annotations

import math
import threading
import time
from collections import deque
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from refsim.errors import ArgumentTypeError, SweepError, check_count
from refsim.sweep.backend import check_backend, open_backend
from refsim.sweep.execute import LOST, RAISED
from refsim.sweep.progress import REFRESH_SECONDS, Progress
from refsim.sweep.records import decode
from refsim.sweep.store import Store
from refsim.sweep.tasks import Task, fingerprint, task_seed


class SweepCancelled(Exception):
    """The caller's ``cancel`` event stopped a sweep (:func:`run_sweep`)."""


#: TaskResult.status values.
DONE_STATUS, FAILED_STATUS = "done", "failed"


@dataclass(frozen=True)
class TaskResult:
    """What became of one task.

    ``value`` is the task's record as JSON gives it back (None when it
    failed); ``error`` the one-line reason it failed (None when done).
    ``attempts`` counts the times it was started (more than 1 after a
    worker died); ``resumed`` is true for a result read from the store, which
    keeps the attempts and time of the run that computed it.
    ``wall_seconds`` is the time of the task's call in its worker: a timing,
    which differs from run to run (NaN when no call finished).
    """

    key: str
    status: str
    value: Any = None
    error: str | None = None
    attempts: int = 0
    resumed: bool = False
    wall_seconds: float = math.nan


@dataclass(frozen=True)
class SweepResult:
    """Every task's :class:`TaskResult`, in task order.

    ``wall_seconds`` (a timing) is the time of the whole call of
    :func:`run_sweep`, resumed tasks and backend start-up included.
    """

    results: tuple[TaskResult, ...]
    backend: str
    wall_seconds: float

    @property
    def values(self) -> list:
        """Each task's value, in task order (None for a failed task)."""
        return [result.value for result in self.results]

    @property
    def failures(self) -> dict[str, str]:
        """Key -> one-line reason, for each failed task, in task order."""
        return {r.key: r.error or "no reason given" for r in self.results
                if r.status == FAILED_STATUS}

    @property
    def ok(self) -> bool:
        """True when every task is done."""
        return not self.failures


def run_sweep(tasks: Iterable[Task], *, backend: str = "inprocess", workers: int | None = None,
              scheduler: str | None = None, store=None, progress: bool = True,
              retries: int = 3, seed: int = 0,
              cancel: threading.Event | None = None) -> SweepResult:
    """Run each task once and return their results in task order.

    Parameters
    ----------
    tasks : iterable of Task
        Keys unique. Each is called as ``function(seed=s, **kwargs)`` with
        ``s = task_seed(seed, key)``.
    backend : {"inprocess", "processes", "dask"}
        Where the calls run: a plain loop here; ``workers`` spawned local
        processes; a Dask cluster. The results are the same on each.
    workers : int, optional
        Local worker processes ("processes", or the local Dask cluster
        started when no ``scheduler`` is given); default the CPU count,
        never more than the tasks to run.
    scheduler : str, optional
        A Dask scheduler's address, ``"tcp://host:port"`` ("dask" only).
    store : str or PathLike, optional
        A directory to keep results in as they arrive. Run again with the
        same store, the sweep runs only the tasks without a stored result.
    progress : bool
        Show done/total, failures and time left on stderr when it is a
        terminal.
    retries : int
        How many more times a task whose worker died (killed, crashed) is
        run before it is reported failed. A task that raises is not retried.
    seed : int
        The sweep's seed (non-negative); each task's seed derives from it
        and the task's key only.
    cancel : threading.Event, optional
        Once set, the sweep stops as on Ctrl-C (within ``REFRESH_SECONDS``)
        and raises :class:`SweepCancelled`: for a sweep run in a thread that
        signals do not reach.

    Returns
    -------
    SweepResult
        One TaskResult per task, in task order; failed tasks carry their
        reason. Raises nothing for a failed task: the caller decides.

    Raises
    ------
    SweepError
        Two tasks with one key; a store written by another task list.
    OptionError
        An unknown backend, an option that does not apply to it, or the
        "dask" backend without ``distributed``.
    ArgumentTypeError
        Something other than a Task among ``tasks``.
    KeyboardInterrupt, SweepCancelled
        After stopping the workers; the stored results stay.
    """
    start = time.perf_counter()
    check_backend(backend, workers=workers, scheduler=scheduler)
    tasks = _checked(tasks)
    retries = check_count("retries", retries, minimum=0)
    seed = check_count("seed", seed, minimum=0)
    seeds = [task_seed(seed, task.key) for task in tasks]
    results: list[TaskResult | None] = [None] * len(tasks)
    saved = None
    if store is not None:
        saved = Store(store, {t.key: fingerprint(t, s) for t, s in zip(tasks, seeds, strict=True)})
        for index, task in enumerate(tasks):
            record = saved.load(task.key)
            if record is not None:
                results[index] = TaskResult(task.key, DONE_STATUS, record["value"],
                                            attempts=record["attempts"], resumed=True,
                                            wall_seconds=record["wall_seconds"])
    waiting = deque(i for i, result in enumerate(results) if result is None)
    shown = Progress(len(tasks), len(tasks) - len(waiting), enabled=progress)
    try:
        if waiting:
            runner = open_backend(backend, workers=workers, scheduler=scheduler,
                                  calls=len(waiting))
            try:
                _run(runner, tasks, seeds, waiting, results, saved, retries, shown, cancel)
            except BaseException:
                runner.close(abort=True)
                raise
            runner.close()
    finally:
        shown.close()
    return SweepResult(_filled(results, tasks), backend, time.perf_counter() - start)


def _run(runner, tasks, seeds, waiting: deque, results: list, saved: Store | None,
         retries: int, shown: Progress, cancel: threading.Event | None) -> None:
    """Steps 3-5 of the module docstring; fills ``results`` in place."""
    attempts = [0] * len(tasks)
    suspects: deque[int] = deque()               # lost with their worker: run next, alone
    in_flight: set[int] = set()
    finished = len(tasks) - len(waiting)         # resumed ones count as finished
    failed = 0
    shown.update(finished, failed, force=True)

    def submit(index: int) -> None:
        attempts[index] += 1
        in_flight.add(index)
        runner.submit(index, tasks[index].function, dict(tasks[index].kwargs), seeds[index])

    while waiting or suspects or in_flight:
        if cancel is not None and cancel.is_set():
            raise SweepCancelled(f"sweep cancelled with {finished} of {len(tasks)} tasks done")
        if suspects:
            if not in_flight:
                submit(suspects.popleft())
        else:
            while waiting and len(in_flight) < runner.slots:
                submit(waiting.popleft())
        arrived = runner.next_outcome(REFRESH_SECONDS)
        if arrived is None:
            shown.update(finished, failed)       # the time left keeps moving
            continue
        index, outcome = arrived
        in_flight.discard(index)
        key = tasks[index].key
        if outcome.kind == LOST:
            attempts[index] += outcome.attempts_used - 1
            if attempts[index] <= retries:
                suspects.append(index)
                continue
            results[index] = TaskResult(
                key, FAILED_STATUS, attempts=attempts[index],
                error=f"{outcome.payload}; gave up after {attempts[index]} attempts")
        elif outcome.kind == RAISED:
            results[index] = TaskResult(key, FAILED_STATUS, error=outcome.payload,
                                        attempts=attempts[index],
                                        wall_seconds=outcome.wall_seconds)
        else:
            if saved is not None:                # stored before anything else can go wrong
                saved.save(key, outcome.payload, attempts[index], outcome.wall_seconds)
            results[index] = TaskResult(key, DONE_STATUS, decode(outcome.payload),
                                        attempts=attempts[index],
                                        wall_seconds=outcome.wall_seconds)
        finished += 1
        failed += results[index].status == FAILED_STATUS
        shown.update(finished, failed, force=finished == len(tasks))


def _filled(results: list[TaskResult | None], tasks: list[Task]) -> tuple[TaskResult, ...]:
    """``results`` once every task has one (``_run`` fills each index it is given)."""
    missing = [task.key for task, result in zip(tasks, results, strict=True) if result is None]
    if missing:
        raise SweepError(f"internal error: the sweep ended without a result for {missing}")
    return tuple(result for result in results if result is not None)


def _checked(tasks) -> list[Task]:
    tasks = list(tasks)
    seen = set()
    for task in tasks:
        if not isinstance(task, Task):
            raise ArgumentTypeError(f"tasks must be refsim.sweep.Task objects, "
                                    f"got {type(task).__name__}")
        if task.key in seen:
            raise SweepError(f"two tasks have the key {task.key!r}; keys must be unique")
        seen.add(task.key)
    return tasks
