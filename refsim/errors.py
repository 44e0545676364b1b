"""The exceptions refsim raises for bad input.

Every error a user can cause (a malformed model or scene file, a degenerate
mesh, a non-finite state, a diverging simulation) is a :class:`RefsimError`.
Each names where the problem is: the file and line, the key path, the body
and step. The command line prints ``str(error)`` as its one line and exits
non-zero; anything that is not a ``RefsimError`` is a bug in refsim and keeps
its traceback.
"""

from __future__ import annotations

from os import PathLike


class RefsimError(Exception):
    """Base class of every error caused by the user's input."""


class ModelError(RefsimError):
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


class SceneError(RefsimError):
    """A scene file that does not follow the schema.

    ``key`` is the dotted path of the offending key, e.g. ``world.half_size``
    or ``body[2].position``.
    """

    def __init__(self, message: str, path: str | PathLike | None = None,
                 key: str | None = None):
        self.message = message
        self.path = None if path is None else str(path)
        self.key = key
        where = self.path or "<scene>"
        if key:
            where = f"{where}: {key}"
        super().__init__(f"{where}: {message}")


class StateError(RefsimError):
    """A non-finite or otherwise invalid numeric input (coordinates, a state)."""


class DivergenceError(RefsimError):
    """A simulation whose state became non-finite or grew without bound.

    The frames computed before the divergence are kept in ``partial`` (a
    trajectory object, or ``None``) so that they can still be written.
    """

    def __init__(self, message: str, step: int, time: float, body: str | None = None,
                 partial=None):
        self.step = step
        self.time = time
        self.body = body
        self.partial = partial
        who = f" body {body!r}," if body is not None else ""
        super().__init__(f"diverged at step {step}, t = {time:.6g},{who} {message}")
