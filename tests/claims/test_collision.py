"""C3, C4 and the speed findings (refsim.claims.collision) at their edges.

C3: false positives that stay equal from a coarse to a fine level still
count as ordered, one more at a finer level does not; times likewise; one
false negative breaks the accuracy half. C4: a float answer wrong at an
angle of exactly ROUNDING_TILT epsilons is "at rounding", one just above is
not. The speed findings: refsim at exactly FCL's time is not slower.
"""

from __future__ import annotations

import sys

import pytest

from refsim.claims.collision import PARITY, ROUNDING_TILT, c3, c4, speed_findings
from refsim.studies.levels import (
    ConfigurationLevels,
    HierarchySpeed,
    LevelsResult,
    LevelSummary,
    RandomLevels,
    SpeedCase,
)
from refsim.studies.triangles import C4Result, C4Series, C4Sweep

LEVELS = ("sphere", "aabb", "triangle-aabb", "exact")
EPS = sys.float_info.epsilon


def configuration(name, kind, answers, exact_seconds=1e-4) -> ConfigurationLevels:
    seconds = dict(zip(LEVELS, (1e-6, 2e-6, 1e-5, exact_seconds), strict=True))
    return ConfigurationLevels(
        name=name, kind=kind, description="", intended=answers[-1],
        answers=dict(zip(LEVELS, answers, strict=True)), seconds=seconds,
        seed_seconds={"triangle-aabb": 1e-5, "exact": 1e-4}, candidate_pairs=10,
        exact_pairs=2 if answers[-1] else 0, pairs_seconds={"bvh": 1e-4, "seed": 1e-3},
        seed_answers_equal=True)


def levels_result(false_positives, medians, false_negatives=(0, 0, 0, 0),
                  configurations=None, repeats=None) -> LevelsResult:
    """Four levels with these false-positive counts (of 10 negatives), median
    times and false negatives, and each level's per-repeat times (none: no
    spread)."""
    repeats = repeats or ((),) * len(LEVELS)
    summary = tuple(LevelSummary(lv, t, fp, 10, fn, r) for lv, fp, t, fn, r
                    in zip(LEVELS, false_positives, medians, false_negatives, repeats,
                           strict=True))
    configurations = configurations or (
        configuration("far", "separated-far", (False,) * 4),
        configuration("cubes-face", "touching", (True,) * 4, exact_seconds=9e-3),
        configuration("inside", "inside", (True, True, False, False), exact_seconds=5e-5))
    random = (RandomLevels("a", "b", 5, 2, dict.fromkeys(LEVELS, 0),
                           dict(zip(LEVELS, false_negatives, strict=True)), 30, 4, 0),)
    return LevelsResult(LEVELS, "numba", 3, 0, configurations, random, summary)


ORDERED_TIMES = (1e-6, 2e-6, 1e-5, 1e-4)


@pytest.mark.parametrize(("fp", "times", "fn", "verdict"), [
    ((6, 6, 6, 0), ORDERED_TIMES, (0, 0, 0, 0), "confirmed"),     # equal counts still ordered
    ((6, 7, 5, 0), ORDERED_TIMES, (0, 0, 0, 0), "partly"),        # one more at a finer level
    ((6, 6, 5, 0), (1e-6, 1e-6, 1e-5, 1e-4), (0, 0, 0, 0), "confirmed"),   # equal times
    ((6, 6, 5, 0), (2e-6, 1.999e-6, 1e-5, 1e-4), (0, 0, 0, 0), "partly"),  # coarser slower
    ((6, 6, 5, 0), ORDERED_TIMES, (1, 0, 0, 0), "partly"),        # a missed contact
    ((6, 7, 5, 0), (2e-6, 1e-6, 1e-5, 1e-4), (0, 0, 0, 0), "refuted"),
])
def test_c3_verdict_at_its_thresholds(fp, times, fn, verdict):
    result = c3(levels_result(fp, times, fn))
    assert result.verdict == verdict and result.timing


def test_c3_speed_is_undecided_within_the_run_to_run_spread():
    """The sphere level at 1.05 times the box level's time, over repeats
    whose ratio spreads by 0.2: another run may find it faster, so the speed
    half is open and C3 (accuracy half holding) is undecided; with repeats
    that agree, the same medians make it clearly slower: partly."""
    medians = (1.05e-6, 1e-6, 1e-5, 1e-4)
    noisy = ((0.9e-6, 1.0e-6, 1.05e-6, 1.2e-6, 1.3e-6),) + tuple((t,) * 5 for t in medians[1:])
    steady = tuple((t,) * 5 for t in medians)
    undecided = c3(levels_result((6, 6, 5, 0), medians, repeats=noisy))
    assert undecided.verdict == "undecided" and undecided.facts["speed_open"]
    assert undecided.facts["speed_against_parity"]["sphere / aabb"]["side"] == "within spread"
    decided = c3(levels_result((6, 6, 5, 0), medians, repeats=steady))
    assert decided.verdict == "partly" and not decided.facts["speed_open"]
    assert decided.facts["speed_against_parity"]["sphere / aabb"]["side"] == "above"
    # far apart against the same spread: clearly ordered
    ordered = c3(levels_result((6, 6, 5, 0), (0.5e-6, 1e-6, 1e-5, 1e-4),
                               repeats=((0.4e-6, 0.45e-6, 0.5e-6, 0.55e-6, 0.6e-6),)
                               + tuple((t,) * 5 for t in medians[1:])))
    assert ordered.verdict == "confirmed"


def test_c3_facts():
    facts = c3(levels_result((6, 6, 5, 0), ORDERED_TIMES, (0, 1, 0, 0))).facts
    assert facts["false_negatives"] == 1 and facts["conservative"] is False
    assert facts["missed"] == ["a / b random poses (aabb: 1)"]
    assert facts["false_positive_rate"] == {"sphere": 0.6, "aabb": 0.6, "triangle-aabb": 0.5,
                                            "exact": 0.0}
    assert facts["exact_over_box"] == pytest.approx(50.0)
    assert facts["exact_over_coarsest"] == pytest.approx(100.0)
    assert [c["name"] for c in facts["slowest_exact"]] == ["cubes-face", "far"]
    assert facts["slowest_all_touching"] is False
    assert facts["box_only"] == [] and facts["coarsest_only"] == []
    assert facts["random_poses"] == 5 and facts["configurations"] == 3


THETAS = (1e-1, 1e-8, ROUNDING_TILT * EPS, 1e-14, 1e-17)


def sweep(float_wrong, oracle_wrong=None) -> C4Sweep:
    """Float (and oracle) wrong counts per configuration over THETAS."""
    configs = ("overlap", "touch", "miss", "shared-edge")
    zero = (0,) * len(THETAS)
    return C4Sweep(frames=10, thetas=THETAS, configs=configs,
                   exact_true={c: zero for c in configs},
                   float_wrong={c: float_wrong.get(c, zero) for c in configs},
                   oracle_wrong={} if oracle_wrong is None else
                   {c: oracle_wrong.get(c, zero) for c in configs})


def c4_result(aligned_wrong=0) -> C4Result:
    series = tuple(C4Series(config=c, frame=frame, intended=True, thetas=THETAS,
                            exact=(True,) * 5, plain_float=(True,) * 5, oracle=(),
                            flip_exact=None, flip_float=None, flip_oracle=None,
                            float_wrong=aligned_wrong if frame == "axis-aligned" else 0,
                            oracle_wrong=0)
                   for frame in ("axis-aligned", "generic") for c in ("overlap", "touch"))
    return C4Result(series)


def test_c4_never_wrong_is_confirmed():
    result = c4(c4_result(), sweep({}, {}))
    assert result.verdict == "confirmed"
    assert result.facts["float_worst"] is None and result.facts["oracle_worst"] is None
    assert result.facts["oracle_measured"] is True      # an oracle ran (and was never wrong)


@pytest.mark.parametrize(("wrong_from", "at_rounding"), [
    (2, True),          # wrong from exactly ROUNDING_TILT epsilons: at rounding
    (1, False),         # wrong from 1e-8 rad: far above the rounding
])
def test_c4_rounding_threshold(wrong_from, at_rounding):
    counts = tuple(1 if i >= wrong_from else 0 for i in range(len(THETAS)))
    result = c4(c4_result(), sweep({"miss": counts}))
    assert result.verdict == "partly"
    assert result.facts["float_worst"] == THETAS[wrong_from]
    assert result.facts["at_rounding"] is at_rounding
    assert result.facts["float_worst_over_eps"] == pytest.approx(THETAS[wrong_from] / EPS)
    assert result.facts["oracle_measured"] is False


def test_c4_touching_contacts():
    wrong_everywhere = (1,) * len(THETAS)
    facts = c4(c4_result(aligned_wrong=1), sweep({"touch": wrong_everywhere},
                                                  {"overlap": (0, 0, 0, 3, 0)})).facts
    assert facts["touching_wrong_from"] == {"touch": 1e-1, "shared-edge": None}
    assert facts["touching_wrong_at_largest_angle"] is True
    assert facts["axis_aligned_never_wrong"] is False
    assert facts["oracle_worst"] == 1e-14
    only_small = c4(c4_result(), sweep({"shared-edge": (0, 1, 0, 0, 0)})).facts
    assert only_small["touching_worst"] == 1e-8
    assert only_small["touching_wrong_at_largest_angle"] is False


def speed_case(model, kind, bvh, fcl) -> SpeedCase:
    return SpeedCase(model=model, kind=kind, description="", candidate_pairs=10, exact_pairs=0,
                     fcl_pairs=0, bvh_seconds=bvh, seed_seconds=10 * bvh, fcl_seconds=fcl,
                     bvh_boolean_seconds=bvh / 2, fcl_boolean_seconds=fcl)


@pytest.mark.parametrize(("ratio", "slower"), [(PARITY, False), (PARITY * (1 + 1e-9), True)])
def test_speed_findings_parity(ratio, slower):
    speed = HierarchySpeed("numba", 5, (
        speed_case("sphere", "separated-boxes-overlap", ratio * 1e-5, 1e-5),
        speed_case("sphere", "deep", 2e-5, 1e-4)), None)
    found = speed_findings(speed)
    assert found["apart_slower"] is slower
    assert found["apart"][0]["pairs_ratio"] == pytest.approx(ratio)
    assert found["meet"] == [{"model": "sphere", "kind": "deep", "pairs_ratio": 0.2}]
    assert found["best_with_pairs"] is True


def test_speed_findings_without_fcl_are_empty():
    speed = HierarchySpeed("numba", 5, (speed_case("sphere", "separated-boxes-overlap", 1e-5,
                                                   None),), None)
    assert speed_findings(speed) == {}
