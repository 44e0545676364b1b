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

A file loaded again, the same bytes at the same path, gives the same
:class:`Mesh` object back (:data:`CACHED_MESHES` of them are kept, the most
recently loaded): a Mesh is immutable, and the structures it derives (its
triangle hierarchies, built on its first query) are kept with it, so a scene,
a study or a conformance check that loads a model again pays neither the
parse nor the tree build twice.

Cost: reading and hashing the file, O(file size); on a new file, that of the
reader, O(file size), plus the O(n log n) weld.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import logging
import warnings
from collections import OrderedDict
from pathlib import Path

import numpy as np

from refsim.bundled import models_dir
from refsim.errors import ModelError
from refsim.models.ac3d import parse_ac3d_bytes
from refsim.models.mesh import Mesh
from refsim.storage.reading import (
    as_path,
    bundled_if_bare,
    read_regular_file,
    refuse_missing_bundled,
)

#: Suffixes read by trimesh (the formats trimesh reads).
TRIMESH_SUFFIXES = (".obj", ".stl", ".ply", ".off")
SUFFIXES = (".ac",) + TRIMESH_SUFFIXES

#: How many loaded meshes :func:`load_model` keeps for a second load of the
#: same file (least recently loaded dropped first).
CACHED_MESHES = 32

#: key -> (the Mesh, the warnings its reading gave)
_loaded: OrderedDict[tuple, tuple[Mesh, tuple[Warning | str, ...]]] = OrderedDict()


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

    Returns
    -------
    Mesh
        The same object as an earlier call's for the same path, bytes and
        tolerance, while it is among the last :data:`CACHED_MESHES` loaded.

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
    data = read_regular_file(path, ModelError)
    if type(weld_tolerance) not in (int, float):    # Mesh says what is wrong with it
        return _parse(path, suffix, data, weld_tolerance)
    key = (str(path), float(weld_tolerance), hashlib.blake2b(data, digest_size=20).digest())
    # popped and put back (the most recent last): two steps another thread
    # cannot break, at worst both parse
    entry = _loaded.pop(key, None)
    if entry is None:
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            mesh = _parse(path, suffix, data, weld_tolerance)
        entry = (mesh, tuple(w.message for w in said))
    _loaded[key] = entry
    while len(_loaded) > CACHED_MESHES:
        _loaded.popitem(last=False)
    for message in entry[1]:           # what the file's reader said, at every load
        warnings.warn(message, stacklevel=2)
    return entry[0]


def _parse(path: Path, suffix: str, data: bytes, weld_tolerance) -> Mesh:
    if suffix == ".ac":
        return parse_ac3d_bytes(data, path, weld_tolerance=weld_tolerance)
    return _load_with_trimesh(path, data, weld_tolerance)


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
