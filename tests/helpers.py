"""Checks shared by several test modules (tests/ and properties/)."""

from __future__ import annotations

import pytest

from refsim.errors import SceneError
from refsim.models.mesh import Mesh
from refsim.scenes.loader import load_scene


def assert_meshes_identical(a: Mesh, b: Mesh) -> None:
    """Same vertices bit for bit (-0.0 included), faces and per-face data,
    materials and object names."""
    assert a.vertices.tobytes() == b.vertices.tobytes()
    assert a.faces.tolist() == b.faces.tolist()
    assert a.face_material.tolist() == b.face_material.tolist()
    assert a.face_flags.tolist() == b.face_flags.tolist()
    assert a.face_object.tolist() == b.face_object.tolist()
    assert a.materials == b.materials
    assert a.objects == b.objects


def assert_scene_error(tmp_path, text: str, key: str, phrase: str) -> None:
    """Loading ``text`` as a scene raises SceneError naming the file and ``key``."""
    path = tmp_path / "scene.toml"
    path.write_text(text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    err = info.value
    assert err.key == key
    assert phrase in err.message
    assert str(path) in str(err) and key in str(err)


def new_workers(process, before: set[int]) -> list:
    """The spawned worker processes (``multiprocessing``'s spawn) below
    ``process`` (a ``psutil.Process``) whose pids are not in ``before``:
    a sweep's, told apart from those of a fixture started earlier."""
    import psutil

    found = []
    for child in process.children(recursive=True):
        try:
            if child.pid not in before and "spawn_main" in " ".join(child.cmdline()):
                found.append(child)
        except psutil.NoSuchProcess:
            continue
    return found
