"""The call every backend makes in its worker: run one task, report plainly.

:func:`execute` runs ``function(seed=seed, **kwargs)`` and returns an
:class:`Outcome`: the result as JSON text (:mod:`refsim.sweep.records`), or
the one-line message of the exception it raised, and the wall time of the
call. An ordinary exception is an answer, not a crash: the task is recorded
as failed and not run again (it would fail the same way). A result that is
not a plain record fails the task the same way, in the worker, where the
traceback's frames still exist.

``KeyboardInterrupt`` and ``SystemExit`` pass through: in-process they stop
the sweep; in a worker process they are the worker's end, which the backend
reports as a lost worker.

Cost: the task's own, plus O(size of the result) to encode it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

from refsim.sweep.records import encode

#: Outcome kinds: a result; an exception raised by the task; the worker died
#: (killed, crashed, lost) before it answered.
DONE, RAISED, LOST = "done", "raised", "lost"


@dataclass(frozen=True)
class Outcome:
    """What became of one attempt at a task.

    ``payload`` is the result's JSON text (DONE) or a one-line message
    (RAISED, LOST). ``wall_seconds`` is the time of the call in the worker
    (NaN when lost). ``attempts_used`` is how many attempts this outcome
    stands for: 1, or more when a Dask scheduler retried a task itself
    before giving up on it.
    """

    kind: str
    payload: str
    wall_seconds: float = float("nan")
    attempts_used: int = 1


def execute(function, kwargs: dict, seed: int) -> Outcome:
    """Run ``function(seed=seed, **kwargs)`` and encode what came of it."""
    start = time.perf_counter()
    try:
        text = encode(function(seed=seed, **kwargs))
    except Exception as error:                     # the task's answer: failed, with why
        return Outcome(RAISED, one_line(error), time.perf_counter() - start)
    return Outcome(DONE, text, time.perf_counter() - start)


def one_line(error: BaseException) -> str:
    """``"TypeName: first line of the message"`` (the type alone when empty)."""
    lines = str(error).strip().splitlines()
    name = type(error).__name__
    return f"{name}: {lines[0].strip()}" if lines else name
