"""Report section: the bundled models (seed S1).

Arranges the plan's ``models-facts`` (refsim's own facts of each bundled
model) and ``models-agreement`` (the same facts by trimesh).
"""

from __future__ import annotations

from refsim.claims.models import facts_agreement
from refsim.report.charts import bar_chart
from refsim.report.plan import command
from refsim.report.section import Agreement, Figure, Section, Table

#: Coordinates below this are rounding noise of models about 1 unit in size
#: (sums of ~1e3 terms of ~1e-16 error); the table shows them as 0. The exact
#: values are in results.json.
SHOWN_AS_ZERO = 1e-12

AGREEMENT_COMMAND = command("models-agreement")


def _point(p) -> str:
    return ", ".join(f"{(0.0 if abs(x) < SHOWN_AS_ZERO else x):.3g}" for x in p)


def build(ctx) -> Section:
    facts = ctx.run.get("models-facts")
    rows = tuple(
        (f.name, f.triangles, f.vertices, "yes" if f.convex else "no",
         "yes" if f.closed else "no", f.degenerate_triangles,
         "n/a" if f.volume is None else f"{f.volume:.6g}",
         _point(f.centroid_vertex_average),
         "n/a" if f.centroid_volume is None else _point(f.centroid_volume),
         f.max_neighbors)
        for f in facts)
    table = Table(
        id="models-facts", title="Bundled models",
        columns=("model", "triangles", "vertices", "convex", "closed", "degenerate",
                 "volume", "centroid (vertex average)", "centroid (volume)", "max neighbours"),
        rows=rows,
        caption="Read by refsim's own AC3D reader, welded to shared-vertex form. "
                f"Reproduce: {command('models-facts')} (one row: refsim info models/NAME.ac)")
    agreement = ctx.run.get("models-agreement")
    agree_table = Table(
        id="models-trimesh", title="Agreement with trimesh",
        columns=("model", "convex agrees", "closed agrees", "volume |difference| / volume",
                 "centre of mass |difference| / diagonal"),
        rows=tuple((a.name, "yes" if a.convex_agrees else "NO",
                    "yes" if a.closed_agrees else "NO",
                    f"{a.volume_relative_difference:.2g}",
                    f"{a.centroid_difference_over_diagonal:.2g}") for a in agreement),
        caption="trimesh computes the same quantities with its own code (the mass "
                "properties by a different summation), so agreement to rounding is expected. "
                f"Reproduce: {AGREEMENT_COMMAND}")
    found = facts_agreement(agreement)
    agreements = [Agreement(
        "trimesh", "convexity, closedness, volume, centre of mass of every bundled model",
        f"{found['convex_and_closed_agree']} / {found['models']} "
        f"agree on convex and closed; volume within {found['worst_volume']:.1g} relative, "
        f"centre of mass within {found['worst_centroid']:.1g} of the diagonal",
        AGREEMENT_COMMAND)]
    offsets = [(f.name, f.centroid_offset) for f in facts if f.centroid_offset is not None]
    figure = Figure(
        id="models-centroid-offset",
        title="The seed's centroid against the centre of mass",
        svg=bar_chart([name for name, _ in offsets],
                      [max(value, 1e-17) for _, value in offsets], logy=True,
                      ylabel="|vertex average - volume centroid| / diagonal"),
        caption="The seed puts the centre of mass at the average of the vertices (S9). "
                "For the symmetric models the two agree to rounding (bars near the "
                "1e-17 floor are exact zeros or rounding noise). For the L-beam, whose "
                "mass is not spread like its vertices, they do not: the seed's torque "
                "arm would be measured from the wrong point. "
                "Reproduce: refsim info models/l-beam.ac")
    return Section(
        key="models", title="Models",
        intro="Every bundled model is read by refsim's AC3D reader and converted to "
              "shared-vertex form with vertex neighbours (seed S1). The seed's centroid "
              "is the average of the vertices; the volume centroid is the centre of mass "
              "of the uniform solid. They differ wherever vertices are spread unevenly.",
        tables=[table, agree_table],
        figures=[figure],
        agreements=agreements,
        results={"models": [f.as_dict() for f in facts],
                 "trimesh_agreement": agreement})
