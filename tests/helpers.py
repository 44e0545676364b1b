"""Checks shared by several test modules (tests/ and properties/)."""

from __future__ import annotations

import platform
from pathlib import Path

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


#: The OpenBLAS core types a test may force with ``OPENBLAS_CORETYPE``, each
#: with the /proc/cpuinfo flags its kernels use: forcing a core type whose
#: instructions the processor lacks kills the process with SIGILL (SkylakeX
#: on an x86-64 processor without AVX-512, as many AMD EPYC are). Prescott
#: (SSE3) runs on every x86-64 processor.
OPENBLAS_CORE_FLAGS = {
    "Prescott": frozenset(),
    "Haswell": frozenset({"avx2", "fma"}),
    "SkylakeX": frozenset({"avx512f", "avx512bw", "avx512dq", "avx512vl", "avx512cd"}),
}

#: platform.machine()'s names for x86-64 (Linux, the BSDs and macOS; Windows).
X86_64_MACHINES = frozenset({"x86_64", "amd64", "AMD64"})


def cpu_flags(cpuinfo: Path = Path("/proc/cpuinfo")) -> frozenset[str]:
    """The processor's feature flags (the first ``flags`` line of ``cpuinfo``;
    none where the file is missing or has no such line)."""
    try:
        text = cpuinfo.read_text()
    except OSError:
        return frozenset()
    for line in text.splitlines():
        key, _, value = line.partition(":")
        if key.strip() == "flags":
            return frozenset(value.split())
    return frozenset()


def openblas_core_types(flags: frozenset[str] | None = None,
                        machine: str | None = None) -> list[str]:
    """The OpenBLAS core types this host can run, in the order of
    :data:`OPENBLAS_CORE_FLAGS`: none off x86-64 (there only the default
    kernels run), else Prescott and those whose flags are all in ``flags``
    (default: :func:`cpu_flags`)."""
    machine = platform.machine() if machine is None else machine
    if machine not in X86_64_MACHINES:
        return []
    flags = cpu_flags() if flags is None else flags
    return [core for core, needed in OPENBLAS_CORE_FLAGS.items() if needed <= flags]
