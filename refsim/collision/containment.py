"""Whether a point lies inside a closed mesh: refsim's one point-in-mesh test.

:func:`contains_point` sums the signed solid angles of the mesh's triangles
seen from the point (A. van Oosterom, J. Strackee, "The Solid Angle of a
Plane Triangle", IEEE Trans. Biomed. Eng. 30(2), 1983): over 4 pi this is
the point's winding number, +-1 inside a closed mesh (either orientation)
and 0 outside. Unlike the parity of a ray's crossings it needs no ray
direction, so a ray that grazes an edge or a vertex cannot miscount.

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
