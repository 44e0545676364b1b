"""The "dask" backend: a Dask cluster (package ``distributed``).

Either a scheduler someone runs (``scheduler="tcp://host:port"``: its
workers are used as they are), or a local cluster started for the sweep and
closed after it: ``LocalCluster(n_workers=workers, threads_per_worker=1,
processes=True)`` on 127.0.0.1, without a dashboard. One thread per worker
process because refsim's tasks are CPU-bound Python and numba code, which
threads of one process would run one at a time (the GIL), and because a
task that dies then takes only itself down.

The workers of a scheduler refsim did not start must be able to import
refsim (the same version) and each task's module, as the client does.

Calls are submitted with ``pure=False`` (every attempt a new Dask key, never
a cached result) and the client does not become the process's default
(``set_as_default=False``: no global state left behind). Each finished
future is handed to the run loop through a queue filled by the futures'
callbacks, then released.

Worker deaths. Dask's scheduler itself reruns a task whose worker died,
until it has died ``distributed.scheduler.allowed-failures`` times (default
3), and then fails it with ``KilledWorker``. The local cluster is started
with ``allowed_failures=0``, so that the first death comes back to the run
loop, which retries the same way as for every backend. A scheduler refsim
did not start keeps its own setting: its ``KilledWorker`` counts as the
``allowed_failures + 1`` attempts it says it made, and a task it reran
successfully shows 1 attempt (the client is not told about reruns).

Cost per task: a scheduler round trip and the pickled call and JSON result
over TCP (see the benchmarks for the measured overhead); a local cluster
takes a few seconds to start (one interpreter per worker plus the
scheduler).
"""

from __future__ import annotations

import logging
import queue
from typing import TYPE_CHECKING

from refsim.errors import OptionError, SweepError
from refsim.sweep.execute import LOST, RAISED, Outcome, execute, one_line

#: Seconds to reach a scheduler, and to wait for its first worker: a cluster
#: that is still starting gets time; a wrong address fails within a minute.
CONNECT_SECONDS = 30.0
WORKERS_SECONDS = 60.0

#: Seconds to fetch one finished result from its worker (it is small JSON text).
GATHER_SECONDS = 60.0

#: Seconds to close the client and a local cluster before giving up on them.
CLOSE_SECONDS = 20.0

#: Calls kept submitted per worker thread: one running and one waiting, so
#: that a worker does not idle for a scheduler round trip between two tasks.
#: More would put more calls on a worker that may die with them.
CALLS_PER_THREAD = 2

if TYPE_CHECKING:                                # imported when used: see _distributed
    from distributed import Future

#: The local scheduler's HTTP server (health checks; no dashboard is shown)
#: listens on a free port of the loopback interface, never on the dashboard's
#: usual 8787, which another cluster on the machine may hold.
HTTP_ADDRESS = "127.0.0.1:0"

#: Workers' log messages below this level are not shown: a killed worker's
#: restart is reported by the sweep itself (as an attempt), not as a warning.
WORKER_LOG_LEVEL = logging.ERROR


def _distributed():
    try:
        import distributed
    except ImportError:
        raise OptionError("backend 'dask' needs the package 'distributed': "
                          "pip install 'refsim[sweep]'") from None
    return distributed


class DaskCluster:
    """A client of a Dask scheduler, and the local cluster it started if any
    (state: client, cluster, the futures in flight)."""

    name = "dask"

    def __init__(self, *, scheduler: str | None, workers: int):
        distributed = _distributed()
        self._killed_worker = distributed.KilledWorker
        self._cluster = None
        self._finished: queue.SimpleQueue[tuple[int, Future]] = queue.SimpleQueue()
        self._in_flight: dict[int, Future] = {}  # index -> future
        if scheduler is None:
            self._cluster = distributed.LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                dashboard_address=None, silence_logs=WORKER_LOG_LEVEL,
                scheduler_kwargs={"allowed_failures": 0, "dashboard_address": HTTP_ADDRESS})
            address = self._cluster
        else:
            address = scheduler
        try:
            self._client = distributed.Client(address, timeout=CONNECT_SECONDS,
                                              set_as_default=False)
        except (OSError, TimeoutError) as error:
            self._close_cluster()
            raise SweepError(f"cannot reach the Dask scheduler at {scheduler}: {error}") from None
        try:
            self._client.wait_for_workers(1, timeout=WORKERS_SECONDS)
        except (OSError, TimeoutError) as error:
            self.close(abort=True)
            raise SweepError(f"the Dask scheduler at {scheduler} has no worker after "
                             f"{WORKERS_SECONDS:g} s: {error}") from None
        threads = sum(self._client.nthreads().values())
        self.slots = CALLS_PER_THREAD * max(1, threads)

    def submit(self, index: int, function, kwargs: dict, seed: int) -> None:
        future = self._client.submit(execute, function, kwargs, seed, pure=False)
        self._in_flight[index] = future
        future.add_done_callback(lambda f: self._finished.put((index, f)))

    def next_outcome(self, timeout: float) -> tuple[int, Outcome] | None:
        try:
            index, future = self._finished.get(timeout=timeout)
        except queue.Empty:
            return None
        self._in_flight.pop(index, None)
        try:
            return index, self._outcome(future)
        finally:
            future.release()

    def _outcome(self, future: Future) -> Outcome:
        if future.status == "finished":
            try:
                return future.result(timeout=GATHER_SECONDS)
            except Exception as error:           # its worker died before we fetched it
                return Outcome(LOST, f"result lost with its worker: {one_line(error)}")
        if future.status != "error":             # cancelled or lost by the scheduler
            return Outcome(LOST, f"the scheduler reports the task {future.status}")
        exception = future.exception(timeout=GATHER_SECONDS)
        if isinstance(exception, self._killed_worker):
            return Outcome(LOST, f"worker process died while running the task "
                                 f"({exception.allowed_failures + 1} time(s) on the scheduler)",
                           attempts_used=exception.allowed_failures + 1)
        return Outcome(RAISED, one_line(exception))   # raised outside execute's handler

    def close(self, *, abort: bool = False) -> None:
        try:
            if abort and self._in_flight:
                self._client.cancel(list(self._in_flight.values()), force=True)
            self._in_flight.clear()
            self._client.close(timeout=CLOSE_SECONDS)
        finally:
            self._close_cluster()

    def _close_cluster(self) -> None:
        cluster, self._cluster = self._cluster, None
        if cluster is not None:
            cluster.close(timeout=CLOSE_SECONDS)

