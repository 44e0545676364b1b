"""Response between two colliding bodies: the seed's velocity exchange (S8)
and the corrected impulse with positional correction.

The seed ("Translational Collision Response Between Bodies"): "We then
create a contact plane using the vector formed between the object's
centroids as the normal to the plane. All exchange and reflection of normals
occurred about this plane. Perfectly inelastic collision responses were
performed; so, if two objects are moving towards each other during contact,
they exchange velocities (the objects are assumed to have equal mass)."

:func:`exchange_velocities_seed`: with ``N = (c_a - c_b) / |c_a - c_b|``
(from B to A), the bodies approach when ``(v_a - v_b) . N < 0``; then they
swap the components of their velocities along N and keep the lateral ones.

AMBIGUITY: "exchange velocities" "about this plane": the normal components
are exchanged (what "exchange and reflection of normals ... about this
plane" says, and what an elastic collision of equal masses along N does);
for a head-on collision this is the exchange of the whole velocities.

Terminology: this is a perfectly *elastic* collision of equal masses
(momentum and kinetic energy both conserved, relative normal velocity
reversed: restitution 1). A perfectly inelastic collision would leave both
with the common velocity ``(v_a + v_b) / 2`` along N. The seed's
"perfectly inelastic" is a misnomer (the report's terminology table records it). The
seed ignores the masses: with unequal masses the exchange conserves neither
momentum nor energy.

Why bodies interpenetrate (claim C11): the response changes only
velocities, never positions, and acts only while the bodies approach. A
collision is found after the bodies overlap (by up to ``|v_rel| h``); after
the exchange they separate at the old relative speed, so the overlap lasts
at least one more step; if they approach slowly, or move the same way (a
chaser that, after the exchange, is pushed on by gravity or by a wall), the
overlap persists for many steps. Nothing pushes them apart.

:func:`separate_bodies` and the impulse of :mod:`refsim.dynamics.impulse`
are the corrected response (``body_response = "impulse"``). DEVIATION (D4,
D5): the contact normal is the axis of least overlap of the two bodies' projections among the
centroid line and the bodies' own axes; the impulse uses masses and inertia
and acts only when approaching; and the bodies are moved apart along the
normal until their projections no longer overlap, so the normal is a
separating axis and no interpenetration persists into the next frame.

Seed section: S8 (and claim C11).

References: B. Mirtich, *Impulse-based Dynamic Simulation of Rigid Body
Systems*, PhD thesis, UC Berkeley 1996, chapter 3; positional correction by
projection as in M. Mueller et al., "Position Based Dynamics", 2007
(distribution by inverse mass); the separating axis test as in S. Gottschalk,
M. C. Lin, D. Manocha, "OBBTree", SIGGRAPH 1996 (which the seed cites).

Cost: O(1) for the exchange; O(n_a + n_b) per candidate axis for the
corrected normal, depth and contact point.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from refsim.dynamics.products import dot, norm
from refsim.kernels import CONTACT_GEOMETRY

#: Extra separation after the positional correction, relative to the bodies'
#: size (the sum of their projection extents along n): the exact collision
#: test counts touching as colliding, so bodies left exactly touching would
#: still "interpenetrate". 1e-9 is far above the rounding of the projections
#: (~1e-15 relative) and far below anything visible.
SEPARATION_SLOP = 1e-9

#: A vertex within this fraction of the half size of a wall touches it: the
#: contacts of the walls that the bodies of a body contact rest on, solved
#: together with it (:meth:`refsim.dynamics.simulation.Simulation._solve_island`).
#: The wall stage leaves a body's outermost vertex on the wall up to the
#: rounding of a coordinate (~1e-16 relative); 1e-9 of a 5 m cube is 5 nm,
#: far below anything a scene shows.
WALL_TOUCH = 1e-9


def exchange_velocities_seed(c_a, c_b, v_a, v_b) -> tuple[np.ndarray, np.ndarray, bool]:
    """The seed's response: ``(v_a', v_b', approaching)``; new arrays."""
    N = np.asarray(c_a, dtype=np.float64) - c_b
    # |N| and the dot products summed left to right (products.py), not by BLAS,
    # whose order and fused multiply-adds depend on the processor: the same
    # bits on every machine and in the compiled loop (_numba_kernels._exchange_seed)
    length = float(norm(N))
    v_a, v_b = np.array(v_a, dtype=np.float64), np.array(v_b, dtype=np.float64)
    if length == 0.0:
        return v_a, v_b, False                     # no contact plane: the seed is silent
    N /= length
    va_n, vb_n = float(dot(v_a, N)), float(dot(v_b, N))
    if va_n - vb_n >= 0.0:                          # moving apart (or not approaching)
        return v_a, v_b, False
    # exchange the normal components, keep the lateral ones
    return v_a + (vb_n - va_n) * N, v_b + (va_n - vb_n) * N, True


@dataclass(frozen=True)
class ContactGeometry:
    """The corrected model's contact: normal n (from B into A), overlap depth
    along n, and contact point p (world)."""

    n: np.ndarray
    depth: float
    point: np.ndarray
    extent: float


def contact_geometry(world_a: np.ndarray, world_b: np.ndarray, c_a, c_b, axes_a, axes_b,
                     kernel: str | None = None) -> ContactGeometry:
    """Normal, depth and point of two overlapping bodies' vertex sets.

    A negative depth means the normal separates the bodies (no contact).

    Candidate axes: the centroid line (the seed's normal) and each body's
    three axes (the columns of its orientation: the face normals of a box).
    On each, the overlap of the projections ``[min_A, max_A]`` and
    ``[min_B, max_B]`` is the translation along it that separates them; the
    axis of least overlap is the normal (a reduced separating-axis test; the
    exact one would add every face normal and edge-pair cross product). The
    point is the midpoint of the centroids of the two bodies' vertices lying
    in the overlap slab (for a face on a face, the middle of the shared part).

    Raises ValueError when no candidate has a direction: coincident
    centroids and zero orientation axes on both bodies.

    ``kernel`` (:mod:`refsim.kernels`): "compiled" runs
    :func:`refsim.dynamics._numba_contact.contact_geometry_numba`, the same
    bits (:func:`contact_geometry_compiled`); "readable",
    :func:`contact_geometry_readable`.
    """
    return CONTACT_GEOMETRY(kernel)(world_a, world_b, c_a, c_b, axes_a, axes_b)


def contact_geometry_compiled(world_a: np.ndarray, world_b: np.ndarray, c_a, c_b, axes_a,
                              axes_b) -> ContactGeometry:
    """:func:`contact_geometry` by its compiled twin,
    :func:`refsim.dynamics._numba_contact.contact_geometry_numba`."""
    from refsim.dynamics._numba_contact import contact_geometry_numba

    out = np.empty(8)
    if contact_geometry_numba(np.ascontiguousarray(world_a, dtype=np.float64),
                              np.ascontiguousarray(world_b, dtype=np.float64),
                              np.asarray(c_a, dtype=np.float64),
                              np.asarray(c_b, dtype=np.float64),
                              np.asarray(axes_a, dtype=np.float64),
                              np.asarray(axes_b, dtype=np.float64), out):
        return ContactGeometry(n=out[0:3], depth=float(out[3]), point=out[4:7],
                               extent=float(out[7]))
    raise ValueError(_NO_AXIS)


def contact_geometry_readable(world_a: np.ndarray, world_b: np.ndarray, c_a, c_b, axes_a,
                              axes_b) -> ContactGeometry:
    """The readable kernel of :func:`contact_geometry` (its docstring says
    what it computes)."""
    d = np.asarray(c_a, dtype=np.float64) - c_b
    candidates = [d] + [axes_a[:, k] for k in range(3)] + [axes_b[:, k] for k in range(3)]
    best = None
    for axis in candidates:
        # sums written out (refsim.dynamics.products), not BLAS: the same
        # normal and depth on every processor
        length = float(norm(axis))
        if length == 0.0:
            continue
        n = axis / length
        if dot(n, d) < 0.0:
            n = -n                                   # from B into A
        pa, pb = dot(world_a, n), dot(world_b, n)
        depth = pb.max() - pa.min()                  # A lies above B along n
        if best is None or depth < best[1]:
            best = (n, depth, pa, pb)
    if best is None:
        # Only when the centroids coincide and both bodies' axes are zero
        # vectors (a degenerate orientation): no direction to separate along.
        raise ValueError(_NO_AXIS)
    n, depth, pa, pb = best
    if depth < 0.0:
        # a separating axis: the bodies do not touch (their boxes, or spheres,
        # overlapped at a coarse collision level); the nearest points
        point = 0.5 * (world_a[pa.argmin()] + world_b[pb.argmax()])
    else:
        slab_lo, slab_hi = pa.min(), pb.max()
        point = 0.5 * (_centroid(world_a[pa <= slab_hi]) + _centroid(world_b[pb >= slab_lo]))
    extent = float((pa.max() - pa.min()) + (pb.max() - pb.min()))
    return ContactGeometry(n=n, depth=float(depth), point=point, extent=extent)


_NO_AXIS = ("contact_geometry: every candidate axis has zero length (coincident centroids "
            "and zero orientation axes); no contact normal")


def _centroid(points: np.ndarray) -> np.ndarray:
    """The mean of ``points`` (k >= 1, 3), summed row by row in index order
    (cumsum: one order on every machine, which the compiled twin repeats)."""
    return np.cumsum(points, axis=0)[-1] / len(points)


def separate_bodies(geometry: ContactGeometry, m_inv_a: float, m_inv_b: float
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Translations ``(dx_a, dx_b)`` that end the overlap along the normal,
    shared in proportion to the inverse masses (the lighter body moves more;
    momentum is untouched). Zero when the projections do not overlap."""
    gap = geometry.depth + SEPARATION_SLOP * geometry.extent
    if geometry.depth < 0.0 or m_inv_a + m_inv_b == 0.0:
        return np.zeros(3), np.zeros(3)
    share = gap / (m_inv_a + m_inv_b)
    return share * m_inv_a * geometry.n, -share * m_inv_b * geometry.n
