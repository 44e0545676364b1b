"""Model facts against a mesh oracle: convexity, closedness, volume and the
volume centroid of each model file (seed S1; the report's models section).

Cost: O(m log m) per model for refsim's facts plus the oracle's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from refsim.models.loading import load_model


@dataclass(frozen=True)
class MeshFactsAgreement:
    """refsim's facts about one model against trimesh's (the mesh oracle)."""

    name: str
    convex_agrees: bool
    closed_agrees: bool
    volume_relative_difference: float
    centroid_difference_over_diagonal: float


def measure_mesh_facts_agreement(oracle, paths) -> list[MeshFactsAgreement]:
    """Compare convexity, closedness, volume and volume centroid with a mesh
    oracle (``is_convex``, ``is_watertight``, ``volume``, ``center_mass`` of
    ``(vertices, faces)``: :class:`refsim.oracles.trimesh_adapter.TrimeshOracle`)
    for each model file (``refsim info`` shows refsim's side)."""
    rows = []
    for path in paths:
        mesh = load_model(path)
        v, f = mesh.vertices, mesh.faces
        lo, hi = mesh.bounds
        diagonal = math.hypot(*(hi - lo))
        volume = oracle.volume(v, f)
        rows.append(MeshFactsAgreement(
            name=path.name,
            convex_agrees=mesh.is_convex == oracle.is_convex(v, f),
            closed_agrees=mesh.is_closed == oracle.is_watertight(v, f),
            volume_relative_difference=abs(mesh.volume - volume) / abs(volume),
            centroid_difference_over_diagonal=math.hypot(
                *(mesh.centroid_volume - oracle.center_mass(v, f))) / diagonal))
    return rows
