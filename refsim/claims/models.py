"""The models' findings: refsim's facts of the bundled models against
trimesh's (:func:`refsim.studies.models.measure_mesh_facts_agreement`).
No seed claim turns on them; the report's summary quotes them."""

from __future__ import annotations

from collections.abc import Sequence

from refsim.studies.models import MeshFactsAgreement


def facts_agreement(rows: Sequence[MeshFactsAgreement]) -> dict:
    """Over the models: how many agree with trimesh on both convexity and
    closedness, and the largest volume difference (relative) and centre of
    mass difference (over the box diagonal)."""
    return {"models": len(rows),
            "convex_and_closed_agree": sum(a.convex_agrees and a.closed_agrees for a in rows),
            "worst_volume": max(a.volume_relative_difference for a in rows),
            "worst_centroid": max(a.centroid_difference_over_diagonal for a in rows)}
