"""Triangle meshes in shared-vertex form with vertex neighbours (seed S1).

The seed loads "triangle soup" models with per-triangle information and
"converts models to shared-vertex format with vertex neighbor information for
use in the incremental bounding box update routine". :class:`Mesh` is that
shared-vertex form:

1. Weld: vertices with equal coordinates become one vertex (exactly equal by
   default; ``weld_tolerance > 0`` merges vertices closer than the tolerance,
   transitively, each group taking the position of its lowest-index member).
2. Drop vertices that no triangle uses, keeping the order of the rest. An
   isolated vertex is unreachable in the neighbour graph, so the incremental
   box (S2) could never find it while the linear scan would: dropping it keeps
   the two methods answering the same question.
3. Neighbours: vertex ``i``'s neighbours are the vertices it shares an edge
   with, sorted, stored compactly (CSR: ``neighbor_offsets``,
   ``neighbor_indices``) for the fast paths and as a tuple of arrays
   (``neighbors``) for readers.

Derived facts: the seed's centroid (the average of the vertices, "assuming
equal masses for each vertex"), the volume centroid of the solid a closed mesh
bounds, closedness, convexity and degenerate (zero-area) triangles.

Cost: welding is O(n log n) (a sort; with a tolerance, a k-d tree), and it
and the checks are all a Mesh costs when it is made. The neighbour lists,
closedness and convexity are built on first use: O(m log m) in the triangle
count plus one O(n log n) convex hull.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, QhullError, cKDTree

from refsim.errors import ArgumentTypeError, ModelError
from refsim.types import unit_exponent

#: Relative tolerance of the convexity test. A vertex of a neighbouring face
#: may stand this far above a face's plane, relative to the diagonal of the
#: mesh's box, and still count as convex. Coordinates written to text with
#: ``repr`` are exact, so the slack only has to absorb the rounding of the
#: plane computation itself (a few ulps of the coordinates); 1e-9 is far above
#: that and far below any concavity a model would have on purpose.
CONVEX_RTOL = 1e-9


@dataclass(frozen=True)
class Material:
    """An AC3D material (only what the simulation and the writer need)."""

    name: str = "default"
    rgb: tuple[float, float, float] = (0.8, 0.8, 0.8)
    # The rest of the MATERIAL line (amb, emis, spec, shi, trans) as written,
    # so that a round trip keeps it exactly.
    rest: str = "amb 0.2 0.2 0.2  emis 0 0 0  spec 0.5 0.5 0.5  shi 10  trans 0"


class Mesh:
    """A triangle mesh in shared-vertex form.

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
        Vertex coordinates, finite.
    faces : array_like of int, shape (m, 3)
        Vertex indices of each triangle, counter-clockwise seen from outside
        for a closed mesh. ``m >= 1``.
    weld_tolerance : float, default 0.0
        0 welds exactly equal vertices only (``-0.0`` equals ``0.0``). A
        positive value merges vertices closer than it (Euclidean), transitively.
    face_material, face_flags, face_object : array_like of int, shape (m,), optional
        Per-triangle data kept from the file: material index, AC3D ``SURF``
        flags and the index of the object the triangle came from. Default 0.
    materials : sequence of Material, optional
        The palette ``face_material`` indexes.
    objects : sequence of str, optional
        The names of the objects ``face_object`` indexes.
    name : str, optional
        A label for messages and reports.
    source : str, optional
        The file the mesh came from, for error messages.

    Raises
    ------
    ModelError
        For wrong shapes, non-finite coordinates, out-of-range indices or no
        triangles.
    """

    def __init__(self, vertices, faces, *, weld_tolerance: float = 0.0,
                 face_material=None, face_flags=None, face_object=None,
                 materials=(), objects=(), name: str | None = None,
                 source: str | None = None):
        self.name = name
        self.source = source
        try:
            vertices = np.asarray(vertices, dtype=np.float64)
            faces = np.asarray(faces)
        except (TypeError, ValueError) as exc:  # ragged or non-numeric input
            raise self._error(f"vertices and faces must be numeric arrays: {exc}") from None
        if vertices.ndim != 2 or vertices.shape[1] != 3:
            raise self._error(f"vertices must have shape (n, 3), got {vertices.shape}")
        if faces.ndim != 2 or faces.shape[1] != 3 or faces.shape[0] == 0:
            raise self._error(f"faces must have shape (m, 3) with m >= 1, got {faces.shape}")
        if not np.issubdtype(faces.dtype, np.integer):
            raise self._error("face indices must be integers")
        if not np.isfinite(vertices).all():
            bad = int(np.flatnonzero(~np.isfinite(vertices).all(axis=1))[0])
            raise self._error(f"vertex {bad} has a non-finite coordinate")
        faces = faces.astype(np.int64)
        if faces.min() < 0 or faces.max() >= len(vertices):
            raise self._error(f"face index out of range [0, {len(vertices)})")
        if not isinstance(weld_tolerance, int | float | np.integer | np.floating) \
                or weld_tolerance < 0 or not np.isfinite(weld_tolerance):
            raise self._error("weld_tolerance must be finite and >= 0")

        m = len(faces)
        per_face = {}
        for key, value in (("face_material", face_material), ("face_flags", face_flags),
                           ("face_object", face_object)):
            try:
                array = np.zeros(m, np.int64) if value is None else np.asarray(value)
            except (TypeError, ValueError) as exc:
                raise self._error(f"{key} must be an integer array: {exc}") from None
            if not (np.issubdtype(array.dtype, np.integer) or array.size == 0):
                raise self._error(f"{key} must hold integers, got dtype {array.dtype}")
            array = array.astype(np.int64)
            if array.shape != (m,):
                raise self._error(f"{key} must have shape ({m},), got {array.shape}")
            per_face[key] = _readonly(array)

        vertices, faces = _weld(vertices, faces, weld_tolerance)
        vertices, faces = _drop_unreferenced(vertices, faces)
        self.vertices = _readonly(vertices)
        self.faces = _readonly(faces)
        self.face_material = per_face["face_material"]
        self.face_flags = per_face["face_flags"]
        self.face_object = per_face["face_object"]
        self.materials = tuple(materials) or (Material(),)
        self.objects = tuple(objects) or (name or "mesh",)

    def derived(self, key: str, build):
        """A structure derived from this mesh (e.g. a triangle hierarchy),
        built by ``build(mesh)`` on first use and kept: the mesh is immutable,
        so the structure stays valid for the mesh's lifetime."""
        try:
            return self.__dict__["_derived"][key]     # the common case, kept cheap
        except KeyError:
            cache = self.__dict__.setdefault("_derived", {})
            cache[key] = structure = build(self)
            return structure

    def scaled(self, factor: float) -> Mesh:
        """This mesh with every vertex times ``factor`` (> 0), kept with the
        mesh (a scene's bodies of one model and one scale share it)."""
        if factor == 1.0:
            return self
        return self.derived(f"scaled:{factor!r}", lambda m: Mesh(
            m.vertices * factor, m.faces, face_material=m.face_material,
            face_flags=m.face_flags, face_object=m.face_object, materials=m.materials,
            objects=m.objects, name=m.name, source=m.source))

    def _error(self, message: str) -> ModelError:
        return ModelError(message, path=self.source or self.name)

    def __repr__(self) -> str:
        label = f" {self.name!r}" if self.name else ""
        return f"<Mesh{label}: {self.n_vertices} vertices, {self.n_faces} triangles>"

    # -- sizes -----------------------------------------------------------------

    @property
    def n_vertices(self) -> int:
        return len(self.vertices)

    @property
    def n_faces(self) -> int:
        return len(self.faces)

    # -- connectivity ------------------------------------------------------------

    @cached_property
    def edges(self) -> np.ndarray:
        """Undirected edges (e, 2) as sorted pairs ``i < j``, rows sorted.

        Each pair is one integer key ``i n + j`` (``j < n``, so the keys sort
        as the rows do), made unique as a plain 1-d array: ``np.unique`` of
        the rows themselves sorts a structured view, seven times slower on
        a 20480-face icosphere's 61440 pairs."""
        f, n = self.faces, np.int64(self.n_vertices)
        pairs = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
        pairs = np.sort(pairs, axis=1)
        pairs = pairs[pairs[:, 0] != pairs[:, 1]]  # a repeated index is no edge
        keys = np.unique(pairs[:, 0] * n + pairs[:, 1])
        return _readonly(np.column_stack([keys // n, keys % n]))

    @cached_property
    def _neighbor_lists(self) -> tuple[np.ndarray, np.ndarray]:
        return _neighbor_csr(self.edges, self.n_vertices)

    @property
    def neighbor_offsets(self) -> np.ndarray:
        """(n + 1,) int64: vertex ``i``'s neighbours are
        ``neighbor_indices[neighbor_offsets[i]:neighbor_offsets[i + 1]]``
        (built on first use: a collision query never needs them)."""
        return self._neighbor_lists[0]

    @property
    def neighbor_indices(self) -> np.ndarray:
        """The neighbours of every vertex, sorted, one after another."""
        return self._neighbor_lists[1]

    @property
    def neighbors(self) -> tuple[np.ndarray, ...]:
        """Vertex ``i``'s neighbours (sorted indices), for every ``i``."""
        o, idx = self.neighbor_offsets, self.neighbor_indices
        return tuple(idx[o[i]:o[i + 1]] for i in range(self.n_vertices))

    @cached_property
    def _half_edge_twins(self) -> np.ndarray | None:
        """For each face corner's half-edge, the face across it; None if open.

        Half-edge ``(f, k)`` runs from ``faces[f, k]`` to ``faces[f, (k+1) % 3]``.
        The mesh is closed and consistently oriented exactly when every
        directed half-edge occurs once and its reverse occurs once.
        """
        f, n = self.faces, np.int64(self.n_vertices)
        tail, head = f, np.roll(f, -1, axis=1)
        key = (tail * n + head).ravel()
        reverse = (head * n + tail).ravel()
        order = np.argsort(key, kind="stable")
        sorted_key = key[order]
        if len(sorted_key) > 1 and (np.diff(sorted_key) == 0).any():
            return None  # a directed edge used twice: non-manifold or flipped
        pos = np.searchsorted(sorted_key, reverse)
        pos = np.minimum(pos, len(sorted_key) - 1)
        if not (sorted_key[pos] == reverse).all():
            return None  # a boundary edge (or a degenerate triangle)
        twin_face = (order[pos] // 3).reshape(f.shape)
        return twin_face

    @property
    def is_closed(self) -> bool:
        """Every edge is shared by exactly two triangles, oppositely oriented."""
        return self._half_edge_twins is not None

    # -- geometry ------------------------------------------------------------------

    @cached_property
    def _exponent(self) -> int:
        """``e`` with the largest coordinate times ``2**-e`` in [0.5, 1)
        (:func:`refsim.types.unit_exponent`)."""
        return unit_exponent(self.vertices)

    @cached_property
    def _unit_vertices(self) -> np.ndarray:
        """The vertices times ``2**-e``: every coordinate below 1 in magnitude.

        The volume, centroid, areas, convexity and hull are computed on these
        and scaled back, so that no intermediate overflows or underflows
        whatever the model's units (a cube of side 1e-300 or 1e300 is as
        convex as one of side 1).
        """
        return np.ldexp(self.vertices, -self._exponent)

    @cached_property
    def _face_cross(self) -> np.ndarray:
        """Cross products of each face's edges, in unit coordinates (times ``2**-2e``)."""
        v = self._unit_vertices[self.faces]
        return np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])

    @cached_property
    def face_areas(self) -> np.ndarray:
        cross = self._face_cross
        norm = np.sqrt((cross * cross).sum(axis=1))
        with np.errstate(over="ignore", under="ignore"):    # out of float64's range: inf, 0
            return _readonly(np.ldexp(0.5 * norm, 2 * self._exponent))

    @cached_property
    def degenerate_faces(self) -> np.ndarray:
        """Indices of zero-area triangles (a segment or a point).

        Zero means exactly zero in floating point: the cross product of two
        edge vectors, in unit coordinates, vanishes (collinear corners or a
        repeated vertex).
        """
        return _readonly(np.flatnonzero((self._face_cross == 0.0).all(axis=1)))

    @property
    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Body-space axis-aligned box ``(lo, hi)``."""
        return self.vertices.min(axis=0), self.vertices.max(axis=0)

    @cached_property
    def centroid_vertex_average(self) -> np.ndarray:
        """The seed's centroid: the mean of the shared vertices (S9), summed in
        unit coordinates (so that it is finite whenever the vertices are)."""
        return _readonly(np.ldexp(self._unit_vertices.mean(axis=0), self._exponent))

    @cached_property
    def volume(self) -> float | None:
        """Enclosed volume of a closed mesh (signed: positive when the faces
        wind outward), or None for an open mesh."""
        if not self.is_closed:
            return None
        with np.errstate(over="ignore"):      # a volume beyond float64 is inf, as IEEE rounds it
            return float(np.ldexp(self._tetra_volumes().sum(), 3 * self._exponent))

    @cached_property
    def volume_log10(self) -> float | None:
        """log10 of the enclosed volume's magnitude, finite even where
        :attr:`volume` overflows to inf (a mesh with coordinates near 1e154
        bounds about 1e462); None for an open mesh, -inf for a flat one."""
        if not self.is_closed:
            return None
        unit = abs(float(self._tetra_volumes().sum()))
        if unit == 0.0:
            return -math.inf
        return math.log10(unit) + 3 * self._exponent * math.log10(2.0)

    @cached_property
    def centroid_volume(self) -> np.ndarray | None:
        """Centre of mass of the uniform solid a closed mesh bounds, or None.

        Sum over faces of the tetrahedra (c, a, b, d) from a reference point c
        (the vertex average, for conditioning): the solid's centroid is the
        volume-weighted mean of the tetrahedra's centroids (c + a + b + d) / 4.
        """
        if not self.is_closed:
            return None
        volumes = self._tetra_volumes()
        total = volumes.sum()
        if total == 0.0:
            return None
        u = self._unit_vertices
        c = u.mean(axis=0)
        centroids = (c + u[self.faces].sum(axis=1)) / 4.0
        centre = (volumes[:, None] * centroids).sum(axis=0) / total
        return _readonly(np.ldexp(centre, self._exponent))

    def _tetra_volumes(self) -> np.ndarray:
        """Signed volumes of the tetrahedra (c, a, b, d) in unit coordinates."""
        u = self._unit_vertices
        v = u[self.faces] - u.mean(axis=0)
        cross = np.cross(v[:, 1], v[:, 2])
        return (v[:, 0] * cross).sum(axis=1) / 6.0

    @cached_property
    def is_convex(self) -> bool:
        """Whether the mesh bounds a convex solid.

        True when (a) the mesh is closed and winds outward (positive volume),
        (b) at every edge the triangle across it bends inward: its far vertex
        is not above this triangle's plane by more than ``CONVEX_RTOL`` times
        the box diagonal, and (c) the enclosed volume equals the convex hull's
        to a relative 1e-9. (b) is local; (c) rules out a surface that is
        locally convex everywhere yet winds around more than once.
        """
        twins = self._half_edge_twins
        if twins is None:
            return False
        volume = float(self._tetra_volumes().sum())        # in unit coordinates
        if not volume > 0.0:
            return False
        v, f = self._unit_vertices, self.faces
        span = v.max(axis=0) - v.min(axis=0)
        tol = CONVEX_RTOL * float(np.sqrt((span * span).sum()))
        cross = self._face_cross
        norm = np.sqrt((cross * cross).sum(axis=1))
        usable = norm > 0.0
        unit = np.zeros_like(cross)
        unit[usable] = cross[usable] / norm[usable, None]
        # The vertex of the twin face opposite half-edge (f, k): the twin face
        # holds the edge's two vertices; its third vertex is the one not on it.
        for k in range(3):
            g = twins[:, k]
            a, b = f[:, k], f[:, (k + 1) % 3]
            tf = f[g]
            third = np.where((tf != a[:, None]) & (tf != b[:, None]), tf, -1).max(axis=1)
            height = ((v[third] - v[a]) * unit).sum(axis=1)
            if (height[usable] > tol).any():
                return False
        try:
            hull = ConvexHull(v)
        except QhullError:
            return False
        return abs(hull.volume - volume) <= 1e-9 * hull.volume


def require_mesh(obj, what: str = "mesh") -> Mesh:
    """``obj`` when it is a :class:`Mesh`; else :class:`ArgumentTypeError`
    naming the argument (``refsim.Mesh(vertices, faces)`` builds one)."""
    if not isinstance(obj, Mesh):
        raise ArgumentTypeError(f"{what} must be a refsim.Mesh, got {type(obj).__name__} "
                                "(build one with refsim.Mesh(vertices, faces) or "
                                "refsim.load_model(path))")
    return obj


def _readonly(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array)
    array.flags.writeable = False
    return array


def _weld(vertices: np.ndarray, faces: np.ndarray, tolerance: float):
    """Merge equal (or, with a tolerance, near) vertices; remap faces.

    Each group of merged vertices is represented by its lowest index; the
    representative keeps its own coordinates. Unused slots are dropped later.
    Exact welding is O(n log n) (a sort of the rows).
    """
    n = len(vertices)
    if n == 0:
        return vertices, faces
    if tolerance == 0.0:
        # Rows ranked by value (-0.0 equals 0.0) with a stable sort, so that
        # equal rows sit together in index order and each group's first is
        # its lowest index (as np.unique(axis=0, return_index=True) gives;
        # it sorts a structured view of the rows, several times slower).
        order = np.lexsort((vertices[:, 2], vertices[:, 1], vertices[:, 0]))
        ranked = vertices[order]
        starts = np.empty(n, dtype=bool)
        starts[0] = True
        starts[1:] = (ranked[1:] != ranked[:-1]).any(axis=1)
        representative = np.empty(n, dtype=np.int64)
        representative[order] = order[starts][np.cumsum(starts) - 1]
    else:
        # in unit coordinates (an exact power-of-two scale), so that squared
        # distances cannot overflow for coordinates anywhere in float64's range
        # (unit coordinates are below 1 in magnitude: a radius of 4 already
        # joins every pair, and caps one that would overflow)
        # The tree compares squared distances, which underflow to 0 below
        # about 2**-537 in unit coordinates: its pairs are candidates, kept
        # when their distance, by hypot (no overflow, no underflow to 0 of a
        # nonzero distance), is within the radius.
        e = unit_exponent(vertices)
        radius = 4.0 if math.frexp(tolerance)[1] - e > 3 else math.ldexp(tolerance, -e)
        unit = np.ldexp(vertices, -e)
        pairs = cKDTree(unit).query_pairs(r=radius, output_type="ndarray")
        d = unit[pairs[:, 0]] - unit[pairs[:, 1]]
        pairs = pairs[np.hypot(np.hypot(d[:, 0], d[:, 1]), d[:, 2]) <= radius]
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        lowest = np.full(label.max() + 1, n, dtype=np.int64)
        np.minimum.at(lowest, label, np.arange(n))
        representative = lowest[label]
    return vertices, representative[faces]


def _drop_unreferenced(vertices: np.ndarray, faces: np.ndarray):
    """Keep only vertices some face uses, in their original order."""
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    new_index = np.cumsum(used) - 1
    return vertices[used], new_index[faces]


def _neighbor_csr(edges: np.ndarray, n: int):
    """Compressed neighbour lists from undirected edges (each row i < j)."""
    both = np.concatenate([edges, edges[:, ::-1]])
    order = np.lexsort((both[:, 1], both[:, 0]))
    both = both[order]
    counts = np.bincount(both[:, 0], minlength=n)
    offsets = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    return _readonly(offsets), _readonly(both[:, 1].astype(np.int64))
