"""refsim.storage.npz: an .npz written entry by entry that numpy reads back exactly,
and errors on reading that name the file and the entry."""

from __future__ import annotations

import io
import zipfile

import numpy as np
import pytest

import refsim.storage.npz
from refsim.errors import NpzFileError
from refsim.storage.npz import read_npz, write_npz

ARRAYS = {
    "t": np.linspace(0.0, 1.0, 7),
    "position": np.arange(7 * 2 * 3, dtype=np.float64).reshape(7, 2, 3) / 3.0,
    "step": np.arange(7, dtype=np.int64),
    "names": np.array(["ball", "cube"]),
    "json": np.array('{"a": [1, 2]}'),             # 0-d unicode, as the JSON entries
    "empty": np.empty((0, 2, 3)),
    "fortran": np.asfortranarray(np.arange(12.0).reshape(3, 4)),
}


def _bytes(arrays, compressed):
    buffer = io.BytesIO()
    write_npz(buffer, arrays, compressed=compressed)
    return buffer.getvalue()


@pytest.mark.parametrize("compressed", [False, True])
def test_numpy_reads_back_every_entry_exactly(compressed):
    data = _bytes(ARRAYS, compressed)
    with np.load(io.BytesIO(data)) as loaded:
        assert loaded.files == list(ARRAYS)
        for name, a in ARRAYS.items():
            assert loaded[name].dtype == a.dtype and loaded[name].shape == a.shape
            assert np.array_equal(loaded[name], a)
    method = zipfile.ZIP_DEFLATED if compressed else zipfile.ZIP_STORED
    with zipfile.ZipFile(io.BytesIO(data)) as archive:
        assert {i.compress_type for i in archive.infolist()} == {method}


def test_each_entry_is_what_numpy_save_writes():
    # header and data of every .npy entry, byte for byte (in C order: a
    # Fortran-ordered array is written as its C-ordered copy)
    with zipfile.ZipFile(io.BytesIO(_bytes(ARRAYS, False))) as archive:
        for name, a in ARRAYS.items():
            expected = io.BytesIO()
            np.save(expected, a if a.flags.c_contiguous else np.ascontiguousarray(a))
            assert archive.read(f"{name}.npy") == expected.getvalue()


def test_the_same_arrays_give_the_same_bytes():
    assert _bytes(ARRAYS, True) == _bytes(ARRAYS, True)


def test_a_large_entry_goes_through_in_chunks(monkeypatch):
    # 3 chunks of 64 bytes and a part: the chunk boundaries leave no trace
    monkeypatch.setattr(refsim.storage.npz, "CHUNK_BYTES", 64)
    a = np.arange(25, dtype=np.float64)           # 200 bytes
    written = []
    real = refsim.storage.npz._array_chunks

    def counted(array, size):
        for chunk in real(array, size):
            written.append(len(chunk))
            yield chunk

    monkeypatch.setattr(refsim.storage.npz, "_array_chunks", counted)
    with np.load(io.BytesIO(_bytes({"a": a}, False))) as loaded:
        assert np.array_equal(loaded["a"], a)
    assert written == [64, 64, 64, 8]


def test_object_arrays_are_refused():
    with pytest.raises(TypeError, match="'bad'"):
        _bytes({"bad": np.array([object()])}, False)


# -- reading ---------------------------------------------------------------------------


def _saved(tmp_path, arrays=None, name="f.npz"):
    path = tmp_path / name
    path.write_bytes(_bytes(ARRAYS if arrays is None else arrays, False))
    return path


def test_read_npz_returns_the_named_entries(tmp_path):
    got = read_npz(_saved(tmp_path), ["t", "names"])
    assert list(got) == ["t", "names"]
    assert np.array_equal(got["t"], ARRAYS["t"]) and list(got["names"]) == ["ball", "cube"]


def test_a_missing_file(tmp_path):
    path = tmp_path / "absent.npz"
    with pytest.raises(NpzFileError) as info:
        read_npz(path, ["t"])
    assert str(info.value) == f"{path}: no such file"
    assert info.value.path == str(path) and info.value.entry is None


def test_a_directory(tmp_path):
    with pytest.raises(NpzFileError, match=r"not a regular file \(a directory\)"):
        read_npz(tmp_path, ["t"])


@pytest.mark.parametrize("content", [b"", b"hello, not an npz\n", b"PK\x03\x04 cut"])
def test_another_format(tmp_path, content):
    path = tmp_path / "f.npz"
    path.write_bytes(content)
    with pytest.raises(NpzFileError, match="not an .npz file") as info:
        read_npz(path, ["t"])
    assert str(info.value).startswith(f"{path}: ")


def test_a_truncated_file(tmp_path):
    path = _saved(tmp_path)
    data = path.read_bytes()
    path.write_bytes(data[:len(data) // 2])        # the zip directory at the end is gone
    with pytest.raises(NpzFileError, match="truncated") as info:
        read_npz(path, ["t"])
    assert str(info.value).startswith(f"{path}: not an .npz file")


def test_a_single_npy_file(tmp_path):
    path = tmp_path / "f.npz"
    np.save(open(path, "wb"), np.zeros(3))
    with pytest.raises(NpzFileError, match="single .npy array"):
        read_npz(path, ["t"])


def test_a_missing_entry_names_it_and_the_entries_there(tmp_path):
    path = _saved(tmp_path, {"t": ARRAYS["t"]})
    with pytest.raises(NpzFileError) as info:
        read_npz(path, ["t", "position"])
    assert str(info.value) == f"{path}: entry 'position': missing (entries: t)"
    assert info.value.entry == "position"


def test_a_corrupt_entry_names_it(tmp_path):
    path = _saved(tmp_path, {"t": ARRAYS["t"], "step": ARRAYS["step"]})
    data = bytearray(path.read_bytes())
    # flip one byte of the data of "step" (stored, so its bytes are there as is)
    at = bytes(data).index(ARRAYS["step"].tobytes())
    data[at] ^= 0xFF
    path.write_bytes(bytes(data))
    with pytest.raises(NpzFileError, match="corrupt or truncated") as info:
        read_npz(path, ["t", "step"])
    assert info.value.entry == "step"


def test_an_interruption_inside_archive_open_propagates_as_itself(monkeypatch):
    """Ctrl-C (or SIGTERM's Interrupted) raised inside zipfile's ``open``,
    after it marked an entry open and before the entry is returned: the
    interruption propagates, not zipfile's "open writing handle" error, and
    the abandoned archive writes nothing when it is collected."""
    import gc
    import sys

    real_open = zipfile.ZipFile.open

    opened = []                                    # kept, as the traceback's frames keep it

    def interrupted_open(self, *args, **kwargs):
        opened.append(real_open(self, *args, **kwargs))     # the entry is open now
        raise KeyboardInterrupt

    unraisable = []
    monkeypatch.setattr(zipfile.ZipFile, "open", interrupted_open)
    monkeypatch.setattr(sys, "unraisablehook", unraisable.append)
    with pytest.raises(KeyboardInterrupt):
        write_npz(io.BytesIO(), {"a": np.arange(3.0)}, compressed=False)
    opened.clear()
    gc.collect()
    assert unraisable == []
