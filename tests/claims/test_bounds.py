"""C1 and C2 (refsim.claims.bounds) at the edges of their thresholds.

Each case is a hand-built set of measurements and the verdict it must give:
just inside and just outside the factor-of-two band of "nearly equal", the
compiled crossover at and just past the seed's 2000 triangles, and the
convex and non-convex meshes that make C2 hold, hold partly or fail.
"""

from __future__ import annotations

import pytest

from refsim.claims.bounds import ABOUT_EQUAL, COMPILED, INTERPRETED, SEED_LARGE_MODEL, c1, c2
from refsim.studies.bounds import IncrementalError, UpdateCostStudy


def cost_study(crossover, ratios, interpreted=20480, repeats=None) -> UpdateCostStudy:
    """A cost study whose compiled crossover and scan/incremental ratios
    (size -> ratio) are given, and the ratios of each repeat (size -> tuple;
    none: no spread); C1 reads nothing else."""
    return UpdateCostStudy(rows=(), degrees_per_frame=1.0, frames=50, repeats=3, seed=0,
                           pose_check_seconds=1e-5,
                           crossovers={COMPILED: crossover, INTERPRETED: interpreted},
                           speedups={COMPILED: sorted(ratios.items())},
                           speedup_repeats={COMPILED: sorted((repeats or {}).items())})


def around(ratio, iqr):
    """Five repeats with median ``ratio`` and interquartile range ``iqr``."""
    return (ratio - iqr, ratio - iqr / 2, ratio, ratio + iqr / 2, ratio + iqr)


LOW, HIGH = ABOUT_EQUAL
BELOW = 1 - 1e-9       # a factor just inside a bound
ABOVE = 1 + 1e-9       # and just outside


@pytest.mark.parametrize(("crossover", "ratios", "verdict"), [
    # faster from 2000 on, equal below: both parts hold
    (SEED_LARGE_MODEL, {80: LOW, 980: HIGH, 2000: 1.3}, "confirmed"),
    # the band's edges, just outside: only the speed part holds
    (SEED_LARGE_MODEL, {80: LOW * BELOW, 2000: 1.3}, "partly"),
    (SEED_LARGE_MODEL, {80: HIGH * ABOVE, 2000: 1.3}, "partly"),
    # the crossover just past the seed's size: only the equality part holds
    (SEED_LARGE_MODEL + 1, {80: 1.0, 2000: 0.99}, "partly"),
    # no crossover at all and a ratio out of the band: neither holds
    (None, {80: 0.3, 2000: 0.9}, "refuted"),
    # no smaller size measured below the crossover: "equal below" cannot hold
    (80, {80: 1.2, 2000: 1.5}, "partly"),
])
def test_c1_verdict_at_its_thresholds(crossover, ratios, verdict):
    result = c1(cost_study(crossover, ratios))
    assert result.claim == "C1" and result.verdict == verdict and result.timing


@pytest.mark.parametrize(("ratios", "repeats", "verdict", "open_sizes"), [
    # 2000 triangles: 1.05 against a spread of 0.1: it may be slower next run
    ({80: 1.0, 2000: 1.05}, {80: around(1.0, 0.1), 2000: around(1.05, 0.1)},
     "undecided", [2000]),
    # the same ratio with repeats that agree to 0.01: faster
    ({80: 1.0, 2000: 1.05}, {80: around(1.0, 0.1), 2000: around(1.05, 0.01)},
     "confirmed", []),
    # clearly slower at 2000 and clearly outside the band below it
    ({80: 0.3, 2000: 0.7}, {80: around(0.3, 0.05), 2000: around(0.7, 0.1)}, "refuted", []),
    # 1.95 below the crossover against a spread of 0.1: at the band's edge
    ({80: 1.95, 2000: 1.5}, {80: around(1.95, 0.1), 2000: around(1.5, 0.1)},
     "undecided", [80]),
    # 2.3 is three spreads outside the band: only the speed part holds
    ({80: 2.3, 2000: 1.5}, {80: around(2.3, 0.1), 2000: around(1.5, 0.1)}, "partly", []),
])
def test_c1_is_undecided_within_the_run_to_run_spread(ratios, repeats, verdict, open_sizes):
    crossover = 2000 if verdict != "refuted" else None
    result = c1(cost_study(crossover, ratios, repeats=repeats))
    assert result.verdict == verdict
    assert result.facts["open"] == open_sizes
    at_large = result.facts["against_parity"][2000]
    assert at_large["spread"] == pytest.approx(repeats[2000][3] - repeats[2000][1])


def test_c1_facts_are_the_quoted_numbers():
    facts = c1(cost_study(980, {80: 0.6, 180: 0.9, 980: 1.1, 2000: 1.38},
                          interpreted=5120)).facts
    assert facts["compiled_crossover"] == 980
    assert facts["interpreted_crossover"] == 5120
    assert facts["ratio_at_large_model"] == 1.38
    assert facts["ratios_below_crossover"] == [0.6, 0.9]
    assert facts["equal_below_crossover"] is True
    assert facts["faster_at_large_model"] is True


def error(mesh, convex, wrong) -> IncrementalError:
    return IncrementalError(mesh=mesh, n_triangles=80, convex=convex, motion="coherent",
                            frames=100, wrong_frames=wrong, wrong_fraction=wrong / 100,
                            wrong_side_fraction=wrong / 600, max_deficit=0.1 * bool(wrong),
                            median_deficit=0.0, visits_per_update=10.0)


@pytest.mark.parametrize(("errors", "verdict", "sufficient_not_necessary"), [
    # right on every convex mesh, wrong on the only non-convex one
    ([error("sphere", True, 0), error("torus", False, 7)], "confirmed", False),
    # and never wrong on another non-convex mesh: convexity is not necessary
    ([error("sphere", True, 0), error("torus", False, 7), error("bumpy", False, 0)],
     "partly", True),
    # one wrong frame on a convex mesh: refuted
    ([error("sphere", True, 1), error("torus", False, 7)], "refuted", False),
    # never wrong anywhere: the need is not shown
    ([error("sphere", True, 0), error("bumpy", False, 0)], "refuted", False),
])
def test_c2_verdict(errors, verdict, sufficient_not_necessary):
    result = c2(errors)
    assert result.verdict == verdict and not result.timing
    assert result.facts["sufficient_not_necessary"] is sufficient_not_necessary


def test_c2_facts_name_the_meshes():
    facts = c2([error("sphere", True, 0), error("torus", False, 7), error("torus", False, 3),
                error("bumpy", False, 0), error("l-beam", False, 2)]).facts
    assert facts["convex_wrong_frames"] == 0
    assert facts["nonconvex_wrong"] == ["l-beam", "torus"]
    assert facts["nonconvex_never_wrong"] == ["bumpy"]


def test_box_agreement():
    from refsim.claims.bounds import TRIMESH_BITS_CLASS, box_agreement
    from refsim.studies.bounds import BoundsAgreement

    rows = [BoundsAgreement("cube.ac", 12, 50, 50, 48, 50, 0.25),
            BoundsAgreement("star.ac", 96, 50, None, 50, 50, 0.0)]
    found = box_agreement(rows)
    assert found == {"poses": 100, "trimesh_within": 100, "trimesh_bitwise": 98,
                     "trimesh_differ": 2, "convex_poses": 50, "incremental_exact": 50,
                     "largest_over_bound": 0.25, "class": TRIMESH_BITS_CLASS}
    same = box_agreement([BoundsAgreement("star.ac", 96, 50, None, 50, 50, 0.0)])
    assert same["trimesh_differ"] == 0 and "class" not in same
