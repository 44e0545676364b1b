"""How fast each sweep backend is: speed-up on CPU-bound tasks, cost per task.

Two measurements, each the median of ``repeats`` whole ``run_sweep`` calls
per backend ("inprocess", "processes" with W workers, "dask" with a local
cluster of W single-thread worker processes):

- **speed-up**: ``tasks`` runs of :func:`refsim.sweep.examples.bounce` for
  ``duration`` simulated seconds each; the
  speed-up of a backend is the in-process median over its median. A local
  backend's time includes starting its workers, as every sweep call does
  (spawned interpreters importing numpy and refsim and loading the compiled
  kernels; a Dask cluster besides), so it is the speed-up a caller sees, not
  the workers' ideal W. The CPU time of the sweep (this process and its
  workers) is reported beside it: unlike the wall time it hardly depends on
  what else the machine runs, and its excess over in-process is the CPU cost
  of the backend (workers' imports, kernel loading, a scheduler);
- **overhead per task**: sweeps of W and of ``trivial`` tasks that do
  nothing (:func:`refsim.sweep.examples.trivial`), W being the number of
  workers (1 in-process), so that both start the same workers;
  ``(T(trivial) - T(W)) / (trivial - W)`` is the marginal cost of one task
  (submit, run the wrapper, return and decode the result), and ``T(W)``,
  the start-up, is reported apart;
- **store cost per task**: the in-process sweep of ``trivial`` tasks with a
  new store directory against the same without one, per task (a result
  file written and fsync'd, whatever the backend).

In-process sweeps run after a warm-up call, in a process that has refsim
loaded and compiled kernels cached: the state of a session that calls
``run_sweep``. Timings vary between runs and machines, and this machine's
cores may be shared: quote medians with the command
``refsim study sweep-speed`` (which prints the load average too).

Cost: about ``repeats * (tasks * task time * (1 + 2/W) + 3 start-ups)``.
"""

from __future__ import annotations

import math
import os
import statistics
import tempfile
import time
from dataclasses import dataclass, field

from refsim.studies import TIMED
from refsim.sweep.backend import BACKENDS
from refsim.sweep.examples import bounce, trivial
from refsim.sweep.run import run_sweep
from refsim.sweep.tasks import Task

#: Simulated seconds of bounce.toml per benchmark task: long enough that a
#: task's computation, not the backend's cost per task, dominates the
#: speed-up, and short enough that the benchmark stays a quick one.
BENCH_DURATION = 6.0


@dataclass(frozen=True)
class BackendSpeed:
    """One backend's medians (seconds; all timings)."""

    backend: str
    workers: int | None
    bench_seconds: float = field(metadata=TIMED)  # the sweep of the CPU-bound tasks
    bench_cpu_seconds: float = field(metadata=TIMED)  # CPU time of that sweep, here and in workers
    speedup: float = field(metadata=TIMED)  # in-process bench_seconds over this one's
    startup_seconds: float = field(metadata=TIMED)  # a sweep of one trivial task per worker
    trivial_seconds: float = field(metadata=TIMED)  # a sweep of ``trivial`` trivial tasks
    # (trivial_seconds - startup_seconds) / (trivial - workers)
    per_task_seconds: float = field(metadata=TIMED)


@dataclass(frozen=True)
class SweepSpeed:
    tasks: int
    duration: float
    trivial: int
    repeats: int
    task_seconds: float = field(metadata=TIMED)  # median wall time of one benchmark task in-process
    store_per_task_seconds: float = field(metadata=TIMED)  # added per task by a store
    # The machine's 1-minute load, before and after: it varies from run to run
    # as the timings do.
    load_average: tuple[float, float] = field(metadata=TIMED)
    backends: tuple[BackendSpeed, ...]


def _cpu_seconds() -> float:
    """User and system CPU time of this process and of its finished children
    (worker processes count once the backend has stopped and reaped them);
    NaN where there is no ``getrusage`` (Windows)."""
    try:
        import resource
    except ImportError:
        return math.nan
    own, children = (resource.getrusage(who) for who in (resource.RUSAGE_SELF,
                                                          resource.RUSAGE_CHILDREN))
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def _load_average() -> float:
    """The 1-minute load average (NaN where the system has none)."""
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):
        return math.nan


def _seconds(tasks: list[Task], *, stored: bool = False, **options) -> tuple[float, float]:
    """Wall and CPU time of one sweep of ``tasks`` (in a new store when ``stored``)."""
    with tempfile.TemporaryDirectory() as folder:
        cpu, start = _cpu_seconds(), time.perf_counter()
        result = run_sweep(tasks, progress=False, store=folder if stored else None, **options)
        seconds, cpu = time.perf_counter() - start, _cpu_seconds() - cpu
    if not result.ok:
        raise RuntimeError(f"benchmark sweep failed: {result.failures}")
    return seconds, cpu


def measure_sweep_speed(*, tasks: int = 16, duration: float = BENCH_DURATION, workers: int = 2,
                        trivial_tasks: int = 200, repeats: int = 3,
                        backends=BACKENDS) -> SweepSpeed:
    """Time every backend in ``backends`` (see the module docstring).

    The repeats are interleaved (every backend once, then again), so that a
    change in the machine's load over the run hits every backend alike.
    """
    load_before = _load_average()
    bench = [Task(f"bounce-{i}", bounce, {"duration": duration}) for i in range(tasks)]
    nothing = [Task(f"trivial-{i}", trivial) for i in range(trivial_tasks)]
    warm = run_sweep(bench[:3], progress=False)                  # imports, kernels
    task_seconds = statistics.median(r.wall_seconds for r in warm.results)
    options = {b: {"backend": b} if b == "inprocess" else {"backend": b, "workers": workers}
               for b in backends}
    started = {b: options[b].get("workers", 1) for b in backends}
    times: dict[tuple[str, str], list[float]] = {(b, what): [] for b in backends
             for what in ("bench", "bench_cpu", "startup", "trivial")}
    stored, plain = [], []
    for _ in range(repeats):
        for b in backends:
            wall, cpu = _seconds(bench, **options[b])
            times[b, "bench"].append(wall)
            times[b, "bench_cpu"].append(cpu)
            times[b, "startup"].append(_seconds(nothing[:started[b]], **options[b])[0])
            times[b, "trivial"].append(_seconds(nothing, **options[b])[0])
        stored.append(_seconds(nothing, stored=True)[0])
        plain.append(_seconds(nothing)[0])
    median = {k: statistics.median(v) for k, v in times.items()}
    reference = median.get(("inprocess", "bench"), math.nan)
    rows = tuple(BackendSpeed(
        backend=b, workers=options[b].get("workers"), bench_seconds=median[b, "bench"],
        bench_cpu_seconds=median[b, "bench_cpu"],
        speedup=reference / median[b, "bench"], startup_seconds=median[b, "startup"],
        trivial_seconds=median[b, "trivial"],
        per_task_seconds=(median[b, "trivial"] - median[b, "startup"])
        / max(1, trivial_tasks - started[b])) for b in backends)
    store_cost = (statistics.median(stored) - statistics.median(plain)) / trivial_tasks
    return SweepSpeed(tasks=tasks, duration=duration, trivial=trivial_tasks, repeats=repeats,
                      task_seconds=task_seconds, store_per_task_seconds=store_cost,
                      load_average=(load_before, _load_average()), backends=rows)
