"""The facts about a model that ``refsim info`` prints and the report lists."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np

from refsim.models.mesh import Mesh


@dataclass(frozen=True)
class ModelFacts:
    name: str
    triangles: int
    vertices: int
    objects: int
    convex: bool
    closed: bool
    degenerate_triangles: int
    bounds_lo: tuple[float, float, float]
    bounds_hi: tuple[float, float, float]
    centroid_vertex_average: tuple[float, float, float]
    centroid_volume: tuple[float, float, float] | None
    volume: float | None
    #: log10 of |volume|: finite where the volume itself overflows.
    volume_log10: float | None
    max_neighbors: int
    #: |vertex-average centroid - volume centroid| / box diagonal; None when
    #: open. The seed takes the vertex average as the centre of mass (S9).
    centroid_offset: float | None

    def as_dict(self) -> dict:
        return asdict(self)


def _triple(a) -> tuple[float, float, float]:
    x, y, z = a
    return float(x), float(y), float(z)


def describe(mesh: Mesh, name: str | None = None) -> ModelFacts:
    lo, hi = mesh.bounds
    degree = np.diff(mesh.neighbor_offsets)
    return ModelFacts(
        name=name or mesh.name or "mesh",
        triangles=mesh.n_faces,
        vertices=mesh.n_vertices,
        objects=len(mesh.objects),
        convex=bool(mesh.is_convex),
        closed=bool(mesh.is_closed),
        degenerate_triangles=int(len(mesh.degenerate_faces)),
        bounds_lo=_triple(lo),
        bounds_hi=_triple(hi),
        centroid_vertex_average=_triple(mesh.centroid_vertex_average),
        centroid_volume=None if mesh.centroid_volume is None else _triple(mesh.centroid_volume),
        volume=mesh.volume,
        volume_log10=mesh.volume_log10,
        max_neighbors=int(degree.max()),
        centroid_offset=centroid_offset(mesh),
    )


def centroid_offset(mesh: Mesh) -> float | None:
    """How far the seed's centroid (vertex average) is from the centre of mass
    of the uniform solid, relative to the diagonal of the mesh's box."""
    if mesh.centroid_volume is None:
        return None
    lo, hi = mesh.bounds
    # Lengths by math.hypot, which scales internally: no overflow for any
    # finite coordinates (np.linalg.norm squares them). The differences of
    # coordinates near 1e308 are taken in half scale for the same reason.
    gap = math.hypot(*(0.5 * mesh.centroid_vertex_average - 0.5 * mesh.centroid_volume))
    diagonal = math.hypot(*(0.5 * hi - 0.5 * lo))
    return gap / diagonal


def _volume_text(facts: ModelFacts) -> str:
    """The volume, in decimal; beyond float64's range (inf) as a mantissa and
    an exponent from its logarithm, since the mesh's coordinates are finite."""
    if facts.volume is None or facts.volume_log10 is None:
        return "n/a (open mesh)"
    if math.isfinite(facts.volume):
        return f"{facts.volume:.6g}"
    exponent = math.floor(facts.volume_log10)
    mantissa = math.copysign(10.0 ** (facts.volume_log10 - exponent), facts.volume)
    return f"{mantissa:.6g}e+{exponent} (beyond float64's range)"


def format_facts(facts: ModelFacts) -> str:
    """Plain text, one fact a line (``refsim info``)."""

    def vec(v):
        return "n/a (open mesh)" if v is None else "(" + ", ".join(f"{x:.6g}" for x in v) + ")"

    rows = [
        ("model", facts.name),
        ("triangles", facts.triangles),
        ("vertices", facts.vertices),
        ("objects", facts.objects),
        ("convex", "yes" if facts.convex else "no"),
        ("closed", "yes" if facts.closed else "no"),
        ("degenerate triangles", facts.degenerate_triangles),
        ("bounds min", vec(facts.bounds_lo)),
        ("bounds max", vec(facts.bounds_hi)),
        ("centroid (vertex average, seed)", vec(facts.centroid_vertex_average)),
        ("centroid (volume)", vec(facts.centroid_volume)),
        ("volume", _volume_text(facts)),
        ("centroid offset / diagonal", "n/a (open mesh)" if facts.centroid_offset is None
         else f"{facts.centroid_offset:.3g}"),
        ("most neighbours of a vertex", facts.max_neighbors),
    ]
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"{k:<{width}}  {v}" for k, v in rows)
