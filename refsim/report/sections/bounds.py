"""Report section: bounding boxes and the world cube (seed S2, S3; claims C1, C2).

Arranges the plan's ``bounds-cost``, ``bounds-error`` and ``bounds-agreement``
records and the verdicts of :mod:`refsim.claims.bounds`.
"""

from __future__ import annotations

from refsim.claims.bounds import box_agreement
from refsim.report.charts import Series, line_chart
from refsim.report.plan import command
from refsim.report.section import Agreement, Divergence, Figure, Section, Table, Timing, Verdict
from refsim.report.words import against_spread, listing

STYLES = {"scan-numpy": "s--", "scan-numba": "s-", "incremental-python": "o--",
          "incremental-numba": "o-"}
C1_COMMAND = command("bounds-cost")
C2_COMMAND = command("bounds-error")


def build(ctx) -> Section:
    study = ctx.run.get("bounds-cost")
    errors = ctx.run.get("bounds-error")
    agreement = ctx.run.get("bounds-agreement")

    methods = sorted({r.method for r in study.rows}, key=list(STYLES).index)
    figures = [_cost_figure(study, motion, methods) for motion in ("coherent", "jump")]
    figures.append(_visits_figure(study))
    tables = [_cost_table(study, methods), _error_table(errors), _agreement_table(agreement)]
    verdicts = [_c1_verdict(ctx.run.claim("C1")), _c2_verdict(ctx.run.claim("C2"))]
    found = box_agreement(agreement)
    agreements = _agreements(found)
    divergences = [Divergence(
        "trimesh's transformed boxes differ in the last bits", found["class"],
        f"{found['trimesh_differ']} of {found['poses']} random poses differ from refsim's "
        f"scan, every one within the arithmetic bound (largest "
        f"{found['largest_over_bound']:.2g} of it): trimesh multiplies 4x4 matrices through "
        "BLAS, with fused multiply-adds and its own order; refsim rounds each operation once",
        "bounds-agreement")] if found["trimesh_differ"] else []
    return Section(
        key="bounds", title="Bounding boxes and the world cube",
        intro="The seed keeps each body's axis-aligned box up to date either by scanning "
              "every transformed vertex (linear, O(n)) or by walking the vertex-neighbour "
              "graph from last frame's six extreme vertices (incremental, the seed's "
              "O(1)). Both use one arithmetic for a transformed coordinate, so on convex "
              "meshes they agree bit for bit. Costs are medians per update on this machine "
              "(shared, two cores); the vertex counts are exact.",
        figures=figures, tables=tables, verdicts=verdicts, agreements=agreements,
        divergences=divergences,
        results={"update_cost": study.rows,
                 "pose_check_seconds": Timing(study.pose_check_seconds),
                 "crossovers": Timing({" / ".join(k): v for k, v in study.crossovers.items()}),
                 "incremental_error": errors,
                 "agreement": agreement})


def _rows(study, motion, method):
    rows = sorted((r for r in study.rows if r.motion == motion and r.method == method),
                  key=lambda r: r.n_triangles)
    return [r.n_triangles for r in rows], rows


def _cost_figure(study, motion, methods) -> Figure:
    series = []
    for method in methods:
        x, rows = _rows(study, motion, method)
        series.append(Series(method, x, [1e6 * r.seconds_per_update for r in rows],
                             STYLES[method]))
    crossover = study.crossovers.get((motion, "incremental-numba", "scan-numba"))
    marks = [(crossover, f"compiled crossover: {crossover} triangles")] if crossover else []
    label = "1 degree per frame" if motion == "coherent" else "random jumps"
    return Figure(
        id=f"bounds-cost-{motion}", title=f"Cost per box update against mesh size ({label})",
        svg=line_chart(series, xlabel="triangles", ylabel="microseconds per update",
                       logx=True, logy=True, vlines=marks),
        caption="Geodesic spheres from 80 to 81920 triangles (box and icosahedron at the "
                "small end). The dotted line marks the smallest size from which the "
                "compiled incremental update is faster than the compiled scan at every "
                f"larger size. Reproduce: {C1_COMMAND}")


def _visits_figure(study) -> Figure:
    series = []
    for motion, style in (("coherent", "o-"), ("jump", "s--")):
        x, rows = _rows(study, motion, "incremental-numba" if any(
            r.method == "incremental-numba" for r in study.rows) else "incremental-python")
        series.append(Series(f"incremental, {motion}", x, [r.visits_per_update for r in rows],
                             style))
    x, rows = _rows(study, "coherent", "scan-numpy")
    series.append(Series("scan (all vertices)", x, [r.n_vertices for r in rows], "k:"))
    return Figure(
        id="bounds-visits", title="Vertices examined per update",
        svg=line_chart(series, xlabel="triangles", ylabel="vertices examined",
                       logx=True, logy=True),
        caption="At 1 degree per frame the walk examines a near-constant number of "
                "vertices whatever the size: the seed's O(1). After random jumps it grows "
                f"like the square root of the vertex count. Reproduce: {C1_COMMAND}")


def _cost_table(study, methods) -> Table:
    rows = []
    for n in sorted({r.n_triangles for r in study.rows}):
        row = [n]
        for method in methods:
            r = next(r for r in study.rows if r.n_triangles == n and r.motion == "coherent"
                     and r.method == method)
            row.append(round(1e6 * r.seconds_per_update, 2))
        inc = next(r for r in study.rows if r.n_triangles == n and r.motion == "coherent"
                   and r.method.startswith("incremental"))
        row += [round(inc.visits_per_update, 1), inc.max_visits]
        rows.append(tuple(row))
    return Table(
        id="bounds-cost-table", title="C1: microseconds per update at 1 degree per frame",
        columns=("triangles", *methods, "visits (mean)", "visits (max)"), rows=tuple(rows),
        timing=True,
        caption="Medians of timed blocks of consecutive updates; the public call adds the "
                f"pose check ({1e6 * study.pose_check_seconds:.1f} us). "
                f"Reproduce: {C1_COMMAND}")


def _error_table(errors) -> Table:
    rows = tuple((e.mesh, e.n_triangles, "yes" if e.convex else "no", e.motion,
                  f"{100 * e.wrong_fraction:.1f}%", f"{e.max_deficit:.3g}",
                  f"{e.median_deficit:.3g}") for e in errors)
    return Table(
        id="bounds-c2", title="C2: the incremental box on non-convex meshes",
        columns=("mesh", "triangles", "convex", "motion", "frames wrong",
                 "max deficit", "median deficit"),
        rows=rows,
        caption="Deficit: how far the incremental box falls short of the true box, as a "
                "fraction of the box's extent on that axis (the walk stops at a local "
                "extreme, so its box is always inside the true one). "
                f"Reproduce: {C2_COMMAND}")


def _agreement_table(agreement) -> Table:
    rows = tuple((a.mesh, a.n_triangles, a.poses,
                  "n/a (non-convex)" if a.incremental_exact is None else a.incremental_exact,
                  a.trimesh_bitwise, a.trimesh_within, f"{a.max_difference_over_tolerance:.3g}")
                 for a in agreement)
    return Table(
        id="bounds-agreement", title="Agreement: incremental against scan, scan against trimesh",
        columns=("mesh", "triangles", "random poses", "incremental == scan (bitwise)",
                 "trimesh == scan (bitwise)", "within arithmetic bound", "max / bound"),
        rows=rows,
        caption="trimesh transforms with a 4x4 matrix product (BLAS, fused multiply-adds), "
                "so its boxes differ from refsim's in the last bits; every difference is "
                "within the bound of the arithmetic (16 ulps of the magnitudes involved). "
                f"Reproduce: {AGREEMENT_COMMAND}")


AGREEMENT_COMMAND = command("bounds-agreement")


def _agreements(found: dict) -> list[Agreement]:
    """The summary lines (:func:`refsim.claims.bounds.box_agreement`)."""
    return [
        Agreement("trimesh", "AABB of a transformed mesh (linear scan)",
                  f"{found['trimesh_within']} / {found['poses']} within the arithmetic bound, "
                  f"{found['trimesh_bitwise']} bitwise equal", AGREEMENT_COMMAND),
        Agreement("refsim (scan)", "incremental AABB on convex meshes, random jumps",
                  f"{found['incremental_exact']} / {found['convex_poses']} bitwise equal",
                  AGREEMENT_COMMAND),
    ]


def _c1_verdict(c1) -> Verdict:
    f = c1.facts
    below = f["ratios_below_crossover"]
    band = (f"{min(below):.2f}x to {max(below):.2f}x" if below else "no smaller size")
    at_large = f["ratio_at_large_model"]
    crossover = f["compiled_crossover"]
    sentence = (f"Compiled kernels (the seed's setting): the incremental update is faster "
                f"than the scan from {crossover} triangles on"
                + (f" ({at_large:.2f}x at {f['large_model']})" if at_large else "")
                + f"; below that the scan/incremental time ratio is {band} "
                f"(the factor-of-two band of 'nearly equal': {f['equal_part']}). Readable "
                f"Python against numpy's scan: faster only from {f['interpreted_crossover']} "
                "triangles, because each vertex the walk visits costs interpreter time. "
                "Each ratio against its threshold, with the interquartile range of its "
                "repeats: "
                + "; ".join(f"{n} triangles {against_spread(c)}"
                            for n, c in f["against_parity"].items())
                + ".")
    if c1.verdict == "undecided":
        summary = ("Too close to call in this run: at "
                   + listing([str(n) for n in sorted(f["open"])])
                   + " triangles the time ratio lies within its run-to-run spread of its "
                     "threshold.")
    elif crossover is None:
        summary = "Compiled, the incremental update is never faster than the scan."
    else:
        summary = (f"Compiled, the incremental update is faster from {crossover} triangles "
                   "on; " + ("below that the two cost about the same."
                             if f["equal_below_crossover"] else
                             "below that the two do not cost about the same."))
    return Verdict("C1", sentence, c1.verdict, "bounds-cost-coherent", C1_COMMAND,
                   timing=c1.timing, summary=summary)


def _c2_verdict(c2) -> Verdict:
    f = c2.facts
    sentence = (f"Convex meshes: {f['convex_wrong_frames']} wrong frames. Wrong on "
                f"{', '.join(f['nonconvex_wrong']) or 'none'}; never wrong on "
                f"{', '.join(f['nonconvex_never_wrong']) or 'none'}.")
    if f["sufficient_not_necessary"]:
        sentence += " Convexity is sufficient but not necessary."
    wrong, never = f["nonconvex_wrong"], f["nonconvex_never_wrong"]
    if f["convex_wrong_frames"]:
        summary = "The incremental box is wrong even on convex meshes."
    else:
        summary = (f"Never wrong on convex meshes; wrong on {len(wrong)} of "
                   f"{len(wrong) + len(never)} non-convex ones"
                   + (", so convexity is sufficient, not necessary." if never else "."))
    return Verdict("C2", sentence, c2.verdict, "bounds-c2", C2_COMMAND, timing=c2.timing,
                   summary=summary)
