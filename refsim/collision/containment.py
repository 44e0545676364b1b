"""Whether a point lies inside a closed mesh: refsim's one point-in-mesh test.

:func:`contains_point` sums the signed solid angles of the mesh's triangles
seen from the point (A. van Oosterom, J. Strackee, "The Solid Angle of a
Plane Triangle", IEEE Trans. Biomed. Eng. 30(2), 1983): over 4 pi this is
the point's winding number, +-1 inside a closed mesh (either orientation)
and 0 outside. Unlike the parity of a ray's crossings it needs no ray
direction, so a ray that grazes an edge or a vertex cannot miscount.

:func:`contains_part` asks it of one vertex per connected part of a
surface that does not meet the mesh's: whether a body (or a part of it)
lies inside the other.

Float arithmetic, for classifying disagreements only (why an engine's answer
differs from refsim's exact one), never for a ground truth: the callers ask
about points well away from the surface (a vertex or a centroid of a body
whose surface does not meet the mesh's), where the winding number is an
integer to within rounding and the threshold 1/2 cannot be crossed.
"""

from __future__ import annotations

import numpy as np

from refsim.collision.boxes import world_vertices
from refsim.collision.contact import winding_numbers
from refsim.types import Pose


def winding_number(mesh, pose: Pose, point) -> float:
    """The winding number of the closed ``mesh`` at ``pose`` about the world
    ``point``: the sum of its triangles' signed solid angles over 4 pi
    (:func:`refsim.collision.contact.winding_numbers`, for one point)."""
    triangles = world_vertices(mesh, pose)[mesh.faces]
    point = np.asarray(point, dtype=np.float64).reshape(1, 3)
    return float(winding_numbers(point, triangles)[0])


def contains_point(mesh, pose: Pose, point) -> bool:
    """Whether the world ``point`` lies inside the closed ``mesh`` at ``pose``
    (its :func:`winding_number` is +-1, not 0). For points away from the
    surface only (module docstring)."""
    return abs(winding_number(mesh, pose, point)) > 0.5


def _component_vertices(mesh) -> np.ndarray:
    """One vertex index per connected component of the mesh's surface
    (faces joined by a shared vertex), the lowest of each."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    def build(mesh):
        faces = np.asarray(mesh.faces, dtype=np.int64)
        n = len(mesh.vertices)
        rows = np.concatenate([faces[:, 0], faces[:, 1]])
        cols = np.concatenate([faces[:, 1], faces[:, 2]])
        graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        used = np.unique(faces)
        _, first = np.unique(label[used], return_index=True)
        return used[first]

    return mesh.derived("component_vertices", build)


def contains_part(container, pose_c, inner, pose_i) -> bool:
    """Whether some connected part of ``inner``'s surface lies inside the
    closed mesh ``container``, for two surfaces that do not meet.

    A connected part of one surface that does not meet the other lies in
    one connected region of the space the other surface bounds, so every
    point of it has the same winding number: one vertex per part decides
    (:func:`_component_vertices`, each tested as :func:`contains_point`
    does). Neither a single
    vertex (a part of a body in several parts may be missed) nor the
    vertices' centroid (it lies in the hole of a torus, outside its surface
    and inside whatever sits there) decides it.
    """
    points = world_vertices(inner, pose_i)[_component_vertices(inner)]
    triangles = world_vertices(container, pose_c)[container.faces]
    return bool((np.abs(winding_numbers(points, triangles)) > 0.5).any())
