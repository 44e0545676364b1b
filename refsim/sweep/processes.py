"""The "processes" backend: local worker processes, started fresh.

A ``concurrent.futures.ProcessPoolExecutor`` whose workers are started with
the ``spawn`` method: each is a new interpreter that imports what it needs.
Forking the parent would copy its state into every worker: threads that
hold locks (a Dask client's, numba's), pybullet's process-global physics
server connection, whatever a task left in module globals. ``forkserver``
would also give clean workers on Linux, but leaves a server process behind
for the parent's lifetime and does not exist on Windows; ``spawn`` is the
one method every platform has, and its cost (each worker imports numpy and
refsim and loads refsim's compiled kernels from numba's cache, once per
worker per sweep) is measured with the sweep benchmarks. The caller's main
script must therefore be importable without side effects (the usual ``if
__name__ == "__main__":`` guard).

A worker that dies (killed, a segfault in compiled code) breaks the whole
pool: every call it held comes back ``BrokenProcessPool``. Each comes back
as a LOST outcome, and the next submit starts a new pool. The workers
ignore SIGINT: Ctrl-C in a terminal reaches the whole process group, and the
parent alone decides to stop, terminating the workers
(:meth:`Processes.close` with ``abort``).

Cost per task: pickling the call and its JSON result through a pipe (see
the benchmarks for the measured overhead); per pool, one interpreter start
per worker.
"""

from __future__ import annotations

import multiprocessing
import queue
import signal
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool

from refsim.sweep.execute import LOST, RAISED, Outcome, execute, one_line


def _ignore_interrupt() -> None:
    """Worker initializer: SIGINT is the parent's to act on (see the module docstring)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


class Processes:
    """A pool of ``workers`` spawned processes, renewed when one dies (state:
    the current pool, its generation, and the finished futures)."""

    name = "processes"

    def __init__(self, workers: int):
        self.slots = workers
        self._workers = workers
        self._pool: ProcessPoolExecutor | None = None
        self._generation = 0                     # which pool a future belongs to
        # (index, generation, future), from callbacks
        self._finished: queue.SimpleQueue[tuple[int, int, Future[Outcome]]] = queue.SimpleQueue()

    def submit(self, index: int, function, kwargs: dict, seed: int) -> None:
        for _ in range(2):                       # a pool found broken is renewed once
            try:
                future = self._current_pool().submit(execute, function, kwargs, seed)
                break
            except BrokenProcessPool:
                self._discard(self._generation)
        else:
            raise BrokenProcessPool("a new pool of worker processes broke at once")
        generation = self._generation
        future.add_done_callback(lambda f: self._finished.put((index, generation, f)))

    def next_outcome(self, timeout: float) -> tuple[int, Outcome] | None:
        try:
            index, generation, future = self._finished.get(timeout=timeout)
        except queue.Empty:
            return None
        error = future.exception()               # never raises: the future is done
        if error is None:
            return index, future.result()
        if isinstance(error, BrokenProcessPool):
            self._discard(generation)
            return index, Outcome(LOST, "worker process died while running the task (killed, "
                                        "crashed in compiled code, or could not start: the "
                                        "main script must be importable)")
        # Raised in the worker outside execute's handler: a BaseException of the
        # task (SystemExit, KeyboardInterrupt), or a result pickle could not send.
        return index, Outcome(RAISED, one_line(error))

    def close(self, *, abort: bool = False) -> None:
        pool, self._pool = self._pool, None
        if pool is None:
            return
        if abort:
            _terminate_workers(pool)
        pool.shutdown(wait=True, cancel_futures=True)

    def _current_pool(self) -> ProcessPoolExecutor:
        if self._pool is None:
            self._pool = ProcessPoolExecutor(
                self._workers, mp_context=multiprocessing.get_context("spawn"),
                initializer=_ignore_interrupt)
        return self._pool

    def _discard(self, generation: int) -> None:
        """Drop the pool of ``generation`` if it is the current one (the other
        calls of a broken pool report the same break; the first one renews)."""
        if generation == self._generation and self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
            self._generation += 1


def _terminate_workers(pool: ProcessPoolExecutor) -> None:
    """SIGTERM every worker of ``pool`` now, mid-task.

    Python 3.14 has ``ProcessPoolExecutor.terminate_workers()``; before it,
    the executor offers no way to stop a running call, so its (private but
    long-stable) ``_processes`` map of worker processes is used.
    """
    terminate = getattr(pool, "terminate_workers", None)
    if terminate is not None:
        terminate()
        return
    for process in list((getattr(pool, "_processes", None) or {}).values()):
        if process.is_alive():
            process.terminate()
