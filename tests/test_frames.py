"""refsim.storage.frames: frames kept in memory or spilled beside the output give the
same arrays, bit for bit; spill files never outlive their sink; the disk
guard's arithmetic."""

from __future__ import annotations

import io
import shutil

import numpy as np
import pytest

from refsim.errors import OutputError, StateError
from refsim.storage.frames import (
    MemorySink,
    SpillSink,
    check_disk_space,
    frame_count,
    spill_disk_bound,
)
from refsim.storage.npz import write_npz


def _frames(n, B=2, seed=3):
    """``n`` frames of random (B, 3) and (B, 3, 3) data and their times."""
    rng = np.random.default_rng(seed)
    for i in range(n):
        yield {"t": i * 1e-3, "step": np.int64(i), "x": rng.standard_normal((B, 3)),
               "R": rng.standard_normal((B, 3, 3))}


def names(directory):
    return sorted(p.name for p in directory.iterdir())


def test_frame_count_is_first_every_kth_and_last():
    assert frame_count(100, 10) == 11              # 0, 10, ..., 100
    assert frame_count(100, 30) == 5               # 0, 30, 60, 90, 100
    assert frame_count(100, 100) == frame_count(100, 1000) == 2
    assert frame_count(0, 1) == 1


@pytest.mark.parametrize("capacity", [1, 5, 64])
def test_memory_sink_stacks_the_frames(capacity):
    # capacity below, at and above the 5 frames: growth by doubling is invisible
    frames = list(_frames(5))
    sink = MemorySink(capacity=capacity)
    for f in frames:
        sink.append(f)
    a = sink.arrays()
    assert list(a) == ["t", "step", "x", "R"] and sink.n_frames == 5
    assert a["t"].dtype == np.float64 and a["step"].dtype == np.int64
    for name in a:
        assert np.array_equal(a[name], np.stack([np.asarray(f[name]) for f in frames]))


def test_a_sink_copies_what_it_is_given():
    sink = MemorySink()
    x = np.zeros((2, 3))
    sink.append({"x": x})
    x[:] = 1.0                                     # the caller reuses its array
    sink.append({"x": x})
    assert np.array_equal(sink.arrays()["x"][:, 0, 0], [0.0, 1.0])


def test_later_appends_leave_earlier_arrays_alone():
    sink = MemorySink(capacity=1)
    sink.append({"x": np.zeros(3)})
    first = sink.arrays()["x"]
    for _ in range(4):
        sink.append({"x": np.ones(3)})
    assert first.shape == (1, 3) and not first.any()


@pytest.mark.parametrize(("frame", "match"), [
    ({"t": 0.0}, "entries"),
    ({"t": 0.0, "x": np.zeros(4)}, "shape"),
])
def test_a_frame_unlike_the_first_is_refused(frame, match):
    sink = MemorySink()
    sink.append({"t": 0.0, "x": np.zeros(3)})
    with pytest.raises(StateError, match=match):
        sink.append(frame)


def test_spilled_frames_are_the_memory_frames_bit_for_bit(tmp_path):
    memory = MemorySink()
    with SpillSink(tmp_path / "out.npz") as spill:
        for f in _frames(37):
            memory.append(f)
            spill.append(f)
        spilled, kept = spill.arrays(), memory.arrays()
        assert list(spilled) == list(kept)
        for name in kept:
            assert spilled[name].shape == kept[name].shape
            assert spilled[name].dtype == kept[name].dtype
            assert np.array_equal(np.asarray(spilled[name]), kept[name])
            assert np.array_equal(spilled[name][-1], kept[name][-1])
            assert np.array_equal(spilled[name][3:9], kept[name][3:9])
        assert len(spilled["t"]) == 37 and spilled["t"][-1] == 36 * 1e-3
        # the .npz written from either is the same file, byte for byte
        a, b = io.BytesIO(), io.BytesIO()
        write_npz(a, spilled, compressed=True)
        write_npz(b, kept, compressed=True)
        assert a.getvalue() == b.getvalue()
        # one hidden spill file per entry, beside the output
        assert len(names(tmp_path)) == 4
        assert all(n.startswith(".out.npz.") and n.endswith(".spill") for n in names(tmp_path))
    assert names(tmp_path) == []


def test_spill_chunks_cover_the_file_in_order(tmp_path):
    with SpillSink(tmp_path / "out.npz") as spill:
        for i in range(10):
            spill.append({"x": np.full(3, float(i))})
        x = spill.arrays()["x"]
        pieces = [bytes(c) for c in x.chunks(40)]  # 240 bytes: 6 pieces of 40
        assert [len(p) for p in pieces] == [40] * 6
        assert b"".join(pieces) == np.repeat(np.arange(10.0), 3).tobytes()
        with pytest.raises(IndexError):
            x[10]


def test_spill_files_go_even_when_the_run_fails(tmp_path):
    with pytest.raises(KeyboardInterrupt):
        with SpillSink(tmp_path / "out.npz") as spill:
            spill.append({"x": np.zeros(3)})
            assert len(names(tmp_path)) == 1
            raise KeyboardInterrupt
    assert names(tmp_path) == []


def test_spill_files_go_beside_a_symlinks_target(tmp_path):
    (tmp_path / "data").mkdir()
    link = tmp_path / "latest.npz"
    link.symlink_to(tmp_path / "data" / "run.npz")
    with SpillSink(link) as spill:
        spill.append({"x": np.zeros(3)})
        assert len(names(tmp_path / "data")) == 1 and names(tmp_path) == ["data",
                                                                           "latest.npz"]


def test_a_spill_into_a_missing_directory_names_the_output(tmp_path):
    out = tmp_path / "absent" / "out.npz"
    with SpillSink(out) as spill, pytest.raises(OutputError, match="no directory"):
        spill.append({"x": np.zeros(3)})


# -- the disk guard -----------------------------------------------------------------


def _free(monkeypatch, free_bytes):
    monkeypatch.setattr(shutil, "disk_usage",
                        lambda path: shutil._ntuple_diskusage(10**12, 10**12 - free_bytes,
                                                              free_bytes))


def test_the_disk_bound_is_the_spill_plus_the_npz():
    # 11 frames of 8 + 240 bytes: 2728 bytes of spill, and an .npz of the
    # same data plus 4096 bytes per entry and 4096 for the directory
    assert spill_disk_bound([8, 240], 11, compressed=False) == 2728 + 2728 + 3 * 4096
    # deflate may expand incompressible data by 1/1024 at most
    assert spill_disk_bound([1024], 1024, compressed=True) == \
        2 * 1024 * 1024 + 1024 + 2 * 4096


def test_the_guard_passes_what_fits_and_names_the_smallest_stride(tmp_path, monkeypatch):
    out = tmp_path / "out.npz"
    entry = [8, 8, 24_000_000, 24_000_000]          # 1e6 particles
    # 1000 steps: need(k) = 2 * 48e6 * frame_count(1000, k) + overhead
    free = 2 * 48_000_000 * 21 + 10**6             # 21 frames fit: k = 50
    _free(monkeypatch, free)
    check_disk_space(out, entry, 1000, 50, compressed=False, frames_of="1000000 particles",
                     size_hint="s.toml: particles.count")
    with pytest.raises(OutputError) as info:
        check_disk_space(out, entry, 1000, 1, compressed=False,
                         frames_of="1000000 particles", size_hint="s.toml: particles.count")
    message = str(info.value)
    assert message.startswith(f"{out}: cannot write: 1001 frames of 1000000 particles need "
                              "96.1 GB on disk")
    assert message.endswith("2.0 GB free; store fewer frames with --every 50 or more")
    assert "\n" not in message


def test_the_guard_names_the_size_when_no_stride_helps(tmp_path, monkeypatch):
    _free(monkeypatch, 10**6)
    with pytest.raises(OutputError) as info:
        check_disk_space(tmp_path / "o.npz", [8, 8, 24_000_000, 24_000_000], 10, 1,
                         compressed=False, frames_of="1000000 particles",
                         size_hint="s.toml: particles.count")
    assert str(info.value).endswith("1.0 MB free; even 2 frames need 192.0 MB: make a "
                                    "frame smaller (s.toml: particles.count)")
