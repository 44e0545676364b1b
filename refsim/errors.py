"""The exceptions refsim raises for bad input.

Every error a user can cause (a malformed model or scene file, a degenerate
mesh, a non-finite state, an unknown option, a diverging simulation) is a
:class:`RefsimError`. Each names where the problem is: the file and line, the
key path, the argument, the body and step. The command line prints
``str(error)`` as its one line and exits non-zero; anything that is not a
``RefsimError`` is a bug in refsim and keeps its traceback.

The errors about a bad value are also :class:`ValueError`, and
:class:`ArgumentTypeError` is also :class:`TypeError`, so that code written
for Python's conventions (``except ValueError``) catches them too:

    RefsimError
    ├── ModelError          (ValueError)  a model file or mesh
    ├── SceneError          (ValueError)  a scene file or scene key
    ├── NpzFileError        (ValueError)  a recorded run (.npz) that cannot be read
    ├── StateError          (ValueError)  a number, array or state
    ├── OptionError         (ValueError)  an option not among its choices
    ├── ArgumentTypeError   (TypeError)   an argument of the wrong type
    ├── OutputError         (OSError)     an output file that cannot be written
    ├── SweepError          (ValueError)  a sweep's task list or result store
    └── DivergenceError                   a simulation that blew up
"""

from __future__ import annotations

from os import PathLike
from typing import Any


class RefsimError(Exception):
    """Base class of every error caused by the user's input."""


class ModelError(RefsimError, ValueError):
    """A model file or mesh that cannot be used.

    Parameters
    ----------
    message : str
        What is wrong, without the location.
    path : str or PathLike, optional
        The file, when the mesh came from one.
    line : int, optional
        1-based line number in ``path``.
    """

    def __init__(self, message: str, path: str | PathLike | None = None,
                 line: int | None = None):
        self.message = message
        self.path = None if path is None else str(path)
        self.line = line
        where = self.path or "<mesh>"
        if line is not None:
            where = f"{where}:{line}"
        super().__init__(f"{where}: {message}")


class ModelWarning(UserWarning):
    """A model file that loads, but with something left out (e.g. AC3D line
    surfaces, which have no area and become no triangles)."""


class SceneError(RefsimError, ValueError):
    """A scene file that does not follow the schema.

    ``key`` is the dotted path of the offending key, e.g. ``world.half_size``
    or ``body[2].position``; ``line`` the 1-based line of a problem found
    before the keys are known (text that is not UTF-8, nesting too deep).
    """

    def __init__(self, message: str, path: str | PathLike | None = None,
                 key: str | None = None, line: int | None = None):
        self.message = message
        self.path = None if path is None else str(path)
        self.key = key
        self.line = line
        where = self.path or "<scene>"
        if line is not None:
            where = f"{where}:{line}"
        if key:
            where = f"{where}: {key}"
        super().__init__(f"{where}: {message}")


class UnposableKey(SceneError):
    """A valid scene key that the engine, or the model chosen, cannot pose
    (a torque for the seed's rotation, a tilted gravity for an engine
    without one): ``key`` names the scene's key. The conformance kit reports
    such a scene as not posed, with this message as the reason, never as the
    engine's failure."""


class NpzFileError(RefsimError, ValueError):
    """An .npz that cannot be read as the expected content: missing,
    unreadable, truncated, another format, an entry missing or of the wrong
    shape. ``path`` is the file, ``entry`` the entry's name when one is at
    fault (:mod:`refsim.storage.npz` raises it)."""

    def __init__(self, message: str, path: str | PathLike, entry: str | None = None):
        self.message = message
        self.path = str(path)
        self.entry = entry
        where = self.path if entry is None else f"{self.path}: entry {entry!r}"
        super().__init__(f"{where}: {message}")


class StateError(RefsimError, ValueError):
    """A non-finite or otherwise invalid numeric input (coordinates, a state)."""


class OptionError(RefsimError, ValueError):
    """An option whose value is not one of its choices (see :func:`check_option`)."""


class ArgumentTypeError(RefsimError, TypeError):
    """An argument of the wrong type (``None`` where a mesh is expected, say)."""


class OutputError(RefsimError, OSError):
    """An output file that cannot be written (the message names it)."""


class SweepError(RefsimError, ValueError):
    """A sweep that cannot run as asked: two tasks with one key, or a result
    store written by another task list (see :mod:`refsim.sweep`)."""


def check_option(name: str, value, choices) -> str:
    """``value`` when it is one of ``choices``; else :class:`OptionError`
    naming the option, the value and the choices. The one check of every
    string option in refsim's public functions."""
    if isinstance(value, str) and value in choices:
        return value
    listed = ", ".join(repr(c) for c in choices)
    raise OptionError(f"{name} must be one of {listed}, got {value!r}")


class DivergenceError(RefsimError):
    """A simulation whose state became non-finite or grew without bound.

    The frames computed before the divergence are kept in ``partial`` (a
    trajectory object, or ``None``) so that they can still be written.
    """

    def __init__(self, message: str, step: int, time: float, body: str | None = None,
                 partial: Any = None):
        self.message = message
        self.step = step
        self.time = time
        self.body = body
        self.partial = partial
        who = f" body {body!r}," if body is not None else ""
        super().__init__(f"diverged at step {step}, t = {time:.6g},{who} {message}")


def check_count(name: str, value, minimum: int = 0, maximum: int | None = None) -> int:
    """``value`` as an int when it is a whole number in ``[minimum, maximum]``;
    else :class:`ArgumentTypeError` (not an integer; ``True`` is not a count)
    or :class:`StateError` (out of range), naming the argument."""
    import numbers

    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ArgumentTypeError(f"{name} must be an integer, got {type(value).__name__} "
                                f"{value!r}")
    value = int(value)
    if value < minimum or (maximum is not None and value > maximum):
        upper = "" if maximum is None else f" and at most {maximum}"
        raise StateError(f"{name} must be at least {minimum}{upper}, got {value}")
    return value


def check_number(name: str, value) -> float:
    """``value`` as a float when it is a real number (an int, a float, a
    numpy scalar; not a bool, a string or None); else
    :class:`ArgumentTypeError` naming the argument. Finiteness and range are
    the caller's checks."""
    import numbers

    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ArgumentTypeError(f"{name} must be a real number, got {type(value).__name__} "
                                f"{value!r}")
    return float(value)


def check_callable(name: str, value):
    """``value`` when it can be called; else :class:`ArgumentTypeError`."""
    if not callable(value):
        raise ArgumentTypeError(f"{name} must be callable, got {type(value).__name__} "
                                f"{value!r}")
    return value


def as_numbers(name: str, value, *, complex_ok: bool = False):
    """``value`` as a numpy array of float64 (of complex128 too when
    ``complex_ok`` and it holds complex numbers), any shape; else
    :class:`ArgumentTypeError` naming the argument: None, a string, a ragged
    or non-numeric sequence, complex numbers where they are not allowed.
    Shape and finiteness are the caller's checks."""
    import numpy as np

    kinds = "biufc" if complex_ok else "biuf"
    problem = ArgumentTypeError(f"{name} must be an array of {'' if complex_ok else 'real '}"
                                f"numbers, got {type(value).__name__}")
    if value is None or isinstance(value, str | bytes):
        raise problem
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):
        raise problem from None
    if array.dtype.kind not in kinds:
        raise problem
    return array.astype(np.complex128 if array.dtype.kind == "c" else np.float64, copy=False)
