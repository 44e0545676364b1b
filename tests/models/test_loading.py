"""load_model across formats (refsim.models.loading, seed S1).

The same shape is written as AC3D by refsim and as OBJ, STL, PLY and OFF by
trimesh, loaded back through :func:`refsim.load_model`, and compared.
"""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest
import trimesh
from scipy.spatial import cKDTree

import refsim
from refsim.bundled import models_dir
from refsim.errors import ModelError
from refsim.limits import MAX_MODEL_BYTES
from refsim.models.ac3d import write_ac3d
from refsim.models.loading import load_model
from refsim.models.mesh import Mesh

#: How far each format may move a coordinate of the unit-scale test shape
#: (|x| <= 1.5), with the reason:
#: - .ac: refsim writes ``repr`` floats, which read back exactly.
#: - .off: trimesh writes 10 decimal places: at most 0.5e-10 off.
#: - .obj: trimesh writes 8 decimal places: at most 0.5e-8 off.
#: - .stl, .ply: trimesh stores float32: rounding to 24 significant bits moves
#:   a coordinate by at most 2**-24 relative, i.e. <= 1.5 * 2**-24 ~ 9e-8 here.
COORD_ATOL = {
    ".ac": 0.0,
    ".off": 0.5e-10,
    ".obj": 0.5e-8,
    ".stl": 1.5 * 2.0 ** -24,
    ".ply": 1.5 * 2.0 ** -24,
}


def _shape():
    """A non-convex closed torus, as plain arrays (trimesh's generator)."""
    t = trimesh.creation.torus(major_radius=1.0, minor_radius=0.4, major_sections=24,
                               minor_sections=12)
    return np.asarray(t.vertices, dtype=np.float64), np.asarray(t.faces, dtype=np.int64)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    vertices, faces = _shape()
    folder = tmp_path_factory.mktemp("formats")
    paths = {".ac": folder / "torus.ac"}
    write_ac3d(Mesh(vertices, faces, objects=["torus"]), paths[".ac"])
    source = trimesh.Trimesh(vertices, faces, process=False)
    for suffix in (".obj", ".stl", ".ply", ".off"):
        paths[suffix] = folder / f"torus{suffix}"
        source.export(paths[suffix])
    return vertices, faces, paths


@pytest.mark.parametrize("suffix", sorted(COORD_ATOL))
def test_every_format_gives_the_same_geometry(files, suffix):
    vertices, faces, paths = files
    reference = Mesh(vertices, faces)
    mesh = refsim.load_model(paths[suffix])
    atol = COORD_ATOL[suffix]
    # Welded vertex sets: the same count, each loaded vertex within atol of
    # one reference vertex, and that match one-to-one (STL's three copies per
    # triangle have been welded back to one).
    assert mesh.n_vertices == reference.n_vertices == len(vertices)
    distance, match = cKDTree(reference.vertices).query(mesh.vertices)
    assert distance.max() <= atol * np.sqrt(3.0)
    assert len(set(match.tolist())) == mesh.n_vertices
    # The same triangles in the same order (no format reorders faces).
    assert mesh.n_faces == len(faces)
    assert match[mesh.faces].tolist() == reference.faces.tolist()
    # The same volume: moving each vertex by at most d changes the volume by
    # at most (surface area) * d, to first order.
    d = atol * np.sqrt(3.0)
    area = reference.face_areas.sum()
    assert mesh.is_closed
    assert abs(mesh.volume - reference.volume) <= 2.0 * area * d + 1e-12 * reference.volume
    assert reference.volume == pytest.approx(trimesh.Trimesh(vertices, faces).volume,
                                             rel=1e-12)
    assert mesh.source == str(paths[suffix])


def test_ac_keeps_per_triangle_data(files):
    _, faces, paths = files
    mesh = refsim.load_model(paths[".ac"])
    assert mesh.objects == ("torus",)
    assert mesh.face_object.tolist() == [0] * len(faces)


def test_suffix_is_case_insensitive(files, tmp_path):
    _, faces, paths = files
    upper = tmp_path / "TORUS.STL"
    upper.write_bytes(paths[".stl"].read_bytes())
    assert refsim.load_model(upper).n_faces == len(faces)


def test_weld_tolerance_is_passed_on(tmp_path):
    # Two triangles whose shared corner differs by 1e-6 (kept by OBJ's 8
    # decimals): welded only with a tolerance.
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1 + 1e-6, 0, 0], [1, 1, 0], [0, 1, 0]])
    path = tmp_path / "two.obj"
    trimesh.Trimesh(v, [[0, 1, 2], [3, 4, 5]], process=False).export(path)
    assert refsim.load_model(path).n_vertices == 5
    assert refsim.load_model(path, weld_tolerance=1e-5).n_vertices == 4


def test_missing_file(tmp_path):
    path = tmp_path / "absent.obj"
    with pytest.raises(ModelError, match="no such file") as info:
        refsim.load_model(path)
    assert info.value.path == str(path)
    assert str(info.value) == f"{path}: no such file"


@pytest.mark.parametrize("name", ["model.3ds", "model", "model.ac.bak"])
def test_unknown_suffix(tmp_path, name):
    path = tmp_path / name
    path.write_text("whatever")
    with pytest.raises(ModelError, match="unknown model format") as info:
        refsim.load_model(path)
    assert info.value.path == str(path)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("name, content", [
    ("broken.stl", b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n"),
    ("empty.obj", b""),
    ("garbage.ply", b"ply\nformat nonsense\n"),
    ("points.off", b"OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"),
])
def test_files_trimesh_cannot_read_are_model_errors(tmp_path, name, content):
    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(ModelError) as info:
        refsim.load_model(path)
    assert info.value.path == str(path)
    assert "\n" not in str(info.value)


def test_broken_ac_file_goes_through_our_reader(tmp_path):
    path = tmp_path / "bad.ac"
    path.write_text("AC3Db\nOBJECT poly\nnumvert x\n")
    with pytest.raises(ModelError) as info:
        refsim.load_model(path)
    assert info.value.line == 3


@pytest.mark.parametrize("suffix", [".ac", ".obj", ".stl"])
@pytest.mark.parametrize("kind", ["directory", "FIFO"])
def test_special_files_are_refused_without_opening_them(tmp_path, suffix, kind):
    path = tmp_path / f"model{suffix}"
    path.mkdir() if kind == "directory" else os.mkfifo(path)
    with pytest.raises(ModelError) as info:
        refsim.load_model(path)
    assert str(info.value) == f"{path}: not a regular file (a {kind})"


def test_an_obj_file_with_a_latin1_comment_loads(tmp_path):
    path = tmp_path / "tetra.obj"
    path.write_bytes(b"# caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
                     b"f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n")
    mesh = refsim.load_model(path)
    assert mesh.n_faces == 4 and mesh.is_convex


def test_a_bare_name_finds_a_bundled_model(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)                       # no cube.ac here
    assert refsim.load_model("cube.ac").n_faces == 12
    with pytest.raises(ModelError, match="no such file"):
        refsim.load_model("no-such-model.ac")


@pytest.mark.parametrize("suffix", [".ac", ".stl"])
def test_a_model_larger_than_its_limit_is_refused_unread(tmp_path, suffix):
    path = tmp_path / f"big{suffix}"
    with open(path, "wb") as file:
        file.truncate(MAX_MODEL_BYTES + 1)          # sparse: no disk used, nothing read
    with pytest.raises(ModelError) as info:
        refsim.load_model(path)
    assert str(info.value) == (f"{path}: file too large: more than {MAX_MODEL_BYTES} bytes "
                               "(refsim.limits)")


def test_a_name_too_long_to_look_up_is_one_model_error(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    name = "x" * 300 + ".ac"                         # beyond NAME_MAX: stat() fails
    with pytest.raises(ModelError) as info:
        refsim.load_model(name)
    assert str(info.value) == f"{name}: cannot read: File name too long"


def test_trimesh_reads_quietly_and_a_non_finite_vertex_is_one_error(tmp_path, caplog):
    # An ASCII STL with a stray token after a normal: trimesh tries it as
    # binary first, then as ASCII without the normals, and logs both
    # attempts' tracebacks; refsim's load prints nothing and keeps the triangle.
    ascii_stl = tmp_path / "t.stl"
    ascii_stl.write_text("solid t\nfacet normal 0 0 1 junk\nouter loop\nvertex 0 0 0\n"
                         "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n")
    assert refsim.load_model(ascii_stl).n_faces == 1
    assert [r.getMessage() for r in caplog.records] == []
    # A binary STL with an infinite coordinate: refused by Mesh; numpy's
    # warning about the NaN trimesh makes of it (inf * 0) stays inside.
    header = b"\0" * 80 + np.uint32(1).tobytes()
    triangle = np.array([0, 0, 1, np.inf, 0, 0, 1, 0, 0, 0, 1, 0], dtype="<f4").tobytes()
    nan_stl = tmp_path / "nan.stl"
    nan_stl.write_bytes(header + triangle + b"\0\0")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(ModelError, match="non-finite"):
            refsim.load_model(nan_stl)
    assert [str(w.message) for w in caught] == []


# -- a file loaded again -------------------------------------------------------------------


def test_the_same_file_loaded_again_is_the_same_mesh_with_its_trees(tmp_path):
    from refsim.collision import bvh

    path = tmp_path / "cube.ac"
    path.write_bytes((models_dir() / "cube.ac").read_bytes())
    first = load_model(path)
    tree = bvh.tree_of(first, "readable")
    again = load_model(path)
    assert again is first and bvh.tree_of(again, "readable") is tree
    assert load_model(path, weld_tolerance=1e-9) is not first


def test_new_bytes_at_the_same_path_are_read_again(tmp_path):
    path = tmp_path / "m.ac"
    path.write_bytes((models_dir() / "cube.ac").read_bytes())
    cube = load_model(path)
    path.write_bytes((models_dir() / "tetrahedron.ac").read_bytes())
    tetra = load_model(path)
    assert tetra is not cube and (cube.n_faces, tetra.n_faces) == (12, 4)


def test_the_same_bytes_at_another_path_name_their_own_file(tmp_path):
    a, b = tmp_path / "a.ac", tmp_path / "b.ac"
    for p in (a, b):
        p.write_bytes((models_dir() / "cube.ac").read_bytes())
    assert (load_model(a).source, load_model(b).source) == (str(a), str(b))


def test_only_the_last_meshes_loaded_are_kept(tmp_path):
    from refsim.models import loading

    cube = (models_dir() / "cube.ac").read_bytes()
    paths = []
    for i in range(loading.CACHED_MESHES + 1):
        paths.append(tmp_path / f"m{i}.ac")
        paths[-1].write_bytes(cube)
    meshes = [load_model(p) for p in paths]
    assert load_model(paths[-1]) is meshes[-1]         # kept
    assert load_model(paths[0]) is not meshes[0]       # the oldest was dropped
    assert len(loading._loaded) <= loading.CACHED_MESHES


def test_a_file_loaded_again_warns_again_at_the_callers_line(tmp_path):
    # a line surface (SURF type 1) in a cube: skipped, with a ModelWarning
    text = (models_dir() / "cube.ac").read_text()
    head, _, tail = text.partition("kids 0")
    numsurf = int(head.split("numsurf ")[1].split()[0])
    text = (head.replace(f"numsurf {numsurf}", f"numsurf {numsurf + 1}")
            + "SURF 0x1\nmat 0\nrefs 2\n0 0 0\n1 0 0\nkids 0" + tail)
    path = tmp_path / "cube-and-line.ac"
    path.write_text(text)
    for _ in range(2):
        with pytest.warns(refsim.ModelWarning, match="skipped 1 line surface") as said:
            load_model(path)
        assert [w.filename for w in said] == [__file__]
