"""The one interface every sweep backend implements, and the choice of one.

A backend runs :func:`refsim.sweep.execute.execute` calls somewhere (this
process, local worker processes, a Dask cluster) and hands back their
outcomes as they finish. It does not retry, store, order or count: the run
loop (:mod:`refsim.sweep.run`) does that once, the same way for all of them,
so that the backends cannot drift apart (two copies of one rule, each
correct alone, are how two engines come to disagree).

Backends are imported only when chosen: the local ones need only the
standard library; "dask" needs ``distributed`` (``pip install
'refsim[sweep]'``), and without it fails with one :class:`OptionError`
saying so.

Cost: see each backend.
"""

from __future__ import annotations

import os
from typing import Protocol

from refsim.errors import OptionError, check_count, check_option
from refsim.sweep.execute import Outcome

BACKENDS = ("inprocess", "processes", "dask")


class Backend(Protocol):
    """Where a sweep's calls run.

    ``slots`` is how many calls the run loop keeps submitted at once: enough
    to keep every worker busy, few enough that a worker's death involves
    only the calls it was given, and that Ctrl-C has little to cancel.
    """

    name: str
    slots: int

    def submit(self, index: int, function, kwargs: dict, seed: int) -> None:
        """Start ``execute(function, kwargs, seed)`` for task ``index``."""

    def next_outcome(self, timeout: float) -> tuple[int, Outcome] | None:
        """The next finished call as ``(index, outcome)``, or None when none
        finished within ``timeout`` seconds. A call whose worker died comes
        back as a LOST outcome; the backend replaces the worker itself."""

    def close(self, *, abort: bool = False) -> None:
        """Stop what the backend started: wait for nothing more when
        ``abort`` (calls still running are cancelled, local workers stopped)."""


def check_backend(name: str, *, workers: int | None, scheduler: str | None) -> None:
    """Raise :class:`OptionError` unless ``name`` is a backend and the
    options apply to it (``ArgumentTypeError`` or ``StateError`` for a
    ``workers`` that is not a positive count)."""
    check_option("backend", name, BACKENDS)
    if workers is not None:
        check_count("workers", workers, minimum=1)
    if scheduler is not None and name != "dask":
        raise OptionError(f"scheduler is an option of the 'dask' backend, not of {name!r}")
    if scheduler is not None and not isinstance(scheduler, str):
        raise OptionError(f"scheduler must be an address like 'tcp://host:port', "
                          f"got {scheduler!r}")
    if workers is not None and name == "inprocess":
        raise OptionError("workers is an option of the 'processes' and 'dask' backends; "
                          "'inprocess' runs in this process")
    if workers is not None and scheduler is not None:
        raise OptionError("give the dask backend a scheduler (its cluster's workers are used) "
                          "or workers (a local cluster is started), not both")


def open_backend(name: str, *, workers: int | None, scheduler: str | None,
                 calls: int) -> Backend:
    """The backend ``name`` ready for ``calls`` calls (at least one).

    ``workers`` (default: the machine's CPU count, and never more than
    ``calls``) is the number of local worker processes of "processes" and of
    the local Dask cluster; ``scheduler`` is a Dask scheduler's address.

    Raises
    ------
    OptionError
        As :func:`check_backend`, and for "dask" without ``distributed``.
    """
    check_backend(name, workers=workers, scheduler=scheduler)
    if name == "inprocess":
        from refsim.sweep.inprocess import InProcess

        return InProcess()
    local = min(int(workers or os.cpu_count() or 1), calls)
    if name == "processes":
        from refsim.sweep.processes import Processes

        return Processes(local)
    from refsim.sweep.dask_cluster import DaskCluster

    return DaskCluster(scheduler=scheduler, workers=local)
