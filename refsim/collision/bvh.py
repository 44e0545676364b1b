"""A bounding-volume hierarchy over triangles: the seed's wish for "more
levels of hierarchy" (seed S4, "Existing Problems"), giving the same pairs as
its test 2 in far fewer box tests.

Build (once per mesh, body space): a binary tree of triangles, split at the
median triangle centroid, until a leaf holds at most ``LEAF_SIZE`` triangles
(top-down median split; G. van den Bergen, "Efficient Collision Detection of
Complex Deformable Models using AABB Trees", JGT 1997, which also argues for
refitting). Of the three axes, the split takes the one whose two halves have
the least total box surface area (the cost measure of J. D. MacDonald and
K. S. Booth, "Heuristics for ray tracing using space subdivision", 1990).
Against the longest-axis split and OBBTree's principal-axis split it visits
fewer node pairs on most of the benchmark poses, not on all of them (the
trials, counted in node pairs: docs/decisions/hierarchy-split.md).
Nodes are numbered in pre-order, so every child has a larger index than its
parent.

Query (per pose): transform the vertices, compute each triangle's world box,
and refit the tree bottom-up (a node's box is the union of its children's).
The boxes are then exact unions of the same floats the seed's test 2 uses,
so no padding is needed and no touching pair can be lost. Then descend both
trees together from the roots, dropping every pair of nodes whose boxes are
apart, and at pairs of leaves test the triangle boxes themselves. Each pair
of leaves is reached at most once, so each triangle pair is reported once.

Two kernels do the same arithmetic: :func:`prepare` and :func:`traverse`
(``refit`` and ``_pairs_python``: plain loops, the reference) and a
numba-compiled mirror of each (:mod:`refsim.collision._numba_kernels`), each
pair chosen by ``kernel=`` through its :class:`refsim.kernels.KernelPair`
("readable" or "compiled").
The build too: :func:`build_tree` (the reference) and
:func:`build_tree_compiled` (:mod:`refsim.collision._numba_build`), the same
tree bit for bit, chosen by :func:`tree_of`'s ``kernel=``.

This path serves level "triangle-aabb", whose answer is test 2's pairs. The
exact level only needs a superset of the intersecting pairs and uses the
cheaper traversal of :mod:`refsim.collision.bvh_exact`, over a tree built by
this module's :func:`build_tree` with a split of its own (oriented node
boxes want another split than axis-aligned ones).

Cost: build O(m log m) once; transform, boxes and refit O(n + m) per query;
traversal about O(k log m) for k overlapping node pairs in practice, against
O(ka kb) box tests for the seed's test 2.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from refsim.bounds.aabb_linear import transform_vertices
from refsim.collision.boxes import triangle_boxes
from refsim.errors import check_option
from refsim.kernels import HIERARCHY_BUILD, HIERARCHY_REFIT, HIERARCHY_TRAVERSAL, resolve
from refsim.types import unit_exponent

#: Triangles per leaf. Small leaves prune more; each leaf-leaf visit costs
#: LEAF_SIZE^2 box tests. 4 was fastest for 2k-triangle meshes here (the
#: collision benchmarks); the answers do not depend on it.
LEAF_SIZE = 4


@dataclass(frozen=True)
class TriangleTree:
    """The topology of the hierarchy (body space, built once).

    left, right : (nodes,) int64, children; -1 at a leaf.
    start, count : (nodes,) int64, a leaf's triangles are
        ``order[start:start + count]``.
    order : (m,) int64, triangle indices, each leaf's contiguous.
    """

    left: np.ndarray
    right: np.ndarray
    start: np.ndarray
    count: np.ndarray
    order: np.ndarray

    @property
    def n_nodes(self) -> int:
        return len(self.left)


def _surface_area(lo: np.ndarray, hi: np.ndarray) -> float:
    """Surface area / 2 of the box covering the boxes ``lo``, ``hi`` (k, 3)."""
    d = hi.max(axis=0) - lo.min(axis=0)
    return float(d[0] * d[1] + d[1] * d[2] + d[2] * d[0])


def least_area_split(triangles: np.ndarray, members: np.ndarray, mid: int) -> np.ndarray:
    """``members`` (triangle indices, k > 1) ranked by centroid along the axis
    whose halves ``[:mid]`` and ``[mid:]`` have the least total box surface
    area; ``triangles`` (m, 3, 3) as :func:`build_tree` scales them."""
    centroids = triangles[members].mean(axis=1)
    tri_lo, tri_hi = triangles[members].min(axis=1), triangles[members].max(axis=1)
    best_area = np.inf
    for axis in range(3):
        # stable tie-break by index, so the same mesh always gives the same tree
        ranked = np.lexsort((members, centroids[:, axis]))
        first, second = ranked[:mid], ranked[mid:]
        area = (_surface_area(tri_lo[first], tri_hi[first])
                + _surface_area(tri_lo[second], tri_hi[second]))
        if area < best_area:                  # ties keep the lower axis
            best_area, best = area, ranked
    return members[best]


def scaled_triangles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(m, 3, 3): each face's vertices times ``2**-e``, as :func:`build_tree`
    chooses its splits on them."""
    return np.ldexp(vertices, -unit_exponent(vertices))[faces]


def build_tree(vertices: np.ndarray, faces: np.ndarray, leaf_size: int = LEAF_SIZE,
               split=least_area_split) -> TriangleTree:
    """Top-down median split: each node's triangles ranked by ``split``
    (by default :func:`least_area_split`), the first half to the left child."""
    # The split is chosen on coordinates times 2**-e (every one below 1): the
    # areas of boxes of a mesh with coordinates near 1e154 would overflow to
    # inf (and inf - inf to nan), leaving no axis "best". The tree's
    # topology is all that is built here, and scaling by a power of two
    # changes no comparison.
    triangles = scaled_triangles(vertices, faces)
    order = np.arange(len(faces), dtype=np.int64)
    left, right, start, count = [], [], [], []

    def new_node(lo: int, hi: int) -> int:
        left.append(-1)
        right.append(-1)
        start.append(lo)
        count.append(hi - lo)
        return len(left) - 1

    stack = [(new_node(0, len(faces)), 0, len(faces))]
    while stack:
        node, lo, hi = stack.pop()
        if hi - lo <= leaf_size:
            continue
        mid = (hi - lo) // 2
        order[lo:hi] = split(triangles, order[lo:hi], mid)
        a = new_node(lo, lo + mid)
        b = new_node(lo + mid, hi)
        left[node], right[node] = a, b
        stack += [(b, lo + mid, hi), (a, lo, lo + mid)]
    as_array = lambda x: np.asarray(x, dtype=np.int64)  # noqa: E731
    return TriangleTree(as_array(left), as_array(right), as_array(start), as_array(count), order)


@functools.cache
def build_kernels():
    """The compiled build's module, :mod:`refsim.collision._numba_build`
    (imported on first use: it imports numba)."""
    from refsim.collision import _numba_build

    return _numba_build


#: The split rules both builds know, by the names :func:`build_tree_by_name`
#: and :func:`build_tree_compiled` take: this module's :func:`least_area_split`
#: and the exact level's :func:`refsim.collision.bvh_exact.least_volume_split`
#: (as ``module:function``, imported on use: that module imports this one).
SPLITS = {"least-area": "refsim.collision.bvh:least_area_split",
          "least-volume": "refsim.collision.bvh_exact:least_volume_split"}
SPLIT_RULES = tuple(SPLITS)


def build_tree_by_name(vertices: np.ndarray, faces: np.ndarray, split: str = "least-area",
                       leaf_size: int = LEAF_SIZE) -> TriangleTree:
    """:func:`build_tree` with the split rule named by ``split``
    (:data:`SPLIT_RULES`): the readable twin of :func:`build_tree_compiled`,
    with its signature (:data:`refsim.kernels.HIERARCHY_BUILD`)."""
    check_option("split", split, SPLIT_RULES)
    return build_tree(vertices, faces, leaf_size, split=resolve(SPLITS[split]))


def build_tree_compiled(vertices: np.ndarray, faces: np.ndarray, split: str = "least-area",
                        leaf_size: int = LEAF_SIZE) -> TriangleTree:
    """:func:`build_tree` compiled (:func:`refsim.collision._numba_build.build_tree`):
    the same tree, every array bit for bit, with the split rule named by
    ``split`` (:data:`SPLIT_RULES`)."""
    check_option("split", split, SPLIT_RULES)
    nb = build_kernels()
    rule = nb.LEAST_AREA if split == "least-area" else nb.LEAST_VOLUME
    return TriangleTree(*nb.build_tree_of(kernel_array(vertices, np.float64),
                                          kernel_array(faces, np.int64), leaf_size, rule))


def kernel_array(array: np.ndarray, dtype) -> np.ndarray:
    """``array`` as the compiled build takes a mesh's arrays: C-contiguous,
    of ``dtype``, read-only (a Mesh's arrays already are, and pass as they
    are). One layout, so that numba compiles each build kernel for one
    signature (a read-only array is another type than a writable one)."""
    if array.dtype == dtype and array.flags.c_contiguous and not array.flags.writeable:
        return array
    array = np.array(array, dtype=dtype, order="C")
    array.flags.writeable = False
    return array


def tree_of(mesh, kernel: str | None = None) -> TriangleTree:
    """The mesh's hierarchy, built on first use and kept with the mesh, by
    the readable :func:`build_tree` or its compiled twin (``kernel``, see
    :mod:`refsim.kernels`; the same tree either way)."""
    def build(m) -> TriangleTree:
        return HIERARCHY_BUILD(kernel)(m.vertices, m.faces, "least-area")

    return mesh.derived("triangle_tree", build)


# -- the readable kernel ---------------------------------------------------------


def refit(tree: TriangleTree, tri_lo: np.ndarray, tri_hi: np.ndarray):
    """Node boxes (nodes, 3) as exact unions of the triangle boxes."""
    lo = np.empty((tree.n_nodes, 3))
    hi = np.empty((tree.n_nodes, 3))
    for node in range(tree.n_nodes - 1, -1, -1):     # children before parents
        if tree.left[node] < 0:
            members = tree.order[tree.start[node]:tree.start[node] + tree.count[node]]
            lo[node] = tri_lo[members].min(axis=0)
            hi[node] = tri_hi[members].max(axis=0)
        else:
            a, b = tree.left[node], tree.right[node]
            lo[node] = np.minimum(lo[a], lo[b])
            hi[node] = np.maximum(hi[a], hi[b])
    return lo, hi


def _pairs_python(tree_a, lo_a, hi_a, tri_lo_a, tri_hi_a,
                  tree_b, lo_b, hi_b, tri_lo_b, tri_hi_b, first_only: bool) -> list:
    """Simultaneous descent; returns the (i, j) of overlapping triangle boxes."""

    def apart(l1, h1, l2, h2):
        return (l1 > h2).any() or (l2 > h1).any()

    found = []
    stack = [(0, 0)]
    while stack:
        a, b = stack.pop()
        if apart(lo_a[a], hi_a[a], lo_b[b], hi_b[b]):
            continue
        leaf_a, leaf_b = tree_a.left[a] < 0, tree_b.left[b] < 0
        if leaf_a and leaf_b:
            for i in tree_a.order[tree_a.start[a]:tree_a.start[a] + tree_a.count[a]]:
                for j in tree_b.order[tree_b.start[b]:tree_b.start[b] + tree_b.count[b]]:
                    if not apart(tri_lo_a[i], tri_hi_a[i], tri_lo_b[j], tri_hi_b[j]):
                        found.append((int(i), int(j)))
                        if first_only:
                            return found
        elif leaf_b or (not leaf_a and _size(lo_a[a], hi_a[a]) >= _size(lo_b[b], hi_b[b])):
            stack += [(tree_a.right[a], b), (tree_a.left[a], b)]    # open the bigger node
        else:
            stack += [(a, tree_b.right[b]), (a, tree_b.left[b])]
    return found


def _size(lo, hi) -> float:
    d = hi - lo
    return d[0] + d[1] + d[2]


def prepare(vertices, faces, rotation, translation, left, right, start, count, order):
    """A body's per-pose work (readable): its world vertices, its
    triangles' boxes and the node boxes refit from them, ``(world, lo, hi,
    tri_lo, tri_hi)``. The tree comes as its five arrays, the signature of
    the compiled twin (:data:`refsim.kernels.HIERARCHY_REFIT`)."""
    world = transform_vertices(vertices, (rotation, translation))
    tri_lo, tri_hi = triangle_boxes(world, faces)
    lo, hi = refit(TriangleTree(left, right, start, count, order), tri_lo, tri_hi)
    return world, lo, hi, tri_lo, tri_hi


def traverse(left_a, right_a, start_a, count_a, order_a, lo_a, hi_a, tri_lo_a, tri_hi_a,
             left_b, right_b, start_b, count_b, order_b, lo_b, hi_b, tri_lo_b, tri_hi_b,
             first_only: bool) -> np.ndarray:
    """:func:`_pairs_python` over two trees given as their arrays, the
    signature of the compiled twin (:data:`refsim.kernels.HIERARCHY_TRAVERSAL`):
    the (k, 2) int64 pairs in the order found."""
    found = _pairs_python(TriangleTree(left_a, right_a, start_a, count_a, order_a),
                          lo_a, hi_a, tri_lo_a, tri_hi_a,
                          TriangleTree(left_b, right_b, start_b, count_b, order_b),
                          lo_b, hi_b, tri_lo_b, tri_hi_b, first_only)
    return np.array(found, dtype=np.int64).reshape(-1, 2)


# -- a query: both kernels through their pairs ------------------------------------
#
# The compiled twins of prepare and traverse (refsim.collision._numba_kernels)
# do the same steps in plain loops, with refsim's one transform arithmetic
# ((R[k,0] x + R[k,1] y) + R[k,2] z + t[k], see refsim.bounds.aabb_linear), so
# the boxes are the same floats.
#
# DEVIATION from a lazier design, measured and rejected: carrying each node's
# body-space box to the world at every visit (the box of the rotated box)
# instead of refitting touches less up front but yields boxes up to sqrt(3)
# larger, and visited about 3x more node pairs on the 2k-triangle benchmarks,
# slower in every configuration. (The exact level's traversal,
# refsim.collision.bvh_exact, is lazy too but tests the rotated box itself, by
# separating axes, which is as tight as the body-space box.)


@dataclass(frozen=True)
class PreparedBody:
    """A body at a pose, ready to traverse: its world vertices, the refit
    node boxes and the triangle boxes (the per-query O(n + m) work)."""

    mesh: object
    tree: TriangleTree
    world: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    tri_lo: np.ndarray
    tri_hi: np.ndarray


def prepare_body(mesh, pose, kernel: str) -> PreparedBody:
    """Transform, box and refit one body (``kernel`` already chosen)."""
    tree = tree_of(mesh, kernel)
    world, lo, hi, tri_lo, tri_hi = HIERARCHY_REFIT.pick(kernel)(
        mesh.vertices, mesh.faces, pose[0], pose[1], tree.left, tree.right, tree.start,
        tree.count, tree.order)
    return PreparedBody(mesh, tree, world, lo, hi, tri_lo, tri_hi)


def tree_box_pairs(pa: PreparedBody, pb: PreparedBody, kernel: str,
                   first_only: bool = False) -> np.ndarray:
    """Every (i, j) whose world triangle boxes overlap, via the hierarchy
    (``kernel`` already chosen).

    Returns (k, 2) int64 with rows sorted; with ``first_only`` at most one row.
    """
    ta, tb = pa.tree, pb.tree
    pairs = HIERARCHY_TRAVERSAL.pick(kernel)(
        ta.left, ta.right, ta.start, ta.count, ta.order, pa.lo, pa.hi, pa.tri_lo, pa.tri_hi,
        tb.left, tb.right, tb.start, tb.count, tb.order, pb.lo, pb.hi, pb.tri_lo, pb.tri_hi,
        first_only)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
