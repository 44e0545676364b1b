"""The compiled build of the hierarchies (refsim.collision._numba_build)
gives the readable build's trees bit for bit: every array of the
triangle-aabb level's TriangleTree (least-area split) and of the exact
level's FrameTree (least-volume split, oriented node boxes, axes
deviation), on the bundled meshes and on generated ones: trimesh's
primitives, random convex hulls, a noisy blob, a flat mesh (signed zeros
in the node boxes), coincident triangles (ties in every ranking), and
meshes scaled far from 1 (the power-of-two scaling of the splits and the
axes)."""

from __future__ import annotations

import functools

import numpy as np
import pytest
import trimesh

from refsim.bundled import models_dir
from refsim.collision import bvh, bvh_exact
from refsim.models.loading import load_model
from refsim.models.mesh import Mesh

#: Bundled meshes, all but sphere-20k.ac, whose readable build alone takes
#: tens of seconds (its compiled build is compared in the benchmarks'
#: answers, tests/benchmarks/test_bench_tree_build.py).
BUNDLED = sorted(p.name for p in models_dir().glob("*.ac") if p.name != "sphere-20k.ac")

SEED = 20261202


def _blob(rng) -> trimesh.Trimesh:
    """An icosphere with each vertex moved radially by seeded noise."""
    sphere = trimesh.creation.icosphere(subdivisions=3)
    radii = 1.0 + 0.15 * rng.standard_normal(len(sphere.vertices))
    return trimesh.Trimesh(sphere.vertices * radii[:, None], sphere.faces, process=False)


def _flat_grid() -> trimesh.Trimesh:
    """A 7 x 5 grid of squares in the plane z = -0.0, two triangles each, at
    x <= 0: the nodes' points project to zeros of both signs along their
    normal, and some node boxes' centres get z = -0.0, others 0.0."""
    xs, ys = np.meshgrid(np.linspace(-2.0, 0.0, 8), np.linspace(-0.5, 0.5, 6), indexing="ij")
    vertices = np.column_stack([xs.ravel(), ys.ravel(), np.full(xs.size, -0.0)])
    index = np.arange(xs.size).reshape(xs.shape)
    a, b, c, d = index[:-1, :-1], index[1:, :-1], index[1:, 1:], index[:-1, 1:]
    faces = np.concatenate([np.column_stack([a.ravel(), b.ravel(), c.ravel()]),
                            np.column_stack([a.ravel(), c.ravel(), d.ravel()])])
    return trimesh.Trimesh(vertices, faces, process=False)


def _generated() -> dict[str, tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(SEED)
    meshes = {f"icosphere-{s}": trimesh.creation.icosphere(subdivisions=s) for s in range(4)}
    meshes.update({
        "torus": trimesh.creation.torus(major_radius=1.0, minor_radius=0.3),
        "capsule": trimesh.creation.capsule(height=2.0, radius=0.5),
        "cylinder": trimesh.creation.cylinder(radius=0.5, height=2.0, sections=17),
        "box": trimesh.creation.box(extents=(1.0, 2.0, 3.0)),
        "blob": _blob(rng),
        "flat-grid": _flat_grid(),
    })
    for n in (8, 60, 400):
        meshes[f"hull-{n}"] = trimesh.convex.convex_hull(rng.standard_normal((n, 3)))
    out = {name: (np.asarray(m.vertices, dtype=np.float64), np.asarray(m.faces, dtype=np.int64))
           for name, m in meshes.items()}
    # every triangle twice: equal centroids, ties broken by face index
    v, f = out["icosphere-1"]
    out["coincident"] = (v, np.concatenate([f, f[::-1]]))
    torus = out["torus"]
    # subnormal coordinates (the axes' scaling, 2**1040 or so, is beyond one
    # product by a normal power of two) and coordinates near 2**1000
    out["torus-tiny"] = (torus[0] * 2.0 ** -1040, torus[1])
    out["torus-huge"] = (torus[0] * 2.0 ** 1000, torus[1])
    return out


GENERATED = _generated()


def _mesh(name: str) -> Mesh:
    """A new Mesh each call: nothing built yet."""
    if name in GENERATED:
        vertices, faces = GENERATED[name]
        return Mesh(vertices, faces)
    model = load_model(models_dir() / name)
    return Mesh(model.vertices, model.faces)


def _arrays(tree: bvh.TriangleTree) -> list[np.ndarray]:
    return [tree.left, tree.right, tree.start, tree.count, tree.order]


def _assert_same_bits(readable, compiled, what):
    for r, c in zip(readable, compiled, strict=True):
        r, c = np.asarray(r), np.asarray(c)
        assert r.dtype == c.dtype and r.shape == c.shape, what
        assert r.tobytes() == c.tobytes(), what


@pytest.mark.parametrize("name", BUNDLED + sorted(GENERATED))
def test_compiled_build_equals_readable_build_bit_for_bit(name):
    readable_mesh, compiled_mesh = _mesh(name), _mesh(name)
    for tree_of in (bvh.tree_of, bvh_exact.frame_topology_of):
        _assert_same_bits(_arrays(tree_of(readable_mesh, "readable")),
                          _arrays(tree_of(compiled_mesh, "compiled")), (name, tree_of.__name__))
    readable = bvh_exact.frame_tree_of(readable_mesh, "readable")
    # on a mesh whose topology is built (above), and on a new one, where the
    # one compiled call builds topology, boxes and the packed arrays
    fresh_mesh = _mesh(name)
    for mesh in (compiled_mesh, fresh_mesh):
        compiled = bvh_exact.frame_tree_of(mesh, "compiled")
        _assert_same_bits([*_arrays(readable.tree), readable.links, readable.boxes,
                           readable.reach, readable.axes_deviation],
                          [*_arrays(compiled.tree), compiled.links, compiled.boxes,
                           compiled.reach, compiled.axes_deviation], name)
    _assert_same_bits(bvh_exact.pack_frame_tree(readable_mesh),
                      bvh_exact._kernel_arrays(fresh_mesh), (name, "packed"))


def test_the_cases_reach_what_they_are_there_for():
    """The flat grid's node boxes have centres with zeros of both signs; the
    coincident triangles tie in every ranking; the tori lie at the ends of
    float64's exponents."""
    boxes = bvh_exact.frame_tree_of(_mesh("flat-grid"), "compiled").boxes
    centre_z = boxes[:, 2]
    assert (centre_z == 0.0).all()
    assert np.signbit(centre_z).any() and not np.signbit(centre_z).all()
    tree = bvh_exact.frame_topology_of(_mesh("coincident"), "compiled")
    faces = GENERATED["coincident"][1]
    leaves = [tree.order[s:s + c]
              for s, c, left in zip(tree.start, tree.count, tree.left, strict=True) if left < 0]
    shared = sum(len({tuple(sorted(faces[i])) for i in leaf}) < len(leaf) for leaf in leaves)
    assert shared > 0                          # a leaf holds both copies of a triangle
    for name, exponent in (("torus-tiny", -1040), ("torus-huge", 1000)):
        reach = bvh_exact.frame_tree_of(_mesh(name), "compiled").reach
        assert np.frexp(reach)[1] - exponent in (0, 1)


def test_the_default_kernel_builds_the_compiled_tree_and_keeps_it():
    mesh = _mesh("torus.ac")
    frame = bvh_exact.frame_tree_of(mesh)
    assert bvh_exact.frame_tree_of(mesh, "readable") is frame      # built once per mesh
    assert bvh_exact.frame_topology_of(mesh) is frame.tree
    assert bvh.tree_of(mesh) is bvh.tree_of(mesh, "readable")


def test_an_unknown_split_rule_is_refused():
    from refsim.errors import OptionError

    vertices, faces = GENERATED["box"]
    with pytest.raises(OptionError, match="split must be one of"):
        bvh.build_tree_compiled(vertices, faces, "longest-axis")


def test_any_array_layout_builds_the_same_tree_by_one_compiled_signature():
    """build_tree_compiled takes arrays of any layout, dtype and writability
    (converted to a Mesh's: C-contiguous, float64 and int64, read-only), so
    numba compiles the build for one signature."""
    vertices, faces = GENERATED["hull-60"]
    expected = _arrays(bvh.build_tree(vertices, faces))
    for v, f in ((vertices, faces), (np.asfortranarray(vertices), faces.astype(np.int32)),
                 (vertices[::-1][::-1], faces[:, ::-1][:, ::-1])):
        _assert_same_bits(expected, _arrays(bvh.build_tree_compiled(v, f)), v.flags)
    assert len(bvh.build_kernels().build_tree_of.signatures) == 1


def test_the_compiled_split_ties_volumes_as_the_readable_one():
    assert bvh.build_kernels().VOLUME_TIE == bvh_exact.VOLUME_TIE


def test_both_builds_share_the_small_node_size():
    assert bvh.build_kernels().SMALL_NODE == bvh_exact.SMALL_NODE
    assert bvh.LEAF_SIZE < bvh_exact.SMALL_NODE < 1280


def test_large_nodes_split_as_before_and_small_ones_in_their_own_frame():
    """On icosphere-3 (1280 triangles, leaves of 4; nodes on both sides of
    SMALL_NODE, as in the meshes compared bit for bit above), each node of
    more than SMALL_NODE triangles puts the same triangles in its left child
    as the rule before (``small=0``: every half measured in its own frame),
    and some smaller node does not. (The topology arrays alone would not
    tell: every split is at the median, so they depend on the sizes only.)"""
    mesh = _mesh("icosphere-3")
    ours = bvh.build_tree(mesh.vertices, mesh.faces, split=bvh_exact.least_volume_split)
    before = bvh.build_tree(mesh.vertices, mesh.faces,
                            split=functools.partial(bvh_exact.least_volume_split, small=0))

    def left_members(tree, node):
        child = tree.left[node]
        return np.sort(tree.order[tree.start[child]:tree.start[child] + tree.count[child]])

    split = ours.left >= 0
    large = np.flatnonzero(split & (ours.count > bvh_exact.SMALL_NODE))
    small = np.flatnonzero(split & (ours.count <= bvh_exact.SMALL_NODE))
    assert len(large) > 10 and len(small) > 100
    for node in large:
        assert np.array_equal(left_members(ours, node), left_members(before, node)), node
    assert any(not np.array_equal(left_members(ours, node), left_members(before, node))
               for node in small)


def test_a_ring_is_cut_into_arcs_not_into_flat_rings():
    """A torus about z: cut across z (two flat rings, each as wide as the
    whole) or across x (two arcs) gives boxes of about the same total
    volume, and the area breaks the tie (bvh_exact.least_volume_split): the
    root's children are arcs, each holding triangles above and below the
    torus's mid-plane and lying on one side of the axis (the mean of the
    centroids' unit directions about z is about 2/pi long for a half ring,
    about 0 for a whole one)."""
    torus = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3, major_sections=32,
                                   minor_sections=16)
    mesh = Mesh(np.asarray(torus.vertices), np.asarray(torus.faces))
    for kernel in ("readable", "compiled"):
        tree = bvh_exact.frame_topology_of(Mesh(mesh.vertices, mesh.faces), kernel)
        centroids = mesh.vertices[mesh.faces].mean(axis=1)
        for child in (tree.left[0], tree.right[0]):
            members = tree.order[tree.start[child]:tree.start[child] + tree.count[child]]
            z = centroids[members, 2]
            assert z.min() < -0.2 and z.max() > 0.2, kernel     # the tube's whole section
            xy = centroids[members, :2]
            directions = xy / np.linalg.norm(xy, axis=1)[:, None]
            assert np.linalg.norm(directions.mean(axis=0)) > 0.5, kernel


@pytest.mark.parametrize("keys", ["normal", "ties, zeros of both signs and NaN"])
def test_the_ranking_merge_sort_gives_numpys_lexsort_order(keys):
    """merge_sort, the ranking's sort for the runs its buckets cannot split
    (and for keys with a NaN), puts any stretch of ``ranked`` in the order
    of ``np.lexsort((members, key))``: by key, a NaN last, ties by member."""
    nb = bvh.build_kernels()
    rng = np.random.default_rng(SEED)
    values = np.array([0.0, -0.0, 1.0, 2.0, np.nan, -1.5, 3.25])
    for _ in range(400):
        k = int(rng.integers(0, 70))
        key = rng.normal(size=k) if keys == "normal" else rng.choice(values, size=k)
        members = rng.permutation(1000)[:k].astype(np.intp)
        lo = int(rng.integers(0, k + 1))
        hi = int(rng.integers(lo, k + 1))
        ranked = rng.permutation(k).astype(np.intp)
        expected = ranked.copy()
        stretch = expected[lo:hi]
        expected[lo:hi] = stretch[np.lexsort((members[stretch], key[stretch]))]
        nb.merge_sort(np.ascontiguousarray(key), members, ranked, lo, hi)
        assert np.array_equal(ranked, expected), (k, lo, hi)
