"""The report's entries on the bundled models (seed S1).

``models-facts``: refsim's own facts of each bundled model;
``models-agreement``: the same facts by trimesh.
"""

from __future__ import annotations

from refsim.report.run import Run


def models_facts(run: Run):
    from refsim.bundled import bundled_models
    from refsim.models.facts import describe
    from refsim.models.loading import load_model

    return [describe(load_model(path), name=path.name) for path in bundled_models()]


def models_agreement(run: Run):
    from refsim.bundled import bundled_models
    from refsim.studies.models import measure_mesh_facts_agreement

    return measure_mesh_facts_agreement(run.engine("trimesh-mesh"), bundled_models())
