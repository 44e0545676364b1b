"""Task functions for the sweep tests, importable by worker processes and by
Dask workers (as ``tests.sweep.tasks``, with the checkout on the path).

Each draws from its seed, so that a wrong seed shows as a wrong value; the
ones that misbehave (die, raise, interrupt) do it once or always, steered by
marker files, and the counting ones leave a file per finished execution.
"""

from __future__ import annotations

import os
import signal
import time
import uuid
from pathlib import Path

import numpy as np


def draws(*, seed: int, n: int = 64) -> dict:
    """A little seeded numpy work: normal draws, their sum and a product."""
    rng = np.random.default_rng(seed)
    x = rng.standard_normal(n)
    total = 0.0
    for value in x:                      # summed in one order, not numpy's pairwise order
        total += float(value)
    return {"first": x[:3], "sum": total, "max": x.max(), "count": np.int64(n),
            "pair": (float(x[0] * x[1]), int(rng.integers(0, 1 << 62)))}


def die_once(*, seed: int, marker: str, n: int = 64) -> dict:
    """Kill this process the first time (no marker yet); then as ``draws``."""
    path = Path(marker)
    if not path.exists():
        path.write_text(str(os.getpid()))
        os.kill(os.getpid(), signal.SIGKILL)
    return draws(seed=seed, n=n)


def die_always(*, seed: int) -> None:
    """Kill this process, every time."""
    os.kill(os.getpid(), signal.SIGKILL)


def fail(*, seed: int, message: str) -> None:
    """Raise an ordinary exception whose message has two lines."""
    raise ValueError(f"{message}\nsecond line, not shown")


def not_plain(*, seed: int) -> object:
    """Return something that is not a plain record."""
    return {"a set": {1, 2}}


def counted(*, seed: int, marker_dir: str, key: str, pause: float = 0.0,
            interrupt_once: str | None = None) -> dict:
    """As ``draws``, after ``pause`` seconds; leaves one file per finished
    execution in ``marker_dir`` (named by the key and a fresh id, holding
    the pid). With ``interrupt_once`` (a marker path that does not exist
    yet) it raises KeyboardInterrupt instead, once, as Ctrl-C would."""
    if interrupt_once is not None and not Path(interrupt_once).exists():
        Path(interrupt_once).write_text("interrupted")
        raise KeyboardInterrupt
    time.sleep(pause)
    value = draws(seed=seed, n=8)
    (Path(marker_dir) / f"{key}.{uuid.uuid4().hex}.done").write_text(str(os.getpid()))
    return value


def executions(marker_dir) -> dict[str, int]:
    """Key -> how many executions of it finished (from ``counted``'s files)."""
    counts: dict[str, int] = {}
    for path in Path(marker_dir).glob("*.done"):
        key = path.name.split(".")[0]
        counts[key] = counts.get(key, 0) + 1
    return counts
