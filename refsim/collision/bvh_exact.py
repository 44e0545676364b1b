"""The exact level through the triangle hierarchy, traversed in the first
body's frame (seed S4's "more levels of hierarchy", for test 3).

The refit hierarchy of :mod:`refsim.collision.bvh` reproduces the seed's
test 2 pair for pair, but pays for it on every query: it transforms every
vertex and refits every node box of both bodies before it looks at a single
pair. The exact level does not need test 2's pairs, only a superset of the
intersecting ones, so this query follows RAPID and FCL instead (S. Gottschalk,
M. C. Lin, D. Manocha, "OBBTree: A Hierarchical Structure for Rapid
Interference Detection", SIGGRAPH 1996):

1. Node volumes are boxes in body space, computed once per mesh
   (:class:`FrameTree`: the topology of :func:`refsim.collision.bvh.tree_of`,
   each node's box as centre and half-extents).
2. A query expresses body b in a's frame, ``x_a = M x_b + u`` with
   ``M = Ra^T Rb`` and ``u = Ra^T (tb - ta)``. A's boxes stay axis-aligned
   there and b's become oriented boxes, and a pair of nodes is dropped when
   one of the 15 separating axes of two boxes (three face normals of each,
   nine edge-edge cross products) separates them by more than a margin
   (:func:`boxes_apart`). Nothing is transformed for a node that is never
   visited.
3. At a pair of leaves the leaves' vertices are transformed to the world
   (each vertex once per query, with refsim's one transform arithmetic, so
   the triangles are the same floats every other path tests), the
   triangles' world boxes are compared, and the pairs whose boxes overlap
   are tested exactly.

The pairs returned are exactly the intersecting pairs the seed's path finds:
the node test only ever drops pairs of triangles that are apart, and every
pair it keeps is decided by the exact test.

Why the margin, and how big. The node test decides in floating point, about
transformed boxes, and the answer has to hold for the rounded world
triangles. It can be wrong by (all in units of
``S = reach_a + reach_b + |ta|_inf + |tb|_inf``, where ``reach`` is the
largest absolute body coordinate of a mesh, which bounds every point of every
node box):

- the rounding of a world vertex (four operations, <= 4u(3 reach + |t|),
  u = 2^-53), carried through Ra^T (factor <= 3);
- the rounding of M, u, T and of the two sides of each comparison (sums of
  at most seven products of numbers <= S; < 64u);
- a rotation that is orthonormal only to within ``g = max|R^T R - I|``
  (``refsim.types.ORTHONORMAL_TOL`` allows 1e-6): Ra^T is then not Ra's
  inverse (a's boxes move by <= 3 g reach_a), and the box formulas, which
  assume M orthonormal, misjudge b's extent by <= 6 g' reach_b with
  g' <= 2(g_a + g_b) + 8u for M.

Together less than ``(100 u + 16 g) S``. The margin is
``(MARGIN_ROUNDING + MARGIN_PER_DEVIATION * g) S`` with 2^-40 (about 8000 u)
and 64, several times that: a node pair closer than the margin is simply
visited, which costs a few node tests and changes no answer. The tests check
that the margin is needed (with it set to zero, pairs that intersect by less
than it are lost) and sufficient (random and near-touching poses, rotations
off orthonormal by up to the tolerance).

Two kernels take the same steps: :func:`candidate_pairs` (readable loops)
and a numba-compiled copy (``refsim[fast]``,
:func:`refsim.collision._numba_kernels.exact_query`) that also certifies the
pairs with the float filter as it finds them and can stop at the first hit.
The compiled copy checks the poses itself (the checks of
:func:`refsim.types.as_pose`), which keeps a query's fixed cost to a few
microseconds.

Cost: O(m) once per mesh for the boxes; per query about O(k log m) node
tests for k overlapping node pairs, plus O(1) per vertex and triangle of the
leaves reached. The speed against FCL is measured in
:func:`refsim.collision.measure_levels.measure_hierarchy_speed`.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from refsim.collision.boxes import triangle_boxes, world_vertices
from refsim.collision.bvh import TriangleTree, tree_of
from refsim.collision.seed_levels import exact_pairs
from refsim.collision.triangle import triangles_intersect
from refsim.errors import StateError
from refsim.types import ORTHONORMAL_TOL, as_pose

#: The node test's margin, relative to the scene's size S (see the module
#: docstring): about 8000 unit roundoffs against the ~100 the arithmetic can
#: lose...
MARGIN_ROUNDING = 2.0 ** -40
#: ... plus this many times the rotations' departure from orthonormality
#: (~16 needed).
MARGIN_PER_DEVIATION = 64.0

#: Modes of the compiled query (refsim.collision._numba_kernels).
ALL_HITS, FIRST_HIT, CANDIDATES = 0, 1, 2


@dataclass(frozen=True)
class FrameTree:
    """A mesh's hierarchy with its node boxes in body space (built once).

    tree : the topology (:class:`refsim.collision.bvh.TriangleTree`).
    links : (nodes, 4) int64, the tree's left, right, start, count as columns
        (one array, for the compiled kernel).
    boxes : (nodes, 6) float64, each node's box: centre xyz, half-extents xyz.
    reach : the largest absolute body coordinate of the mesh.

    The box from centre and half-extent can miss the exact one by a rounding
    (an ulp of ``reach``); the node test's margin is far larger.
    """

    tree: TriangleTree
    links: np.ndarray
    boxes: np.ndarray
    reach: float

    @property
    def centre(self) -> np.ndarray:
        return self.boxes[:, :3]

    @property
    def half(self) -> np.ndarray:
        return self.boxes[:, 3:]


def build_frame_tree(mesh) -> FrameTree:
    tree = tree_of(mesh)
    lo_t, hi_t = triangle_boxes(mesh.vertices, mesh.faces)
    lo = np.empty((tree.n_nodes, 3))
    hi = np.empty((tree.n_nodes, 3))
    for node in range(tree.n_nodes):
        members = tree.order[tree.start[node]:tree.start[node] + tree.count[node]]
        lo[node] = lo_t[members].min(axis=0)
        hi[node] = hi_t[members].max(axis=0)
    links = np.column_stack([tree.left, tree.right, tree.start, tree.count]).astype(np.int64)
    boxes = np.column_stack([(lo + hi) / 2, (hi - lo) / 2])
    return FrameTree(tree, np.ascontiguousarray(links), np.ascontiguousarray(boxes),
                     float(np.abs(mesh.vertices).max()))


def frame_tree_of(mesh) -> FrameTree:
    """The mesh's :class:`FrameTree`, built on first use and kept with the mesh."""
    return mesh.derived("frame_tree", build_frame_tree)


# -- the readable kernel ------------------------------------------------------------


def relative_frame(pose_a, pose_b):
    """``(M, u)``: body b's coordinates in a's frame are ``M x + u``."""
    (ra, ta), (rb, tb) = pose_a, pose_b
    return ra.T @ rb, ra.T @ (tb - ta)


def deviation(rotation) -> float:
    """``max |R^T R - I|``: how far a rotation is from orthonormal."""
    return float(np.abs(rotation.T @ rotation - np.eye(3)).max())


def node_margin(frame_a: FrameTree, pose_a, frame_b: FrameTree, pose_b,
                rounding: float = MARGIN_ROUNDING,
                per_deviation: float = MARGIN_PER_DEVIATION) -> float:
    """The node test's margin for these two bodies (module docstring)."""
    scale = frame_a.reach + frame_b.reach + float(np.max(np.abs(pose_a[1]) + np.abs(pose_b[1])))
    return (rounding + per_deviation * max(deviation(pose_a[0]), deviation(pose_b[0]))) * scale


def boxes_apart(M, T, half_a, half_b, margin: float) -> bool:
    """Whether a separating axis puts the two boxes more than ``margin`` apart.

    Box a is axis-aligned with half-extents ``half_a``; box b has axes the
    columns of ``M``, half-extents ``half_b`` and its centre at ``T`` from
    a's centre. The 15 candidate axes of two boxes, in the order of the
    compiled kernel: a's face normals e_i, b's face normals M[:, j], and the
    cross products e_i x M[:, j].
    """
    absM = np.abs(M)
    for i in range(3):
        if abs(T[i]) > half_a[i] + half_b @ absM[i] + margin:
            return True
    for j in range(3):
        if abs(T @ M[:, j]) > half_a @ absM[:, j] + half_b[j] + margin:
            return True
    for i in range(3):
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            projection = T[i2] * M[i1, j] - T[i1] * M[i2, j]
            radius = (half_a[i1] * absM[i2, j] + half_a[i2] * absM[i1, j]
                      + half_b[j1] * absM[i, j2] + half_b[j2] * absM[i, j1])
            if abs(projection) > radius + margin:
                return True
    return False


def candidate_pairs(mesh_a, pose_a, mesh_b, pose_b, *,
                    margin_rounding: float = MARGIN_ROUNDING,
                    margin_per_deviation: float = MARGIN_PER_DEVIATION) -> np.ndarray:
    """The triangle pairs the traversal hands to the exact test: their leaves'
    node boxes are not separated and their world triangle boxes overlap.
    A superset of the intersecting pairs. (k, 2) int64, rows sorted; poses
    already checked."""
    fa, fb = frame_tree_of(mesh_a), frame_tree_of(mesh_b)
    M, u = relative_frame(pose_a, pose_b)
    margin = node_margin(fa, pose_a, fb, pose_b, margin_rounding, margin_per_deviation)
    lo_a, hi_a = triangle_boxes(world_vertices(mesh_a, pose_a), mesh_a.faces)
    lo_b, hi_b = triangle_boxes(world_vertices(mesh_b, pose_b), mesh_b.faces)
    ta, tb = fa.tree, fb.tree

    def members(tree, node):
        return tree.order[tree.start[node]:tree.start[node] + tree.count[node]]

    found = []
    stack = [(0, 0)]
    while stack:
        a, b = stack.pop()
        T = M @ fb.centre[b] + u - fa.centre[a]
        half_a, half_b = fa.half[a], fb.half[b]
        if boxes_apart(M, T, half_a, half_b, margin):
            continue
        leaf_a, leaf_b = ta.left[a] < 0, tb.left[b] < 0
        if leaf_a and leaf_b:
            for i in members(ta, a):
                for j in members(tb, b):
                    if (lo_a[i] <= hi_b[j]).all() and (lo_b[j] <= hi_a[i]).all():
                        found.append((int(i), int(j)))
        elif leaf_b or (not leaf_a and half_a.sum() >= half_b.sum()):
            stack += [(ta.right[a], b), (ta.left[a], b)]          # open the bigger node
        else:
            stack += [(a, tb.right[b]), (a, tb.left[b])]
    pairs = np.array(found, dtype=np.int64).reshape(-1, 2)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]


# -- the compiled kernel and the public entry points ------------------------------------


@functools.cache
def _compiled():
    """The compiled ``exact_query``, or None without numba."""
    try:
        from refsim.collision import _numba_kernels as nk
    except ImportError:
        return None
    return nk.exact_query


_FLOAT64 = np.dtype(np.float64)
#: shape and strides of a C-contiguous float64 (3, 3) rotation and (3,) translation
_POSE_LAYOUT = ((3, 3), (24, 8), (3,), (8,))


def _pose_arrays(pose, what: str):
    """The pose as two float64 C-contiguous arrays: as given when it already
    is (the compiled query checks the values; this check costs ~0.3 us
    against ~5 us for ``as_pose``), else through ``as_pose``."""
    if type(pose) is tuple and len(pose) == 2:
        rotation, translation = pose
        if (type(rotation) is np.ndarray and type(translation) is np.ndarray
                and rotation.dtype is _FLOAT64 and translation.dtype is _FLOAT64
                and (rotation.shape, rotation.strides, translation.shape,
                     translation.strides) == _POSE_LAYOUT):
            return pose
    rotation, translation = as_pose(pose, what=what)
    return np.ascontiguousarray(rotation), np.ascontiguousarray(translation)


def query_compiled(mesh_a, pose_a, mesh_b, pose_b, mode: int, *,
                   margin_rounding: float = MARGIN_ROUNDING,
                   margin_per_deviation: float = MARGIN_PER_DEVIATION):
    """Run the compiled query: ``(found, uncertain)`` as the kernel returns
    them (see :func:`refsim.collision._numba_kernels.exact_query`).

    Raises
    ------
    StateError
        For a pose that is not a valid rigid transform (as ``as_pose``).
    """
    ra, ta = pose_a = _pose_arrays(pose_a, "pose_a")
    rb, tb = pose_b = _pose_arrays(pose_b, "pose_b")
    fa, fb = frame_tree_of(mesh_a), frame_tree_of(mesh_b)
    status, found, uncertain = _compiled()(
        mesh_a.vertices, mesh_a.faces, fa.links, fa.tree.order, fa.boxes, fa.reach, ra, ta,
        mesh_b.vertices, mesh_b.faces, fb.links, fb.tree.order, fb.boxes, fb.reach, rb, tb,
        mode, ORTHONORMAL_TOL, margin_rounding, margin_per_deviation)
    if status:
        what, pose = ("pose_a", pose_a) if status == 1 else ("pose_b", pose_b)
        as_pose(pose, what=what)     # raises with the precise reason
        # as_pose's Gram product rounds differently; at the tolerance's edge
        # it may accept what the kernel rejected: reject all the same.
        raise StateError(f"{what}: rotation is not orthonormal")
    return found, uncertain


def _sorted(pairs: np.ndarray) -> np.ndarray:
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))] if len(pairs) > 1 else pairs


def _resolve(mesh_a, pose_a, mesh_b, pose_b, uncertain: np.ndarray) -> np.ndarray:
    """Which of the pairs the float filter left open intersect (readable
    exact kernel); bool (k,)."""
    world_a = world_vertices(mesh_a, as_pose(pose_a))
    world_b = world_vertices(mesh_b, as_pose(pose_b))
    return np.array([triangles_intersect(world_a[mesh_a.faces[i]], world_b[mesh_b.faces[j]])
                     for i, j in uncertain], dtype=bool)


def intersecting_pairs_bvh(mesh_a, pose_a, mesh_b, pose_b, kernel: str) -> np.ndarray:
    """All intersecting face pairs, (k, 2) int64 with rows sorted."""
    if kernel == "python":
        pose_a, pose_b = as_pose(pose_a, what="pose_a"), as_pose(pose_b, what="pose_b")
        candidates = candidate_pairs(mesh_a, pose_a, mesh_b, pose_b)
        return exact_pairs(world_vertices(mesh_a, pose_a), mesh_a.faces,
                           world_vertices(mesh_b, pose_b), mesh_b.faces, candidates, "python")
    found, uncertain = query_compiled(mesh_a, pose_a, mesh_b, pose_b, ALL_HITS)
    if len(uncertain):
        hit = _resolve(mesh_a, pose_a, mesh_b, pose_b, uncertain)
        found = np.concatenate([found, uncertain[hit]])
    return _sorted(found)


def collide_bvh(mesh_a, pose_a, mesh_b, pose_b, kernel: str) -> bool:
    """Whether any pair of triangles intersects; stops at the first."""
    if kernel == "python":
        return len(intersecting_pairs_bvh(mesh_a, pose_a, mesh_b, pose_b, kernel)) > 0
    found, uncertain = query_compiled(mesh_a, pose_a, mesh_b, pose_b, FIRST_HIT)
    if len(found):
        return True
    return bool(len(uncertain)) and bool(_resolve(mesh_a, pose_a, mesh_b, pose_b,
                                                   uncertain).any())
