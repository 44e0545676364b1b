"""Reading input files: regular files only, errors that name the file.

Every file refsim reads (a model, a scene, a recorded trajectory) is read
through :func:`read_regular_file`: a directory, FIFO, socket or device is
refused before it is opened (reading a FIFO would block forever, a device
might never end), and every failure is the caller's error type carrying the
path, so the command line prints one line naming the file.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from refsim.errors import ArgumentTypeError


def as_path(value, what: str = "path") -> Path:
    """``value`` as a Path when it is a str or os.PathLike; else
    :class:`~refsim.errors.ArgumentTypeError` naming the argument."""
    if isinstance(value, str | os.PathLike):
        return Path(value)
    raise ArgumentTypeError(f"{what} must be a file path (str or os.PathLike), got "
                            f"{type(value).__name__}")


def require_regular_file(path, error: type) -> Path:
    """``path`` as a Path when it names a regular file (a symlink to one
    included); else ``error(message, path)``, without opening it."""
    path = as_path(path)
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise error("no such file", path) from None
    except OSError as exc:
        raise error(f"cannot read: {exc.strerror or exc}", path) from None
    if not stat.S_ISREG(mode):
        raise error(f"not a regular file ({file_kind(mode)})", path)
    return path


def read_regular_file(path, error: type) -> bytes:
    """The bytes of the regular file at ``path``, or ``error(message, path)``."""
    path = require_regular_file(path, error)
    try:
        return path.read_bytes()
    except OSError as exc:
        raise error(f"cannot read: {exc.strerror or exc}", path) from None


def decode_utf8(data: bytes, path, error: type) -> str:
    """``data`` as UTF-8 text; undecodable bytes are reported by line and
    column, as a text editor shows them."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise error(f"line {line}, column {column}: not UTF-8 text (byte "
                    f"0x{data[exc.start]:02x})", path) from None


def file_kind(mode: int) -> str:
    """What a file that is not a regular file is: "a directory", "a FIFO", ..."""
    for test, kind in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"),
                       (stat.S_ISSOCK, "a socket"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device")):
        if test(mode):
            return kind
    return "a special file"
