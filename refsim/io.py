"""Writing output files whole or not at all.

Every file refsim writes (the report, results.json, trajectories, models)
goes through :func:`write_atomic`: the content is written to a temporary file
in the same directory and moved over the target with ``os.replace``, which is
atomic on POSIX and Windows. A reader sees the old file or the whole new one;
an error or Ctrl-C part way leaves no partial file behind (DESIGN.md, Errors).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path


def write_atomic(path, write: Callable, *, binary: bool = False) -> Path:
    """Call ``write(handle)`` on a temporary file, then move it to ``path``.

    The new file keeps the permissions of the file it replaces, or gets what
    ``open()`` would give (mkstemp's 0600 would hide it from other users). It
    is flushed to disk before the move, so a crash cannot leave an empty file
    under the old name. Raises ``OSError`` as ``open()`` would.
    """
    path = Path(path)
    try:
        mode = path.stat().st_mode & 0o777
    except OSError:
        mode = 0o666 & ~_umask()
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb" if binary else "w", **({} if binary else
                                                      {"encoding": "utf-8"})) as handle:
            write(handle)
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def write_text_atomic(path, text: str) -> Path:
    return write_atomic(path, lambda handle: handle.write(text))


def write_npz_atomic(path, arrays: dict, *, compressed: bool = False) -> Path:
    """``numpy.savez`` (or ``savez_compressed``) of ``arrays`` to ``path``."""
    import numpy as np

    save = np.savez_compressed if compressed else np.savez
    return write_atomic(path, lambda handle: save(handle, **arrays), binary=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
