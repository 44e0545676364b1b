"""Sweeps: many independent runs, here, on local processes or on a Dask
cluster, with the same results on each (docs/design.md, Architecture).

    from refsim.sweep import Task, run_sweep
    from refsim.sweep.examples import bounce

    tasks = [Task(f"lift-{i}", bounce, {"duration": 1.0}) for i in range(16)]
    result = run_sweep(tasks, backend="processes", workers=2, store="out/sweep", seed=7)
    result.values            # 16 records, in task order
    result.failures          # {key: one-line reason} of the tasks that failed

Design, one module per concern:

- :mod:`~refsim.sweep.tasks`: a :class:`Task` is a module-level function, its
  plain keyword arguments and a key; its seed comes from the sweep's seed
  and the key (not the index, so that extending a sweep keeps every other
  task's seed and stored result).
- :mod:`~refsim.sweep.records`: what a task may take and return (plain
  JSON-able data); every result makes the same JSON round trip on every
  backend, so the results are equal bit for bit.
- :mod:`~refsim.sweep.execute`: the call made in the worker; an exception is
  the task's answer (failed, one line, not retried).
- backends (:mod:`~refsim.sweep.backend` for the interface):
  :mod:`~refsim.sweep.inprocess`, :mod:`~refsim.sweep.processes` (spawned
  processes), :mod:`~refsim.sweep.dask_cluster` (``distributed``, the
  ``sweep`` extra). They only run calls and hand back outcomes.
- :mod:`~refsim.sweep.store`: results written as they arrive, one atomic
  file per task, so that a sweep run again with its store resumes; a store
  of another task list is refused.
- :mod:`~refsim.sweep.run`: :func:`run_sweep`, the one loop: ordering,
  storing, retrying a task whose worker died (alone, a bounded number of
  times), Ctrl-C.
- :mod:`~refsim.sweep.progress`: done/total, failures and time left on
  stderr, only on a terminal.
- :mod:`~refsim.sweep.examples`, :mod:`~refsim.studies.sweep`: an example
  task, and the speed of each backend on it.
"""

from __future__ import annotations

from refsim.sweep.backend import BACKENDS
from refsim.sweep.run import SweepCancelled, SweepResult, TaskResult, run_sweep
from refsim.sweep.tasks import Task, task_seed

__all__ = ["BACKENDS", "SweepCancelled", "SweepResult", "Task", "TaskResult", "run_sweep",
           "task_seed"]
