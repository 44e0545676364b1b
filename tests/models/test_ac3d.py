"""The AC3D reader and writer (refsim.models.ac3d, seed S1)."""

from __future__ import annotations

import os
import warnings

import numpy as np
import pytest

from refsim.errors import ModelError, ModelWarning
from refsim.models.ac3d import format_ac3d, parse_ac3d, read_ac3d, write_ac3d
from refsim.models.mesh import Material, Mesh
from refsim.types import rotation_about_axis
from tests.helpers import assert_meshes_identical

REST = "amb 0.2 0.2 0.2  emis 0 0 0  spec 0.5 0.5 0.5  shi 10  trans 0"


def _write(tmp_path, text, name="model.ac", encoding="utf-8"):
    path = tmp_path / name
    path.write_bytes(text.encode(encoding) if isinstance(text, str) else text)
    return path


def _read_quiet(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning expected in these files
        return read_ac3d(path)


# -- transforms ------------------------------------------------------------------------

NESTED = f"""AC3Db
MATERIAL "red paint" rgb 1 0 0  {REST}
MATERIAL "blue" rgb 0 0 1  {REST}
OBJECT world
kids 1
OBJECT group
name "arm"
rot 0 1 0  -1 0 0  0 0 1
loc 10 0 0
kids 1
OBJECT poly
name "hand part"
rot 1 0 0  0 0 1  0 -1 0
loc 0 0 2
numvert 3
1 0 0
0 1 0
0 0 0
numsurf 1
SURF 0x10
mat 1
refs 3
0 0 0
1 1 0
2 0 1
kids 0
"""


def test_nested_rot_and_loc_compose_child_first(tmp_path):
    # world = R_arm (R_hand v + loc_hand) + loc_arm, where each rot's three
    # triples are the images of x, y and z:
    #   R_hand: x -> x, y -> z, z -> -y;   R_arm: x -> y, y -> -x, z -> z.
    # (1,0,0) -> (1,0,0) -> (1,0,2) -> (0,1,2) -> (10,1,2)
    # (0,1,0) -> (0,0,1) -> (0,0,3) -> (0,0,3) -> (10,0,3)
    # (0,0,0) -> (0,0,0) -> (0,0,2) -> (0,0,2) -> (10,0,2)
    mesh = _read_quiet(_write(tmp_path, NESTED))
    assert mesh.vertices.tolist() == [[10, 1, 2], [10, 0, 3], [10, 0, 2]]
    assert mesh.faces.tolist() == [[0, 1, 2]]
    assert mesh.objects == ("hand part",)  # world and group contribute no triangles
    assert mesh.face_object.tolist() == [0]
    assert mesh.face_material.tolist() == [1]
    assert mesh.face_flags.tolist() == [0x10]
    assert mesh.name == "model"
    assert mesh.source == str(tmp_path / "model.ac")


def test_rot_triples_are_the_images_of_the_axes():
    # Column-major in our convention: rot a b c  d e f  g h i  maps x to
    # (a, b, c). +90 degrees about z sends x to y and y to -x.
    text = """AC3Db
OBJECT poly
rot 0 1 0  -1 0 0  0 0 1
numvert 3
1 0 0
0 1 0
0 0 1
numsurf 1
SURF 0
refs 3
0 0 0
1 0 0
2 0 0
kids 0
"""
    mesh = parse_ac3d(text)
    assert mesh.vertices.tolist() == [[0, 1, 0], [-1, 0, 0], [0, 0, 1]]
    assert mesh.objects == ("poly",)  # an unnamed object is named by its type
    assert mesh.materials == (Material(),)  # no MATERIAL lines: the default palette


# -- polygons --------------------------------------------------------------------------

POLYGONS = """AC3Db
MATERIAL "" rgb 1 1 1  amb 0.2 0.2 0.2  emis 0 0 0  spec 0.5 0.5 0.5  shi 10  trans 0
OBJECT world
kids 1
OBJECT poly
name "plate"
numvert 10
0 0 0
2 0 0
2 1 0
1 1 0
1 2 0
0 2 0
5 0 0
6 0 0
6 1 0
5 1 0
numsurf 2
SURF 0x20
mat 0
refs 6
0 0 0
1 0 0
2 0 0
3 0 0
4 0 0
5 0 0
SURF 0x30
mat 0
refs 4
6 0 0
7 0 0
8 0 0
9 0 0
kids 0
"""


def test_quads_and_non_convex_polygons_are_triangulated(tmp_path):
    mesh = _read_quiet(_write(tmp_path, POLYGONS))
    assert mesh.n_faces == 4 + 2
    assert mesh.face_flags.tolist() == [0x20] * 4 + [0x30] * 2
    v = mesh.vertices[mesh.faces]
    normals = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    # both polygons run counter-clockwise seen from +z: so do their triangles
    assert (normals[:, 2] > 0).all()
    areas = 0.5 * np.linalg.norm(normals, axis=1)
    assert areas[:4].sum() == 3.0  # the L shape, exact in binary
    assert areas[4:].sum() == 1.0  # the unit quad
    # no triangle of the L joins (2,1) and (1,2): that diagonal leaves the L
    corners = {tuple(p) for p in mesh.vertices[mesh.faces[:4]].reshape(-1, 3).tolist()}
    assert len(corners) == 6
    for tri in mesh.vertices[mesh.faces[:4]].tolist():
        assert not ([2, 1, 0] in tri and [1, 2, 0] in tri)
    assert mesh.materials[0].name == ""


#: The 20 000 triangle areas are products of coordinates ~3 rotated with
#: relative rounding ~1e-16; their sum is good to ~k u = 2e-12 relative,
#: and a missing or doubled triangle would change it by 5e-5.
LARGE_POLYGON_AREA_RTOL = 1e-10


def test_a_polygon_of_20000_corners_is_read(tmp_path):
    # About 1 MB: one surface whose ear clipping the O(k^2) reference took
    # minutes over. A 20 000-gon approximating a circle of radius 3, tilted out of
    # the coordinate planes; its refs start at corner 5 and wrap around.
    k = 20_000
    t = 2.0 * np.pi * np.arange(k) / k
    points = np.column_stack([3.0 * np.cos(t), 3.0 * np.sin(t), np.zeros(k)])
    points = points @ rotation_about_axis([1.0, 2.0, 3.0], 0.7).T + np.array([1.0, -2.0, 0.5])
    refs = (np.arange(k) + 5) % k
    lines = ["AC3Db", f"MATERIAL \"\" rgb 1 1 1  {REST}", "OBJECT world", "kids 1",
             "OBJECT poly", 'name "disc"', f"numvert {k}"]
    lines += [f"{x!r} {y!r} {z!r}" for x, y, z in points.tolist()]
    lines += ["numsurf 1", "SURF 0x10", "mat 0", f"refs {k}"]
    lines += [f"{r} 0 0" for r in refs.tolist()]
    lines += ["kids 0", ""]
    path = _write(tmp_path, "\n".join(lines))
    assert path.stat().st_size > 1_000_000
    mesh = _read_quiet(path)
    assert mesh.n_faces == k - 2
    assert sorted(set(mesh.faces.ravel().tolist())) == list(range(k))
    v = mesh.vertices[mesh.faces]
    normals = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    axis = rotation_about_axis([1.0, 2.0, 3.0], 0.7)[:, 2]  # the disc's normal
    assert (normals @ axis > 0.0).all()  # every triangle turns the polygon's way
    # the areas add up to the 20 000-gon's, 0.5 k r^2 sin(2 pi / k), to rounding
    area = 0.5 * k * 9.0 * np.sin(2.0 * np.pi / k)
    assert 0.5 * np.linalg.norm(normals, axis=1).sum() == pytest.approx(
        area, rel=LARGE_POLYGON_AREA_RTOL)


def test_line_surfaces_are_skipped_with_a_warning(tmp_path):
    text = POLYGONS.replace("numsurf 2", "numsurf 4").replace("kids 0", """SURF 0x1
mat 0
refs 3
0 0 0
1 0 0
2 0 0
SURF 0x22
refs 2
7 0 0
8 0 0
kids 0""")
    path = _write(tmp_path, text)
    with pytest.warns(ModelWarning, match="skipped 2 line surface"):
        mesh = read_ac3d(path)
    assert mesh.n_faces == 6  # only the two polygons
    assert mesh.face_flags.tolist() == [0x20] * 4 + [0x30] * 2


# -- data, names, materials, leniency ------------------------------------------------------


def _one_triangle(extra_object_lines="", name='"t"'):
    return f"""AC3Db
OBJECT poly
name {name}
{extra_object_lines}numvert 3
0 0 0
1 0 0
0 1 0
numsurf 1
SURF 0x10
refs 3
0 0 0
1 0 0
2 0 0
kids 0
"""


@pytest.mark.parametrize("data", [
    "line one\nline two",           # embedded newline, count excludes the final one
    "kids 7\nnumvert 99\n",          # tokens inside the blob, count includes the newline
    "",                              # data 0
    "caf\u00e9 \u2713",               # non-ASCII: the count is UTF-8 bytes
])
def test_data_blocks_are_skipped_by_byte_count(tmp_path, data):
    n = len(data.encode("utf-8"))
    text = _one_triangle(f"data {n}\n{data}\n" if not data.endswith("\n")
                         else f"data {n}\n{data}")
    mesh = _read_quiet(_write(tmp_path, text))
    assert mesh.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    assert mesh.objects == ("t",)


def test_data_count_is_bytes_in_a_latin1_file(tmp_path):
    # Not UTF-8, so read as Latin-1: one byte per character.
    text = _one_triangle('data 6\n\u00c4rger!\n', name='"M\u00fcller"')
    mesh = _read_quiet(_write(tmp_path, text, encoding="latin-1"))
    assert mesh.objects == ("M\u00fcller",)


def test_quoted_names_with_spaces_and_materials_kept_verbatim(tmp_path):
    text = f"""AC3Db
MATERIAL "red paint" rgb 1 0 0.25  amb 0.1 0.2 0.3  emis 0 0 0  spec 1 1 1  shi 64  trans 0.5
MATERIAL plain rgb 0.5 0.5 0.5 {REST}
OBJECT world
kids 2
OBJECT poly
name "left  wing 1"
numvert 3
0 0 0
1 0 0
0 1 0
numsurf 1
SURF 0x10
mat 1
refs 3
0 0 0
1 0 0
2 0 0
kids 0
OBJECT poly
name "right wing"
numvert 3
0 0 1
1 0 1
0 1 1
numsurf 1
SURF 0x0
mat 0
refs 3
0 0 0
1 0 0
2 0 0
kids 0
"""
    mesh = _read_quiet(_write(tmp_path, text))
    assert mesh.materials == (
        Material("red paint", (1.0, 0.0, 0.25),
                 "amb 0.1 0.2 0.3  emis 0 0 0  spec 1 1 1  shi 64  trans 0.5"),
        Material("plain", (0.5, 0.5, 0.5), REST),
    )
    assert mesh.objects == ("left  wing 1", "right wing")
    assert mesh.face_material.tolist() == [1, 0]
    assert mesh.face_object.tolist() == [0, 1]
    # and the writer reproduces the MATERIAL lines' text
    out = format_ac3d(mesh)
    assert 'MATERIAL "red paint" rgb 1.0 0.0 0.25  amb 0.1 0.2 0.3  emis 0 0 0  spec 1 1 1  ' \
           'shi 64  trans 0.5\n' in out


def test_lenient_layout_crlf_bom_blank_lines_tabs_and_newer_tokens(tmp_path):
    text = ("\ufeffAC3Dc\r\n\r\n" + f"MATERIAL \"m\"\trgb 1 1 1   {REST}\r\n"
            "OBJECT world\r\n  kids 1\r\n\r\nOBJECT poly\r\n\tname \"t\"\r\n"
            "texture \"wood grain.png\"\r\ntexrep 1 1\r\ntexoff 0 0\r\nsubdiv 2\r\n"
            "crease 45.0\r\nfolded\r\nhidden\r\nlocked\r\nurl \"http://x\"\r\n"
            "numvert 3\r\n0   0 0\r\n\r\n1 0 0\r\n0 1\t0\r\nnumsurf 1\r\nSURF 16\r\n"
            "mat 0\r\nrefs 3\r\n0 0 0\r\n1 0.5 0\r\n2 0 0.5   \r\nkids 0\r\n\r\n")
    mesh = _read_quiet(_write(tmp_path, text))
    assert mesh.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    assert mesh.face_flags.tolist() == [16]
    assert mesh.materials[0].rest == REST


def test_deep_nesting_does_not_recurse(tmp_path):
    depth = 3000  # well past Python's default recursion limit of 1000
    lines = ["AC3Db"]
    for _ in range(depth):
        lines += ["OBJECT group", "loc 1 0 0", "kids 1"]
    lines += _one_triangle().split("\n")[1:]
    mesh = _read_quiet(_write(tmp_path, "\n".join(lines)))
    assert mesh.vertices[:, 0].tolist() == [3000.0, 3001.0, 3000.0]


# -- broken files ------------------------------------------------------------------------

BASE = f"""AC3Db
MATERIAL "m" rgb 1 1 1  {REST}
OBJECT world
kids 1
OBJECT poly
name "square"
loc 0 0 0
numvert 4
0 0 0
1 0 0
1 1 0
0 1 0
numsurf 1
SURF 0x20
mat 0
refs 4
0 0 0
1 1 0
2 1 1
3 0 1
kids 0
""".split("\n")  # 21 lines and a final empty string


def _variant(replace=None, cut=None, insert=None):
    lines = list(BASE)
    for k, text in sorted((replace or {}).items(), reverse=True):
        lines[k - 1:k] = text.split("\n") if text is not None else []
    if insert:
        k, text = insert
        lines[k:k] = text.split("\n")
    if cut is not None:
        lines = lines[:cut] + [""]
    return "\n".join(lines)


BROKEN = {
    "bad header": (_variant({1: "AC3X"}), 1),
    "missing header": (_variant({1: None}), 1),
    "header with a non-hex version": (_variant({1: "AC3Dz"}), 1),
    "unknown token": (_variant({7: "spin 1 2 3"}), 7),
    "unknown object type": (_variant({5: "OBJECT blob"}), 5),
    "bad material": (_variant({2: 'MATERIAL "m" rgb 1 1'}), 2),
    "unknown material field": (_variant({2: f'MATERIAL "m" rgb 1 1 1 {REST} glow 1'}), 2),
    "numvert too large": (_variant({8: "numvert 5"}), 13),  # 'numsurf 1' read as a vertex
    "non-numeric vertex": (_variant({10: "1 zero 0"}), 10),
    "non-finite vertex": (_variant({11: "1 inf 0"}), 11),
    "overflowing vertex": (_variant({11: "1 1e999 0"}), 11),
    "four coordinates": (_variant({12: "0 1 0 0"}), 12),
    "ref index out of range": (_variant({19: "7 1 1"}), 19),
    "negative ref index": (_variant({19: "-1 1 1"}), 19),
    "negative count": (_variant({13: "numsurf -1"}), 13),
    "polygon with two refs": (_variant({16: "refs 2", 19: None, 20: None}), 16),
    "material index out of range": (_variant({15: "mat 3"}), 15),
    "unknown surface type": (_variant({14: "SURF 0x23"}), 14),
    "bad flags": (_variant({14: "SURF twenty"}), 14),
    "unterminated quote": (_variant({6: 'name "square'}), 6),
    "duplicate numvert": (_variant({7: "numvert 0"}), 8),
    "truncated inside refs": (_variant(cut=18), 19),
    "truncated before kids": (_variant(cut=20), 21),
    "missing child object": (_variant({4: "kids 2"}), 22),
    "data count beyond end": (_variant(insert=(6, "data 5000\nblob")), 7),
    "text after data": (_variant(insert=(6, "data 2\nblob")), 8),
    "child that is not an object": (_variant({5: "MATERIAL \"x\" rgb 1 1 1"}), 5),
    "empty file": ("", 1),
}


@pytest.mark.parametrize("name", sorted(BROKEN))
def test_broken_files_name_the_line(tmp_path, name):
    text, line = BROKEN[name]
    path = _write(tmp_path, text)
    with pytest.raises(ModelError) as info:
        read_ac3d(path)
    err = info.value
    assert err.line == line, str(err)
    assert err.path == str(path)
    assert str(err).startswith(f"{path}:{line}: ")
    assert "\n" not in str(err)


def test_base_of_the_broken_variants_is_valid(tmp_path):
    mesh = _read_quiet(_write(tmp_path, _variant()))
    assert mesh.n_faces == 2 and mesh.n_vertices == 4


def test_file_without_triangles_is_an_error_without_a_line(tmp_path):
    path = _write(tmp_path, "AC3Db\nOBJECT world\nkids 0\n")
    with pytest.raises(ModelError, match="no polygon surfaces") as info:
        read_ac3d(path)
    assert info.value.line is None and info.value.path == str(path)


def test_missing_file_is_a_model_error(tmp_path):
    with pytest.raises(ModelError, match="no such file") as info:
        read_ac3d(tmp_path / "absent.ac")
    assert info.value.path == str(tmp_path / "absent.ac")


# -- writing ----------------------------------------------------------------------------


def _two_object_mesh():
    vertices = np.array([[0.1, 0.2, 0.3], [1e-300, -0.0, 1e300], [2.0 / 3.0, 5e-324, -1.5],
                         [np.pi, np.e, -7.0], [3.0, 4.0, 5.0]])
    faces = np.array([[0, 1, 2], [1, 3, 2], [2, 3, 4]])
    return Mesh(vertices, faces, face_material=[1, 0, 1], face_flags=[0x20, 0x10, 0x30],
                face_object=[0, 0, 1],
                materials=[Material("a b", (0.1, 0.2, 0.3), REST), Material()],
                objects=["first part", "second"])


def test_write_read_round_trip_is_exact(tmp_path):
    mesh = _two_object_mesh()
    path = tmp_path / "out.ac"
    write_ac3d(mesh, path)
    back = _read_quiet(path)
    assert_meshes_identical(mesh, back)
    assert path.read_text() == format_ac3d(mesh)
    # and again: the written file is a fixed point
    assert format_ac3d(back) == format_ac3d(mesh)


def test_writer_layout(tmp_path):
    text = format_ac3d(_two_object_mesh())
    lines = text.split("\n")
    assert lines[0] == "AC3Db"
    assert lines[3:6] == ["OBJECT world", "kids 2", "OBJECT poly"]
    assert lines[6] == 'name "first part"'
    assert lines[7] == "numvert 4"  # object 0 uses vertices 0..3, ascending
    assert lines[8:12] == ["0.1 0.2 0.3", "1e-300 -0.0 1e+300",
                           "0.6666666666666666 5e-324 -1.5",
                           "3.141592653589793 2.718281828459045 -7.0"]
    assert "SURF 0x20" in lines and text.count("kids 0") == 2
    assert text.endswith("kids 0\n")


def test_vertex_order_survives_when_a_later_object_uses_an_earlier_vertex():
    # Object 0 uses vertices 1..3, object 1 uses 0: the first object then
    # lists all vertices so that reading keeps the order.
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    f = np.array([[1, 2, 3], [0, 1, 2]])
    mesh = Mesh(v, f, face_object=[0, 1], objects=["a", "b"])
    assert_meshes_identical(mesh, parse_ac3d(format_ac3d(mesh)))


def test_empty_objects_and_duplicate_names_round_trip():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    mesh = Mesh(v, [[0, 1, 2]], face_object=[1], objects=["same", "same", "empty"])
    back = parse_ac3d(format_ac3d(mesh))
    assert_meshes_identical(mesh, back)


def test_unsorted_face_objects_are_regrouped_with_a_warning():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    f = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 1]])
    mesh = Mesh(v, f, face_object=[1, 0, 1], objects=["a", "b"])
    with pytest.warns(ModelWarning, match="not sorted"):
        text = format_ac3d(mesh)
    back = parse_ac3d(text)
    assert back.faces.tolist() == [[0, 2, 3], [0, 1, 2], [0, 3, 1]]
    assert back.face_object.tolist() == [0, 1, 1]


@pytest.mark.parametrize("kwargs, match", [
    ({"objects": ['say "hi"']}, "quote"),
    ({"materials": [Material("line\nbreak")]}, "line break"),
    ({"face_material": [2]}, "face_material out of range"),
    ({"face_object": [1]}, "face_object out of range"),
    ({"face_flags": [0x21]}, "face_flags"),
    ({"face_flags": [-16]}, "face_flags"),
    ({"materials": [Material(rest="glow 1")]}, "unknown MATERIAL field"),
    ({"materials": [Material(rgb=(1.0, float("nan"), 0.0))]}, "finite"),
])
def test_unwritable_meshes_raise_and_leave_no_file(tmp_path, kwargs, match):
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    mesh = Mesh(v, [[0, 1, 2]], **kwargs)
    path = tmp_path / "out.ac"
    path.write_text("old contents")
    with pytest.raises(ModelError, match=match):
        write_ac3d(mesh, path)
    assert path.read_text() == "old contents"
    assert os.listdir(tmp_path) == ["out.ac"]


def test_write_into_a_missing_directory_is_a_model_error(tmp_path):
    with pytest.raises(ModelError, match="cannot write") as info:
        write_ac3d(_two_object_mesh(), tmp_path / "nowhere" / "out.ac")
    assert info.value.path == str(tmp_path / "nowhere" / "out.ac")


def test_write_replaces_an_existing_file(tmp_path):
    path = tmp_path / "out.ac"
    path.write_text("old")
    os.chmod(path, 0o640)
    write_ac3d(_two_object_mesh(), path)
    assert path.read_text().startswith("AC3Db\n")
    assert os.stat(path).st_mode & 0o777 == 0o640
    assert os.listdir(tmp_path) == ["out.ac"]
