"""Generated shapes: the bundled models and the meshes the measurements sweep.

Every function returns a closed :class:`~refsim.models.mesh.Mesh` whose faces
wind counter-clockwise seen from outside (positive volume), built from exact
formulas so that the same call gives the same bytes on every machine.

- ``geodesic_sphere(frequency)``: the icosahedron with each face cut into
  ``frequency**2`` triangles and the points pushed onto the unit sphere
  (a class I geodesic sphere; Kenner, *Geodesic Math and How to Use It*, 1976).
  It has ``20 f^2`` triangles and ``10 f^2 + 2`` vertices: f = 10 gives the
  seed's benchmark size of 2000 triangles.
- ``box``, ``tetrahedron``, ``icosahedron``: convex solids.
- ``torus``, ``l_beam``, ``star_prism``: non-convex solids.

Cost: O(triangles) each.
"""

from __future__ import annotations

import numpy as np

from refsim.models.mesh import Mesh

GOLDEN = (1.0 + 5.0 ** 0.5) / 2.0


def tetrahedron(size: float = 1.0) -> Mesh:
    """Regular tetrahedron with edge length ``size * 2**1.5 / 2``, centred."""
    v = 0.5 * size * np.array([[1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]], float)
    f = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]]
    return Mesh(v, f, name="tetrahedron")


def box(extents=(1.0, 1.0, 1.0), name: str = "box") -> Mesh:
    """Axis-aligned box with the given edge lengths, centred at the origin."""
    h = 0.5 * np.asarray(extents, dtype=np.float64)
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    v = corners * h
    # corner index = 4 * (x > 0) + 2 * (y > 0) + (z > 0); two triangles a side
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    f = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]
    return Mesh(v, f, name=name)


def _icosahedron_arrays():
    """Unit-circumradius icosahedron: 12 vertices (0, +-1, +-phi) cycled, 20 faces."""
    v = []
    for a in (-1.0, 1.0):
        for b in (-GOLDEN, GOLDEN):
            v += [(0.0, a, b), (a, b, 0.0), (b, 0.0, a)]
    v = np.array(v) / np.sqrt(1.0 + GOLDEN ** 2)
    # Faces: the triples of mutually adjacent vertices (edge length 2 before
    # scaling), wound outward. Found once from the geometry, not typed in.
    edge = 2.0 / np.sqrt(1.0 + GOLDEN ** 2)
    near = np.isclose(np.linalg.norm(v[:, None] - v[None], axis=2), edge)
    faces = []
    for i in range(12):
        for j in range(i + 1, 12):
            for k in range(j + 1, 12):
                if near[i, j] and near[j, k] and near[i, k]:
                    tri = [i, j, k]
                    if np.dot(np.cross(v[j] - v[i], v[k] - v[i]), v[i]) < 0:
                        tri = [i, k, j]
                    faces.append(tri)
    return v, np.array(faces)


def icosahedron(radius: float = 1.0) -> Mesh:
    v, f = _icosahedron_arrays()
    return Mesh(radius * v, f, name="icosahedron")


def geodesic_sphere(frequency: int, radius: float = 1.0) -> Mesh:
    """Class I geodesic sphere with ``20 * frequency**2`` triangles.

    Each icosahedron face (A, B, C) gets the grid points (i A + j B + k C) / f
    with i + j + k = f. A point on an edge shared by two faces is computed
    from the same integer weights summed in the same (vertex-index) order in
    both, so the two copies are bitwise equal and weld exactly.
    """
    if frequency < 1:
        raise ValueError("frequency must be >= 1")
    f = int(frequency)
    base_v, base_f = _icosahedron_arrays()
    points: dict[tuple, int] = {}
    coords: list[np.ndarray] = []

    def point(weights: dict[int, int]) -> int:
        key = tuple(sorted((vi, w) for vi, w in weights.items() if w))
        if key not in points:
            p = np.zeros(3)
            for vi, w in key:
                p = p + w * base_v[vi]
            points[key] = len(coords)
            # |p| written out in one order: np.linalg.norm goes through BLAS,
            # whose summation order (and so the last bit) differs per processor.
            coords.append(p / np.sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]))
        return points[key]

    faces = []
    for a, b, c in base_f:
        grid = {}
        for i in range(f + 1):
            for j in range(f + 1 - i):
                grid[i, j] = point({a: f - i - j, b: i, c: j})
        for i in range(f):
            for j in range(f - i):
                faces.append((grid[i, j], grid[i + 1, j], grid[i, j + 1]))
                if i + j < f - 1:
                    faces.append((grid[i + 1, j], grid[i + 1, j + 1], grid[i, j + 1]))
    return Mesh(radius * np.array(coords), np.array(faces), name=f"geodesic-sphere-{f}")


def torus(major: float = 1.0, minor: float = 0.35, n_major: int = 40,
          n_minor: int = 25) -> Mesh:
    """Torus about the y axis: ``2 * n_major * n_minor`` triangles.

    ``n_major`` and ``n_minor`` (segments around and across the tube) must be
    at least 3: with fewer, faces repeat and the surface is not closed.
    """
    if n_major < 3 or n_minor < 3:
        raise ValueError(f"torus: n_major and n_minor must be >= 3, got {n_major}, {n_minor}")
    u = 2.0 * np.pi * np.arange(n_major) / n_major
    w = 2.0 * np.pi * np.arange(n_minor) / n_minor
    uu, ww = np.meshgrid(u, w, indexing="ij")
    ring = major + minor * np.cos(ww)
    v = np.stack([ring * np.cos(uu), minor * np.sin(ww), ring * np.sin(uu)], axis=-1)
    idx = np.arange(n_major * n_minor).reshape(n_major, n_minor)
    i0, j0 = np.meshgrid(np.arange(n_major), np.arange(n_minor), indexing="ij")
    a, b = idx[i0, j0], idx[(i0 + 1) % n_major, j0]
    c, d = idx[(i0 + 1) % n_major, (j0 + 1) % n_minor], idx[i0, (j0 + 1) % n_minor]
    faces = np.concatenate([np.stack([a, d, c], -1).reshape(-1, 3),
                            np.stack([a, c, b], -1).reshape(-1, 3)])
    mesh = Mesh(v.reshape(-1, 3), faces, name="torus")
    volume = mesh.volume
    if volume is None:
        raise ValueError(f"torus: the surface is not closed (n_major={n_major}, "
                         f"n_minor={n_minor})")
    if volume < 0:  # wind outward whatever the parametrisation's handedness
        mesh = Mesh(mesh.vertices, mesh.faces[:, ::-1], name="torus")
    return mesh


def _prism(outline: np.ndarray, cap: list[tuple[int, int, int]], depth: float,
           name: str) -> Mesh:
    """Extrude a counter-clockwise outline (k, 2) in the xy plane along z.

    ``cap`` triangulates the outline (indices into it, counter-clockwise).
    The result is shifted so that its vertex average (the seed's centroid)
    is the origin.
    """
    k = len(outline)
    z0 = np.column_stack([outline, np.full(k, -0.5 * depth)])
    z1 = np.column_stack([outline, np.full(k, 0.5 * depth)])
    v = np.vstack([z0, z1])
    faces = [(a + k, b + k, c + k) for a, b, c in cap]             # top, facing +z
    faces += [(c, b, a) for a, b, c in cap]                        # bottom, facing -z
    for i in range(k):
        j = (i + 1) % k
        faces += [(i, j, j + k), (i, j + k, i + k)]                # sides, outward
    v = v - v.mean(axis=0)
    return Mesh(v, faces, name=name)


def l_beam(length: float = 2.0, width: float = 0.5, depth: float = 0.5) -> Mesh:
    """An L-shaped beam: two arms of ``length`` and thickness ``width``."""
    L, w = length, width
    outline = np.array([[0, 0], [L, 0], [L, w], [w, w], [w, L], [0, L]], float)
    cap = [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)]
    return _prism(outline, cap, depth, "l-beam")


def star_prism(points: int = 5, outer: float = 1.0, inner: float = 0.4,
               depth: float = 0.4) -> Mesh:
    """A star with ``points`` tips, extruded: a non-convex solid.

    Outline vertices alternate tip (even index) and notch (odd index),
    counter-clockwise. The cap is the inner polygon of notches (a fan) plus
    one triangle per tip: ``2 * points - 2`` triangles, none outside the star.
    """
    n = 2 * points
    angle = np.pi / 2 + np.pi * np.arange(n) / points
    radius = np.where(np.arange(n) % 2 == 0, outer, inner)
    outline = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
    tips = [((i - 1) % n, i, i + 1) for i in range(0, n, 2)]
    notches = list(range(1, n, 2))
    fan = [(notches[0], notches[i], notches[i + 1]) for i in range(1, points - 1)]
    return _prism(outline, tips + fan, depth, "star")
