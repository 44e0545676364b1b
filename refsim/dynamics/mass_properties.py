"""Mass, centre of mass and inertia tensor of a uniform solid bounded by a
closed triangle mesh (needed by the corrected rotation model).

What: the solid is cut into signed tetrahedra ``(c, a, b, d)``, one per
triangle ``(a, b, d)``, from a reference point ``c`` (the vertex average, for
conditioning). For a tetrahedron with vertices ``p_0 .. p_3`` and signed
volume ``V = (p_1 - p_0) . ((p_2 - p_0) x (p_3 - p_0)) / 6`` the integrals are
exact polynomials of the vertices:

    int 1 dV       = V
    int x dV       = V (p_0 + p_1 + p_2 + p_3) / 4
    int x x^T dV   = V / 20 (sum_i p_i p_i^T + s s^T),  s = sum_i p_i

(the second moment of a simplex: e.g. F. Tonon, "Explicit exact formulas for
the 3-D tetrahedron inertia tensor in terms of its vertex coordinates",
J. Math. Stat. 2004; equivalently D. Eberly, "Polyhedral Mass Properties
(Revisited)", 2002, and B. Mirtich, "Fast and accurate computation of
polyhedral mass properties", J. Graphics Tools 1996, who integrate over
the faces instead). Summed over the faces the signed parts outside the
solid cancel, for convex and non-convex meshes alike. With the covariance
``C = rho int (x - c_m)(x - c_m)^T dV`` about the centre of mass ``c_m`` and
density ``rho = mass / volume``, the inertia tensor is

    I = trace(C) E - C.

Seed section: none; the seed sets the inertia tensor to the identity ("we
have effectively factored out angular momentum and the inertia tensor", S9).
The corrected model (``rotation = "impulse"``) needs the real one.

Scale: the integrals are computed on the vertices times ``2**-e``
(:func:`refsim.types.unit_exponent`, every coordinate below 1) and scaled
back: the volume by ``2**(3e)``, the centre by ``2**e``, the inertia by
``2**(2e)`` (it is mass times length squared). The products of five
coordinates in the second moment would otherwise underflow to zero for a
body of size 1e-65 and overflow for one of size 1e62.

Cost: O(m) for m triangles, once per body.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from refsim.errors import ModelError
from refsim.types import unit_exponent

#: A body's inertia tensor must be positive definite: its smallest principal
#: moment above this fraction of its largest. The vertices of a segment or a
#: single point leave one moment zero up to rounding (about 1e-16 of the
#: largest); the flattest body a scene means to simulate, a thin plate or a
#: needle, keeps a ratio many orders above 1e-12.
INERTIA_RTOL = 1e-12


@dataclass(frozen=True)
class MassProperties:
    """Of one body, in body coordinates (the mesh's own frame, scaled).

    ``inertia`` is about ``center`` (3, 3), in kg m^2 for ``mass`` in kg.
    """

    mass: float
    volume: float
    center: np.ndarray
    inertia: np.ndarray


def mass_properties(vertices: np.ndarray, faces: np.ndarray, mass: float) -> MassProperties:
    """Mass properties of the uniform solid of ``mass`` bounded by the mesh.

    Parameters
    ----------
    vertices : (n, 3) float64
    faces : (m, 3) int, wound counter-clockwise seen from outside (closed mesh).
    mass : float, > 0

    Raises
    ------
    ModelError
        When the enclosed volume is not positive (open, inside-out or flat mesh).
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    e = unit_exponent(vertices)
    vertices = np.ldexp(vertices, -e)                    # unit coordinates (see Scale)
    c = vertices.mean(axis=0)                            # reference point
    p = vertices[np.asarray(faces)] - c                  # (m, 3, 3): p_1, p_2, p_3 (p_0 = 0)
    V = np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])) / 6.0
    volume = float(V.sum())
    if not volume > 0.0:
        raise ModelError(f"mass properties need a closed, outward-wound mesh "
                         f"(enclosed volume {np.ldexp(volume, 3 * e):.6g})")
    s = p.sum(axis=1)                                    # p_0 = 0 adds nothing
    first = (V[:, None] * s).sum(axis=0) / 4.0           # int x dV about c
    second = (np.einsum("i,ikj,ikl->jl", V, p, p)
              + np.einsum("i,ij,il->jl", V, s, s)) / 20.0  # int x x^T dV about c
    center = first / volume                              # relative to c
    rho = mass / volume
    # Parallel-axis shift of the second moment from c to the centre of mass.
    C = rho * (second - volume * np.outer(center, center))
    inertia = np.trace(C) * np.eye(3) - C
    inertia = 0.5 * (inertia + inertia.T)                # exact symmetry
    with np.errstate(over="ignore"):    # beyond float64: inf (inertia_problem reports it)
        return MassProperties(mass=float(mass), volume=float(np.ldexp(volume, 3 * e)),
                              center=np.ldexp(center + c, e),
                              inertia=np.ldexp(inertia, 2 * e))


def point_mass_properties(vertices: np.ndarray, mass: float) -> MassProperties:
    """The seed's reading of a body as equal masses at its vertices ("The
    average position of all vertices should be the centroid (assuming equal
    masses for each vertex)"): centre the vertex average, inertia of the
    point masses. Used for open meshes, which bound no solid."""
    vertices = np.asarray(vertices, dtype=np.float64)
    e = unit_exponent(vertices)
    vertices = np.ldexp(vertices, -e)                    # unit coordinates (see Scale)
    center = vertices.mean(axis=0)
    d = vertices - center
    # (m/n) d^T d by numpy's own loop, not BLAS: the same bits on every processor
    C = np.einsum("ij,il->jl", (mass / len(vertices)) * d, d)
    inertia = np.trace(C) * np.eye(3) - C
    return MassProperties(mass=float(mass), volume=0.0, center=np.ldexp(center, e),
                          inertia=np.ldexp(inertia, 2 * e))


def body_mass_properties(mesh, mass: float) -> MassProperties:
    """A simulated body's mass properties: those of the uniform solid when the
    mesh is closed and encloses a positive volume, else the seed's point
    masses at the vertices (:func:`point_mass_properties`: an open or flat
    surface bounds no solid)."""
    if mesh.is_closed and (mesh.volume or 0.0) > 0.0:
        return mass_properties(mesh.vertices, mesh.faces, mass)
    return point_mass_properties(mesh.vertices, mass)


def inertia_problem(props: MassProperties) -> str | None:
    """Why a body with these mass properties cannot be simulated, or None.

    The loop inverts the inertia tensor and bounds the rotational energy by
    its largest moment, so it needs finite moments, all positive
    (``INERTIA_RTOL``).
    """
    if not (np.isfinite(props.inertia).all() and np.isfinite(props.center).all()):
        return "its inertia is beyond float64's range (the body is too large or too heavy)"
    moments = np.linalg.eigvalsh(props.inertia)
    if not moments[0] > INERTIA_RTOL * moments[-1]:
        return ("its inertia tensor is singular: the model's vertices lie on a line or "
                "at one point; a body needs triangles that span a plane")
    return None
