"""Loading a model file of any supported format into a Mesh (seed S1).

The seed "loads arbitrary triangle soup models with per-triangle
information". :func:`load_model` picks the reader by the file's suffix:

- ``.ac``: refsim's own AC3D reader (:mod:`refsim.models.ac3d`), which keeps
  materials, surface flags and objects per triangle;
- ``.obj``, ``.stl``, ``.ply``, ``.off``: trimesh (``trimesh.load`` with
  ``force="mesh", process=False``, so trimesh neither merges nor reorders
  anything; refsim's :class:`Mesh` does the welding). Per-triangle data is
  the default (material 0, flags 0, object 0).

Every failure (missing file, unknown suffix, a file the reader rejects) is a
one-line :class:`~refsim.errors.ModelError` naming the path.

Cost: that of the reader, O(file size), plus the O(n log n) weld.
"""

from __future__ import annotations

import contextlib
import io
import logging
import warnings
from pathlib import Path

import numpy as np

from refsim.bundled import models_dir
from refsim.errors import ModelError
from refsim.files import as_path, bundled_if_bare, read_regular_file, refuse_missing_bundled
from refsim.models.ac3d import read_ac3d
from refsim.models.mesh import Mesh

#: Suffixes read by trimesh (the formats trimesh reads).
TRIMESH_SUFFIXES = (".obj", ".stl", ".ply", ".off")
SUFFIXES = (".ac",) + TRIMESH_SUFFIXES


def load_model(path, *, weld_tolerance: float = 0.0) -> Mesh:
    """Load the model at ``path`` as a :class:`Mesh` in shared-vertex form.

    Parameters
    ----------
    path : str or PathLike
        A ``.ac``, ``.obj``, ``.stl``, ``.ply`` or ``.off`` file (suffix in any
        case). A bare file name that is not in the current directory names a
        bundled model (``refsim.bundled.models_dir()``), e.g. ``"cube.ac"``.
    weld_tolerance : float
        Passed to :class:`Mesh`: 0 welds exactly equal vertices only.

    Raises
    ------
    ModelError
        When the file is missing or a directory, its suffix is not
        supported, or it cannot be read as a triangle mesh.
    """
    path = as_path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES and path.is_dir():     # a folder is no format, known or not
        raise ModelError(f"a directory, not a model file ({', '.join(SUFFIXES)})", path=path)
    if suffix not in SUFFIXES:
        raise ModelError(f"unknown model format {path.suffix or '(no suffix)'!r}; "
                         f"supported: {', '.join(SUFFIXES)}", path=path)
    path = bundled_if_bare(path, models_dir())
    refuse_missing_bundled(path, models_dir(), "model", ModelError)
    if suffix == ".ac":
        return read_ac3d(path, weld_tolerance=weld_tolerance)
    return _load_with_trimesh(path, read_regular_file(path, ModelError), weld_tolerance)


#: The formats trimesh reads as text (the others, binary STL and PLY, as bytes).
TEXT_SUFFIXES = (".obj", ".off")


def _load_with_trimesh(path: Path, data: bytes, weld_tolerance: float) -> Mesh:
    import trimesh  # lazy: only these formats need it

    suffix = path.suffix.lower()
    if suffix in TEXT_SUFFIXES:
        # Decoded here, UTF-8 or else Latin-1 (every byte is a Latin-1
        # character), as the AC3D reader does: trimesh would otherwise guess
        # the encoding of a file that is not UTF-8 with the optional package
        # charset_normalizer, and fail without it.
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError:
            text = data.decode("latin-1")
        source: io.StringIO | io.BytesIO = io.StringIO(text)
    else:
        source = io.BytesIO(data)
    try:
        with _quiet_trimesh():
            loaded = trimesh.load(source, file_type=suffix[1:], force="mesh", process=False)
    except Exception as exc:  # trimesh raises many types for bad files
        raise ModelError(f"trimesh cannot read it: {_one_line(exc)}", path=path) from None
    faces = getattr(loaded, "faces", None)
    vertices = getattr(loaded, "vertices", None)
    if faces is None or vertices is None or len(faces) == 0:
        raise ModelError("the file holds no triangles", path=path)
    return Mesh(np.asarray(vertices, dtype=np.float64), np.asarray(faces),
                weld_tolerance=weld_tolerance, name=path.stem, source=str(path))


@contextlib.contextmanager
def _quiet_trimesh():
    """trimesh reading a file without speaking: it logs the tracebacks of
    the attempts it recovers from (an ASCII STL tried as binary first) and
    lets numpy warn about the non-finite numbers of a broken file. What
    matters reaches the user otherwise: a file trimesh cannot read is its
    exception, and a non-finite vertex is refused by :class:`Mesh`."""
    logger = logging.getLogger("trimesh")  # its modules log through children
    level = logger.level
    logger.setLevel(logging.CRITICAL + 1)
    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            yield
    finally:
        logger.setLevel(level)


def _one_line(exc: Exception) -> str:
    text = " ".join(str(exc).split()) or type(exc).__name__
    return text[:200]
