"""Reading input files: regular files only, errors that name the file.

Every file refsim reads (a model, a scene, a recorded trajectory) is read
through :func:`read_regular_file`: a directory, FIFO, socket or device is
refused before it is opened (reading a FIFO would block forever, a device
might never end), and every failure is the caller's error type carrying the
path, so the command line prints one line naming the file. A bare file name that
is not here names a bundled model or scene (:func:`bundled_if_bare`), and a
missing path whose base name is bundled says so (:func:`refuse_missing_bundled`).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from refsim.errors import ArgumentTypeError
from refsim.limits import MAX_MODEL_BYTES


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
    except ValueError:                  # the one name the system refuses to take
        raise error("a file name cannot contain a NUL byte", path) from None
    if not stat.S_ISREG(mode):
        raise error(f"not a regular file ({file_kind(mode)})", path)
    return path


def read_regular_file(path, error: type, max_bytes: int = MAX_MODEL_BYTES) -> bytes:
    """The bytes of the regular file at ``path``, or ``error(message, path)``;
    a file larger than ``max_bytes`` is refused before it is read."""
    path = require_regular_file(path, error)
    too_large = error(f"file too large: more than {max_bytes} bytes (refsim.limits)", path)
    try:
        with path.open("rb") as file:
            size = os.fstat(file.fileno()).st_size
            if size > max_bytes:
                raise too_large
            # read() of n bytes allocates n at once: the size, not the limit,
            # plus one byte to see a file that grew meanwhile
            data = file.read(size + 1)
            while len(data) <= max_bytes and (more := file.read(2**20)):
                data += more
    except OSError as exc:
        raise error(f"cannot read: {exc.strerror or exc}", path) from None
    if len(data) > max_bytes:
        raise too_large
    return data


def bundled_if_bare(path: Path, directory: Path) -> Path:
    """``path`` itself, or ``directory / path.name`` when ``path`` is a bare
    file name that does not exist here and does there (a bundled model or
    scene). A name the system cannot look up here (too long, behind an
    unsearchable directory) is returned as given, for the reader to refuse."""
    if path.name != str(path):
        return path
    try:
        if path.exists():
            return path
        bundled = directory / path.name
        return bundled if bundled.is_file() else path
    except (OSError, ValueError):       # ValueError: a NUL byte in the name
        return path


def refuse_missing_bundled(path: Path, directory: Path, kind: str, error: type) -> None:
    """Nothing, unless ``path`` names no file and ``directory`` holds a
    bundled ``kind`` ("model", "scene") of the same base name or of a
    similar one; then the usual ``error("no such file", path)`` with the
    bare name that works from any directory added (a path such as
    ``models/cube.ac`` only exists in a source checkout), or the similar
    bundled names (``sphere.ac``: ``sphere-2k.ac``)."""
    if "\0" in str(path):
        return                          # the reader refuses the name itself
    try:
        if os.path.lexists(path):
            return
        namesake = (directory / path.name).is_file()
    except (OSError, ValueError):       # ValueError: a NUL byte in the name
        return
    if namesake:
        raise error(f"no such file (a bundled {kind} of that name exists: use "
                    f"'{path.name}')", path)
    similar = similar_bundled(path.name, directory, BUNDLED_SUFFIX[kind])
    if similar:
        raise error(f"no such file ({similar_hint(similar, kind)})", path)


#: At most this many similar bundled names are suggested.
SIMILAR_NAMES = 3

#: The suffix of each kind of bundled file.
BUNDLED_SUFFIX = {"model": ".ac", "scene": ".toml"}


def similar_bundled(name: str, directory: Path, suffix: str) -> list[str]:
    """The bundled ``suffix`` files of ``directory`` whose names or stems are
    close to ``name``'s (``difflib``'s ratio at least 0.6, its default; the
    closest first, at most ``SIMILAR_NAMES``): a typo or a remembered stem
    (``sphere.ac``, ``cube.obj``) finds the bundled file."""
    import difflib

    try:
        names = sorted(p.name for p in directory.glob(f"*{suffix}") if p.is_file())
    except OSError:
        return []
    stems = {Path(n).stem: n for n in names}
    close = difflib.get_close_matches(name, names, n=SIMILAR_NAMES)
    close += [stems[s] for s in difflib.get_close_matches(Path(name).stem, list(stems),
                                                           n=SIMILAR_NAMES)]
    return list(dict.fromkeys(close))[:SIMILAR_NAMES]


def similar_hint(similar: list[str], kind: str) -> str:
    """``bundled models with a similar name: 'a.ac', 'b.ac'`` and how to list them all."""
    names = ", ".join(f"'{n}'" for n in similar)
    return (f"bundled {kind}s with a similar name: {names}; refsim info --bundled "
            f"lists them all")


def decode_utf8(data: bytes, path, error: type) -> str:
    """``data`` as UTF-8 text; undecodable bytes are reported by line and
    column, as a text editor shows them."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise error(f"not UTF-8 text (byte 0x{data[exc.start]:02x} at column {column})",
                    path, line=line) from None


def file_kind(mode: int) -> str:
    """What a file that is not a regular file is: "a directory", "a FIFO", ..."""
    for test, kind in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"),
                       (stat.S_ISSOCK, "a socket"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device")):
        if test(mode):
            return kind
    return "a special file"
