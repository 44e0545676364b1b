"""Generated case sets kept on disk between runs.

The generated sets (triangle pairs, mesh poses, boxes) cost their exact
answers: about 9 s for 1e5 triangle pairs and 1 ms a pose on this
project's two-core machine (docs/decisions/conformance.md). A run asked
for the same set again reads it back instead, in well under a second.

A file is named by everything its content depends on: the set, ``n``, the
seed, and a digest of the source of the module that builds the set and of
every refsim module it imports (:func:`refsim.kernels.sources_digest`),
with the numpy version (its random generators draw the cases). An edit to
any of those, or another numpy, names another file: a stale set is never
read. A file that cannot be read (truncated, from another Python) is built
again and replaced; a directory that cannot be written only costs the
saving.

Where: ``$REFSIM_CACHE_DIR`` if set (an empty value turns the cache off),
else ``$XDG_CACHE_HOME/refsim/cases``, else ``~/.cache/refsim/cases``. The
files are pickles written by this module; the directory is the user's own,
trusted like their scene files. Delete it to free the space: each file is a
few megabytes at 1e5 cases.
"""

from __future__ import annotations

import hashlib
import os
import pickle
from collections.abc import Callable
from pathlib import Path

#: The sets worth keeping (the others are fixed and built in milliseconds),
#: with the module that builds each.
CACHED_SETS = {"triangles": "refsim.conformance.cases_triangles",
               "poses": "refsim.conformance.cases_meshes",
               "boxes": "refsim.conformance.cases_boxes"}


def cache_directory() -> Path | None:
    """Where case sets are kept (module docstring), or None when turned off."""
    chosen = os.environ.get("REFSIM_CACHE_DIR")
    if chosen is not None:
        return Path(chosen) if chosen else None
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "refsim" / "cases"


def _builder_digest(module: str) -> str:
    import numpy

    from refsim import __version__
    from refsim.kernels import _source_file, sources_digest

    digest = hashlib.sha256()
    own = _source_file(module)
    for part in (__version__, numpy.__version__, sources_digest(module),
                 own.read_text(encoding="utf-8") if own else ""):
        digest.update(part.encode() + b"\0")
    return digest.hexdigest()[:16]


def cache_path(name: str, n: int, seed: int) -> Path | None:
    """The file that holds set ``name`` of ``n`` cases from ``seed``; None
    when the cache is off or the set is not one that is kept."""
    directory = cache_directory()
    if directory is None or name not in CACHED_SETS:
        return None
    return directory / f"{name}-n{n}-seed{seed}-{_builder_digest(CACHED_SETS[name])}.pickle"


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
    from refsim.io import write_atomic

    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, lambda handle: pickle.dump(value, handle, protocol=5), binary=True)
    except (OSError, pickle.PicklingError):
        pass
