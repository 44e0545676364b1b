"""The "inprocess" backend: a plain loop in this process.

The default, and the right choice for a few quick tasks or for debugging: no
worker to start (a spawned worker pays the imports again, and refsim's
compiled kernels are loaded again), a traceback's frames at hand, Ctrl-C
straight into the task. A task that kills its process kills the sweep; its
stored results survive it.

Cost: the tasks' own, one after the other.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable

from refsim.sweep.execute import Outcome, execute


class InProcess:
    """Runs each submitted call when its outcome is asked for (state: the queue)."""

    name = "inprocess"
    slots = 1

    def __init__(self) -> None:
        self._queue: deque[tuple[int, Callable, dict, int]] = deque()   # submitted calls

    def submit(self, index: int, function, kwargs: dict, seed: int) -> None:
        self._queue.append((index, function, kwargs, seed))

    def next_outcome(self, timeout: float) -> tuple[int, Outcome] | None:
        if not self._queue:
            return None
        index, function, kwargs, seed = self._queue.popleft()
        return index, execute(function, kwargs, seed)

    def close(self, *, abort: bool = False) -> None:
        self._queue.clear()
