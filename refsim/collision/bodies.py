"""Body-body collision at the seed's four levels of accuracy (seed S4).

``bodies_collide`` answers "do these two bodies collide?" at one level:

============== ====================================================== ========
level          test                                                   answers
============== ====================================================== ========
sphere         bounding spheres about the centroids overlap           coarsest
aabb           world boxes of the bodies overlap (seed test 1)
triangle-aabb  some pair of triangle boxes overlaps (seed test 2)
exact          some pair of triangles intersects (seed test 3)        exact
============== ====================================================== ========

``intersecting_pairs`` lists the triangle pairs at the two finest levels.
Every level is conservative: it never says "apart" where the exact test says
"touching". The box levels nest (exact pairs are a subset of triangle-aabb
pairs, which exist only when the object boxes overlap); the sphere level is
conservative too but does not nest with the box levels.

``method`` picks how the pairs are found, with identical answers: "seed"
tests the triangle boxes pairwise as the seed does
(:mod:`refsim.collision.seed_levels`); "bvh" (the default) descends a
triangle hierarchy: at level "triangle-aabb" one refit in world space, which
finds test 2's pairs themselves (:mod:`refsim.collision.bvh`); at level
"exact" one traversed in the first body's frame, which transforms only the
leaves it reaches (:mod:`refsim.collision.bvh_exact`).
"""

from __future__ import annotations

import numpy as np

from refsim.collision.boxes import boxes_overlap, world_vertices
from refsim.collision.bvh import prepare_body, tree_box_pairs
from refsim.collision.seed_levels import exact_pairs, triangle_box_pairs
from refsim.collision.spheres import spheres_overlap
from refsim.errors import check_option
from refsim.kernels import EXACT_HIERARCHY_COLLIDE, EXACT_HIERARCHY_QUERY, Tier, choose_kernel
from refsim.models.mesh import require_mesh
from refsim.types import as_pose

LEVELS = ("sphere", "aabb", "triangle-aabb", "exact")
PAIR_LEVELS = ("triangle-aabb", "exact")
METHODS = ("bvh", "seed")

#: Candidate pairs tested per batch by the boolean exact query, which stops at
#: the first batch with a hit: small enough to stop early, large enough that
#: numpy's per-call overhead is amortized.
BOOLEAN_BATCH = 256

#: The exact hierarchy query's compiled kernels as one family
#: (:class:`refsim.kernels.Tier`): until numba's cache holds them, the
#: default query runs readable for up to ``compile_seconds`` in a process
#: before it compiles them (their compile time as measured in
#: docs/decisions/cold-start.md, rounded down).
EXACT_QUERY = Tier("exact collision query",
                   ("refsim.collision._numba_kernels:exact_query",
                    "refsim.collision._numba_kernels:exact_collide",
                    "refsim.collision._numba_build:frame_tree_arrays",
                    "refsim.collision._numba_build:build_tree",
                    "refsim.collision._numba_build:frame_boxes"), compile_seconds=45.0)

#: A body with more triangles than this takes the compiled query even on a
#: cold cache: the readable build of its hierarchy, in one call, would cost
#: a good part of the compile it is meant to spare
#: (docs/decisions/tree-build.md).
READABLE_FACES = 5000


def _readable_first(mesh_a, mesh_b) -> bool:
    """Whether a default exact query runs readable now, charged to
    :data:`EXACT_QUERY` (asked only while the tier has not settled, so that
    a settled query pays one attribute for it)."""
    return (EXACT_QUERY.readable_first()
            and max(mesh_a.n_faces, mesh_b.n_faces) <= READABLE_FACES)


def _check(level: str, allowed: tuple[str, ...], method: str, mesh_a, mesh_b) -> None:
    check_option("level", level, allowed)
    check_option("method", method, METHODS)
    require_mesh(mesh_a, "mesh_a")
    require_mesh(mesh_b, "mesh_b")


def intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, level: str = "exact",
                       method: str = "bvh", *, kernel: str | None = None) -> np.ndarray:
    """Face-index pairs (i of ``mesh_a``, j of ``mesh_b``) that collide.

    Parameters
    ----------
    mesh_a, mesh_b : Mesh
    pose_a, pose_b : (rotation (3, 3), translation (3,))
    level : "exact" (triangles intersect, touching counts) or
        "triangle-aabb" (their world boxes overlap)
    method : "bvh" (hierarchy) or "seed" (pairwise triangle boxes)
    kernel : "compiled" (compiled traversal and exact filter; the default
        where numba works) or "readable" (readable traversal, numpy filter);
        see :mod:`refsim.kernels`. The default at level "exact" runs
        readable while numba's cache lacks the query (:data:`EXACT_QUERY`).

    Returns
    -------
    (k, 2) int64 array, rows sorted.
    """
    _check(level, PAIR_LEVELS, method, mesh_a, mesh_b)
    if level == "exact" and method == "bvh":
        if kernel is None and not EXACT_QUERY.settled and _readable_first(mesh_a, mesh_b):
            with EXACT_QUERY.charged():
                return EXACT_HIERARCHY_QUERY.readable(mesh_a, pose_a, mesh_b, pose_b)
        return EXACT_HIERARCHY_QUERY.pick(choose_kernel(kernel))(mesh_a, pose_a, mesh_b, pose_b)
    kernel = choose_kernel(kernel)
    pose_a, pose_b = as_pose(pose_a, what="pose_a"), as_pose(pose_b, what="pose_b")
    if method == "seed":
        world_a, world_b = world_vertices(mesh_a, pose_a), world_vertices(mesh_b, pose_b)
        pairs = triangle_box_pairs(world_a, mesh_a.faces, world_b, mesh_b.faces)
        if level == "exact":
            pairs = exact_pairs(world_a, mesh_a.faces, world_b, mesh_b.faces, pairs, kernel)
        return pairs
    pa, pb = prepare_body(mesh_a, pose_a, kernel), prepare_body(mesh_b, pose_b, kernel)
    return tree_box_pairs(pa, pb, kernel)                               # triangle-aabb


def bodies_collide(mesh_a, pose_a, mesh_b, pose_b, level: str = "exact",
                   method: str = "bvh", *, kernel: str | None = None) -> bool:
    """Whether two posed bodies collide at ``level`` (seed S4).

    Parameters
    ----------
    mesh_a, mesh_b : Mesh
    pose_a, pose_b : (rotation (3, 3), translation (3,))
        Each maps a body-space point ``p`` to the world point ``R p + t``;
        checked with :func:`refsim.types.as_pose`.
    level : {"sphere", "aabb", "triangle-aabb", "exact"}
        The seed's four types of test, coarse to fine (module docstring):
        bounding spheres, body boxes, triangle boxes, exact triangle overlap
        (closed triangles: touching counts). Every coarse level is
        conservative: it never says apart where ``"exact"`` says collide.
    method : {"bvh", "seed"}
        The deeper hierarchy or the seed's levels; the same answers.
    kernel : {"readable", "compiled"}, optional
        See :mod:`refsim.kernels`; the same answers. The default at level
        "exact" runs readable while numba's cache lacks the query
        (:data:`EXACT_QUERY`).

    Returns
    -------
    bool

    Raises
    ------
    OptionError
        An unknown level, method or kernel.
    ArgumentTypeError
        A mesh that is not a :class:`refsim.Mesh`.
    StateError
        A pose that is not finite, not orthonormal or of the wrong shape, or
        one that puts the body's world coordinates beyond float64's range.
    """
    _check(level, LEVELS, method, mesh_a, mesh_b)
    if level == "exact" and method == "bvh":
        if kernel is None and not EXACT_QUERY.settled and _readable_first(mesh_a, mesh_b):
            with EXACT_QUERY.charged():
                return EXACT_HIERARCHY_COLLIDE.readable(mesh_a, pose_a, mesh_b, pose_b)
        return EXACT_HIERARCHY_COLLIDE.pick(choose_kernel(kernel))(mesh_a, pose_a, mesh_b,
                                                                   pose_b)
    kernel = choose_kernel(kernel)
    pose_a, pose_b = as_pose(pose_a, what="pose_a"), as_pose(pose_b, what="pose_b")
    if level == "sphere":
        return spheres_overlap(mesh_a, pose_a, mesh_b, pose_b)
    if level == "aabb" or method == "seed":
        world_a, world_b = world_vertices(mesh_a, pose_a), world_vertices(mesh_b, pose_b)
        if level == "aabb":
            return boxes_overlap(world_a.min(axis=0), world_a.max(axis=0),
                                 world_b.min(axis=0), world_b.max(axis=0))
        candidates = triangle_box_pairs(world_a, mesh_a.faces, world_b, mesh_b.faces)
        if level == "triangle-aabb":
            return len(candidates) > 0
        return _any_exact(world_a, mesh_a, world_b, mesh_b, candidates, kernel)
    pa, pb = prepare_body(mesh_a, pose_a, kernel), prepare_body(mesh_b, pose_b, kernel)
    return len(tree_box_pairs(pa, pb, kernel, first_only=True)) > 0     # triangle-aabb


def _any_exact(world_a, mesh_a, world_b, mesh_b, candidates, kernel) -> bool:
    """Whether any candidate pair intersects, testing in batches and stopping
    at the first batch with a hit."""
    for start in range(0, len(candidates), BOOLEAN_BATCH):
        batch = candidates[start:start + BOOLEAN_BATCH]
        if len(exact_pairs(world_a, mesh_a.faces, world_b, mesh_b.faces, batch, kernel)):
            return True
    return False


#: :func:`exact_answers`' codes: the meshes touch, are apart, or the
#: compiled query left the pair to :func:`bodies_collide`.
TOUCH, APART, UNDECIDED = 1, 0, -1


def exact_answers(packed: tuple, R: np.ndarray, origin: np.ndarray,
                  rows: np.ndarray) -> np.ndarray:
    """The exact level's answer for many body pairs in one compiled call:
    ``packed`` the bodies' frame trees laid end to end (``floats,
    float_start, ints, int_start, mesh_of``, each body's from
    :func:`refsim.collision.bvh_exact.pack_frame_tree`), ``R`` (B, 3, 3) and
    ``origin`` (B, 3) the bodies' poses, ``rows`` (P, 2) int64 the pairs.
    Returns (P,) int64 codes: :data:`TOUCH`, :data:`APART`, or
    :data:`UNDECIDED` for a pair the query leaves to :func:`bodies_collide`
    (which decides it, or raises on a pose it rejects). The query is
    :func:`bodies_collide`'s at level "exact", so the same pairs touch."""
    from refsim.collision import _numba_contact, _numba_kernels
    from refsim.collision.bvh_exact import MARGIN_PER_DEVIATION, MARGIN_ROUNDING
    from refsim.types import ORTHONORMAL_TOL

    floats, float_start, ints, int_start, mesh_of = packed
    codes = np.empty(len(rows), dtype=np.int64)
    _numba_contact.collide_pairs_numba(floats, float_start, ints, int_start, mesh_of, R,
                                       origin, rows, ORTHONORMAL_TOL, MARGIN_ROUNDING,
                                       MARGIN_PER_DEVIATION, codes)
    return np.where(codes == _numba_kernels.HIT, TOUCH,
                    np.where(codes == _numba_kernels.APART, APART, UNDECIDED))
