"""The shared-vertex Mesh (refsim.models.mesh, seed S1), checked against trimesh."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from refsim.errors import ModelError
from refsim.models.mesh import Material, Mesh
from refsim.models.triangulate import ear_clip

#: Volumes and centroids are sums over a few hundred triangles of products of
#: coordinates of size ~1: the two implementations round differently, by a
#: few hundred ulps at most. 1e-12 relative (and 1e-12 absolute for centroids
#: that are zero) is far tighter than any formula error would be.
MASS_RTOL = 1e-12
MASS_ATOL = 1e-12


def _tetrahedron():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    f = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    return v, f


def _cube():
    """Unit cube, two triangles a side, wound outward."""
    v = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    f = np.array([t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))])
    return v, f


def _l_prism(depth=0.5):
    """A non-convex L-shaped prism: ear-clipped caps and quad sides, off centre."""
    xy = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    k = len(xy)
    bottom = np.c_[xy, np.zeros(k)]
    top = np.c_[xy, np.full(k, depth)]
    v = np.vstack([bottom, top]) + np.array([3.0, -1.0, 0.25])
    cap = ear_clip(top)  # counter-clockwise seen from +z: the top faces up
    faces = [cap + k, cap[:, ::-1]]
    for i in range(k):
        j = (i + 1) % k
        faces.append(np.array([[i, j, j + k], [i, j + k, i + k]]))
    return v, np.concatenate(faces)


def _solids():
    """Closed shapes with trimesh's verdicts, by name."""
    ico = trimesh.creation.icosphere(subdivisions=2)
    torus = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3)
    rng = np.random.default_rng(7)
    hull = trimesh.convex.convex_hull(rng.normal(size=(60, 3)) + [0.5, -2.0, 1.0])
    return {
        "icosphere": (ico.vertices, ico.faces),
        "torus": (torus.vertices + [1.0, 2.0, 3.0], torus.faces),
        "random hull": (hull.vertices, hull.faces),
        "cube": _cube(),
        "L prism": _l_prism(),
        "tetrahedron": _tetrahedron(),
    }


# -- welding -------------------------------------------------------------------------------


def test_exact_weld_merges_equal_vertices_to_the_lowest_index():
    # a triangle soup of two triangles sharing an edge
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    mesh = Mesh(v, [[0, 1, 2], [3, 4, 5]])
    assert mesh.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]
    assert mesh.faces.tolist() == [[0, 1, 2], [1, 3, 2]]


def test_exact_weld_treats_negative_zero_as_zero():
    v = np.array([[0.0, 0.0, 0.0], [1, 0, 0], [0, 1, 0], [-0.0, 0.0, -0.0], [0, 0, 1]])
    mesh = Mesh(v, [[0, 1, 2], [3, 1, 4]])
    assert mesh.n_vertices == 4
    assert mesh.faces.tolist() == [[0, 1, 2], [0, 1, 3]]
    # the representative keeps its own bits: vertex 0 was +0.0
    assert not np.signbit(mesh.vertices[0]).any()


def test_exact_weld_and_edges_are_numpys_unique_of_the_rows():
    """The weld ranks rows by lexsort and the edges are unique 1-d keys;
    both give what np.unique of the rows (axis=0) defines: each vertex
    welded to the lowest index of its equal rows, edges in row order.
    Seeded soup: 600 triangles over 150 points drawn from a 5 x 5 x 5 grid,
    so that many rows repeat and others tie in one or two coordinates,
    half of the zeros negative."""
    rng = np.random.default_rng(11)
    points = rng.integers(-2, 3, size=(150, 3)).astype(float)
    points[rng.random(points.shape) < 0.5] *= -1.0             # -0.0 among the zeros
    faces = rng.integers(0, len(points), size=(600, 3))
    mesh = Mesh(points, faces)
    canonical = points + 0.0
    _, first, inverse = np.unique(canonical, axis=0, return_index=True, return_inverse=True)
    welded = first[inverse.ravel()][faces]
    used = np.unique(welded)
    assert np.array_equal(mesh.vertices, points[used])
    assert np.array_equal(mesh.faces, np.searchsorted(used, welded))
    f = mesh.faces
    pairs = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
    assert np.array_equal(mesh.edges, np.unique(pairs[pairs[:, 0] != pairs[:, 1]], axis=0))
    assert len(mesh.edges) > 500 and mesh.n_vertices < len(points)   # some rows welded


def test_exact_weld_keeps_nearby_vertices_apart():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [np.nextafter(1.0, 2.0), 0, 0], [1, 1, 0]])
    mesh = Mesh(v, [[0, 1, 2], [3, 4, 2]])
    assert mesh.n_vertices == 5


def test_tolerance_weld_is_transitive_and_keeps_the_first_position():
    # 0 -- 0.6e-3 -- 1.2e-3 along x: neighbours are within 1e-3, the ends are
    # not, yet all three merge (transitively) at the lowest index's position.
    v = np.array([[0, 0, 0], [0.6e-3, 0, 0], [1.2e-3, 0, 0], [1, 0, 0], [0, 1, 0]])
    mesh = Mesh(v, [[0, 3, 4], [1, 3, 4], [2, 3, 4]], weld_tolerance=1e-3)
    assert mesh.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    assert mesh.faces.tolist() == [[0, 1, 2]] * 3
    assert Mesh(v, [[0, 3, 4], [1, 3, 4], [2, 3, 4]]).n_vertices == 5


@pytest.mark.parametrize("scale", [1e300, 1e-300, 1.0])
def test_tolerance_weld_is_the_same_at_every_scale(scale):
    # the same points and tolerance, scaled: the same merges (squared
    # distances of 1e300 coordinates overflowed in the k-d tree: a fuzz finding)
    v = np.array([[0, 0, 0], [0.6e-3, 0, 0], [1.2e-3, 0, 0], [1, 0, 0], [0, 1, 0]]) * scale
    mesh = Mesh(v, [[0, 3, 4], [1, 3, 4], [2, 3, 4]], weld_tolerance=1e-3 * scale)
    assert mesh.n_vertices == 3 and mesh.faces.tolist() == [[0, 1, 2]] * 3
    apart = Mesh(v, [[0, 3, 4], [1, 3, 4], [2, 3, 4]], weld_tolerance=5e-324)
    assert apart.n_vertices == 5                           # the smallest tolerance joins none
    everything = Mesh(v, [[0, 3, 4]], weld_tolerance=1e308)
    assert everything.n_vertices == 1                      # the largest joins all


def test_unreferenced_vertices_are_dropped_in_order():
    v = np.array([[9, 9, 9], [0, 0, 0], [8, 8, 8], [1, 0, 0], [0, 1, 0], [7, 7, 7]], float)
    mesh = Mesh(v, [[1, 3, 4]])
    assert mesh.vertices.tolist() == [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    assert mesh.faces.tolist() == [[0, 1, 2]]


def test_per_face_data_and_defaults():
    v, f = _tetrahedron()
    mesh = Mesh(v, f, face_material=[0, 1, 1, 0], face_flags=[0x20] * 4,
                face_object=[0, 0, 1, 1], materials=[Material("a"), Material("b")],
                objects=["x", "y"], name="tet")
    assert mesh.face_material.tolist() == [0, 1, 1, 0]
    assert mesh.face_flags.tolist() == [0x20] * 4
    assert mesh.objects == ("x", "y")
    assert [m.name for m in mesh.materials] == ["a", "b"]
    plain = Mesh(v, f, name="tet")
    assert plain.face_material.tolist() == [0] * 4
    assert plain.materials == (Material(),)
    assert plain.objects == ("tet",)
    assert not plain.vertices.flags.writeable and not plain.faces.flags.writeable


# -- neighbours ------------------------------------------------------------------------------


def _neighbours_by_loops(faces, n):
    """Independent reference: vertex -> sorted set of vertices sharing an edge."""
    out = [set() for _ in range(n)]
    for tri in faces.tolist():
        for a in tri:
            for b in tri:
                if a != b:
                    out[a].add(b)
    return [sorted(s) for s in out]


def test_tetrahedron_neighbours_are_the_other_three():
    mesh = Mesh(*_tetrahedron())
    assert [nb.tolist() for nb in mesh.neighbors] == [[1, 2, 3], [0, 2, 3], [0, 1, 3],
                                                      [0, 1, 2]]
    assert mesh.edges.shape == (6, 2)


def test_cube_neighbours_edges_and_diagonals():
    v, f = _cube()
    mesh = Mesh(v, f)
    got = [nb.tolist() for nb in mesh.neighbors]
    assert got == _neighbours_by_loops(mesh.faces, 8)
    # 12 cube edges + 6 face diagonals; Euler: V - E + F = 8 - 18 + 12 = 2
    assert len(mesh.edges) == 18
    # corner 0 is joined to its 3 cube neighbours 1, 2, 4 and to the
    # diagonals its three faces chose: (0,3), (0,5) and (0,6)
    assert got[0] == [1, 2, 3, 4, 5, 6]
    # every neighbour differs from its vertex in one coordinate (an edge) or
    # two (a face diagonal), never three (the body diagonal)
    for i, nb in enumerate(got):
        for j in nb:
            assert 1 <= np.abs(v[i] - v[j]).sum() <= 2
    assert mesh.neighbor_offsets[-1] == 2 * 18


def test_neighbours_match_loops_on_a_torus():
    t = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3)
    mesh = Mesh(t.vertices, t.faces)
    assert [nb.tolist() for nb in mesh.neighbors] == _neighbours_by_loops(mesh.faces,
                                                                          mesh.n_vertices)
    assert {len(nb) for nb in mesh.neighbors} == {6}  # a regular torus grid


# -- closedness, convexity, mass properties vs trimesh -----------------------------------


@pytest.mark.oracle
@pytest.mark.parametrize("name", sorted(_solids()))
def test_closed_and_convex_agree_with_trimesh(name):
    v, f = _solids()[name]
    mesh = Mesh(v, f)
    reference = trimesh.Trimesh(v, f, process=False)
    assert mesh.is_closed == reference.is_watertight is True
    assert mesh.is_convex == reference.is_convex
    assert mesh.is_convex == (name not in ("torus", "L prism"))


@pytest.mark.oracle
def test_cube_with_a_face_removed_is_open():
    v, f = _cube()
    mesh = Mesh(v, f[2:])
    reference = trimesh.Trimesh(v, f[2:], process=False)
    assert mesh.is_closed is False and reference.is_watertight is False
    assert mesh.is_convex is False and reference.is_convex is False
    assert mesh.volume is None and mesh.centroid_volume is None


def test_flipped_face_is_not_closed():
    v, f = _cube()
    f = f.copy()
    f[0] = f[0, ::-1]
    assert Mesh(v, f).is_closed is False


@pytest.mark.oracle
@pytest.mark.parametrize("name", sorted(_solids()))
def test_volume_and_volume_centroid_agree_with_trimesh(name):
    v, f = _solids()[name]
    mesh = Mesh(v, f)
    reference = trimesh.Trimesh(v, f, process=False)
    assert mesh.volume == pytest.approx(reference.volume, rel=MASS_RTOL)
    assert mesh.centroid_volume == pytest.approx(reference.center_mass, rel=MASS_RTOL,
                                                 abs=MASS_ATOL)


def test_exact_volumes_and_centroids():
    cube = Mesh(*_cube())
    assert cube.volume == pytest.approx(1.0, rel=1e-15)
    assert cube.centroid_volume.tolist() == pytest.approx([0.5, 0.5, 0.5], rel=1e-15)
    tet = Mesh(*_tetrahedron())
    assert tet.volume == pytest.approx(1.0 / 6.0, rel=1e-15)
    assert tet.centroid_volume.tolist() == pytest.approx([0.25] * 3, rel=1e-15)
    l_prism = Mesh(*_l_prism(depth=0.5))
    assert l_prism.volume == pytest.approx(1.5, rel=1e-14)  # area 3 x depth 0.5
    # L = [0,2]x[0,1] (area 2, centre (1, .5)) + [0,1]x[1,2] (area 1, centre (.5, 1.5))
    expected = np.array([(2 * 1 + 0.5) / 3, (2 * 0.5 + 1.5) / 3, 0.25]) + [3.0, -1.0, 0.25]
    assert l_prism.centroid_volume == pytest.approx(expected, rel=1e-14)


def test_inward_winding_gives_negative_volume_and_not_convex():
    v, f = _cube()
    mesh = Mesh(v, f[:, ::-1])
    assert mesh.is_closed
    assert mesh.volume == pytest.approx(-1.0)
    assert mesh.is_convex is False


def test_vertex_average_centroid_is_the_seeds_centroid():
    # The L prism: vertex average differs from the volume centroid.
    v, f = _l_prism()
    mesh = Mesh(v, f)
    assert mesh.centroid_vertex_average.tolist() == pytest.approx(v.mean(axis=0).tolist())
    assert not np.allclose(mesh.centroid_vertex_average, mesh.centroid_volume)
    # welding first: a soup's duplicated corners do not weigh more
    soup = v[f].reshape(-1, 3)
    welded = Mesh(soup, np.arange(len(soup)).reshape(-1, 3))
    assert welded.centroid_vertex_average.tolist() == pytest.approx(v.mean(axis=0).tolist())


def test_bounds():
    mesh = Mesh(*_l_prism())
    lo, hi = mesh.bounds
    assert lo.tolist() == [3.0, -1.0, 0.25] and hi.tolist() == [5.0, 1.0, 0.75]


# -- degenerate and bad input --------------------------------------------------------------


def test_degenerate_faces_are_reported():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]], float)
    # face 1: collinear corners; face 2: a repeated vertex
    mesh = Mesh(v, [[0, 1, 2], [0, 1, 3], [1, 1, 2]])
    assert mesh.degenerate_faces.tolist() == [1, 2]
    assert mesh.face_areas.tolist() == [0.5, 0.0, 0.0]
    # a repeated index is no edge: vertex 1 is not its own neighbour
    assert 1 not in mesh.neighbors[1].tolist()


@pytest.mark.parametrize("vertices, faces, kwargs, match", [
    ([[0, 0, np.nan], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {}, "non-finite"),
    ([[0, 0, np.inf], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {}, "non-finite"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 3]], {}, "out of range"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, -1, 2]], {}, "out of range"),
    ([[0, 0], [1, 0], [0, 1]], [[0, 1, 2]], {}, r"shape \(n, 3\)"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2, 0]], {}, r"shape \(m, 3\)"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.zeros((0, 3), int), {}, "m >= 1"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0.0, 1.0, 2.0]], {}, "integers"),
    ([[0, 0, 0], [1, 0], [0, 1, 0]], [[0, 1, 2]], {}, "numeric"),
    ([["a", "b", "c"], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {}, "numeric"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {"weld_tolerance": -1.0}, "weld"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {"weld_tolerance": np.nan}, "weld"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {"weld_tolerance": None}, "weld"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {"face_flags": [1, 2]}, "shape"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {"face_material": [np.nan]}, "integer"),
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]], {"face_object": ["x"]}, "integer"),
])
def test_bad_input_raises_model_error(vertices, faces, kwargs, match):
    with pytest.raises(ModelError, match=match) as info:
        Mesh(vertices, faces, source="shape.obj", **kwargs)
    assert info.value.path == "shape.obj"


def test_tolerance_weld_joins_no_points_farther_apart_than_the_tolerance():
    # coordinates from 0 to 1e300: in unit coordinates the 1e130 distances
    # square to 0 in the k-d tree; the distance check keeps them apart
    v = np.array([[1e300, 0, 0], [0, 0, 0], [1e130, 0, 0], [0, 1e130, 0], [0, 0, 1e130]])
    mesh = Mesh(v, [[1, 2, 3], [1, 3, 4], [0, 2, 3]], weld_tolerance=1e-6)
    assert mesh.n_vertices == 5
