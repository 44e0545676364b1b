"""The exact level through the triangle hierarchy, traversed in the first
body's frame (seed S4's "more levels of hierarchy", for test 3).

The refit hierarchy of :mod:`refsim.collision.bvh` reproduces the seed's
test 2 pair for pair, but pays for it on every query: it transforms every
vertex and refits every node box of both bodies before it looks at a single
pair. The exact level does not need test 2's pairs, only a superset of the
intersecting ones, so this query follows RAPID and FCL instead (S. Gottschalk,
M. C. Lin, D. Manocha, "OBBTree: A Hierarchical Structure for Rapid
Interference Detection", SIGGRAPH 1996):

1. Node volumes are oriented boxes in body space, computed once per mesh
   (:class:`FrameTree`: a tree of :func:`refsim.collision.bvh.build_tree`
   split across the one of each node's principal axes whose halves have
   the least total box volume, the area breaking near ties,
   :func:`least_volume_split`; each node's box
   along the principal axes of its vertices, :func:`oriented_box`,
   :func:`principal_axes`). On a curved surface such a box is about as thin
   as the patch is bent, where the axis-aligned box of a tilted patch is as
   thick as the patch is wide: on the separated sphere benchmark the query
   visited 117 node pairs against 751 with axis-aligned node boxes, 2185
   against 4025 on the deep one (both over the least-area tree of
   :mod:`refsim.collision.bvh`; the least-volume split visits 127 and 2255
   there, and 25 instead of 247 on two linked tori).
2. A query expresses body b in a's frame, ``x_a = M x_b + u`` with
   ``M = Ra^T Rb`` and ``u = Ra^T (tb - ta)``, and a pair of nodes in the
   frame of node a's box (:func:`node_pair_frame`: ``R = Aa^T M Ab``,
   ``T = Aa^T (M cb + u - ca)`` for axes A and centres c). The pair is
   dropped when one of the 15 separating axes of two boxes (three face
   normals of each, nine edge-edge cross products) separates them by more
   than a margin (:func:`boxes_apart`). Nothing is transformed for a node
   that is never visited.
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
triangles. Let ``S = reach_a + reach_b + max_k (|ta_k| + |tb_k|)``, where
``reach`` is the largest absolute body coordinate of a mesh (a node box's
centre then lies within 3 reach of the origin and its half-extents are at
most sqrt(3) reach), u = 2^-53, and g the largest ``max|Q^T Q - I|`` of the
two rotations and of all node axes Q (``refsim.types.ORTHONORMAL_TOL``
allows 1e-6 for a rotation; the axes, computed eigenvectors, are within
about 15u on the bundled meshes); in the 2-norm ``|Q^T Q - I| <= 3g``. Along
a separating axis of length 1 + O(g), the test can be wrong by (crude
bounds):

- rounding. A world vertex is off by <= 4u(3 reach + |t|) a coordinate,
  about 21u S in length (Ra^T and Aa^T do not lengthen it). R and T come
  from two and three rounds of three-term dot products: an entry of R is off
  by <= 63u, of T by <= 100u S, so the two sides of a comparison (|T| <= 3S,
  half-extents <= sqrt(3) reach) by <= 900u S between them, the half-extents
  by another ~20u reach. Under 1000u S in all.
- rotations off orthonormal. Ra^T is not Ra's inverse, so a's points appear
  moved by up to ``|Ra^T Ra - I| |p| <= 3g sqrt(3) reach_a``. Node b's box
  is the set ``cb + Ab^-T s`` (``|s_j| <= h_j``) and the test takes Ab for
  Ab^-T: off by <= 3g 3 reach_b. And the test's extents of b along b's face
  normals and the edge axes assume R orthonormal, where
  ``|R^T R - I| <= 12g``: off by <= 36g reach_b and <= 104g reach_b. (Node
  a's extents and the projections of T are right for any R; node a's box is
  exact in its own frame, since T is the very expression it is defined by.
  Axes with determinant -1 (about 40% of the nodes' principal axes)
  change nothing: the extents take absolute values and the boxes are
  symmetric.) Under 120 g S in all.

The margin is ``(MARGIN_ROUNDING + MARGIN_PER_DEVIATION * g) S`` with 2^-40
(8192 u) and 1024, each about eight times its bound: a node pair closer than
the margin is simply visited, which costs a few node tests and changes no
answer (with g ~ 15u from the node axes, the second term is about twice the
first: a margin near 3e-12 S). The tests check that the margin is needed
(with it set to zero, pairs that intersect by less than it are lost) and
sufficient (random and near-touching poses, rotations and node axes off
orthonormal by up to the tolerance).

Two kernels take the same steps: :func:`candidate_pairs` (readable loops)
and a numba-compiled copy (``refsim[fast]``,
:func:`refsim.collision._numba_kernels.exact_query`) that also certifies the
pairs with the float filter as it finds them and can stop at the first hit.
The compiled copy checks the poses itself (the checks of
:func:`refsim.types.as_pose`), which keeps a query's fixed cost small
(docs/decisions/query-fixed-cost.md). The two evaluate the same formulas
in the same order, the readable one on Python floats (the relative frame,
the margin, each node pair's frame and its fifteen axes, the choice of the
node to open), so they visit the same node pairs and find the same
candidates; either's rounding is within the margin's bound in any case.

The pairs the compiled filter cannot certify (on touching bodies, nearly
all of them) are answered by the compiled exact stage
(:mod:`refsim.collision._numba_exact`: the readable triangle test over exact
expansion predicates), and the few it does not take (degenerate triangles,
coordinates outside the filter's range) by the readable exact kernel. The
boolean query (:func:`collide_compiled`) runs that stage inside the traversal,
pair by pair, and stops at the first pair either decides intersecting; the
all-pairs query collects the open pairs and answers them after.

A query's fixed cost (docs/decisions/query-fixed-cost.md): each mesh's
constant arrays travel packed in two (:func:`pack_frame_tree`, built once),
since numba unboxes every array argument at every call; the boolean query's
kernel returns one number, and its poses go to numba unchecked, its one
compiled signature refusing any other layout (then :func:`as_pose` converts).
Building the tree: :func:`build_frame_tree` (readable) or its compiled
twin (:func:`build_frame_tree_compiled`, :mod:`refsim.collision._numba_build`),
chosen by ``kernel=`` like the query and equal to it bit for bit
(tests/collision/test_tree_build.py); both without BLAS or LAPACK, so a
mesh has the same tree on every machine.
Cost: O(m log m) once per mesh for the tree and its boxes (3x3
eigenproblems: seven for a node split above SMALL_NODE triangles, the six
candidate halves of the split and the box; at most two for a smaller one,
its own axes and its box; one for a leaf);
per query about O(k log m) node
tests for k overlapping node pairs, plus O(1) per vertex and triangle of the
leaves reached. The speed against FCL is measured in
:func:`refsim.studies.levels.measure_hierarchy_speed`.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from refsim.collision.boxes import triangle_boxes, world_vertices
from refsim.collision.bvh import (
    LEAF_SIZE,
    TriangleTree,
    build_kernels,
    kernel_array,
)
from refsim.collision.seed_levels import exact_pairs
from refsim.collision.triangle import triangles_intersect
from refsim.collision.triangle_numba import compiled_exact_kernels
from refsim.errors import StateError
from refsim.kernels import (
    HIERARCHY_BUILD,
    ORIENTED_NODE_BOXES,
)
from refsim.types import ORTHONORMAL_TOL, as_pose, unit_exponent

#: The node test's margin, relative to the scene's size S (see the module
#: docstring): 8192 unit roundoffs against the < 1000 the arithmetic can
#: lose...
MARGIN_ROUNDING = 2.0 ** -40
#: ... plus this many times the rotations' and node axes' departure from
#: orthonormality (< 120 needed).
MARGIN_PER_DEVIATION = 1024.0

#: Modes of the compiled query (refsim.collision._numba_kernels).
ALL_HITS, FIRST_HIT, CANDIDATES = 0, 1, 2


@dataclass(frozen=True)
class FrameTree:
    """A mesh's hierarchy with an oriented box per node, in body space (built
    once).

    tree : the topology (:class:`refsim.collision.bvh.TriangleTree`).
    links : (nodes, 4) int64, the tree's left, right, start, count as columns
        (one array, for the compiled kernel).
    boxes : (nodes, 15) float64, each node's box: centre xyz, half-extents
        along its three axes, then the (3, 3) matrix whose columns are the
        axes, row by row.
    reach : the largest absolute body coordinate of the mesh.
    axes_deviation : the largest ``max |A^T A - I|`` of the node axes A (a few
        roundoffs: the axes are computed eigenvectors); the node test's
        margin counts it like a pose rotation's.

    A node's box is the set of points p with ``|A[:, i] . (p - centre)| <=
    half[i]`` for each axis i, and ``half`` is computed from the node's
    vertices with that very expression, so the box holds them (and their
    triangles) up to the rounding of one dot product, which the margin covers.
    """

    tree: TriangleTree
    links: np.ndarray
    boxes: np.ndarray
    reach: float
    axes_deviation: float

    @property
    def centre(self) -> np.ndarray:
        return self.boxes[:, :3]

    @property
    def half(self) -> np.ndarray:
        return self.boxes[:, 3:6]

    @property
    def axes(self) -> np.ndarray:
        """(nodes, 3, 3): ``axes[n][:, i]`` is node n's i-th axis."""
        return self.boxes[:, 6:].reshape(-1, 3, 3)


def principal_axes(points: np.ndarray) -> np.ndarray:
    """(3, 3), columns the principal axes of the points' covariance
    (Gottschalk et al. 1996 take the covariance of the triangles' hull; of
    the vertices is simpler and, on the benchmark meshes, visits about as
    many node pairs), in order of increasing variance, orthonormal up to a
    few roundoffs whatever the points. The covariance is taken of the points
    times ``2**-e`` (:func:`refsim.types.unit_exponent`): the axes do not
    change with the scale, and squares of coordinates near 1e154 would
    overflow.

    No BLAS or LAPACK: the covariance is sums of element-wise products and
    the eigenvectors come from :func:`symmetric_eigenvectors`, so a mesh has
    the same tree on every machine (with ``numpy.cov`` and
    ``numpy.linalg.eigh`` the tree, and the node pairs a query visits,
    changed with ``OPENBLAS_CORETYPE``)."""
    points = np.ldexp(points, -unit_exponent(points))
    if len(points) < 2:
        return np.eye(3)
    centred = points - points.mean(axis=0)
    covariance = [[float(np.sum(centred[:, i] * centred[:, j])) for j in range(3)]
                  for i in range(3)]
    return symmetric_eigenvectors(covariance)


#: Most sweeps of :func:`symmetric_eigenvectors` (three converge a 3 x 3
#: matrix to rounding; the bound only guards against a cycle).
JACOBI_SWEEPS = 50


def symmetric_eigenvectors(a: list[list[float]]) -> np.ndarray:
    """Eigenvectors (columns, orthonormal, by increasing eigenvalue) of the
    symmetric 3 x 3 matrix ``a``, by cyclic Jacobi rotations in a fixed order
    (Golub and Van Loan, *Matrix Computations*, 4th ed., section 8.5.2): plain
    floating-point arithmetic, the same bits on every machine. Each column's
    largest component is made positive."""
    a = [row[:] for row in a]
    v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    for _ in range(JACOBI_SWEEPS):
        if abs(a[0][1]) + abs(a[0][2]) + abs(a[1][2]) == 0.0:
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            if a[p][q] == 0.0:
                continue
            # the rotation that zeroes a[p][q]: t = tan(theta), the smaller root
            tau = (a[q][q] - a[p][p]) / (2.0 * a[p][q])
            t = (1.0 if tau >= 0.0 else -1.0) / (abs(tau) + math.sqrt(1.0 + tau * tau))
            c = 1.0 / math.sqrt(1.0 + t * t)
            s = t * c
            for k in range(3):                        # a <- a J (columns p, q)
                akp, akq = a[k][p], a[k][q]
                a[k][p], a[k][q] = c * akp - s * akq, s * akp + c * akq
            for k in range(3):                        # a <- J^T a (rows p, q)
                apk, aqk = a[p][k], a[q][k]
                a[p][k], a[q][k] = c * apk - s * aqk, s * apk + c * aqk
            a[p][q] = a[q][p] = 0.0
            for k in range(3):                        # v <- v J
                vkp, vkq = v[k][p], v[k][q]
                v[k][p], v[k][q] = c * vkp - s * vkq, s * vkp + c * vkq
    order = sorted(range(3), key=lambda i: (a[i][i], i))
    axes = np.array([[v[k][i] for i in order] for k in range(3)])
    for i in range(3):
        column = axes[:, i]
        if column[int(np.argmax(np.abs(column)))] < 0.0:
            axes[:, i] = -column
    return axes


def project(points: np.ndarray, axes: np.ndarray) -> np.ndarray:
    """``points @ axes`` without BLAS: (k, 3), each entry
    ``(p0 a0j + p1 a1j) + p2 a2j``."""
    return (points[:, 0:1] * axes[0] + points[:, 1:2] * axes[1]) + points[:, 2:3] * axes[2]


def oriented_box(points: np.ndarray, axes: np.ndarray | None = None):
    """``(centre, half, axes)`` of the box about ``points`` (k, 3) along
    ``axes`` (columns; by default :func:`principal_axes`). The box is the set
    ``|axes[:, i] . (p - centre)| <= half[i]``, and ``half`` is computed with
    that expression, so it holds the points for any axes (a flat or a
    one-point set gives a box of zero thickness)."""
    axes = principal_axes(points) if axes is None else axes
    projected = project(points, axes)
    mid = (projected.min(axis=0) + projected.max(axis=0)) / 2
    centre = (axes[:, 0] * mid[0] + axes[:, 1] * mid[1]) + axes[:, 2] * mid[2]
    half = np.abs(project(points - centre, axes)).max(axis=0)
    return centre, half, axes


def box_volume(points: np.ndarray) -> float:
    """Volume of the box about ``points`` (k, 3) along their principal axes."""
    return float(np.prod(box_sides(points)))


def box_sides(points: np.ndarray) -> np.ndarray:
    """(3,): the side lengths of the box about ``points`` (k, 3) along their
    principal axes."""
    return _extents(project(points, principal_axes(points)))


def box_area(sides: np.ndarray) -> float:
    """Half the surface area of a box with these side lengths,
    ``(d0 d1 + d1 d2) + d2 d0``."""
    return float((sides[0] * sides[1] + sides[1] * sides[2]) + sides[2] * sides[0])


#: :func:`least_volume_split` counts two splits' volumes as a tie when the
#: larger is within this fraction of the least, and breaks the tie by area
#: (docs/decisions/tree-build.md, the trials of the split rule).
VOLUME_TIE = 0.1

#: :func:`least_volume_split` measures the candidate halves of a node of at
#: most this many triangles along the node's own principal axes
#: (docs/decisions/tree-build.md, "Fourth round").
SMALL_NODE = 64


def least_volume_split(triangles: np.ndarray, members: np.ndarray, mid: int, *,
                       tie: float = VOLUME_TIE, small: int = SMALL_NODE) -> np.ndarray:
    """``members`` ranked by centroid along one of the node's three principal
    axes, chosen by the oriented boxes of its halves ``[:mid]`` and
    ``[mid:]``: among the axes whose halves' total box volume is within
    ``tie`` of the least, the one whose halves' total box area is least (a
    split rule for :func:`refsim.collision.bvh.build_tree`; the triangles'
    vertices stand for the points, shared ones counted once per triangle).
    The trials of docs/decisions/split_rule_trials.py vary ``tie`` and
    ``small``.

    Splitting across the longest principal axis (OBBTree's rule) keeps a
    tube's segments short, which the least-area split of axis-aligned boxes
    does not, but it cuts a sphere's caps badly; choosing among the three
    axes by the children's volumes does well on both
    (docs/decisions/query-fixed-cost.md). Volume alone is blind where two
    splits give boxes of the same total volume: a ring about its axis cut
    into two flat rings (each as wide as the whole) or into two arcs (each
    half as wide). The area tells them apart; without it the tree of a
    torus about z was a stack of flat rings, and two such tori linked cost
    20 times the node pairs (docs/decisions/tree-build.md).

    Each half's box is along the half's own principal axes, except in a node
    of at most ``small`` triangles, where all six are along the node's: six
    eigenproblems fewer for each such split, where most of the nodes and
    most of the build's time are, for about as many node pairs in the
    queries (docs/decisions/tree-build.md, "Fourth round"). The node's
    frame at every node chose worse: the bundled sphere's caps cut so that
    a cube resting on it cost 505 node pairs instead of 331."""
    points = triangles[members]
    axes = principal_axes(points.reshape(-1, 3))
    centroids = project(points.mean(axis=1), axes)
    if len(members) <= small:
        projected = project(points.reshape(-1, 3), axes).reshape(len(members), 3, 3)

        def sides(part: np.ndarray) -> np.ndarray:
            return _extents(projected[part].reshape(-1, 3))
    else:
        def sides(part: np.ndarray) -> np.ndarray:
            return box_sides(points[part].reshape(-1, 3))
    volumes, areas, rankings = [], [], []
    for axis in range(3):
        # stable tie-break by index, so the same mesh always gives the same tree
        ranked = np.lexsort((members, centroids[:, axis]))
        first, second = sides(ranked[:mid]), sides(ranked[mid:])
        volumes.append(float(np.prod(first)) + float(np.prod(second)))
        areas.append(box_area(first) + box_area(second))
        rankings.append(ranked)
    bound = min(volumes) * (1.0 + tie)
    tied = [axis for axis in range(3) if volumes[axis] <= bound]
    best = min(tied, key=lambda axis: areas[axis])    # area ties keep the lower axis
    return members[rankings[best]]


def _extents(projected: np.ndarray) -> np.ndarray:
    """(3,): the side lengths of the box about projected points (k, 3)."""
    return projected.max(axis=0) - projected.min(axis=0)


def frame_topology_of(mesh, kernel: str | None = None) -> TriangleTree:
    """The exact level's tree (:func:`least_volume_split`), built once per
    mesh, by the readable :func:`refsim.collision.bvh.build_tree` or its
    compiled twin (``kernel``, :mod:`refsim.kernels`: the same tree)."""
    def build(m) -> TriangleTree:
        return HIERARCHY_BUILD(kernel)(m.vertices, m.faces, "least-volume")

    return mesh.derived("frame_topology", build)


def axes_deviation(axes: np.ndarray) -> float:
    """:func:`deviation` of node axes without BLAS: each entry of ``A^T A``
    summed as ``(a0i a0j + a1i a1j) + a2i a2j``, so that the tree's margin
    term is the same on every machine (``A.T @ A`` gave other last bits
    under other OpenBLAS kernels)."""
    gram = ((axes[0][:, None] * axes[0][None, :] + axes[1][:, None] * axes[1][None, :])
            + axes[2][:, None] * axes[2][None, :])
    return float(np.abs(gram - np.eye(3)).max())


def build_frame_tree(mesh, choose_axes=principal_axes) -> FrameTree:
    """The mesh's :class:`FrameTree`, each node's box along
    ``choose_axes(points)`` (the tests pass axes off orthonormal)."""
    tree = frame_topology_of(mesh, "readable")
    boxes = np.empty((tree.n_nodes, 15))
    largest_deviation = 0.0
    for node in range(tree.n_nodes):
        members = tree.order[tree.start[node]:tree.start[node] + tree.count[node]]
        points = mesh.vertices[np.unique(mesh.faces[members])]
        centre, half, axes = oriented_box(points, choose_axes(points))
        boxes[node] = np.concatenate([centre, half, axes.ravel()])
        # (a non-finite deviation, from coordinates near 1e154, makes the
        # margin infinite: nothing is dropped, every answer still exact)
        off = axes_deviation(axes)
        largest_deviation = max(largest_deviation, off if np.isfinite(off) else np.inf)
    return _frame_tree(mesh, tree, boxes, largest_deviation)


def _frame_tree(mesh, tree: TriangleTree, boxes: np.ndarray, largest_deviation: float):
    links = np.column_stack([tree.left, tree.right, tree.start, tree.count]).astype(np.int64)
    return FrameTree(tree, np.ascontiguousarray(links), boxes,
                     float(np.abs(mesh.vertices).max()), largest_deviation)


def build_frame_tree_compiled(mesh) -> FrameTree:
    """:func:`build_frame_tree` (with its default axes) compiled
    (:func:`refsim.collision._numba_build.frame_tree_arrays`): the same
    FrameTree, every array bit for bit. The one compiled call also gives
    the tree's topology and :func:`pack_frame_tree`'s arrays, which are
    kept with the mesh (as :func:`frame_topology_of` and the query keep
    them) unless already there: a new mesh's first query then makes no
    other build call."""
    (left, right, start, count, order, links, boxes, deviation, reach, floats,
     ints) = build_kernels().frame_tree_arrays(kernel_array(mesh.vertices, np.float64),
                                                kernel_array(mesh.faces, np.int64), LEAF_SIZE)
    tree = mesh.derived("frame_topology", lambda m: TriangleTree(left, right, start, count, order))
    mesh.derived("frame_tree_packed", lambda m: (floats, ints))
    return FrameTree(tree, links, boxes, float(reach), float(deviation))


def frame_tree_of(mesh, kernel: str | None = None) -> FrameTree:
    """The mesh's :class:`FrameTree`, built on first use and kept with the
    mesh, by :func:`build_frame_tree` or its compiled twin (``kernel``,
    :mod:`refsim.kernels`: the same tree)."""
    def build(m) -> FrameTree:
        return ORIENTED_NODE_BOXES(kernel)(m)

    return mesh.derived("frame_tree", build)


# -- the readable kernel ------------------------------------------------------------


def relative_frame(pose_a, pose_b) -> tuple[list, list]:
    """``(M, u)``: body b's coordinates in a's frame are ``M x + u``, with
    ``M = Ra^T Rb`` and ``u = Ra^T (tb - ta)``: lists (M by rows) of
    Python floats, each sum left to right, as the compiled kernel sums
    them."""
    (ra, ta), (rb, tb) = pose_a, pose_b
    ra, rb, ta, tb = ra.tolist(), rb.tolist(), ta.tolist(), tb.tolist()
    d = [tb[k] - ta[k] for k in range(3)]
    M = [[ra[0][i] * rb[0][j] + ra[1][i] * rb[1][j] + ra[2][i] * rb[2][j] for j in range(3)]
         for i in range(3)]
    u = [ra[0][i] * d[0] + ra[1][i] * d[1] + ra[2][i] * d[2] for i in range(3)]
    return M, u


def deviation(rotation) -> float:
    """``max |R^T R - I|``: how far a rotation is from orthonormal (each
    entry of ``R^T R`` summed left to right, as the compiled pose check
    sums it)."""
    R = np.asarray(rotation, dtype=np.float64).tolist()
    worst = 0.0
    for i in range(3):
        for j in range(3):
            gram = R[0][i] * R[0][j] + R[1][i] * R[1][j] + R[2][i] * R[2][j]
            worst = max(worst, abs(gram - (1.0 if i == j else 0.0)))
    return worst


def node_margin(frame_a: FrameTree, pose_a, frame_b: FrameTree, pose_b,
                rounding: float = MARGIN_ROUNDING,
                per_deviation: float = MARGIN_PER_DEVIATION) -> float:
    """The node test's margin for these two bodies (module docstring), in
    the compiled kernel's order of operations."""
    reach = frame_a.reach + frame_b.reach
    ta, tb = pose_a[1].tolist(), pose_b[1].tolist()
    scale = reach
    for k in range(3):
        scale = max(scale, reach + abs(ta[k]) + abs(tb[k]))
    g = max(max(deviation(pose_a[0]), deviation(pose_b[0])),
            max(frame_a.axes_deviation, frame_b.axes_deviation))
    return (rounding + per_deviation * g) * scale


def place(box_b: list, M: list, u: list) -> tuple[list, list]:
    """Node b's box in body a's frame: ``(p, P)``, its centre ``p = M cb + u``
    and its axes ``P = M Ab`` (rows), from its row of :attr:`FrameTree.boxes`
    as a list, and M (rows) and u as lists: Python floats, each sum left to
    right, as the compiled kernel sums them."""
    p = [M[i][0] * box_b[0] + M[i][1] * box_b[1] + M[i][2] * box_b[2] + u[i]
         for i in range(3)]
    P = [[M[i][0] * box_b[6 + j] + M[i][1] * box_b[9 + j] + M[i][2] * box_b[12 + j]
          for j in range(3)] for i in range(3)]
    return p, P


def node_pair_frame(box_a: list, p: list, P: list) -> tuple[list, list]:
    """``(T, R)``: node b's box in the frame of node a's box, whose axes are
    then the coordinate axes. ``box_a`` is a's row of :attr:`FrameTree.boxes`
    as a list (centre ca, half-extents, axes Aa row by row); ``(p, P)`` is
    b's box in a's body frame (:func:`place`). R's columns are b's axes, T
    is b's centre: ``R = Aa^T M Ab = Aa^T P``, ``T = Aa^T (M cb + u - ca)
    = Aa^T (p - ca)``, rows of lists."""
    d0, d1, d2 = p[0] - box_a[0], p[1] - box_a[1], p[2] - box_a[2]
    T, R = [], []
    for i in range(3):
        a0, a1, a2 = box_a[6 + i], box_a[9 + i], box_a[12 + i]      # column i of Aa
        T.append(a0 * d0 + a1 * d1 + a2 * d2)
        R.append([a0 * P[0][j] + a1 * P[1][j] + a2 * P[2][j] for j in range(3)])
    return T, R


def boxes_apart(T: list, R: list, half_a: list, half_b: list, margin: float) -> bool:
    """Whether a separating axis puts the two boxes more than ``margin`` apart.

    In box a's frame: box a is axis-aligned about the origin with
    half-extents ``half_a``; box b has axes the columns of ``R``,
    half-extents ``half_b`` and its centre at ``T`` (:func:`node_pair_frame`;
    lists of Python floats). The 15 candidate axes of two boxes, in the
    order of the compiled kernel: a's face normals e_i, b's face normals
    R[:, j], and the cross products e_i x R[:, j], each sum left to right
    as the compiled kernel sums it. Box b's extents along its own normals
    and the cross products assume R orthonormal; the margin covers an R
    that is so only to within a tolerance (module docstring).
    """
    Q = [[abs(x) for x in row] for row in R]                 # |R|
    h, g = half_a, half_b
    for i in range(3):
        if abs(T[i]) > h[i] + g[0] * Q[i][0] + g[1] * Q[i][1] + g[2] * Q[i][2] + margin:
            return True
    for j in range(3):
        if (abs(T[0] * R[0][j] + T[1] * R[1][j] + T[2] * R[2][j])
                > (h[0] * Q[0][j] + h[1] * Q[1][j] + h[2] * Q[2][j] + g[j]) + margin):
            return True
    for i in range(3):
        i1, i2 = (i + 1) % 3, (i + 2) % 3
        for j in range(3):
            j1, j2 = (j + 1) % 3, (j + 2) % 3
            projection = T[i2] * R[i1][j] - T[i1] * R[i2][j]
            radius = h[i1] * Q[i2][j] + h[i2] * Q[i1][j] + g[j1] * Q[i][j2] + g[j2] * Q[i][j1]
            if abs(projection) > radius + margin:
                return True
    return False


def candidate_pairs(mesh_a, pose_a, mesh_b, pose_b, *,
                    margin_rounding: float = MARGIN_ROUNDING,
                    margin_per_deviation: float = MARGIN_PER_DEVIATION,
                    kernel: str | None = None) -> np.ndarray:
    """The triangle pairs the traversal hands to the exact test: their leaves'
    node boxes are not separated and their world triangle boxes overlap.
    A superset of the intersecting pairs. (k, 2) int64, rows sorted; poses
    already checked. ``kernel`` builds trees not yet built."""
    return descend(mesh_a, pose_a, mesh_b, pose_b, margin_rounding=margin_rounding,
                   margin_per_deviation=margin_per_deviation, kernel=kernel)[0]


def descend(mesh_a, pose_a, mesh_b, pose_b, *,
            margin_rounding: float = MARGIN_ROUNDING,
            margin_per_deviation: float = MARGIN_PER_DEVIATION,
            kernel: str | None = None) -> tuple[np.ndarray, int]:
    """The readable traversal: ``(candidate pairs, node pairs visited)``;
    ``kernel`` builds the trees not yet built (:func:`frame_tree_of`)."""
    fa, fb = frame_tree_of(mesh_a, kernel), frame_tree_of(mesh_b, kernel)
    M, u = relative_frame(pose_a, pose_b)
    margin = node_margin(fa, pose_a, fb, pose_b, margin_rounding, margin_per_deviation)
    boxes_a = triangle_boxes(world_vertices(mesh_a, pose_a), mesh_a.faces)
    boxes_b = triangle_boxes(world_vertices(mesh_b, pose_b), mesh_b.faces)
    ta, tb = fa.tree, fb.tree
    # The tests below on Python floats (lists): the same arithmetic and
    # comparisons as on numpy's scalars, without an object made per number;
    # each node and leaf converted once per query, when first visited.
    placed: dict[int, tuple[list, list]] = {}    # node b -> place()
    leaves_a: dict[int, list] = {}               # leaf -> its triangles' boxes
    leaves_b: dict[int, list] = {}

    def triangles(tree, node, boxes, seen):
        """(index, lo, hi) of each triangle of a leaf, lists."""
        if node not in seen:
            members = tree.order[tree.start[node]:tree.start[node] + tree.count[node]]
            seen[node] = list(zip(members.tolist(), boxes[0][members].tolist(),
                                  boxes[1][members].tolist(), strict=True))
        return seen[node]

    def boxes_overlap(lo_1, hi_1, lo_2, hi_2):
        return (lo_1[0] <= hi_2[0] and lo_1[1] <= hi_2[1] and lo_1[2] <= hi_2[2]
                and lo_2[0] <= hi_1[0] and lo_2[1] <= hi_1[1] and lo_2[2] <= hi_1[2])

    found = []
    stack = [(0, 0)]
    visits = 0
    while stack:
        a, b = stack.pop()
        visits += 1
        box_a, box_b = fa.boxes[a].tolist(), fb.boxes[b].tolist()
        if b not in placed:
            placed[b] = place(box_b, M, u)
        T, R = node_pair_frame(box_a, *placed[b])
        half_a, half_b = box_a[3:6], box_b[3:6]
        if boxes_apart(T, R, half_a, half_b, margin):
            continue
        leaf_a, leaf_b = ta.left[a] < 0, tb.left[b] < 0
        if leaf_a and leaf_b:
            for i, lo_a, hi_a in triangles(ta, a, boxes_a, leaves_a):
                for j, lo_b, hi_b in triangles(tb, b, boxes_b, leaves_b):
                    if boxes_overlap(lo_a, hi_a, lo_b, hi_b):
                        found.append((i, j))
        elif leaf_b or (not leaf_a and half_a[0] + half_a[1] + half_a[2]
                                       >= half_b[0] + half_b[1] + half_b[2]):
            stack += [(ta.right[a], b), (ta.left[a], b)]          # open the bigger node
        else:
            stack += [(a, tb.right[b]), (a, tb.left[b])]
    pairs = np.array(found, dtype=np.int64).reshape(-1, 2)
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))], visits


# -- the compiled kernel and the public entry points ------------------------------------


@functools.cache
def _compiled():
    """The compiled kernels module (``exact_query``, ``exact_collide``), or
    None without numba (looked up once: a query costs a few microseconds, and
    an import statement a fraction). ``exact_collide`` is compiled here for
    its one signature, and numba may compile it for no other
    (``EXACT_COLLIDE_SIGNATURE``)."""
    try:
        from refsim.collision import _numba_kernels as nk
    except ImportError:
        return None
    if not nk.exact_collide.signatures:
        nk.exact_collide.compile(nk.EXACT_COLLIDE_SIGNATURE)
        nk.exact_collide.disable_compile()
    return nk


def pack_frame_tree(mesh) -> tuple[np.ndarray, np.ndarray]:
    """The mesh's constant arrays as the compiled query takes them, two in
    all (numba unboxes each array argument at each call: few arrays, small
    fixed cost; docs/decisions/query-fixed-cost.md):

    - float64: reach, axes_deviation, then the vertices (n, 3) and the
      :class:`FrameTree` boxes (nodes, 15), each flattened row by row;
    - int64: the counts of vertices, faces and nodes, then the faces (m, 3),
      the tree's links (nodes, 4) and order (m,), flattened likewise.

    :func:`refsim.collision._numba_kernels.unpack` takes them apart again."""
    tree = frame_tree_of(mesh, "compiled")
    floats = np.concatenate([[tree.reach, tree.axes_deviation], mesh.vertices.ravel(),
                             tree.boxes.ravel()]).astype(np.float64)
    ints = np.concatenate([[mesh.n_vertices, mesh.n_faces, tree.tree.n_nodes],
                           mesh.faces.ravel(), tree.links.ravel(),
                           tree.tree.order]).astype(np.int64)
    # (left writable: numba's dispatcher types a read-only array argument
    # by a slow path, a few hundred nanoseconds a query; nothing writes them)
    return floats, ints


def _kernel_arrays(mesh) -> tuple[np.ndarray, np.ndarray]:
    """:func:`pack_frame_tree` of the mesh, built once and kept with it."""
    return mesh.derived("frame_tree_packed", pack_frame_tree)


_FLOAT64 = np.dtype(np.float64)
#: shape and strides of a C-contiguous float64 (3, 3) rotation and (3,) translation
_POSE_LAYOUT = ((3, 3), (24, 8), (3,), (8,))


def _pose_arrays(pose, what: str):
    """The pose as two float64 C-contiguous arrays: as given when it already
    is (the compiled query checks the values; this layout check costs a
    fraction of ``as_pose``: docs/decisions/hierarchy-pose-check.md), else
    through ``as_pose``."""
    if type(pose) is tuple and len(pose) == 2:
        rotation, translation = pose
        if (type(rotation) is np.ndarray and type(translation) is np.ndarray
                and rotation.dtype is _FLOAT64 and translation.dtype is _FLOAT64
                and (rotation.shape, rotation.strides, translation.shape,
                     translation.strides) == _POSE_LAYOUT):
            return pose
    rotation, translation = as_pose(pose, what=what)
    return np.ascontiguousarray(rotation), np.ascontiguousarray(translation)


def _reject(what: str, pose) -> None:
    """Raise for the pose the compiled query found not valid."""
    as_pose(pose, what=what)     # raises with the precise reason
    # as_pose's Gram product rounds differently; at the tolerance's edge
    # it may accept what the kernel rejected: reject all the same.
    raise StateError(f"{what}: rotation is not orthonormal")


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
    floats_a, ints_a = _kernel_arrays(mesh_a)
    floats_b, ints_b = _kernel_arrays(mesh_b)
    status, found, uncertain = _compiled().exact_query(
        floats_a, ints_a, ra, ta, floats_b, ints_b, rb, tb, mode, ORTHONORMAL_TOL,
        margin_rounding, margin_per_deviation)
    if status:
        _reject(*(("pose_a", pose_a) if status == 1 else ("pose_b", pose_b)))
    return found, uncertain


def _sorted(pairs: np.ndarray) -> np.ndarray:
    return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))] if len(pairs) > 1 else pairs


def _resolve(mesh_a, pose_a, mesh_b, pose_b, uncertain: np.ndarray,
             first_only: bool = False) -> np.ndarray:
    """Which of the pairs the float filter left open intersect; bool (k,).

    The compiled exact stage (:func:`refsim.collision._numba_exact.intersect_posed`,
    expansions) answers the pairs it can take, the readable exact kernel the
    rest (degenerate triangles, coordinates outside the filter's range): the
    same answers either way. With ``first_only`` it may stop at the first
    hit (the caller then only asks whether there is one)."""
    (ra, ta), (rb, tb) = _pose_arrays(pose_a, "pose_a"), _pose_arrays(pose_b, "pose_b")
    answer, decided = compiled_exact_kernels().intersect_posed(
        mesh_a.vertices, mesh_a.faces, ra, ta, mesh_b.vertices, mesh_b.faces, rb, tb,
        uncertain, first_only)
    if first_only and answer.any():
        return answer
    rest = np.flatnonzero(~decided)
    if len(rest):
        world_a = world_vertices(mesh_a, (ra, ta))
        world_b = world_vertices(mesh_b, (rb, tb))
        for n in rest:
            i, j = uncertain[n]
            answer[n] = triangles_intersect(world_a[mesh_a.faces[i]], world_b[mesh_b.faces[j]])
    return answer


def pairs_readable(mesh_a, pose_a, mesh_b, pose_b) -> np.ndarray:
    """All intersecting face pairs, readable: the candidates of the
    traversal (:func:`candidate_pairs`, :func:`descend`), then the exact
    triangle test on each."""
    pose_a, pose_b = as_pose(pose_a, what="pose_a"), as_pose(pose_b, what="pose_b")
    candidates = candidate_pairs(mesh_a, pose_a, mesh_b, pose_b, kernel="readable")
    return exact_pairs(world_vertices(mesh_a, pose_a), mesh_a.faces,
                       world_vertices(mesh_b, pose_b), mesh_b.faces, candidates, "readable")


def pairs_compiled(mesh_a, pose_a, mesh_b, pose_b) -> np.ndarray:
    """:func:`pairs_readable` compiled: the same pairs.

    It asks the boolean query first (:func:`_collide_code`): most pairs of
    bodies a scene asks about are apart, and its answer (a code, no
    arrays; it stops at the first hit) costs less than the full query's
    when there is nothing to find. When it finds them apart, no pair
    intersects, from the same exact stage; otherwise the full query runs,
    and the boolean query's cost is added to a longer one (figures:
    docs/decisions/query-fixed-cost.md)."""
    answer, pose_a, pose_b = _collide_code(mesh_a, pose_a, mesh_b, pose_b)
    if answer == _compiled().APART:
        return np.empty((0, 2), dtype=np.int64)
    found, uncertain = query_compiled(mesh_a, pose_a, mesh_b, pose_b, ALL_HITS)
    if len(uncertain):
        hit = _resolve(mesh_a, pose_a, mesh_b, pose_b, uncertain)
        found = np.concatenate([found, uncertain[hit]])
    return _sorted(found)


def collide_readable(mesh_a, pose_a, mesh_b, pose_b) -> bool:
    """Whether any pair of triangles intersects, readable: whether
    :func:`pairs_readable` finds one."""
    return len(pairs_readable(mesh_a, pose_a, mesh_b, pose_b)) > 0


def collide_compiled(mesh_a, pose_a, mesh_b, pose_b) -> bool:
    """:func:`collide_readable` compiled, stopping at the first hit
    (``exact_collide``: the float filter, else the compiled exact stage,
    pair by pair). Only pairs that stage cannot take (degenerate
    triangles, coordinates outside the filter's range) come back to the
    readable exact kernel, through a second traversal."""
    answer, pose_a, pose_b = _collide_code(mesh_a, pose_a, mesh_b, pose_b)
    nk = _compiled()
    if answer == nk.APART or answer == nk.HIT:
        return answer == nk.HIT
    _, undecided = query_compiled(mesh_a, pose_a, mesh_b, pose_b, FIRST_HIT)
    return bool(_resolve(mesh_a, pose_a, mesh_b, pose_b, undecided, first_only=True).any())


def _collide_code(mesh_a, pose_a, mesh_b, pose_b):
    """The compiled boolean query's code (``exact_collide``: APART, HIT or
    UNDECIDED), and the poses it took (copies when they were not already
    two float64 C-contiguous arrays each). A pose the kernel finds invalid
    raises StateError."""
    floats_a, ints_a = _kernel_arrays(mesh_a)
    floats_b, ints_b = _kernel_arrays(mesh_b)
    nk = _compiled()
    try:
        # numba checks the arrays' types (``EXACT_COLLIDE_SIGNATURE``), the
        # kernel their shapes and values: nothing to check here first
        (ra, ta), (rb, tb) = pose_a, pose_b
        answer = nk.exact_collide(floats_a, ints_a, ra, ta, floats_b, ints_b, rb, tb,
                                  ORTHONORMAL_TOL, MARGIN_ROUNDING, MARGIN_PER_DEVIATION)
    except (TypeError, ValueError):      # not two pairs of float64 C-contiguous arrays
        (ra, ta), (rb, tb) = pose_a, pose_b = _pose_copy(pose_a, "pose_a"), \
            _pose_copy(pose_b, "pose_b")
        answer = nk.exact_collide(floats_a, ints_a, ra, ta, floats_b, ints_b, rb, tb,
                                  ORTHONORMAL_TOL, MARGIN_ROUNDING, MARGIN_PER_DEVIATION)
    if answer == nk.BAD_POSE_A or answer == nk.BAD_POSE_B:
        _reject(*(("pose_a", pose_a) if answer == nk.BAD_POSE_A else ("pose_b", pose_b)))
    return answer, pose_a, pose_b


def _pose_copy(pose, what: str):
    """The pose checked by ``as_pose`` and copied into two new writable
    float64 C-contiguous arrays."""
    rotation, translation = as_pose(pose, what=what)
    return (np.array(rotation, dtype=np.float64, order="C"),
            np.array(translation, dtype=np.float64, order="C"))
