"""Report section: body-body collision (seed S4; claims C3, C4).

Arranges the plan's records of :mod:`refsim.studies.levels` (the four
levels, the body-level oracles, the hierarchy against FCL) and of
:mod:`refsim.studies.triangles` (the triangle test against FCL, claim C4),
and the verdicts and findings of :mod:`refsim.claims.collision`. Nothing is
computed here beyond picking and formatting those numbers.
"""

from __future__ import annotations

from dataclasses import asdict

from refsim.claims.collision import speed_findings
from refsim.collision.disagreement import BODY_REASONS
from refsim.report.charts import Series, line_chart
from refsim.report.plan import command
from refsim.report.section import (
    Agreement,
    Divergence,
    Figure,
    Section,
    Table,
    Timing,
    Verdict,
    fields_of,
)
from refsim.report.words import against_spread

LEVELS_COMMAND = command("collision-levels")
BODY_ORACLES_COMMAND = command("collision-body-oracles")
SPEED_COMMAND = command("collision-speed")
TRIANGLES_COMMAND = command("collision-triangles")
C4_COMMAND = command("collision-c4")


def _us(seconds) -> str:
    return "n/a" if seconds is None else f"{seconds * 1e6:.0f}"


def _ratio(value) -> str:
    return "n/a" if value is None else f"{value:.2f}"


def _yes(value: bool) -> str:
    return "yes" if value else "no"


def build(ctx) -> Section:
    from refsim.studies import levels as measure_levels
    from refsim.studies import triangles as measure

    run = ctx.run
    levels = run.get("collision-levels")
    level_names = levels.levels
    agreement = run.get("collision-body-oracles")
    speed = run.get("collision-speed")
    triangle_rows = [(t.pairs, t.agreement) for t in run.get("collision-triangles")]
    c4_run = run.get("collision-c4")
    c4, sweep = c4_run.c4, c4_run.sweep

    figures, tables, verdicts = [], [], []

    # -- C3: accuracy against speed ---------------------------------------------------
    figures.append(Figure(
        id="collision-levels-tradeoff", title="Accuracy against speed of the four levels",
        svg=line_chart(
            [Series(s.level, [s.median_seconds * 1e6], [100.0 * s.false_positive_rate], "o")
             for s in levels.summary],
            xlabel="median time per boolean query (us, log scale)",
            ylabel="false positives (% of non-colliding queries)", logx=True),
        caption=(f"Each level of bodies_collide (method 'bvh', kernel {levels.kernel}): the "
                 f"median over the {len(levels.configurations)} constructed configurations "
                 f"of the median of {levels.repeats} timed queries, against the share of "
                 f"queries where the surfaces do not meet but the level says 'collide' "
                 f"(constructed configurations and {levels.random[0].n if levels.random else 0}"
                 f" seeded random poses per model pair). Reproduce: {LEVELS_COMMAND}")))
    level_rows = []
    for c in levels.configurations:
        marks = [("yes" if c.answers[lv] else "no") + (" (FP)" if c.false_positive(lv) else "")
                 for lv in level_names]
        level_rows.append((c.name, c.kind, *marks, c.candidate_pairs, c.exact_pairs,
                           *(_us(c.seconds[lv]) for lv in level_names),
                           _us(c.seed_seconds["exact"]),
                           _ratio(c.pairs_seconds["seed"] / c.pairs_seconds["bvh"])))
    tables.append(Table(
        id="collision-levels", title="The four levels on constructed configurations",
        timing=True,
        columns=("configuration", "kind", *level_names, "triangle-box pairs", "exact pairs",
                 *(f"{lv} (us)" for lv in level_names), "exact, seed path (us)",
                 "all pairs: seed path / bvh"),
        rows=tuple(level_rows),
        caption=("Answers of bodies_collide per level ('FP': collide where the exact level "
                 "says no). Times are medians of boolean queries; the last column is the "
                 "time of intersecting_pairs by the seed's pairwise triangle boxes over the "
                 "hierarchy's. "
                 + "; ".join(f"{c.name}: {c.description}" for c in levels.configurations)
                 + f". Reproduce: {LEVELS_COMMAND}")))
    tables.append(Table(
        id="collision-levels-random", title="The four levels on random poses",
        columns=("model pair", "poses", "exact says collide",
                 *(f"{lv} FP" for lv in level_names), "false negatives",
                 "triangle-box pairs", "exact pairs", "seed path differs"),
        rows=tuple((f"{r.model_a} / {r.model_b}", r.n, r.exact_true,
                    *(r.false_positives[lv] for lv in level_names),
                    sum(r.false_negatives.values()), r.candidate_pairs, r.exact_pairs,
                    r.seed_mismatches) for r in levels.random),
        caption=("Both bodies turned at random, centres a uniform distance from 0 to 1.1 "
                 "times the sum of the bounding radii apart (seeded). Pair-level false "
                 "positives are the triangle-box pairs minus the exact pairs. "
                 f"Reproduce: {LEVELS_COMMAND}")))

    # -- agreement with FCL (triangle pairs) and trimesh (bodies) -------------------
    pair_rows = [(label, r.n, r.agree, *(r.counts[k] for k in measure.DISAGREEMENT_KINDS))
                 for label, r in triangle_rows]
    for p in agreement.pairs:
        pair_rows.append((f"face pairs of posed meshes ({p.source}, {p.queries} queries)",
                          p.refsim_pairs + p.oracle_pairs - p.common_pairs, p.common_pairs,
                          *(p.counts[k] for k in measure.DISAGREEMENT_KINDS)))
    tables.append(Table(
        id="collision-fcl-pairs", title="Exact triangle test against python-fcl, by class",
        columns=("pairs", "n", "agree", *measure.DISAGREEMENT_KINDS),
        rows=tuple(pair_rows),
        caption=("Every disagreement classified (refsim.studies.triangles."
                 "classify_disagreement): coplanar, touching (the contact rests on an exact "
                 "zero), tolerance (the pair's gap, distance apart or depth of the crossing, "
                 "within the rounding bound of refsim.collision.gaps, as in the conformance "
                 "kit), bug. For posed meshes n is the "
                 "number of distinct face pairs either engine reports. Reproduce: "
                 f"{TRIANGLES_COMMAND} and {BODY_ORACLES_COMMAND}" if triangle_rows
                 or agreement.pairs
                 else "python-fcl is not installed: not measured.")))
    tables.append(Table(
        id="collision-body-oracles", title="bodies_collide against FCL and trimesh, by class",
        columns=("oracle", "queries", "n", "agree", "refsim collide", "oracle collide",
                 *measure_levels.BODY_DISAGREEMENT_KINDS),
        rows=tuple((b.oracle, b.source, b.n, b.agree, b.refsim_true, b.oracle_true,
                    *(b.counts[k] for k in measure_levels.BODY_DISAGREEMENT_KINDS))
                   for b in agreement.bodies),
        caption=("FCL: fcl.collide on two BVHModels (surfaces, like refsim). trimesh: "
                 "CollisionManager, which makes convex meshes fcl.Convex solids and rounds "
                 "transforms to float32. Every disagreement classified by the conformance "
                 "kit's classifier (refsim.collision.disagreement.classify_bodies, the "
                 "classes of refsim conform), with its reason and gap in metres; reasons: "
                 + "; ".join(f"'{reason}' ({kind}): {meaning}" for reason, (kind, meaning)
                             in BODY_REASONS.items())
                 + ". Disagreements: "
                 + ("; ".join(f"{d.case} ({d.source}, refsim {d.refsim}, {b.oracle} "
                              f"{d.oracle}): {d.kind}, {d.reason}, gap {d.gap:.3g} m"
                              for b in agreement.bodies for d in b.disagreements) or "none")
                 + f". Reproduce: {BODY_ORACLES_COMMAND}")))

    # -- the hierarchy against FCL -----------------------------------------------------
    tables.append(Table(
        id="collision-speed", title="Triangle hierarchy against FCL: 2000-triangle meshes, "
                                    "and touching bodies",
        timing=True,
        columns=("model", "configuration", "exact pairs", "triangle-box pairs",
                 "all pairs: bvh (us)", "seed path (us)", "FCL (us)", "bvh / FCL",
                 "boolean: bvh (us)", "FCL (us)", "bvh / FCL"),
        rows=tuple((c.model, c.kind, c.exact_pairs, c.candidate_pairs, _us(c.bvh_seconds),
                    _us(c.seed_seconds), _us(c.fcl_seconds), _ratio(c.pairs_ratio),
                    _us(c.bvh_boolean_seconds), _us(c.fcl_boolean_seconds),
                    _ratio(c.boolean_ratio)) for c in speed.cases),
        caption=("Medians of " f"{speed.repeats} runs in the same process (kernel "
                 f"{speed.kernel}); FCL's models and refsim's trees built before timing. "
                 "refsim's bvh at the exact level: a box per node along the principal axes "
                 "of its vertices, built once per mesh, tested as oriented boxes in the "
                 "first body's frame (refsim.collision.bvh_exact). "
                 "The second body is turned by "
                 f"{measure_levels.FIXED_ANGLE} rad about {measure_levels.FIXED_AXIS}, "
                 "but in the touching configurations, where the float filter certifies no "
                 "pair and exact predicates decide them all (refsim's answers are exact, "
                 "FCL's are float). "
                 + "; ".join(f"{c.model} {c.kind}: {c.description}" for c in speed.cases)
                 + ". Below 1: refsim faster. " + _speed_findings(speed_findings(speed))
                 + (f"Numba compile cost from a fresh interpreter: triangle kernel "
                    f"{speed.compile.triangle_kernel_cold_seconds:.1f} s; all hierarchy kernels "
                    f"{speed.compile.hierarchy_cold_seconds:.1f} s with an empty cache, "
                    f"{speed.compile.hierarchy_warm_seconds:.1f} s with the cache that run wrote. "
                    if speed.compile else "Numba compile cost: measured in the full report "
                    "only. ")
                 + f"Reproduce: {SPEED_COMMAND}")))

    # -- C4 ------------------------------------------------------------------------------
    series = []
    for config in sweep.configs:
        series.append(Series(f"{config}: plain float", sweep.thetas,
                             sweep.float_wrong[config], "o-"))
        if sweep.oracle_wrong:
            series.append(Series(f"{config}: FCL", sweep.thetas, sweep.oracle_wrong[config],
                                 "x--"))
    figures.append(Figure(
        id="collision-c4-sweep", title="Near-parallel triangles: answers that differ from "
                                      "the exact one",
        svg=line_chart(series, xlabel="angle between the planes (rad, log scale)",
                       ylabel=f"wrong answers (of {sweep.frames} frames)", logx=True),
        caption=("The C4 family (refsim.studies.triangles.C4_CONFIGS) in "
                 f"{sweep.frames} seeded random rigid frames per angle: how often the same "
                 "test in plain floats, and FCL, answer differently from refsim's exact test "
                 f"on the same float coordinates. Reproduce: {C4_COMMAND}")))
    tables.append(Table(
        id="collision-c4", title="Near-parallel triangles: where each answer first flips",
        columns=("frame", "configuration", "intended", "exact flips at", "float flips at",
                 "FCL flips at", "float wrong (of 17)", "FCL wrong (of 17)"),
        rows=tuple((s.frame, s.config, _yes(s.intended), _theta(s.flip_exact),
                    _theta(s.flip_float), _theta(s.flip_oracle), s.float_wrong,
                    s.oracle_wrong) for s in c4.series),
        caption=("Angles 1e-1 down to 1e-17. 'flips at': the largest angle where the "
                 "answer differs from the configuration's intended answer (in a generic "
                 "frame the rounded coordinates themselves can change the exact answer); "
                 "'wrong': angles where a float answer differs from the exact answer on "
                 f"the same coordinates. Reproduce: {C4_COMMAND}")))

    # -- verdicts --------------------------------------------------------------------
    verdicts.append(_c3_verdict(run.claim("C3")))
    verdicts.append(_c4_verdict(run.claim("C4")))

    agreements = []
    for label, r in triangle_rows:
        agreements.append(Agreement(
            "python-fcl", f"exact triangle test, {label}",
            f"{r.agree} / {r.n} agree; " + ", ".join(f"{v} {k}" for k, v in r.counts.items()),
            TRIANGLES_COMMAND))
    for p in agreement.pairs:
        agreements.append(Agreement(
            "python-fcl", f"intersecting face pairs of posed meshes ({p.source})",
            f"{p.queries_equal} / {p.queries} queries identical; "
            + ", ".join(f"{v} {k}" for k, v in p.counts.items()), BODY_ORACLES_COMMAND))
    for b in agreement.bodies:
        agreements.append(Agreement(
            "python-fcl" if b.oracle == "fcl" else b.oracle,
            f"bodies_collide, boolean ({b.source})",
            f"{b.agree} / {b.n} agree; "
            + ", ".join(f"{v} {k}" for k, v in b.counts.items()), BODY_ORACLES_COMMAND))

    results = {
        "levels": levels,
        "body_oracles": {
            "bodies": agreement.bodies,
            "pairs": [{k: v for k, v in asdict(p).items() if k != "disagreements"}
                      | {"disagreements": [asdict(d) for d in p.disagreements[:20]]}
                      for p in agreement.pairs],
            "bugs": agreement.bugs,
        },
        "hierarchy_speed": fields_of(speed) | {
            "ratios": Timing([{"model": c.model, "kind": c.kind,
                               "pairs_bvh_over_fcl": c.pairs_ratio,
                               "boolean_bvh_over_fcl": c.boolean_ratio,
                               "seed_over_bvh": c.seed_over_bvh} for c in speed.cases])},
        "triangle_pairs_vs_fcl": [
            {"pairs": label, "n": r.n, "agree": r.agree, "counts": r.counts,
             "examples": {k: r.examples(k) for k in r.counts}} for label, r in triangle_rows],
        "c4": c4,
        "c4_sweep": sweep,
    }
    divergences = _divergences(triangle_rows, agreement)
    return Section(
        key="collision", title="Body-body collision",
        intro=("The seed detects body-body collisions at rising accuracy: bounding spheres, "
               "object boxes (test 1), triangle boxes (test 2) and exact triangle pairs "
               "(test 3). refsim implements each level as the seed describes it and, as the "
               "seed asks, a deeper hierarchy (a tree of triangle boxes) that gives the same "
               "pairs. Here: what each level costs and how often it says 'collide' wrongly "
               "(C3), how refsim's exact answers compare with python-fcl and trimesh, every "
               "disagreement classified, how the hierarchy's speed compares with FCL's, and "
               "the near-parallel triangles of claim C4."),
        figures=figures, tables=tables, verdicts=verdicts, agreements=agreements,
        divergences=divergences, results=results)


def _c3_verdict(c3) -> Verdict:
    """C3's sentence from :func:`refsim.claims.collision.c3`'s facts."""
    f = c3.facts
    levels = f["levels"]
    fp, median = f["false_positive_rate"], f["median_seconds"]
    if f["conservative"]:
        text = (f"No level missed a contact (0 false negatives over "
                f"{f['configurations']} constructed configurations and {f['random_poses']} "
                "random poses).")
    else:
        text = (f"{f['false_negatives']} false negatives (a level said 'apart' where the "
                f"surfaces meet) over {f['configurations']} constructed configurations "
                f"and {f['random_poses']} random poses: " + "; ".join(f["missed"]) + ".")
    text += (f" False positives among the {f['negative_queries']} non-colliding queries: "
             + ", ".join(f"{lv} {100 * fp[lv]:.0f}%" for lv in levels)
             + (" (no more at each finer level)." if f["false_positives_ordered"] else
                " (more at some finer level than at the coarser one)."))
    text += (" Median time per boolean query: "
             + ", ".join(f"{lv} {median[lv] * 1e6:.0f} us" for lv in levels)
             + (": each coarser level is no slower" if f["speed_ordered"] else
                ": too close to call whether each coarser level is faster"
                if f["speed_open"] else ": some coarser level is slower than a finer one")
             + " (coarser / finer time ratio against 1, with the interquartile range of "
               "its repeats: "
             + "; ".join(f"{pair} {against_spread(c)}"
                         for pair, c in f["speed_against_parity"].items()) + ")"
             + f"; exact costs {f['exact_over_box']:.2g}x the "
             f"{levels[1]} level and {f['exact_over_coarsest']:.2g}x the "
             f"{levels[0]} level.")
    text += (" The exact level's slowest configurations: "
             + ", ".join(f"{c['name']} ({c['kind']}) {c['seconds'] * 1e6:.0f} us"
                         for c in f["slowest_exact"])
             + (" (bodies touching exactly: exact arithmetic decides those pairs)."
                if f["slowest_all_touching"] else "."))
    coarse, box = levels[0], levels[1]
    if f["box_only"]:
        text += (f" The {coarse} level is not nested with the box levels: it says 'apart' "
                 f"where the {box} level says 'collide' in " + ", ".join(f["box_only"])
                 + (f" (and the reverse in {', '.join(f['coarsest_only'])})"
                    if f["coarsest_only"] else "")
                 + ".")
    else:
        text += (f" On the constructed configurations the {coarse} level says 'collide' "
                 f"wherever the {box} level does.")
    accuracy = ("no level misses a contact" if f["conservative"] else
                f"levels miss {f['false_negatives']} contacts")
    accuracy += (" and false positives fall at each finer level"
                 if f["false_positives_ordered"] else
                 ", but a finer level has more false positives than a coarser one")
    speed = ("each coarser level is faster" if f["speed_ordered"] else
             "whether each coarser level is faster is within the timings' spread"
             if f["speed_open"] else "coarser levels are not always faster")
    summary = accuracy[0].upper() + accuracy[1:] + "; " + speed + "."
    return Verdict(claim="C3", measured=text, verdict=c3.verdict,
                   evidence="collision-levels-tradeoff", command=LEVELS_COMMAND,
                   timing=c3.timing, summary=summary)


def _speed_findings(found: dict) -> str:
    """The speed table's findings (:func:`refsim.claims.collision.speed_findings`):
    refsim over FCL where the bodies are apart but their boxes overlap, and
    where they meet."""
    if not found:
        return ""
    text = ("Where the bodies are apart but their boxes overlap, refsim's time over FCL's: "
            + "; ".join(f"{c['model']} {c['pairs_ratio']:.2g}x all pairs, "
                        f"{_ratio_x(c['boolean_ratio'])} boolean" for c in found["apart"]) + ".")
    if found["apart_slower"]:
        text += (" There the query is all node tests and fixed cost (the call into the "
                 "compiled kernel and its per-query arrays, a few microseconds), with "
                 "little exact testing left to save.")
    if found["meet"]:
        text += (" Where they meet: "
                 + "; ".join(f"{c['model']} {c['kind']} {c['pairs_ratio']:.2g}x"
                             for c in found["meet"])
                 + " (all pairs).")
        if found["best_with_pairs"]:
            text += " The hierarchy compares best when there are pairs to report."
    return text + " "


def _ratio_x(value) -> str:
    return "n/a" if value is None else f"{value:.2g}x"


#: What each class of a triangle-pair disagreement means, for the divergence
#: catalogue (a body-level one says its reason, refsim.collision.disagreement.BODY_REASONS).
KIND_MEANING = {
    "coplanar": "all six vertices lie in one plane, exactly; the oracle's float test "
                "decides the in-plane overlap differently",
    "touching": "the contact rests on an exact zero (shared vertex, edge or face); refsim's "
                "exact predicates count it, the oracle's floats may not",
    "tolerance": "a decision within rounding of the boundary: the oracle's float answer "
                 "differs from the exact one on the same coordinates",
    "bug": "no explanation found: a defect to fix",
}


def _divergences(triangle_rows, agreement) -> list[Divergence]:
    """One catalogue entry per class of oracle disagreement that occurred."""
    from refsim.studies import levels as measure_levels
    from refsim.studies import triangles as measure

    entries = []
    for kind in measure.DISAGREEMENT_KINDS:
        found = [(label, r.n, r.counts[kind]) for label, r in triangle_rows if r.counts[kind]]
        found += [(f"posed meshes ({p.source})", p.queries, p.counts[kind])
                  for p in agreement.pairs if p.counts[kind]]
        if found:
            entries.append(Divergence(
                f"python-fcl's triangle answers: {kind}", f"oracle disagreement: {kind}",
                "; ".join(f"{count} of {n} {label}" for label, n, count in found)
                + f" ({KIND_MEANING[kind]})", "collision-fcl-pairs"))
    for kind in measure_levels.BODY_DISAGREEMENT_KINDS:
        bodies = [b for b in agreement.bodies if b.counts[kind]]
        reasons = [r for r, (k, _) in BODY_REASONS.items() if k == kind
                   and any(b.reasons.get(r) for b in bodies)]
        if bodies:
            entries.append(Divergence(
                f"body-level answers: {kind}", f"oracle disagreement: {kind}",
                "; ".join(f"{b.oracle} ({b.source}): {b.counts[kind]} of {b.n} ("
                          + ", ".join(f"{r} {b.reasons[r]}" for r in reasons
                                      if b.reasons.get(r)) + ")" for b in bodies)
                + " (" + "; ".join(f"{r}: {BODY_REASONS[r][1]}" for r in reasons) + ")",
                "collision-body-oracles"))
    return entries


def _theta(value) -> str:
    return "never" if value is None else f"{value:g}"


def _c4_verdict(c4) -> Verdict:
    """C4's sentence from :func:`refsim.claims.collision.c4`'s facts."""
    f = c4.facts
    worst = f["float_worst"]
    measured = (
        f"Crossing or missing triangles: the plain-float test first differs from the exact "
        f"answer at an angle of {worst:g} rad" if worst is not None else
        "Crossing or missing triangles: the plain-float test never differs from the exact "
        "answer")
    measured += f" (over {f['frames']} random frames per angle"
    if f["oracle_measured"]:
        measured += (f"; FCL from {f['oracle_worst']:g} rad" if f["oracle_worst"] is not None
                     else "; FCL never")
    measured += (
        "). Triangles touching "
        "along a line: "
        + ", ".join(f"{c} wrong from {_theta(t)} rad" if t else f"{c} never wrong"
                    for c, t in f["touching_wrong_from"].items())
        + (". With axis-aligned coordinates (exact input) no float answer is wrong at any "
           "angle." if f["axis_aligned_never_wrong"] else "."))
    if worst is None:
        measured += " Near-parallel planes alone never made the float test wrong."
    elif f["at_rounding"]:
        measured += (f" Near-parallel planes alone are harmless down to {worst:g} rad, "
                     f"{f['float_worst_over_eps']:.3g} times the double-precision epsilon: "
                     "where the rounding of the coordinates is as large as the tilt.")
    else:
        measured += (f" Near-parallel planes alone already go wrong at {worst:g} rad, "
                     f"{f['float_worst_over_eps']:.3g} times the double-precision epsilon.")
    if f["touching_wrong_at_largest_angle"]:
        measured += (f" Exact contacts go wrong already at the largest angle measured "
                     f"({f['largest_angle']:g} rad).")
    elif f["touching_worst"] is not None:
        measured += f" Exact contacts go wrong from {f['touching_worst']:g} rad."
    else:
        measured += " Exact contacts never went wrong."
    if worst is None:
        planes = "Near-parallel planes never made the float test wrong"
    elif f["at_rounding"]:
        planes = "Near-parallel planes are harmless until the tilt is at rounding level"
    else:
        planes = f"Near-parallel planes make the float test wrong from {worst:g} rad"
    contacts = ("; exact contacts never went wrong." if f["touching_worst"] is None else
                "; but triangles that touch exactly break the float test.")
    return Verdict(claim="C4", measured=measured, verdict=c4.verdict,
                   evidence="collision-c4-sweep", command=C4_COMMAND, timing=c4.timing,
                   summary=planes + contacts)
