"""The compiled exact stage (refsim.collision._numba_exact) against the
readable exact code: orientation signs equal to the integer-arithmetic
predicates, triangle answers equal to ``triangles_intersect``, on seeded
adversarial input (exact coplanarity, one-ulp perturbations, near-degenerate
and random points, the ends of the filter's range). No tolerance anywhere:
every comparison is of signs or booleans."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import refsim
from refsim.collision import bvh_exact
from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.collision.predicates import (
    FILTER_MAX_ABS,
    FILTER_MIN_ABS,
    in_filter_range,
    orient2d_exact,
    orient3d_exact,
)
from refsim.collision.triangle import point_set, triangles_intersect
from refsim.collision.triangle_numba import compiled_exact_kernels
from refsim.studies.triangles import near_degenerate_pairs

from .test_triangle import CASES, T

ne = compiled_exact_kernels()

#: The three routes of the compiled predicates (``orient3d_batch``'s stage).
FILTERED, EXACT, EXPANSION = 0, 1, 2

#: Power-of-two scales that keep grid points inside the filter's range,
#: near both of its ends (a scaled dyadic grid stays exactly coplanar).
SCALES = (1.0, 2.0 ** -200, 2.0 ** 250, 2.0 ** -30, 3.0)


# -- point sets ---------------------------------------------------------------------


def _coplanar_dyadic(rng, n):
    """(n, 4, 3): d = a + s (b - a) + t (c - a) on a dyadic grid, every
    operation exact, so the four points are exactly coplanar."""
    P = rng.integers(-64, 65, (n, 4, 3)).astype(float) / 8.0
    s, t = (rng.integers(-8, 9, (2, n, 1)) / 4.0)
    P[:, 3] = P[:, 0] + s * (P[:, 1] - P[:, 0]) + t * (P[:, 2] - P[:, 0])
    return P


def _rounded_onto_plane(rng, n):
    """(n, 4, 3): d a float combination of a, b, c (coplanar up to rounding)."""
    P = rng.uniform(-1.0, 1.0, (n, 4, 3))
    s, t = rng.uniform(0.0, 1.0, (2, n, 1))
    P[:, 3] = P[:, 0] + s * (P[:, 1] - P[:, 0]) + t * (P[:, 2] - P[:, 0])
    return P


def _ulp_perturbed(P, rng):
    """Each point set with one coordinate of the last point moved by one ulp
    up or down (zeros move to the smallest in-range magnitude)."""
    Q = P.copy()
    k = rng.integers(0, P.shape[2], len(P))
    up = rng.integers(0, 2, len(P)).astype(bool)
    rows = np.arange(len(P))
    x = Q[rows, -1, k]
    moved = np.where(up, np.nextafter(x, np.inf), np.nextafter(x, -np.inf))
    moved = np.where(x == 0.0, np.where(up, FILTER_MIN_ABS, -FILTER_MIN_ABS), moved)
    Q[rows, -1, k] = moved
    return Q


def _kettner(n_side):
    """Kettner et al.'s family (2008): a on a grid of ulps near (0.5, 0.5),
    nearly collinear with b and c; lifted with d off the plane."""
    out = []
    for i, j in itertools.product(range(n_side), range(n_side)):
        out.append([(0.5 + i * 2.0 ** -53, 0.5 + j * 2.0 ** -53, 0.0), (12.0, 12.0, 0.0),
                    (24.0, 24.0, 0.0), (0.1, 0.3, 1.0)])
    return np.array(out)


def _orient3d_sets(seed):
    rng = np.random.default_rng(seed)
    grid = _coplanar_dyadic(rng, 3000)
    near = _rounded_onto_plane(rng, 3000)
    sets = {
        "coplanar dyadic": grid,
        "coplanar dyadic, one ulp off": _ulp_perturbed(grid, rng),
        "rounded onto a plane": near,
        "rounded onto a plane, one ulp off": _ulp_perturbed(near, rng),
        "random": rng.uniform(-1.0, 1.0, (3000, 4, 3)),
        "small integers": rng.integers(-2, 3, (3000, 4, 3)).astype(float),
        "Kettner grid": _kettner(40),
    }
    scaled = {}
    for name, P in sets.items():
        for scale in SCALES[1:]:
            Q = P * scale
            if in_filter_range(Q.ravel().tolist()) and ((Q / scale) == P).all():
                scaled[f"{name} x {scale:g}"] = Q
    return sets | scaled


def _as_points(row):
    return [tuple(p) for p in row.tolist()]


# -- (1) predicates -----------------------------------------------------------------


@pytest.mark.parametrize("stage", [FILTERED, EXACT, EXPANSION])
def test_orient3d_signs_equal_the_integer_predicate(stage):
    total = zeros = 0
    for name, P in _orient3d_sets(seed=31).items():
        expected = np.array([orient3d_exact(*_as_points(p)) for p in P])
        got = ne.orient3d_batch(np.ascontiguousarray(P), stage)
        assert np.array_equal(got, expected), (name, np.flatnonzero(got != expected)[:5])
        total += len(P)
        zeros += int((expected == 0).sum())
    # the sets exercise exact zeros and both signs
    assert total > 50_000
    assert zeros > 10_000


def _orient2d_sets(seed):
    rng = np.random.default_rng(seed)
    grid = rng.integers(-64, 65, (3000, 3, 2)).astype(float) / 8.0
    s = rng.integers(-8, 9, (3000, 1)) / 4.0
    grid[:, 2] = grid[:, 0] + s * (grid[:, 1] - grid[:, 0])            # exactly collinear
    near = rng.uniform(-1.0, 1.0, (3000, 3, 2))
    near[:, 2] = near[:, 0] + rng.uniform(0, 1, (3000, 1)) * (near[:, 1] - near[:, 0])
    sets = {
        "collinear dyadic": grid,
        "collinear dyadic, one ulp off": _ulp_perturbed(grid, rng),
        "rounded onto a line": near,
        "rounded onto a line, one ulp off": _ulp_perturbed(near, rng),
        "random": rng.uniform(-1.0, 1.0, (3000, 3, 2)),
        "Kettner grid": _kettner(40)[:, :3, :2].copy(),
    }
    scaled = {}
    for name, P in sets.items():
        for scale in SCALES[1:]:
            Q = P * scale
            if in_filter_range(Q.ravel().tolist()) and ((Q / scale) == P).all():
                scaled[f"{name} x {scale:g}"] = Q
    return sets | scaled


@pytest.mark.parametrize("stage", [FILTERED, EXACT, EXPANSION])
def test_orient2d_signs_equal_the_integer_predicate(stage):
    total = zeros = 0
    for name, P in _orient2d_sets(seed=32).items():
        expected = np.array([orient2d_exact(*_as_points(p)) for p in P])
        got = ne.orient2d_batch(np.ascontiguousarray(P), stage)
        assert np.array_equal(got, expected), (name, np.flatnonzero(got != expected)[:5])
        total += len(P)
        zeros += int((expected == 0).sum())
    assert total > 40_000
    assert zeros > 5_000


def test_the_exact_difference_route_is_taken_and_right_at_the_range_ends():
    # Differences of points at the ends of the range: still exact, signs right.
    lo, hi = FILTER_MIN_ABS, FILTER_MAX_ABS
    cases = [
        (((0.0, 0.0, 0.0), (lo, 0.0, 0.0), (0.0, lo, 0.0), (0.0, 0.0, -lo)), 1),
        (((0.0, 0.0, 0.0), (lo, 0.0, 0.0), (0.0, lo, 0.0), (lo, lo, 0.0)), 0),
        (((0.0, 0.0, 0.0), (hi, 0.0, 0.0), (0.0, hi, 0.0), (0.0, 0.0, hi)), -1),
        (((-hi, -hi, -hi), (hi, -hi, -hi), (-hi, hi, -hi), (hi, hi, -hi)), 0),
        (((lo, hi, lo), (hi, lo, -lo), (-hi, -lo, hi), (lo, lo, lo)), None),
    ]
    P = np.array([c[0] for c in cases])
    expected = np.array([orient3d_exact(*c[0]) for c in cases])
    for (_, sign), e in zip(cases, expected, strict=True):
        assert sign is None or e == sign
    for stage in (FILTERED, EXACT, EXPANSION):
        assert np.array_equal(ne.orient3d_batch(P, stage), expected)


# -- (2) the triangle test ----------------------------------------------------------


def _edge_sharing(rng, n):
    """Pairs sharing an edge: B's third vertex from the shared edge's plane
    pencil on a dyadic grid (coplanar on either side, folded, or exactly in
    A's plane across the edge)."""
    A = rng.integers(-8, 9, (n, 3, 3)).astype(float) / 4.0
    B = np.empty_like(A)
    B[:, 0], B[:, 1] = A[:, 1], A[:, 0]
    s, t = rng.integers(-4, 5, (2, n, 1)) / 4.0
    fold = rng.integers(-2, 3, (n, 3)) / 8.0 * (rng.uniform(size=(n, 1)) < 0.5)
    B[:, 2] = A[:, 0] + s * (A[:, 1] - A[:, 0]) + t * (A[:, 2] - A[:, 0]) + fold
    return A, B


def _vertex_touching(rng, n):
    """Pairs where a vertex of B is a vertex of A, a grid point of A's edge or
    of A's face (all exact), the rest of B random on the grid."""
    A = rng.integers(-8, 9, (n, 3, 3)).astype(float) / 4.0
    B = rng.integers(-8, 9, (n, 3, 3)).astype(float) / 4.0
    s, t = rng.integers(0, 3, (2, n, 1)) / 4.0
    kind = rng.integers(0, 3, n)
    B[kind == 0, 0] = A[kind == 0, 0]
    on_edge = A[:, 0] + s * (A[:, 1] - A[:, 0])
    on_face = on_edge + t * (A[:, 2] - A[:, 0])
    B[kind == 1, 0] = on_edge[kind == 1]
    B[kind == 2, 0] = on_face[kind == 2]
    return A, B


def _near_miss(A, B, rng):
    """The same pairs with all of B moved by one ulp along one axis."""
    C = B.copy()
    k = rng.integers(0, 3, len(B))
    up = rng.integers(0, 2, len(B)).astype(bool)
    for n in range(len(B)):
        direction = np.inf if up[n] else -np.inf
        C[n, :, k[n]] = np.nextafter(C[n, :, k[n]], direction)
    return A, C


def _cube_contacts():
    """The triangle pairs of two unit cubes in every face-, edge- and
    corner-touching placement (every triangle of one against every triangle
    of the other)."""
    cube = refsim.load_model("cube.ac")
    world = cube.vertices[cube.faces]
    A, B = [], []
    for offset in itertools.product((-1.0, 0.0, 1.0), repeat=3):
        if offset == (0.0, 0.0, 0.0):
            continue
        for i, j in itertools.product(range(len(world)), repeat=2):
            A.append(world[i])
            B.append(world[j] + np.array(offset))
    return np.array(A), np.array(B)


def _triangle_sets(seed):
    rng = np.random.default_rng(seed)
    coplanar = rng.integers(-4, 5, (2, 3000, 3, 3)).astype(float) / 2.0
    coplanar[:, :, :, 2] = 0.5
    sets = {
        "small integers": tuple(rng.integers(-2, 3, (2, 3000, 3, 3)).astype(float)),
        "near-degenerate families": near_degenerate_pairs(3000, seed=seed)[:2],
        "random": tuple(rng.uniform(-1.0, 1.0, (2, 3000, 3, 3))),
        "coplanar on a grid": tuple(coplanar),
        "edge-sharing": _edge_sharing(rng, 3000),
        "vertex-touching": _vertex_touching(rng, 3000),
        "cube contacts": _cube_contacts(),
    }
    sets["edge-sharing, one ulp apart"] = _near_miss(*sets["edge-sharing"], rng)
    sets["vertex-touching, one ulp apart"] = _near_miss(*sets["vertex-touching"], rng)
    sets["coplanar, one ulp apart"] = _near_miss(*sets["coplanar on a grid"], rng)
    for scale in (2.0 ** -200, 2.0 ** 250):
        A, B = sets["edge-sharing"]
        sets[f"edge-sharing x {scale:g}"] = (A * scale, B * scale)
    return sets


def _takes(a, b) -> bool:
    """Whether the compiled stage should decide a pair: both triangles of
    positive area, every coordinate in the filter's range."""
    return (in_filter_range(np.concatenate([a, b]).ravel().tolist())
            and point_set(_as_points(a))[0] == "triangle"
            and point_set(_as_points(b))[0] == "triangle")


def test_triangle_answers_equal_the_readable_test():
    total = hits = 0
    for name, (A, B) in _triangle_sets(seed=33).items():
        A, B = np.ascontiguousarray(A, np.float64), np.ascontiguousarray(B, np.float64)
        expected = np.array([triangles_intersect(a, b) for a, b in zip(A, B, strict=True)])
        takes = np.array([_takes(a, b) for a, b in zip(A, B, strict=True)])
        answer, decided = ne.intersect_batch(A, B)
        assert np.array_equal(decided, takes), name
        assert np.array_equal(answer[decided], expected[decided]), (
            name, np.flatnonzero(answer[decided] != expected[decided])[:5])
        assert not answer[~decided].any(), name
        # both orders
        answer_ba, decided_ba = ne.intersect_batch(B, A)
        assert np.array_equal(decided_ba, decided), name
        assert np.array_equal(answer_ba[decided], expected[decided]), name
        total += int(decided.sum())
        hits += int(expected[decided].sum())
    assert total > 30_000
    assert 0.2 * total < hits < 0.9 * total


def test_constructed_cases_under_rigid_motions():
    for other, answer in CASES.values():
        for image in _rigid_images_pair(np.asarray(T, float), np.asarray(other, float)):
            a, b = image
            got, decided = ne.intersect_batch(a[None], b[None])
            if _takes(a, b):
                assert decided[0] and got[0] == answer
            else:
                assert not decided[0]


def _rigid_images_pair(a, b):
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1.0, -1.0), repeat=3):
            yield a[:, perm] * np.array(signs), b[:, perm] * np.array(signs)


# -- (3) whole bodies ----------------------------------------------------------------

CUBE = refsim.load_model("cube.ac")
SPHERE = refsim.load_model("sphere-2k.ac")
IDENTITY = (np.eye(3), np.zeros(3))


def _touching_configurations():
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])   # exact quarter turn
    return {
        "cubes face to face": (CUBE, IDENTITY, CUBE, (np.eye(3), np.array([0.0, 1.0, 0.0]))),
        "cubes face to face, x": (CUBE, IDENTITY, CUBE, (np.eye(3), np.array([1.0, 0.0, 0.0]))),
        "cubes edge to edge": (CUBE, IDENTITY, CUBE, (np.eye(3), np.array([1.0, 1.0, 0.0]))),
        "cubes corner to corner": (CUBE, IDENTITY, CUBE, (np.eye(3), np.ones(3))),
        "cubes face to face, shifted half": (CUBE, IDENTITY, CUBE,
                                             (np.eye(3), np.array([0.5, 1.0, 0.25]))),
        "cubes face to face, turned": (CUBE, IDENTITY, CUBE, (turn, np.array([0.0, 1.0, 0.0]))),
        "cubes one ulp apart": (CUBE, IDENTITY, CUBE,
                                (np.eye(3), np.array([0.0, np.nextafter(1.0, 2.0), 0.0]))),
        "cube resting on a sphere": (SPHERE, IDENTITY, CUBE,
                                     (np.eye(3), np.array([0.0, 1.5, 0.0]))),
        "cube resting on a sphere, shifted": (SPHERE, IDENTITY, CUBE,
                                              (np.eye(3), np.array([0.25, 1.5, -0.125]))),
    }


@pytest.mark.parametrize("name", list(_touching_configurations()))
def test_touching_configurations_equal_the_seed_path_and_the_readable_kernel(name):
    mesh_a, pose_a, mesh_b, pose_b = _touching_configurations()[name]
    seed = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, method="seed", kernel="readable")
    readable = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, kernel="readable")
    compiled = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, kernel="compiled")
    seed_compiled = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, method="seed",
                                       kernel="compiled")
    assert np.array_equal(readable, seed)
    assert np.array_equal(compiled, seed)
    assert np.array_equal(seed_compiled, seed)
    expected = len(seed) > 0
    assert expected == (name != "cubes one ulp apart")
    for kernel in ("readable", "compiled"):
        assert bodies_collide(mesh_a, pose_a, mesh_b, pose_b, kernel=kernel) == expected
        assert bodies_collide(mesh_a, pose_a, mesh_b, pose_b, method="seed",
                              kernel=kernel) == expected


@pytest.mark.parametrize("name", list(_touching_configurations()))
def test_the_compiled_stage_decides_every_pair_the_filter_leaves(name):
    mesh_a, pose_a, mesh_b, pose_b = _touching_configurations()[name]
    found, uncertain = bvh_exact.query_compiled(mesh_a, pose_a, mesh_b, pose_b,
                                                bvh_exact.ALL_HITS)
    # touching: the float filter is unsure (one ulp apart it is sure)
    assert (len(uncertain) > 0) == (name != "cubes one ulp apart")
    answer, decided = ne.intersect_posed(mesh_a.vertices, mesh_a.faces, *pose_a,
                                         mesh_b.vertices, mesh_b.faces, *pose_b,
                                         uncertain, False)
    assert decided.all()                          # nothing left for the readable kernel
    expected = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, method="seed",
                                  kernel="readable")
    got = np.concatenate([found, uncertain[answer]])
    assert np.array_equal(got[np.lexsort((got[:, 1], got[:, 0]))], expected)


def test_pairs_the_stage_does_not_take_go_to_the_readable_kernel():
    # A degenerate triangle (a point on the face) and out-of-range coordinates.
    tiny = FILTER_MIN_ABS / 4.0
    A = np.array([T, T, np.array(T) * tiny], dtype=np.float64)
    B = np.array([((0.25, 0.25, 0.0),) * 3, ((0, 0, 0), (1, 0, 0), (0, -1, 0)),
                  np.array(((0, 0, 0), (1, 0, 0), (0, -1, 0))) * tiny], dtype=np.float64)
    answer, decided = ne.intersect_batch(A, B)
    assert decided.tolist() == [False, True, False]
    assert answer.tolist() == [False, True, False]
    from refsim.collision.triangle_numba import triangles_intersect_numba

    assert triangles_intersect_numba(A, B).tolist() == [True, True, True]
