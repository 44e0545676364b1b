"""Generated case sets kept on disk between runs.

The generated sets (triangle pairs, mesh poses, boxes) cost their exact
answers, O(n) and large (measured in docs/decisions/conformance.md). A run
asked for the same set again reads it back instead.

A file is named by everything its content can depend on: the set, ``n``,
the seed, refsim's version, numpy's (its random generators draw the
cases), a digest of the source of every module of the refsim package (the
builders import the collision code that computes the truths, some of it
inside functions, so no import graph is trusted to find them all), and the
directory of models with the bytes of every model in it (the mesh cases'
truths depend on them; ``$REFSIM_MODELS`` may point elsewhere). Any edit,
another numpy or other models name another file: a stale set is never read.
A file that cannot be read (truncated, from another Python) is built again
and replaced; a directory that cannot be written only costs the saving.

Where: ``$REFSIM_CACHE_DIR`` if set (an empty value turns the cache off),
else ``$XDG_CACHE_HOME/refsim/cases``, else ``~/.cache/refsim/cases``. The
files are pickles written by this module; the directory is the user's own,
trusted like their scene files. Delete it to free the space: each file is a
few megabytes at 1e5 cases.
"""

from __future__ import annotations

import functools
import hashlib
import os
import pickle
from collections.abc import Callable
from pathlib import Path


def cache_directory() -> Path | None:
    """Where case sets are kept (module docstring), or None when turned off."""
    chosen = os.environ.get("REFSIM_CACHE_DIR")
    if chosen is not None:
        return Path(chosen) if chosen else None
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "refsim" / "cases"


def _digest(models: Path) -> str:
    """The digest of everything a cached set depends on but its name
    (module docstring)."""
    return _digest_of(str(models), _source_stamp(), _models_stamp(models))


@functools.cache
def _digest_of(models: str, sources: tuple, model_files: tuple) -> str:
    import numpy

    from refsim import __version__

    digest = hashlib.sha256()
    for part in (__version__, numpy.__version__, models):
        digest.update(part.encode() + b"\0")
    for path, _size, _time in (*sources, *model_files):
        digest.update(Path(path).name.encode() + b"\0" + Path(path).read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def _source_stamp() -> tuple:
    """Every source file of the refsim package, with its size and time (the
    content is read once per process for a stamp: :func:`_digest_of`)."""
    package = Path(__file__).resolve().parent.parent
    return tuple((str(p), p.stat().st_size, p.stat().st_mtime_ns)
                 for p in sorted(package.rglob("*.py")))


def _models_stamp(models: Path) -> tuple:
    return tuple((str(p), p.stat().st_size, p.stat().st_mtime_ns)
                 for p in sorted(models.glob("*")) if p.is_file())


def cache_path(name: str, n: int, seed: int) -> Path | None:
    """The file that holds set ``name`` of ``n`` cases from ``seed``; None
    when the cache is off or the set is not one that is kept."""
    from refsim.bundled import models_dir
    from refsim.conformance.registry import GENERATED_SETS

    directory = cache_directory()
    if directory is None or name not in GENERATED_SETS:   # the fixed sets take milliseconds
        return None
    return directory / f"{name}-n{n}-seed{seed}-{_digest(models_dir())}.pickle"


def cached(name: str, n: int, seed: int, build: Callable[[], object]):
    """Set ``name`` read from the cache, or ``build()`` and kept there."""
    path = cache_path(name, n, seed)
    if path is None:
        return build()
    try:
        with path.open("rb") as handle:
            return pickle.load(handle)
    except Exception:         # missing, truncated or unreadable: built again
        pass
    value = build()
    _store(path, value)
    return value


def _store(path: Path, value) -> None:
    """Write ``value`` whole or not at all (a temporary file renamed over
    the name); a failure to write is not an error, only no saving."""
    from refsim.storage.writing import write_atomic

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, lambda handle: pickle.dump(value, handle, protocol=5), binary=True)
    except (OSError, pickle.PicklingError):
        pass
