"""The result store: whole files by key hash, a manifest, refusals."""

from __future__ import annotations

import json

import pytest

from refsim.errors import SweepError
from refsim.sweep.store import FORMAT, Store, file_name


def test_results_are_files_named_by_the_keys_hash_and_read_back(tmp_path):
    store = Store(tmp_path / "s", {"a/b c": "f1", "x": "f2"})
    assert store.load("a/b c") is None
    store.save("a/b c", '{"v":[0.1,2]}', attempts=2, wall_seconds=0.5)
    path = tmp_path / "s" / "results" / file_name("a/b c")
    assert len(path.stem) == 32 and path.is_file()
    assert store.load("a/b c") == {"key": "a/b c", "fingerprint": "f1", "value": {"v": [0.1, 2]},
                                   "attempts": 2, "wall_seconds": 0.5}
    manifest = json.loads((tmp_path / "s" / "manifest.json").read_text())
    assert manifest["format"] == FORMAT
    assert manifest["tasks"]["x"] == {"fingerprint": "f2", "file": f"results/{file_name('x')}"}
    assert not list((tmp_path / "s").rglob("*.tmp"))


def test_an_extended_or_smaller_task_list_is_welcome_and_the_manifest_grows(tmp_path):
    Store(tmp_path, {"a": "f1"}).save("a", "1", 1, 0.1)
    again = Store(tmp_path, {"a": "f1", "b": "f2"})
    assert again.load("a")["value"] == 1 and again.load("b") is None
    assert Store(tmp_path, {"b": "f2"}).load("b") is None
    tasks = json.loads((tmp_path / "manifest.json").read_text())["tasks"]
    assert sorted(tasks) == ["a", "b"]


def test_a_store_of_another_task_list_is_refused_naming_the_keys(tmp_path):
    Store(tmp_path, {f"k{i}": "old" for i in range(5)})
    with pytest.raises(SweepError, match=r"another task list: 5 task\(s\).*'k0', 'k1', 'k2' "
                                         r"and 2 more"):
        Store(tmp_path, {f"k{i}": "new" for i in range(6)})


def test_a_folder_that_is_not_a_store_is_refused(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(SweepError, match="not a sweep store"):
        Store(tmp_path, {"a": "f"})
    (tmp_path / "manifest.json").write_text('{"format": "something else", "tasks": {}}')
    with pytest.raises(SweepError, match="not a manifest of format"):
        Store(tmp_path, {"a": "f"})


def test_a_result_file_of_another_task_is_refused(tmp_path):
    store = Store(tmp_path, {"a": "f1", "b": "f2"})
    store.save("a", "1", 1, 0.1)
    (tmp_path / "results" / file_name("a")).replace(tmp_path / "results" / file_name("b"))
    with pytest.raises(SweepError, match="not the stored result of task 'b'"):
        store.load("b")
