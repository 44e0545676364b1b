"""refsim.storage.writing: where an output goes (symlinks written through, special files
refused), written whole or not at all, no temporary file left."""

from __future__ import annotations

import os
import socket

import pytest

from refsim.errors import OutputError, RefsimError
from refsim.storage.writing import atomic_output, output_target, write_text_atomic


def names(directory):
    return sorted(p.name for p in directory.iterdir())


def test_a_regular_file_is_replaced_whole_keeping_its_mode(tmp_path):
    out = tmp_path / "out.txt"
    out.write_text("old")
    os.chmod(out, 0o640)
    inode = out.stat().st_ino
    write_text_atomic(out, "new")
    assert out.read_text() == "new"
    assert out.stat().st_mode & 0o777 == 0o640
    assert out.stat().st_ino != inode              # a new file moved in, not rewritten
    assert names(tmp_path) == ["out.txt"]


def test_a_symlink_is_written_through_and_stays(tmp_path):
    # the link in one directory, its target in another: the temporary file
    # goes beside the target (one file system for os.replace), none is left
    links, data = tmp_path / "links", tmp_path / "data"
    links.mkdir()
    data.mkdir()
    target = data / "run-1.npz"
    target.write_text("old")
    link = links / "latest.npz"
    link.symlink_to(target)
    write_text_atomic(link, "new")
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text() == "new"
    assert names(links) == ["latest.npz"] and names(data) == ["run-1.npz"]


def test_a_relative_chain_of_symlinks_is_followed(tmp_path):
    (tmp_path / "real.txt").write_text("old")
    (tmp_path / "b").symlink_to("real.txt")
    (tmp_path / "a").symlink_to("b")
    assert output_target(tmp_path / "a") == (tmp_path / "real.txt").resolve()
    write_text_atomic(tmp_path / "a", "new")
    assert (tmp_path / "real.txt").read_text() == "new"
    assert os.readlink(tmp_path / "a") == "b" and os.readlink(tmp_path / "b") == "real.txt"


def test_a_dangling_symlink_creates_its_target(tmp_path):
    # what open(link, "w") does: the link's target comes into being
    link = tmp_path / "link"
    link.symlink_to("new.txt")
    write_text_atomic(link, "content")
    assert link.is_symlink() and (tmp_path / "new.txt").read_text() == "content"


def _fifo(tmp_path):
    path = tmp_path / "pipe"
    os.mkfifo(path)
    return path


def _socket(tmp_path):
    path = tmp_path / "sock"
    server = socket.socket(socket.AF_UNIX)
    server.bind(str(path))
    server.close()                                 # the node stays
    return path


@pytest.mark.parametrize(("make", "kind"), [
    (_fifo, "a FIFO (named pipe)"),
    (_socket, "a socket"),
    (lambda tmp_path: tmp_path, "a directory"),
    (lambda tmp_path: _null(), "a character device"),
])
def test_a_special_file_is_refused_and_left_alone(tmp_path, make, kind):
    path = make(tmp_path)
    before = os.lstat(path)
    with pytest.raises(OutputError) as info:
        write_text_atomic(path, "x")
    assert str(info.value) == (f"{path}: cannot write: it is {kind}; refsim writes only "
                               "regular files")
    assert isinstance(info.value, RefsimError) and isinstance(info.value, OSError)
    after = os.lstat(path)
    assert (after.st_mode, after.st_ino, after.st_rdev) == (before.st_mode, before.st_ino,
                                                            before.st_rdev)


def _null():
    from pathlib import Path

    return Path(os.devnull)


def test_a_symlink_to_a_special_file_names_both(tmp_path):
    fifo = _fifo(tmp_path)
    link = tmp_path / "link"
    link.symlink_to(fifo)
    with pytest.raises(OutputError, match="FIFO") as info:
        write_text_atomic(link, "x")
    assert str(info.value).startswith(f"{link} (-> {fifo.resolve()}): cannot write: ")
    assert link.is_symlink() and os.path.samefile(link, fifo)
    assert names(tmp_path) == ["link", "pipe"]


def test_a_missing_directory_is_one_line(tmp_path):
    out = tmp_path / "absent" / "out.txt"
    with pytest.raises(OutputError) as info:
        write_text_atomic(out, "x")
    assert str(info.value) == f"{out}: cannot write: no directory {tmp_path / 'absent'}"
    assert info.value.strerror == f"no directory {tmp_path / 'absent'}"


def test_a_symlink_loop_is_refused(tmp_path):
    (tmp_path / "a").symlink_to("b")
    (tmp_path / "b").symlink_to("a")
    with pytest.raises(OutputError, match="cannot follow its symlinks"):
        write_text_atomic(tmp_path / "a", "x")
    assert names(tmp_path) == ["a", "b"]


def test_a_failure_part_way_leaves_the_old_file_and_no_temporary(tmp_path):
    out = tmp_path / "out.bin"
    out.write_bytes(b"old")
    for error in (RuntimeError("write failed"), KeyboardInterrupt()):
        with pytest.raises(type(error)):
            with atomic_output(out) as handle:
                handle.write(b"half of the new")
                seen = names(tmp_path)
                raise error
        # the temporary file was there, hidden, beside the target
        assert len(seen) == 2 and seen[0].startswith(".out.bin.") and seen[0].endswith(".tmp")
        assert out.read_bytes() == b"old" and names(tmp_path) == ["out.bin"]


def test_a_special_file_that_appears_during_the_write_is_not_replaced(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(OutputError, match="FIFO"):
        with atomic_output(out) as handle:
            handle.write(b"data")
            os.mkfifo(out)                         # someone else, meanwhile
    assert os.path.exists(out) and not out.is_file()
    assert names(tmp_path) == ["out"]


def test_write_ac3d_onto_a_fifo_is_one_model_error(tmp_path):
    from refsim.errors import ModelError
    from refsim.models.ac3d import write_ac3d
    from refsim.models.loading import load_model

    fifo = _fifo(tmp_path)
    with pytest.raises(ModelError) as info:
        write_ac3d(load_model("cube.ac"), fifo)
    message = str(info.value)
    assert message.count(str(fifo)) == 1 and "FIFO" in message
    assert not fifo.is_file()
