"""The exact level's hierarchy query in the first body's frame
(refsim.collision.bvh_exact): the compiled traversal hands the exact test the
same candidates as the readable one, the candidates lie between the exact
pairs and test 2's pairs, the node margin is both needed and enough, and bad
poses are rejected as everywhere else."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.bundled import models_dir
from refsim.collision import bvh_exact
from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.collision.boxes import world_vertices
from refsim.collision.seed_levels import exact_pairs, triangle_box_pairs
from refsim.errors import StateError
from refsim.models import shapes
from refsim.models.loading import load_model
from refsim.models.mesh import Mesh
from refsim.types import ORTHONORMAL_TOL, random_rotation

SPHERE = load_model(models_dir() / "sphere-2k.ac")
TORUS = load_model(models_dir() / "torus.ac")
STAR = load_model(models_dir() / "star.ac")
CUBE = load_model(models_dir() / "cube.ac")                 # the unit cube about the origin
IDENTITY = (np.eye(3), np.zeros(3))

#: (mesh a, mesh b, spread of b's random translation): overlapping, grazing
#: and separated poses all occur.
PAIRS = [(SPHERE, SPHERE, 1.5), (TORUS, TORUS, 1.5), (STAR, TORUS, 1.0),
         (shapes.geodesic_sphere(1), STAR, 1.2)]


def _poses(seed, n, spread):
    rng = np.random.default_rng(seed)
    return [((random_rotation(rng), rng.uniform(-spread, spread, 3)),
             (random_rotation(rng), rng.uniform(-spread, spread, 3))) for _ in range(n)]


def _seed_pairs(mesh_a, pose_a, mesh_b, pose_b):
    """Test 2's pairs and the exact pairs, by the seed's pairwise path."""
    world_a, world_b = world_vertices(mesh_a, pose_a), world_vertices(mesh_b, pose_b)
    boxes = triangle_box_pairs(world_a, mesh_a.faces, world_b, mesh_b.faces)
    return boxes, exact_pairs(world_a, mesh_a.faces, world_b, mesh_b.faces, boxes)


def _as_set(pairs):
    return set(map(tuple, np.asarray(pairs).tolist()))


def test_the_readable_node_test_is_the_compiled_kernels_arithmetic_bit_for_bit():
    """The readable node test against the compiled query's helpers run as
    plain Python (``py_func``; the helpers they call are numba's): node b
    placed in a's frame, the pair's frame row by row, a pose's deviation,
    and the fifteen axes' verdict at the very margin where the compiled
    verdict turns (found by bisecting the margin's bits) and one ulp above
    it, so that a sum taken in another order would show."""
    from refsim.collision import _numba_kernels as nk

    def bits(x: float) -> int:
        return int(np.float64(x).view(np.int64))

    def from_bits(n: int) -> float:
        return float(np.int64(n).view(np.float64))

    rng = np.random.default_rng(31)
    edges = 0
    for _ in range(300):
        rotation = random_rotation(rng) + rng.normal(scale=1e-9, size=(3, 3))   # off by rounding
        M = rotation.tolist()
        box_a, box_b = (np.concatenate([rng.normal(size=3), rng.uniform(0.1, 1.0, 3),
                                        random_rotation(rng).ravel()]).tolist()
                        for _ in range(2))
        # b's centre lands within about two half-extents of a's: the boxes
        # are near touching
        u = (np.array(box_a[:3]) - rotation @ box_b[:3] + rng.normal(size=3)).tolist()
        p, P = bvh_exact.place(box_b, M, u)
        placed = np.empty((1, 12))
        nk.place.py_func(np.array([box_b]), np.array(M), np.array(u), 0, placed)
        assert [*p, *P[0], *P[1], *P[2]] == placed[0].tolist()

        T, R = bvh_exact.node_pair_frame(box_a, p, P)
        A = tuple(tuple(box_a[6 + 3 * r:9 + 3 * r]) for r in range(3))
        d = (p[0] - box_a[0], p[1] - box_a[1], p[2] - box_a[2])
        for i in range(3):
            t, r = nk.frame_row.py_func(A, i, d, tuple(map(tuple, P)))
            assert (T[i], R[i]) == (t, list(r))
        assert bvh_exact.deviation(rotation) == nk.pose_deviation.py_func(
            rotation, np.zeros(3), 1.0)

        h, g = box_a[3:6], box_b[3:6]

        node_a, node_b = (tuple(box_a[:3]), tuple(h), A), (tuple(p), tuple(map(tuple, P)),
                                                           tuple(g))

        def compiled(margin, node_a=node_a, node_b=node_b):
            return nk.node_boxes_apart.py_func(*node_a, *node_b, margin)

        if not compiled(0.0):
            continue                                 # overlapping: no margin turns it
        low, high = bits(0.0), bits(16.0)
        assert not compiled(16.0)
        while high - low > 1:                        # the largest margin still apart
            middle = (low + high) // 2
            low, high = (middle, high) if compiled(from_bits(middle)) else (low, middle)
        assert bvh_exact.boxes_apart(T, R, h, g, from_bits(low)) is True
        assert bvh_exact.boxes_apart(T, R, h, g, from_bits(high)) is False
        edges += 1
    assert edges > 100


@pytest.mark.parametrize("mesh_a, mesh_b, spread", PAIRS, ids=lambda x: getattr(x, "name", x))
def test_candidates_compiled_equal_readable_and_lie_between_exact_and_test2(
        mesh_a, mesh_b, spread):
    touching = 0
    for pose_a, pose_b in _poses(7, 5, spread):
        readable = bvh_exact.candidate_pairs(mesh_a, pose_a, mesh_b, pose_b)
        compiled, uncertain = bvh_exact.query_compiled(mesh_a, pose_a, mesh_b, pose_b,
                                                       bvh_exact.CANDIDATES)
        assert len(uncertain) == 0
        assert np.array_equal(bvh_exact._sorted(compiled), readable)
        boxes, exact = _seed_pairs(mesh_a, pose_a, mesh_b, pose_b)
        assert _as_set(exact) <= _as_set(readable) <= _as_set(boxes)
        for kernel in ("compiled", "readable"):
            assert np.array_equal(intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b,
                                                     kernel=kernel), exact), kernel
            assert bodies_collide(mesh_a, pose_a, mesh_b, pose_b, kernel=kernel) == (
                len(exact) > 0), kernel
        touching += len(exact) > 0
    assert touching >= 1          # the poses test contact, not only misses


def test_the_node_test_drops_test2_pairs_of_rotated_bodies():
    """With the second body rotated, the oriented node boxes drop pairs that
    test 2's world boxes keep (the separated torus benchmark pose)."""
    from refsim.studies.levels import SPEED_CONFIGURATIONS

    config = next(c for c in SPEED_CONFIGURATIONS
                  if c.model == "torus" and c.kind == "separated-boxes-overlap")
    (mesh_a, mesh_b), (pose_a, pose_b) = (config.as_configuration().meshes(),
                                          config.as_configuration().poses())
    boxes, exact = _seed_pairs(mesh_a, pose_a, mesh_b, pose_b)
    candidates = bvh_exact.candidate_pairs(mesh_a, pose_a, mesh_b, pose_b)
    assert len(exact) == 0 and len(candidates) < len(boxes)


def _scaled_cubes():
    """Cube a at the origin with rotation (1 + e) I, a pose as_pose accepts
    (R^T R - I = 2e + e^2 < ORTHONORMAL_TOL); cube b unrotated at x = 1 + e/4.
    World a reaches x = 0.5 + e/2 and b starts at 0.5 + e/4: they overlap by
    e/4 (all exact in binary). In a's frame, taking Ra^T for Ra's inverse,
    the node boxes look e * 3/4 apart along x."""
    e = 2.0 ** -22
    assert 2 * e + e * e < ORTHONORMAL_TOL
    pose_a = ((1.0 + e) * np.eye(3), np.zeros(3))
    pose_b = (np.eye(3), np.array([1.0 + e / 4, 0.0, 0.0]))
    return pose_a, pose_b


def test_margin_is_needed_for_rotations_off_orthonormal():
    pose_a, pose_b = _scaled_cubes()
    _, exact = _seed_pairs(CUBE, pose_a, CUBE, pose_b)
    assert len(exact) > 0
    zero = dict(margin_rounding=0.0, margin_per_deviation=0.0)
    assert len(bvh_exact.candidate_pairs(CUBE, pose_a, CUBE, pose_b, **zero)) == 0
    found, uncertain = bvh_exact.query_compiled(CUBE, pose_a, CUBE, pose_b,
                                                bvh_exact.ALL_HITS, **zero)
    assert len(found) == 0 and len(uncertain) == 0            # the pairs are lost ...
    for kernel in ("compiled", "readable"):                       # ... and found with the margin
        assert np.array_equal(intersecting_pairs(CUBE, pose_a, CUBE, pose_b, kernel=kernel),
                              exact)


def test_margin_is_enough_near_touching_with_rotations_at_the_tolerance():
    """Two cubes face to face, each rotation a random rotation made
    non-orthonormal by a random perturbation of up to 0.15 ORTHONORMAL_TOL per
    entry, moved apart along the shared face normal by gaps and depths from
    1e-4 down to 1e-12: the same pairs as the seed's path every time. (The
    perturbation keeps R^T R - I below the tolerance, checked below.)"""
    rng = np.random.default_rng(21)
    checked = hits = 0
    for _ in range(6):
        rotation = random_rotation(rng)
        rotation_a = rotation + rng.uniform(-0.15, 0.15, (3, 3)) * ORTHONORMAL_TOL
        rotation_b = rotation + rng.uniform(-0.15, 0.15, (3, 3)) * ORTHONORMAL_TOL
        for offset in (1e-4, 1e-8, 1e-12, -1e-12, -1e-8, -1e-4):
            pose_a = (rotation_a, np.zeros(3))
            pose_b = (rotation_b, (1.0 + offset) * rotation[:, 0])   # unit cubes
            assert max(bvh_exact.deviation(rotation_a), bvh_exact.deviation(rotation_b)) > 1e-8
            _, exact = _seed_pairs(CUBE, pose_a, CUBE, pose_b)
            for kernel in ("compiled", "readable"):
                got = intersecting_pairs(CUBE, pose_a, CUBE, pose_b, kernel=kernel)
                assert np.array_equal(got, exact), (offset, kernel)
            checked += 1
            hits += len(exact) > 0
    assert checked == 36 and hits >= 6


def _fresh(name: str) -> Mesh:
    """A new Mesh of a bundled model, with its own derived structures
    (load_model gives every caller the same Mesh): the tests below plant
    trees built along perturbed axes in it."""
    loaded = load_model(models_dir() / name)
    return Mesh(loaded.vertices, loaded.faces, name=loaded.name)


def test_margin_is_needed_for_node_axes_off_orthonormal():
    """Every node's axes (1 - e) I (deviation 2e - e^2, within the tolerance):
    the node test then takes each box of b for (1 - e)^2 of its size, and two
    cubes overlapping by e/4 along x look apart by nearly 3e/4. The margin's
    deviation term finds the pairs again."""
    e = 2.0 ** -22
    cube = _fresh("cube.ac")
    frame = cube.derived("frame_tree", lambda m: bvh_exact.build_frame_tree(
        m, lambda points: (1.0 - e) * np.eye(3)))
    assert frame.axes_deviation == 2 * e - e * e
    pose_b = (np.eye(3), np.array([1.0 - e / 4, 0.0, 0.0]))
    _, exact = _seed_pairs(cube, IDENTITY, cube, pose_b)
    assert len(exact) > 0
    found, uncertain = bvh_exact.query_compiled(cube, IDENTITY, cube, pose_b,
                                                bvh_exact.ALL_HITS, margin_per_deviation=0.0)
    assert len(found) == 0 and len(uncertain) == 0            # the pairs are lost ...
    assert len(bvh_exact.candidate_pairs(cube, IDENTITY, cube, pose_b,
                                         margin_per_deviation=0.0)) == 0
    for kernel in ("compiled", "readable"):                       # ... and found with the margin
        assert np.array_equal(intersecting_pairs(cube, IDENTITY, cube, pose_b, kernel=kernel),
                              exact)


def test_margin_is_enough_with_node_axes_off_orthonormal():
    """Node boxes along axes perturbed by up to 0.15 ORTHONORMAL_TOL per entry
    (the margin counts the axes' deviation like a rotation's): cubes face to
    face at gaps and depths from 1e-4 to 1e-12, and random torus poses, give
    the seed's pairs."""
    rng = np.random.default_rng(5)

    def perturbed(points):
        return (bvh_exact.principal_axes(points)
                + rng.uniform(-0.15, 0.15, (3, 3)) * ORTHONORMAL_TOL)

    cube, torus = _fresh("cube.ac"), _fresh("torus.ac")
    for mesh in (cube, torus):
        frame = mesh.derived("frame_tree", lambda m: bvh_exact.build_frame_tree(m, perturbed))
        assert bvh_exact.frame_tree_of(mesh) is frame and frame.axes_deviation > 1e-8
    hits = 0
    cases = [(cube, cube, (rotation, np.zeros(3)), (rotation, (1.0 + offset) * rotation[:, 0]))
             for rotation in (random_rotation(rng) for _ in range(3))
             for offset in (1e-4, 1e-8, 1e-12, -1e-12, -1e-8, -1e-4)]
    cases += [(torus, torus, pa, pb) for pa, pb in _poses(9, 6, 1.5)]
    for mesh_a, mesh_b, pose_a, pose_b in cases:
        _, exact = _seed_pairs(mesh_a, pose_a, mesh_b, pose_b)
        for kernel in ("compiled", "readable"):
            got = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, kernel=kernel)
            assert np.array_equal(got, exact), kernel
        hits += len(exact) > 0
    assert hits >= 12


def test_touching_pairs_go_through_the_exact_stage():
    """Cubes sharing a face: every float certificate fails, the pairs come
    back uncertain and the exact stage answers them (the compiled one,
    tests/collision/test_numba_exact.py)."""
    touching = (np.eye(3), np.array([1.0, 0.0, 0.0]))
    found, uncertain = bvh_exact.query_compiled(CUBE, IDENTITY, CUBE, touching,
                                                bvh_exact.ALL_HITS)
    assert len(uncertain) > 0
    _, exact = _seed_pairs(CUBE, IDENTITY, CUBE, touching)
    assert len(exact) > 0
    assert np.array_equal(intersecting_pairs(CUBE, IDENTITY, CUBE, touching), exact)
    assert bodies_collide(CUBE, IDENTITY, CUBE, touching)


def test_poses_in_other_forms_give_the_same_answer():
    rng = np.random.default_rng(4)
    # the star's centre on the torus's tube circle: they cross in any orientation
    rotation, translation = random_rotation(rng), np.array([0.9, 0.1, -0.4])
    expected = intersecting_pairs(TORUS, IDENTITY, STAR, (rotation, translation))
    assert len(expected) > 0
    for pose in [(rotation.tolist(), translation.tolist()),          # through as_pose
                 [rotation, translation],
                 (np.asfortranarray(rotation), translation)]:
        assert np.array_equal(intersecting_pairs(TORUS, IDENTITY, STAR, pose), expected)
    # float32 arrays are converted, not read as float64 bit patterns
    single = (rotation.astype(np.float32), translation.astype(np.float32))
    widened = (single[0].astype(np.float64), single[1].astype(np.float64))
    assert np.array_equal(intersecting_pairs(TORUS, IDENTITY, STAR, single),
                          intersecting_pairs(TORUS, IDENTITY, STAR, widened, method="seed"))


@pytest.mark.parametrize("bad, message", [
    ((np.eye(3), np.array([np.nan, 0.0, 0.0])), "pose_b: non-finite"),
    ((np.full((3, 3), np.inf), np.zeros(3)), "pose_b: non-finite"),
    ((2.0 * np.eye(3), np.zeros(3)), "pose_b: rotation is not orthonormal"),
    ((np.eye(3) + 1e-5, np.zeros(3)), "pose_b: rotation is not orthonormal"),
    ((np.eye(2), np.zeros(3)), "pose_b: expected shapes"),
    ("not a pose", "pose_b"),
])
def test_bad_poses_raise(bad, message):
    for call in (intersecting_pairs, bodies_collide):
        for kernel in ("compiled", "readable"):
            with pytest.raises(StateError, match=message):
                call(STAR, IDENTITY, STAR, bad, kernel=kernel)
    with pytest.raises(StateError, match=message.replace("pose_b", "pose_a")):
        intersecting_pairs(STAR, bad, STAR, IDENTITY)


def test_frame_tree_boxes_contain_their_triangles():
    frame = bvh_exact.frame_tree_of(TORUS)
    tree = frame.tree
    for node in range(tree.n_nodes):
        members = tree.order[tree.start[node]:tree.start[node] + tree.count[node]]
        points = TORUS.vertices[TORUS.faces[members]].reshape(-1, 3)
        # the box's own definition (FrameTree), to the rounding of one dot
        # product: the box holds the points and touches them on every side
        local = np.abs((points - frame.centre[node]) @ frame.axes[node])
        slack = 4 * np.finfo(float).eps * frame.reach
        assert (local <= frame.half[node] + slack).all()
        assert (local.max(axis=0) >= frame.half[node] - slack).all()
    assert frame.reach == np.abs(TORUS.vertices).max()
    assert 0.0 < frame.axes_deviation < 1e-14                      # computed eigenvectors
    assert bvh_exact.frame_tree_of(TORUS) is frame                  # built once per mesh


def test_oriented_boxes_follow_the_surface():
    """A flat set of points gets a box of zero thickness; a tilted patch of
    the sphere a box thinner than its axis-aligned one (why the separated
    benchmark visits about 120 node pairs, not 751 as with axis-aligned boxes)."""
    rng = np.random.default_rng(3)
    rotation = random_rotation(rng)
    flat = np.column_stack([rng.uniform(-1, 1, (20, 2)), np.zeros(20)]) @ rotation.T
    _, half, axes = bvh_exact.oriented_box(flat)
    assert half.min() < 1e-15 and half.max() > 0.5
    assert bvh_exact.deviation(axes) < 1e-14

    frame = bvh_exact.frame_tree_of(SPHERE)
    tree = frame.tree
    thinner = 0
    for node in range(1, tree.n_nodes):
        members = tree.order[tree.start[node]:tree.start[node] + tree.count[node]]
        points = SPHERE.vertices[SPHERE.faces[members]].reshape(-1, 3)
        aabb_half = (points.max(axis=0) - points.min(axis=0)) / 2
        thinner += frame.half[node].min() < 0.5 * aabb_half.min()
    assert thinner >= 0.9 * (tree.n_nodes - 1)


def test_oriented_boxes_prune_the_separated_benchmark_early():
    """The separated sphere benchmark pose: 751 node pairs visited with
    axis-aligned node boxes (commit 762e5f1), 117 with oriented ones over
    the least-area tree, 127 over the least-volume tree used now (151 before
    its area tie-break; the tree is built without BLAS, the same with every
    OPENBLAS_CORETYPE; with numpy.linalg.eigh it was 121 or 179), and no
    candidate pair left for the exact test."""
    from refsim.studies.levels import SPEED_CONFIGURATIONS
    from refsim.types import as_pose

    config = next(c for c in SPEED_CONFIGURATIONS
                  if c.model == "sphere-2k" and c.kind == "separated-boxes-overlap")
    (mesh_a, mesh_b), (pose_a, pose_b) = (config.as_configuration().meshes(),
                                          config.as_configuration().poses())
    pairs, visits = bvh_exact.descend(mesh_a, as_pose(pose_a), mesh_b, as_pose(pose_b))
    assert len(pairs) == 0 and visits <= 160


# -- the compiled query's fixed cost: packed arrays, the boolean's early exit ---------


def test_packed_arrays_unpack_to_the_mesh_and_its_frame_tree():
    from refsim.collision import _numba_kernels as nk

    for mesh in (SPHERE, CUBE):
        frame = bvh_exact.frame_tree_of(mesh)
        vertices, faces, links, order, boxes, reach, axes_deviation = nk.unpack(
            *bvh_exact.pack_frame_tree(mesh))
        assert np.array_equal(vertices, mesh.vertices) and np.array_equal(faces, mesh.faces)
        assert np.array_equal(links, frame.links) and np.array_equal(order, frame.tree.order)
        assert np.array_equal(boxes, frame.boxes)
        assert (reach, axes_deviation) == (frame.reach, frame.axes_deviation)


def test_the_boolean_query_stops_at_the_first_pair_the_exact_stage_decides():
    """Cubes sharing a face: the float filter certifies no pair, and the first
    one the compiled exact stage finds touching ends the boolean query."""
    touching = (np.eye(3), np.array([1.0, 0.0, 0.0]))
    _, uncertain = bvh_exact.query_compiled(CUBE, IDENTITY, CUBE, touching,
                                            bvh_exact.ALL_HITS)
    found, undecided = bvh_exact.query_compiled(CUBE, IDENTITY, CUBE, touching,
                                                bvh_exact.FIRST_HIT)
    assert len(uncertain) > 1 and len(found) == 1 and len(undecided) == 0
    _, exact = _seed_pairs(CUBE, IDENTITY, CUBE, touching)
    assert _as_set(found) <= _as_set(exact)
    assert bodies_collide(CUBE, IDENTITY, CUBE, touching, kernel="compiled") is True


def _torus_grazing():
    from refsim.studies.levels import SPEED_CONFIGURATIONS

    config = next(c for c in SPEED_CONFIGURATIONS
                  if c.model == "torus" and c.kind == "grazing").as_configuration()
    return config.poses()


@pytest.mark.parametrize("poses, expected", [
    (_torus_grazing, True),
    (lambda: _poses(3, 14, 2.5)[13], False),    # 87 candidate pairs, none touching
], ids=["grazing benchmark pose", "close, not touching"])
def test_pairs_the_exact_stage_cannot_take_go_to_the_readable_kernel(poses, expected):
    """Two tori scaled by 2^-245 (coordinates below the filter's range, the
    geometry the same bits times a power of two) with candidate pairs: the
    compiled boolean query answers UNDECIDED, and the readable kernel gives
    the seed's answer."""
    nk = bvh_exact._compiled()       # exact_collide compiled for its one signature
    side = 2.0 ** -245
    tiny = TORUS.scaled(side)
    (ra, ta), (rb, tb) = poses()
    pose_a, pose_b = (ra, side * ta), (rb, side * tb)
    boxes, exact = _seed_pairs(tiny, pose_a, tiny, pose_b)
    assert len(boxes) > 0 and (len(exact) > 0) == expected
    assert len(bvh_exact.candidate_pairs(tiny, pose_a, tiny, pose_b)) > 0
    packed = bvh_exact.pack_frame_tree(tiny)
    answer = nk.exact_collide(*packed, *pose_a, *packed, *pose_b, ORTHONORMAL_TOL,
                              bvh_exact.MARGIN_ROUNDING, bvh_exact.MARGIN_PER_DEVIATION)
    assert answer == nk.UNDECIDED
    for kernel in ("compiled", "readable"):
        assert bodies_collide(tiny, pose_a, tiny, pose_b, kernel=kernel) is expected, kernel


def _layouts(rotation, translation):
    """The same pose as numpy and Python give it in other layouts."""
    frozen = rotation.copy(), translation.copy()
    for array in frozen:
        array.flags.writeable = False
    return {"read-only": frozen, "lists": (rotation.tolist(), translation.tolist()),
            "float32": (rotation.astype(np.float32), translation.astype(np.float32)),
            "Fortran order": (np.asfortranarray(rotation), translation),
            "strided": (np.repeat(rotation, 2, axis=1)[:, ::2], np.repeat(translation, 2)[::2]),
            "list pose": [rotation, translation]}


@pytest.mark.parametrize("layout", list(_layouts(np.eye(3), np.zeros(3))))
def test_the_boolean_query_takes_a_pose_in_any_layout_as_pose_takes(layout):
    """The fast path passes poses to numba unchecked; other layouts than the
    compiled signature's go through as_pose and give the same answers."""
    for offset, expected in ((1.0, True), (1.5, False)):
        pose_b = (np.eye(3), np.array([offset, 0.0, 0.0]))
        assert bodies_collide(CUBE, _layouts(*IDENTITY)[layout], CUBE,
                              _layouts(*pose_b)[layout]) is expected


@pytest.mark.parametrize("pose, message", [
    ((np.eye(4), np.zeros(3)), "pose_b: expected shapes"),
    ((np.eye(3), np.zeros(4)), "pose_b: expected shapes"),
    ((np.eye(3).ravel(), np.zeros(3)), "pose_b: expected shapes"),
    ((np.eye(3), np.zeros((3, 1))), "pose_b: expected shapes"),
    ((np.eye(3), np.array([np.nan, 0.0, 0.0])), "pose_b: non-finite"),
    ((2.0 * np.eye(3), np.zeros(3)), "pose_b: rotation is not orthonormal"),
    ((np.eye(3), np.zeros(3), 1.0), "pose_b: expected \\(rotation, translation\\)"),
    (None, "pose_b: expected \\(rotation, translation\\)"),
])
def test_the_boolean_query_refuses_a_bad_pose_with_as_poses_message(pose, message):
    with pytest.raises(StateError, match=message):
        bodies_collide(CUBE, IDENTITY, CUBE, pose, kernel="compiled")


def test_linked_tori_about_their_axes_are_proved_apart_in_few_node_pairs():
    """trimesh's torus about z (32 x 16 sections), linked with a copy turned
    a quarter about x: the gap between the tubes is 0.4. The split's area
    tie-break (bvh_exact.least_volume_split) cuts each ring into arcs; by
    volume alone it was cut into a stack of flat rings, and the traversal
    visited 1121 node pairs (57 now, docs/decisions/tree-build.md). Both
    kernels build the tree; the answer is the same."""
    import trimesh

    ring = trimesh.creation.torus(major_radius=1.0, minor_radius=0.3, major_sections=32,
                                  minor_sections=16)
    turn_x = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    pose_b = (turn_x, np.array([1.0, 0.0, 0.0]))
    for kernel in ("readable", "compiled"):
        torus = Mesh(np.asarray(ring.vertices), np.asarray(ring.faces))
        pairs, visits = bvh_exact.descend(torus, IDENTITY, torus, pose_b, kernel=kernel)
        assert len(pairs) == 0 and visits <= 100, (kernel, visits)
        assert bodies_collide(torus, IDENTITY, torus, pose_b) is False


def test_the_least_volume_split_separates_linked_tori_in_few_node_pairs():
    """Two tori linked like a chain (overlapping boxes, no contact): the exact
    level's own split (bvh_exact.least_volume_split) proves them apart in
    73 node pairs; over the least-area tree of the triangle-aabb level it
    took 247."""
    from refsim.collision.bvh import tree_of

    turn_x = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    pose_b = (turn_x, np.array([1.0, 0.0, 0.0]))
    pairs, visits = bvh_exact.descend(TORUS, IDENTITY, TORUS, pose_b)
    assert len(pairs) == 0 and visits <= 80
    assert not np.array_equal(bvh_exact.frame_tree_of(TORUS).tree.order, tree_of(TORUS).order)
    assert bodies_collide(TORUS, IDENTITY, TORUS, pose_b) is False


# -- the tree is the same on every machine ---------------------------------------------


def test_symmetric_eigenvectors_diagonalize_and_are_orthonormal():
    rng = np.random.default_rng(20261130)
    for trial in range(300):
        m = rng.standard_normal((3, 3))
        a = m + m.T
        if trial % 3 == 0:                        # nearly equal eigenvalues
            a = np.eye(3) + 1e-9 * a
        v = bvh_exact.symmetric_eigenvectors(a.tolist())
        values = np.linalg.eigvalsh(a)            # increasing, as the columns
        assert np.abs(v.T @ v - np.eye(3)).max() < 1e-14
        assert np.abs(a @ v - v * values).max() < 1e-14 * np.abs(a).max() + 1e-300
    assert np.array_equal(bvh_exact.symmetric_eigenvectors(np.diag([3.0, 1.0, 2.0]).tolist()),
                          np.eye(3)[:, [1, 2, 0]])


TREE_DIGEST = """
import hashlib, refsim
from refsim.collision.bvh_exact import frame_tree_of
from refsim.models.mesh import Mesh
model = refsim.load_model("sphere-2k.ac")
for kernel in ("compiled", "readable"):
    tree = frame_tree_of(Mesh(model.vertices, model.faces), kernel)
    digest = hashlib.sha256(tree.boxes.tobytes() + tree.links.tobytes()
                            + tree.tree.order.tobytes() + repr(tree.axes_deviation).encode())
    print(digest.hexdigest())
"""


def test_the_exact_levels_tree_does_not_depend_on_the_blas_core():
    """The tree (its splits, its node boxes and its axes' deviation, to the
    bit) is built without BLAS or LAPACK, so OpenBLAS's kernels for other
    processors give the same one (with numpy.linalg.eigh they did not:
    another tree, and another count of node pairs visited; with ``A.T @ A``
    the axes' deviation differed in its last bits), by the compiled build
    as by the readable one. The default kernels are compared with every
    core type this processor can run (tests.helpers.openblas_core_types):
    on x86-64 at least Prescott, elsewhere the default alone."""
    import os
    import platform
    import subprocess
    import sys

    from tests.helpers import X86_64_MACHINES, openblas_core_types

    default = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    cores = openblas_core_types()
    if platform.machine() in X86_64_MACHINES:
        assert "Prescott" in cores
    digests = {}
    for core in [None, *cores]:
        env = default if core is None else dict(default, OPENBLAS_CORETYPE=core)
        result = subprocess.run([sys.executable, "-c", TREE_DIGEST], env=env,
                                capture_output=True, text=True, timeout=300, check=True)
        compiled, readable = result.stdout.split()
        assert compiled == readable, core
        digests[core or "default"] = compiled
    assert len(digests) == 1 + len(cores)
    assert len(set(digests.values())) == 1, digests
    assert len(digests["default"]) == 64
