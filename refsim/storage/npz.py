"""The .npz format, written entry by entry in bounded chunks, and read with
errors that name the file and the entry.

An .npz is a zip archive of ``.npy`` files, one per array (numpy's own
``savez``; format: NEP 1, "A simple file format for NumPy arrays", and the
PKWARE APPNOTE for zip with ZIP64). :func:`write_npz` writes the same layout
``numpy.savez`` / ``savez_compressed`` write (each entry's ``.npy`` header
by ``numpy.lib.format``, ZIP64 entries, deflate at zlib's default level when
compressed), so ``numpy.load`` and :meth:`refsim.Trajectory.load` read it.
It differs from ``savez`` in two ways, both deliberate:

- the data of an entry comes in chunks of at most :data:`CHUNK_BYTES`,
  either from an in-memory array (slices of its bytes, no copy) or from a
  *spilled* array whose frames sit in a raw file (:class:`refsim.storage.frames.
  SpilledArray`, anything with ``shape``, ``dtype`` and ``chunks(size)``),
  so writing costs O(chunk) memory whatever the array's size;
- every entry carries the same fixed date (:data:`ZIP_DATE`), so the same
  arrays give the same bytes (docs/design.md, Conventions: reproducible output).

Cost: one pass over the data (plus CRC-32, plus deflate when compressed);
memory O(:data:`CHUNK_BYTES`) and zlib's window.
"""

from __future__ import annotations

import zipfile
import zlib
from collections.abc import Iterator, Mapping

import numpy as np

from refsim.errors import NpzFileError
from refsim.storage.reading import require_regular_file

#: Bytes handed to the zip writer at a time: large enough that the Python
#: work per chunk is small next to CRC-32 and the copy of the chunk itself,
#: small enough to be a rounding error in the memory of any run.
CHUNK_BYTES = 1 << 20

#: The date written into every zip entry (the zip format's epoch): a fixed
#: date makes the file a function of its arrays alone.
ZIP_DATE = (1980, 1, 1, 0, 0, 0)

#: Upper bound of deflate's expansion of incompressible data, as a fraction
#: (zlib's ``deflateBound``: 5 bytes per 16 KiB stored block, plus a few
#: bytes; 1/1024 is a safe round bound), and bytes of fixed overhead per
#: entry (zip local and central headers with ZIP64 extras, the .npy header).
DEFLATE_EXPANSION = 1 / 1024
ENTRY_OVERHEAD = 4096


def npy_header(shape: tuple, dtype: np.dtype) -> bytes:
    """The ``.npy`` header (magic, version 1.0 or 2.0, the dict, padding) of
    a C-ordered array of ``shape`` and ``dtype``, as ``numpy.save`` writes it."""
    import io

    header = {"descr": np.lib.format.dtype_to_descr(np.dtype(dtype)),
              "fortran_order": False, "shape": tuple(int(n) for n in shape)}
    buffer = io.BytesIO()
    try:
        np.lib.format.write_array_header_1_0(buffer, header)
    except ValueError:                         # a header over 64 KiB: version 2.0
        buffer = io.BytesIO()
        np.lib.format.write_array_header_2_0(buffer, header)
    return buffer.getvalue()


def _array_chunks(array: np.ndarray, size: int) -> Iterator[memoryview]:
    """The bytes of C-contiguous ``array`` in slices of ``size`` (views, no copy)."""
    flat = array.reshape(-1).view(np.uint8)
    for start in range(0, flat.size, size):
        yield flat[start:start + size].data


def _entry(name: str, value) -> tuple[tuple, np.dtype, Iterator]:
    """``(shape, dtype, chunks)`` of one entry: an array-like in memory, or a
    spilled array (``shape``, ``dtype``, ``chunks(size)``)."""
    if hasattr(value, "chunks") and not isinstance(value, np.ndarray):
        return tuple(value.shape), np.dtype(value.dtype), value.chunks(CHUNK_BYTES)
    array = np.asarray(value)
    if not array.flags.c_contiguous:
        array = np.ascontiguousarray(array)   # (ascontiguousarray alone makes 0-d 1-d)
    if array.dtype.hasobject:
        raise TypeError(f"entry {name!r}: object arrays are not written (no pickles)")
    return array.shape, array.dtype, _array_chunks(array, CHUNK_BYTES)


def write_npz(handle, entries: Mapping[str, object], *, compressed: bool) -> None:
    """Write ``entries`` (name -> array) as an .npz to the open binary,
    seekable ``handle``, in the mapping's order, entry ``name`` as
    ``name.npy``. ``compressed`` chooses deflate or stored entries.

    An exception on the way (a full disk, or Ctrl-C or SIGTERM raised by
    their handlers) abandons the archive unclosed and propagates: the caller
    discards the half-written file (:func:`refsim.storage.writing.write_atomic`). Closing
    it would be wrong twice: a signal raised inside ``archive.open`` leaves
    zipfile unable to close, and its own error ("an open writing handle")
    would replace the interruption."""
    method = zipfile.ZIP_DEFLATED if compressed else zipfile.ZIP_STORED
    archive = zipfile.ZipFile(handle, mode="w", compression=method, allowZip64=True)
    try:
        for name, value in entries.items():
            shape, dtype, chunks = _entry(name, value)
            info = zipfile.ZipInfo(f"{name}.npy", date_time=ZIP_DATE)
            info.compress_type = method
            info.external_attr = 0o600 << 16       # what savez's entries carry
            with archive.open(info, mode="w", force_zip64=True) as member:
                member.write(npy_header(shape, dtype))
                for chunk in chunks:
                    member.write(chunk)
    except BaseException:
        archive.fp = None          # abandoned: neither close() nor __del__ writes to it
        raise
    archive.close()


def npz_size_bound(entry_bytes, *, compressed: bool) -> int:
    """An upper bound of the size of an .npz whose entries hold
    ``entry_bytes`` bytes of data each (list of ints)."""
    total = 0
    for n in entry_bytes:
        total += n + ENTRY_OVERHEAD + (int(n * DEFLATE_EXPANSION) if compressed else 0)
    return total + ENTRY_OVERHEAD


def read_npz(path, names) -> dict[str, np.ndarray]:
    """The entries ``names`` of the .npz at ``path``, read whole.

    Raises
    ------
    NpzFileError
        Naming ``path`` (and the entry): no such file, unreadable, not an
        .npz (another format, or truncated so that the zip directory at its
        end is gone), an entry missing, or an entry whose data is corrupt or
        cut short (a CRC or length mismatch).
    """
    require_regular_file(path, NpzFileError)           # a FIFO would block np.load
    try:
        archive = np.load(path, allow_pickle=False)
    except (ValueError, EOFError, zipfile.BadZipFile) as exc:
        raise NpzFileError(f"not an .npz file (another format, or truncated): {exc}",
                           path) from None
    except OSError as exc:
        raise NpzFileError(f"cannot read: {exc.strerror or exc}", path) from None
    if not isinstance(archive, np.lib.npyio.NpzFile):
        raise NpzFileError("is a single .npy array, not an .npz file", path)
    arrays = {}
    with archive:
        for name in names:
            if name not in archive.files:
                have = ", ".join(archive.files) or "none"
                raise NpzFileError(f"missing (entries: {have})", path, name)
            try:
                arrays[name] = archive[name]
            except (ValueError, EOFError, OSError, zipfile.BadZipFile, zlib.error) as exc:
                raise NpzFileError(f"corrupt or truncated: {exc}", path, name) from None
    return arrays
