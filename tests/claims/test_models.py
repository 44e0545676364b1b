"""The models' findings against trimesh (refsim.claims.models)."""

from __future__ import annotations

from refsim.claims.models import facts_agreement
from refsim.studies.models import MeshFactsAgreement


def test_facts_agreement():
    rows = [MeshFactsAgreement("cube.ac", True, True, 1e-16, 2e-17),
            MeshFactsAgreement("star.ac", False, True, 3e-15, 0.0)]
    assert facts_agreement(rows) == {"models": 2, "convex_and_closed_agree": 1,
                                     "worst_volume": 3e-15, "worst_centroid": 2e-17}
