"""Where a run's frames go as they are computed: kept in memory, or spilled
to disk beside the output so that memory does not grow with the steps.

A *frame* is a mapping of names to arrays of fixed shape and dtype, one per
stored step: for rigid bodies ``t`` (), ``position``, ``velocity``,
``angular_velocity`` (B, 3), ``orientation`` (B, 3, 3); for particles
``t``, ``step`` (), ``position``, ``velocity`` (N, 3). A producer (the
simulation loop, :func:`refsim.particles.run.run_particles`) calls
``sink.append(frame)`` for each stored step and ``sink.arrays()`` for the
frames so far, each (frames, *shape), when it returns (or diverges). It does
not know where the frames go:

- :class:`MemorySink` stacks them in memory: what ``refsim.simulate()``
  uses, so that a library user gets a :class:`refsim.Trajectory` of numpy
  arrays, as before. Memory: the frames once (a buffer of the expected
  number of frames, grown by doubling if more come).
- :class:`SpillSink` appends each name's frames to its own raw file (the
  bytes of the frames in C order, no header) beside the output, and
  ``arrays()`` returns :class:`SpilledArray` views of those files. Writing
  the .npz (:func:`refsim.storage.npz.write_npz`) then puts each entry's ``.npy``
  header, whose shape is known only now (also after a divergence that
  stopped early), in front of that file's bytes, copied in bounded chunks.
  Memory: one frame and one chunk, whatever the number of steps.

Why this design, and not another:

- *Why not write the .npz as the frames come?* An entry's ``.npy`` header
  holds its shape, unknown until the run ends (a divergence stops it
  early), and a zip archive is written one entry after another while a
  run produces all its arrays at once, frame by frame. One raw file per
  array is the smallest change that makes both possible, and keeps the
  format that ``numpy.load`` and ``Trajectory.load`` read.
- *Why raw files beside the output, not in /tmp?* The same file system
  as the output, so the free-space check of ``refsim run`` measures the
  disk that fills, and /tmp may be a RAM disk (which would put the frames
  back in memory). The files are hidden (``.NAME.XXXXXXXX.ENTRY.spill``)
  and removed when the sink closes, whatever happened (see
  :mod:`refsim.storage.writing` for signals).
- *Why one interface for both?* The producer's loop is the same code in
  both cases, so the arrays are the same bytes; the tests compare them.

Cost on disk of spilling: the raw frames, and while the .npz is assembled
the .npz too (about twice the frame data at that moment for uncompressed
output). Time: one extra sequential write and read of the frame data.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import BinaryIO, Protocol, TypeAlias

import numpy as np

from refsim.errors import StateError
from refsim.storage.writing import hidden_temporary, output_error, output_target, remove_quietly

#: Write buffer of each spill file: small frames (one body: 8 to 72 bytes)
#: reach the disk in few system calls; large frames go straight through.
SPILL_BUFFER_BYTES = 1 << 16


def frame_count(n_steps: int, every: int) -> int:
    """Frames a run of ``n_steps`` steps stores: the initial state, every
    ``every``-th step, and the last step."""
    return 1 + n_steps // every + (1 if n_steps % every else 0)


class FrameSink(Protocol):
    """Receives a run's frames, one mapping of name -> array per stored step.

    ``append`` copies or writes what it needs before it returns (the caller
    reuses its arrays); every frame has the names, shapes and dtypes of the
    first. ``arrays()`` gives the frames so far, name -> (frames, *shape)
    array-like, in the order of the first frame's names.
    """

    n_frames: int

    def append(self, frame: Mapping[str, object]) -> None: ...

    def arrays(self) -> Mapping[str, FrameArray]: ...


def _c_order(value, dtype) -> np.ndarray:
    """``value`` as a C-contiguous array of ``dtype`` (0-d stays 0-d, which
    ``numpy.ascontiguousarray`` alone would make 1-d)."""
    a = np.asarray(value, dtype=dtype)
    return a if a.flags.c_contiguous else np.ascontiguousarray(a)


class CountedSink:
    """A sink that hands every frame to ``inner`` and then tells ``progress``
    (a :class:`refsim.sweep.progress.Progress`) how many frames it has: the
    command line's progress line for a long run. Cost: O(1) per frame."""

    def __init__(self, inner: FrameSink, progress):
        self.inner, self.progress = inner, progress

    @property
    def n_frames(self) -> int:
        return self.inner.n_frames

    def append(self, frame: Mapping[str, object]) -> None:
        self.inner.append(frame)
        self.progress.update(self.inner.n_frames, 0)

    def arrays(self) -> Mapping[str, FrameArray]:
        return self.inner.arrays()


class _Layout:
    """The names, frame shapes and dtypes fixed by the first frame; checks
    later frames against them (a producer's bug, not a user's)."""

    def __init__(self, frame: Mapping[str, object]):
        arrays = {name: np.asarray(value) for name, value in frame.items()}
        self.shapes = {name: a.shape for name, a in arrays.items()}
        self.dtypes = {name: a.dtype for name, a in arrays.items()}
        self._entries = [(name, a.shape, a.dtype) for name, a in arrays.items()]

    def check(self, frame: Mapping[str, object]) -> list[tuple[str, np.ndarray]]:
        """``frame``'s ``(name, value)`` pairs in the layout's order, each a
        C-contiguous array of the layout's shape and dtype. O(1) per entry
        for an array that already fits (used as it is, no copy); this runs
        once per stored frame, so it stays small next to a step."""
        if frame.keys() != self.shapes.keys():
            raise StateError(f"frame has entries {sorted(frame)}, expected "
                             f"{sorted(self.shapes)}")
        out = []
        for name, shape, dtype in self._entries:
            a = frame[name]
            if not (type(a) is np.ndarray and a.dtype == dtype and a.shape == shape
                    and a.flags.c_contiguous):
                a = _c_order(a, dtype)
                if a.shape != shape:
                    raise StateError(f"frame entry {name!r} has shape {a.shape}, expected "
                                     f"{shape}")
            out.append((name, a))
        return out


class MemorySink:
    """Frames kept in memory, in one (capacity, *shape) buffer per name.

    Parameters
    ----------
    capacity : int
        Expected number of frames (a hint: more are taken by doubling the
        buffers). ``arrays()`` returns views of the first ``n_frames`` rows,
        so an exact hint costs no copy and no spare memory.
    """

    def __init__(self, capacity: int = 16):
        self.n_frames = 0
        self._capacity = max(1, int(capacity))
        self._layout: _Layout | None = None
        self._buffers: dict[str, np.ndarray] = {}

    def append(self, frame: Mapping[str, object]) -> None:
        if self._layout is None:
            self._layout = _Layout(frame)
            self._buffers = {name: np.empty((self._capacity, *shape),
                                            dtype=self._layout.dtypes[name])
                             for name, shape in self._layout.shapes.items()}
        values = self._layout.check(frame)
        if self.n_frames == self._capacity:
            self._capacity *= 2
            for name, buffer in self._buffers.items():
                grown = np.empty((self._capacity, *buffer.shape[1:]), dtype=buffer.dtype)
                grown[:self.n_frames] = buffer
                self._buffers[name] = grown
        for name, value in values:
            self._buffers[name][self.n_frames] = value
        self.n_frames += 1

    def arrays(self) -> dict[str, np.ndarray]:
        """name -> (n_frames, *shape) view (later appends do not change it)."""
        return {name: buffer[:self.n_frames] for name, buffer in self._buffers.items()}


class SpilledArray:
    """A (frames, *shape) array whose bytes are in a raw file of a
    :class:`SpillSink` (valid while the sink is open).

    Enough of an array for writing and reporting: ``shape``, ``dtype``,
    ``len()``, ``a[i]`` and ``a[i:j]`` (read from the file),
    ``chunks(size)`` (the bytes in order, ``size`` at a time, for
    :func:`refsim.storage.npz.write_npz`) and ``numpy.asarray(a)`` (reads it all:
    O(size) memory, the thing spilling avoids).
    """

    def __init__(self, path: Path, n_frames: int, frame_shape: tuple, dtype: np.dtype):
        self.path = path
        self.shape = (n_frames, *frame_shape)
        self.dtype = np.dtype(dtype)
        self._frame_bytes = self.dtype.itemsize * int(np.prod(frame_shape, dtype=np.int64))

    def __len__(self) -> int:
        return self.shape[0]

    @property
    def nbytes(self) -> int:
        return self.shape[0] * self._frame_bytes

    def _read(self, start: int, stop: int) -> np.ndarray:
        count = max(0, stop - start)
        with open(self.path, "rb") as handle:
            handle.seek(start * self._frame_bytes)
            data = handle.read(count * self._frame_bytes)
        return np.frombuffer(data, dtype=self.dtype).reshape(count, *self.shape[1:]).copy()

    def __getitem__(self, index):
        n = len(self)
        if isinstance(index, slice):
            start, stop, step = index.indices(n)
            if step != 1:
                raise IndexError("a spilled array is sliced with step 1 only")
            return self._read(start, stop)
        i = int(index)
        if not -n <= i < n:
            raise IndexError(f"frame {index} of {n}")
        i %= n
        return self._read(i, i + 1)[0]

    def __array__(self, dtype=None, copy=None):
        a = self._read(0, len(self))
        return a if dtype is None else a.astype(dtype)

    def chunks(self, size: int) -> Iterator[memoryview]:
        """The array's bytes in order, in pieces of at most ``size`` (one
        reused buffer: each piece is valid until the next is asked for)."""
        buffer = bytearray(size)
        view = memoryview(buffer)
        left = self.nbytes
        with open(self.path, "rb", buffering=0) as handle:
            while left > 0:
                got = handle.readinto(view[:min(size, left)])
                if not got:
                    raise OSError(f"{self.path}: spill file shorter than its "
                                  f"{self.shape[0]} frames")
                left -= got
                yield view[:got]


#: A frame array as a sink gives it back: a numpy array (:class:`MemorySink`)
#: or a view of a spill file (:class:`SpillSink`).
FrameArray: TypeAlias = np.ndarray | SpilledArray


class SpillSink:
    """Frames appended to one raw file per name beside ``out`` (see the
    module docstring). A context manager: leaving it removes the files.

    Parameters
    ----------
    out : path
        The output the frames are for: the files go in its target's
        directory (after symlinks, :func:`refsim.storage.writing.output_target`).

    Raises
    ------
    OutputError
        From ``append``, naming ``out``: the directory refuses the files or
        the disk is full.
    """

    def __init__(self, out: str | os.PathLike):
        self.out = Path(out)
        self.n_frames = 0
        self._layout: _Layout | None = None
        self._files: dict[str, tuple[BinaryIO, Path]] = {}
        self._clean_up: list[Path] = []

    def __enter__(self) -> SpillSink:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _open(self, frame: Mapping[str, object]) -> _Layout:
        self._layout = layout = _Layout(frame)
        target = output_target(self.out)
        for name in layout.shapes:
            fd, path = hidden_temporary(target, f".{name}.spill", self._clean_up)
            self._files[name] = (os.fdopen(fd, "wb", buffering=SPILL_BUFFER_BYTES), path)
        return layout

    def append(self, frame: Mapping[str, object]) -> None:
        layout = self._open(frame) if self._layout is None else self._layout
        values = layout.check(frame)
        try:
            for name, value in values:
                self._files[name][0].write(value.data)    # its bytes, C order
        except OSError as exc:
            raise output_error(self.out, exc.strerror or str(exc)) from None
        self.n_frames += 1

    def arrays(self) -> dict[str, SpilledArray]:
        """name -> :class:`SpilledArray` of the frames so far (the files
        flushed first)."""
        try:
            for handle, _ in self._files.values():
                handle.flush()
        except OSError as exc:
            raise output_error(self.out, exc.strerror or str(exc)) from None
        layout = self._layout
        if layout is None:                       # no frame yet: no files
            return {}
        return {name: SpilledArray(path, self.n_frames, layout.shapes[name],
                                   layout.dtypes[name])
                for name, (_, path) in self._files.items()}

    def close(self) -> None:
        """Close and remove the spill files (idempotent)."""
        try:
            for handle, _ in self._files.values():
                try:
                    handle.close()
                except OSError:
                    pass                        # a full disk: the file goes anyway
        finally:
            self._files = {}
            remove_quietly(self._clean_up)


def spill_disk_bound(entry_frame_bytes, n_frames: int, *, compressed: bool) -> int:
    """Most bytes on disk while a run of ``n_frames`` frames is written
    through a :class:`SpillSink`: the spill files, plus the .npz assembled
    from them before they are removed (:func:`refsim.storage.npz.npz_size_bound`).
    ``entry_frame_bytes`` lists the bytes of each entry of one frame; the
    small entries written at the end (names, JSON) count as overhead."""
    from refsim.storage.npz import npz_size_bound

    spill = n_frames * sum(entry_frame_bytes)
    return spill + npz_size_bound([n_frames * b for b in entry_frame_bytes],
                                  compressed=compressed)


def check_disk_space(out, entry_frame_bytes, n_steps: int, every: int, *,
                     compressed: bool, frames_of: str, size_hint: str) -> None:
    """Refuse, before running, a run whose frames cannot fit on the disk of
    ``out`` (its free space now, :func:`refsim.storage.writing.free_bytes`).

    Why a guard at all, now that memory does not grow with the steps: the
    disk does (:func:`spill_disk_bound`, about twice the frame data at the
    end), and a run that overflows it fails only after it has spent its
    whole computation, having filled a file system other programs share.
    The check is a forecast (others write too), not a promise; a disk that
    fills anyway fails with :class:`~refsim.errors.OutputError` and leaves
    no file.

    Parameters
    ----------
    entry_frame_bytes : list of int
        Bytes of each frame entry (e.g. 8 for ``t``, 24 N for positions).
    n_steps, every : int
        The run's steps and frame stride.
    frames_of : str
        What a frame holds, for the message ("10000 particles").
    size_hint : str
        What makes one frame smaller, named with its file and key, for when
        even two frames do not fit (e.g. "scene.toml: particles.count").

    Raises
    ------
    OutputError
        One line naming ``out``, the bytes needed and free, and the fix: the
        smallest ``--every`` that fits, or ``size_hint``.
    """
    from refsim.storage.writing import free_bytes

    def need(k: int) -> int:
        return spill_disk_bound(entry_frame_bytes, frame_count(n_steps, k),
                                compressed=compressed)

    free = free_bytes(out)
    if need(every) <= free:
        return
    frames = frame_count(n_steps, every)
    wanted = (f"{frames} frames of {frames_of} need {_size(need(every))} on disk "
              f"(the frames, then the .npz made from them), {_size(free)} free")
    largest = max(n_steps, 1)                     # two frames: the first and the last
    if need(largest) > free:
        raise output_error(out, f"{wanted}; even 2 frames need {_size(need(largest))}: "
                                f"make a frame smaller ({size_hint})")
    lo, hi = every, largest                       # need(lo) > free >= need(hi)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if need(mid) <= free else (mid, hi)
    raise output_error(out, f"{wanted}; store fewer frames with --every {hi} or more")


def _size(n: int) -> str:
    """``n`` bytes for a message: "19.4 GB", "12.0 MB", "3.1 kB"."""
    for unit, scale in (("GB", 1e9), ("MB", 1e6)):
        if n >= scale:
            return f"{n / scale:,.1f} {unit}"
    return f"{n / 1e3:,.1f} kB"
