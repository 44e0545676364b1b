"""Writing output files whole or not at all, and only where a file belongs.

Every file refsim writes (the report, results.json, trajectories, particle
frames, models) goes through this module, in three steps:

1. **Where.** :func:`output_target` decides what a path means for writing.
   A symlink is written *through*: the link stays and its target gets the
   new content (what ``open(path, "w")`` would do, and what a user who
   linked ``latest.npz`` to a dated file expects). A directory, device node,
   FIFO or socket is refused with :class:`~refsim.errors.OutputError`
   naming the path: replacing ``/dev/null`` or a named pipe with a regular
   file would break whatever else uses it, and writing into it is not
   "writing a file". A missing parent directory is refused the same way.
2. **Whole.** :func:`atomic_output` writes into a hidden temporary file in
   the *target's* directory (``.NAME.XXXXXXXX.tmp``), flushes it to disk and
   moves it over the target with ``os.replace``, which is atomic on POSIX
   and Windows when both names are on one file system (hence the target's
   directory, not ``/tmp`` and not the link's directory). A reader sees the
   old file or the whole new one. The target is checked again just before
   the move, so a special file that appeared meanwhile is not replaced
   (a race narrowed, not closed: POSIX has no "replace only a regular file").
3. **Or not at all.** Any exception, including ``KeyboardInterrupt`` and the
   :class:`refsim.signals.Interrupted` that ``refsim``'s command line raises
   for SIGTERM and SIGHUP, removes the temporary file before it propagates.
   The moment a temporary file is created and its name recorded for
   clean-up runs with those signals held (:func:`_signals_held`), so no
   signal can land between the two and leak the file.

Hidden temporary files for other purposes (the frame spill of
:mod:`refsim.storage.frames`) are made by :func:`hidden_temporary`, by the same
rules. A hard link to the old file keeps the old content (``os.replace``
makes a new inode), as with every atomic writer.

Cost: one extra ``fsync`` and rename per file; no copy of the content.
"""

from __future__ import annotations

import os
import shutil
import signal
import stat
import tempfile
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO

from refsim.errors import OutputError

#: The signals whose handlers may raise (KeyboardInterrupt for SIGINT, and
#: :class:`refsim.signals.Interrupted` for these under the command line):
#: held while a temporary file is created and recorded, and while it is
#: removed.
HELD_SIGNALS = frozenset(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP")
                         if hasattr(signal, name))          # no SIGHUP on Windows

_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISSOCK, "a socket"),
)


def output_error(path, reason: str) -> OutputError:
    """:class:`OutputError` ``"PATH: cannot write: REASON"``. Its
    ``strerror`` is the reason alone, so that callers which print
    ``exc.strerror`` beside their own copy of the path stay one line
    (``errno`` and ``filename`` stay unset: set, they would replace the
    message with ``OSError``'s "[Errno N] ..." form)."""
    error = OutputError(f"{path}: cannot write: {reason}")
    error.strerror = reason
    return error


def output_target(path) -> Path:
    """The file that writing ``path`` will replace: ``path`` itself, or the
    end of its chain of symlinks. Checks, without touching anything:

    - the target is a regular file or does not exist yet (a dangling link
      is fine: its target is created, as ``open()`` would);
    - the target's directory exists.

    Raises
    ------
    OutputError
        Naming ``path`` (and the link's target when they differ): a
        directory, device, FIFO or socket; a missing directory; a symlink
        loop.
    """
    path = Path(path)
    try:
        target = path.resolve(strict=False)
    except (OSError, RuntimeError) as exc:          # RuntimeError: a symlink loop (3.11)
        raise output_error(path, f"cannot follow its symlinks ({exc})") from None
    shown = path if target == path.absolute() else f"{path} (-> {target})"
    _check_kind(shown, target)
    if not target.parent.is_dir():
        raise output_error(shown, f"no directory {target.parent}")
    return target


def _check_kind(shown, target: Path) -> None:
    """Refuse ``target`` unless it is a regular file or absent."""
    try:
        mode = os.lstat(target).st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise output_error(shown, exc.strerror or str(exc)) from None
    for test, kind in _KINDS:
        if test(mode):
            raise output_error(shown, f"it is {kind}; refsim writes only regular files")


@contextmanager
def _signals_held() -> Iterator[None]:
    """Block :data:`HELD_SIGNALS` for the body (main thread, POSIX); a signal
    that arrives meanwhile is delivered, and its handler runs, right after.
    Elsewhere a no-op."""
    if not (hasattr(signal, "pthread_sigmask")
            and threading.current_thread() is threading.main_thread()):
        yield
        return
    old = signal.pthread_sigmask(signal.SIG_BLOCK, HELD_SIGNALS)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def hidden_temporary(target: Path, suffix: str, clean_up: list) -> tuple[int, Path]:
    """Create ``.NAME.XXXXXXXX<suffix>`` beside ``target`` (its directory,
    mode 0600) and append its path to ``clean_up`` before any signal can
    interrupt; returns ``(fd, path)``. Raises :class:`OutputError` naming
    ``target`` when the directory refuses (permissions, a read-only disk)."""
    with _signals_held():
        try:
            fd, name = tempfile.mkstemp(dir=target.parent, prefix=f".{target.name}.",
                                        suffix=suffix)
        except OSError as exc:
            raise output_error(target, exc.strerror or str(exc)) from None
        clean_up.append(Path(name))
    return fd, Path(name)


def remove_quietly(paths: list) -> None:
    """Unlink every path in ``paths`` (missing ones too), with signals held
    so that a second signal cannot cut the clean-up short; empties the list."""
    with _signals_held():
        while paths:
            Path(paths.pop()).unlink(missing_ok=True)


@contextmanager
def atomic_output(path, *, binary: bool = True) -> Iterator[IO]:
    """Yield a handle on a hidden temporary file beside ``path``'s target
    (:func:`output_target`); when the body finishes, flush it to disk and
    move it over the target. Any exception removes it instead.

    The new file keeps the permissions of the file it replaces, or gets what
    ``open()`` would give (mkstemp's 0600 would hide it from other users).

    Raises
    ------
    OutputError
        The target is not writable as a regular file (see
        :func:`output_target`); or the directory refuses the temporary file.
    OSError
        As ``write`` raises it (e.g. ENOSPC), the temporary file removed.
    """
    target = output_target(path)
    try:
        mode = target.stat().st_mode & 0o777
    except OSError:
        mode = 0o666 & ~_umask()
    clean_up: list[Path] = []
    try:
        fd, tmp = hidden_temporary(target, ".tmp", clean_up)
        with os.fdopen(fd, "wb" if binary else "w",
                       encoding=None if binary else "utf-8") as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.chmod(tmp, mode)
        _check_kind(path, target)                  # again: nothing special appeared
        os.replace(tmp, target)
        clean_up.clear()
    finally:
        remove_quietly(clean_up)


def write_atomic(path, write: Callable, *, binary: bool = False) -> Path:
    """Call ``write(handle)`` on a temporary file, then move it to ``path``
    (:func:`atomic_output`). Returns ``Path(path)``."""
    with atomic_output(path, binary=binary) as handle:
        write(handle)
    return Path(path)


def write_text_atomic(path, text: str) -> Path:
    return write_atomic(path, lambda handle: handle.write(text))


def write_npz_atomic(path, arrays: dict, *, compressed: bool = False) -> Path:
    """An .npz of ``arrays`` (name -> array, or a spilled array of
    :mod:`refsim.storage.frames`) at ``path``, written by :func:`refsim.storage.npz.write_npz`
    in bounded chunks; ``numpy.load`` reads it."""
    from refsim.storage.npz import write_npz

    return write_atomic(path, lambda handle: write_npz(handle, arrays, compressed=compressed),
                        binary=True)


def free_bytes(path) -> int:
    """Free bytes (for this user) on the file system that holds ``path``'s
    target directory."""
    return shutil.disk_usage(output_target(path).parent).free


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
