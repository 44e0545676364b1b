"""C11, C12 and the bounce findings (refsim.claims.dynamics) at their edges.

C11 counts a case when its longest run of interpenetrating frames is longer
than the one frame any discrete detection sees; C12 turns on the at-rest
flags of the seed's and the corrected model; the findings on refsim's own
targets (apex ratio, step cost) and on pybullet's cube tipping.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from refsim.claims.dynamics import (
    APEX_RATIO_TARGET,
    C11_CLAIM_CASES,
    DETECTION_FRAMES,
    DIVERGENCE_CLASSES,
    NOTICEABLE_SPIN,
    ROUNDING_ERROR,
    STEP_COST_TARGET,
    agreement_findings,
    apex_findings,
    c11,
    c12,
    divergences,
    height_gaps,
    rest_findings,
    rounding_series,
    step_cost_findings,
    tipping_spin,
)
from refsim.studies import bounce
from refsim.studies.bounce import (
    ApexRow,
    CostPoint,
    CostStudy,
    DropEnergy,
    ObliqueRow,
    RestRow,
    StepCost,
)
from refsim.studies.dynamics import InterpenetrationRow, SpinSeries


def rows(seed_runs: dict, impulse_runs: dict | None = None) -> list[InterpenetrationRow]:
    """Interpenetration rows with these longest runs per case and response."""
    impulse_runs = impulse_runs or dict.fromkeys(seed_runs, 0)
    return [InterpenetrationRow(engine=bounce.REFSIM, case=case, response=response, frames=1000,
                                interpenetrating=3 * run, longest_run=run, contacts=2)
            for response, runs in (("seed", seed_runs), ("impulse", impulse_runs))
            for case, run in runs.items()]


PERSISTS = DETECTION_FRAMES + 1


@pytest.mark.parametrize(("runs", "verdict"), [
    (dict.fromkeys(C11_CLAIM_CASES, PERSISTS) | {"glancing": 0}, "confirmed"),
    # one case overlaps for the detection frame only: partly
    (dict.fromkeys(C11_CLAIM_CASES, PERSISTS) | {"slow": DETECTION_FRAMES}, "partly"),
    # persistence in a case outside the claim does not count
    (dict.fromkeys(C11_CLAIM_CASES, DETECTION_FRAMES) | {"glancing": 50}, "refuted"),
])
def test_c11_verdict_at_the_detection_frame(runs, verdict):
    assert c11(rows(runs)).verdict == verdict


def test_c11_facts():
    facts = c11(rows({"chase": 40, "slow": 1, "stack": 0, "glancing": 3},
                     {"chase": 2, "slow": 0, "stack": 0, "glancing": 0})).facts
    assert facts["persistent"] == ["chase", "glancing"]
    assert facts["detection_only"] == ["slow"] and facts["never"] == ["stack"]
    assert facts["impulse_persistent"] == ["chase"]
    assert facts["claim_cases_persistent"] == ["chase"]
    assert facts["seed"]["chase"] == {"interpenetrating": 120, "frames": 1000, "longest_run": 40}


def spin(model, at_rest, final=0.5, engine=bounce.REFSIM) -> SpinSeries:
    t = np.linspace(0.0, 6.0, 4)
    return SpinSeries(engine=engine, model=model, t=t, spin=np.full(4, final),
                      spin_normal=np.array([5., 5, 5, 4]), rotational_energy=np.ones(4),
                      speed=np.zeros(4), final_spin=final, final_speed=0.0, at_rest=at_rest)


@pytest.mark.parametrize(("seed_rest", "corrected_rest", "verdict"), [
    (False, True, "confirmed"), (False, False, "partly"), (True, True, "refuted"),
    (True, False, "refuted")])
def test_c12_verdict(seed_rest, corrected_rest, verdict):
    assert c12([spin("seed", seed_rest), spin("impulse", corrected_rest)]).verdict == verdict


def test_c12_facts():
    facts = c12([spin("seed", False, 4.2), spin("impulse", True, 1e-4),
                 spin("pybullet", True, 2e-4, engine="pybullet")]).facts
    assert facts["seed_final_spin"] == 4.2 and facts["corrected_final_spin"] == 1e-4
    assert facts["seed_vertical_spin_start"] == 5.0 and facts["seed_vertical_spin_end"] == 4.0
    assert facts["pybullet_final_spin"] == 2e-4
    assert c12([spin("seed", False), spin("impulse", True)]).facts["pybullet_final_spin"] is None
    # the models are refsim's: another engine's series of the same name is not the seed's
    mixed = [spin("seed", True, engine="other"), spin("seed", False), spin("impulse", True)]
    assert c12(mixed).verdict == "confirmed"


def apex(body="sphere-2k.ac", rotation="off", error=1e-3, literal=0.02, ratio=0.64,
         pybullet_spin=math.nan, refsim_spin=0.0, pybullet=True, e=0.8) -> list[ApexRow]:
    """One drop's long-form rows: analytic, refsim, refsim with the seed's
    wall speed and (unless ``pybullet`` is False) pybullet."""
    drop = {"body": body, "rotation": rotation, "e": e, "step": 1e-3, "solver": "rk4"}
    rows = [ApexRow(**drop, engine=bounce.ANALYTIC, heights=[], times=[], ratio=e * e,
                    first_ratio=e * e, error=0.0, max_spin=0.0),
            ApexRow(**drop, engine=bounce.REFSIM, heights=[], times=[], ratio=ratio,
                    first_ratio=0.64, error=error, max_spin=refsim_spin),
            ApexRow(**drop, engine=bounce.SEED_WALL_SPEED, heights=[], times=[], ratio=0.65,
                    first_ratio=0.65, error=literal, max_spin=0.0)]
    if pybullet:
        rows.append(ApexRow(**drop, engine="pybullet", heights=[], times=[], ratio=0.63,
                            first_ratio=0.63, error=0.01, max_spin=pybullet_spin))
    return rows


def drops(*groups) -> list:
    return [row for group in groups for row in group]


TARGET, ROUNDING = 0.005, 1e-9


@pytest.mark.parametrize(("error", "at_rounding", "within"), [
    (ROUNDING, True, True), (ROUNDING * 1.001, False, True),
    (TARGET, False, True), (TARGET * 1.001, False, False)])
def test_apex_findings_targets(error, at_rounding, within):
    found = apex_findings(apex(error=error, literal=TARGET * 1.001), TARGET, ROUNDING)
    assert found["off_at_rounding"] is at_rounding
    assert found["off_within_target"] is within
    assert found["literal_within_target"] is False


def test_apex_findings_cube_and_pybullet():
    found = apex_findings(drops(apex(), apex("cube.ac", error=2e-3,
                                             pybullet_spin=NOTICEABLE_SPIN),
                                apex("cube.ac", "seed", error=0.05, ratio=0.7, refsim_spin=3.0),
                                apex("cube.ac", "seed", error=0.02, ratio=0.6, refsim_spin=1.0,
                                     e=0.9)),
                          TARGET, ROUNDING)
    assert found["cube_off_worst"] == 2e-3
    assert (found["seeded_drops"], found["seeded_above_e2"]) == (2, 1)
    assert found["seeded_max_spin"] == 3.0 and found["seeded_worst"] == 0.05
    assert found["pybullet_cube_spin"] == NOTICEABLE_SPIN
    assert found["pybullet_cube_tips"] is False         # exactly the threshold: no tipping


@pytest.mark.parametrize(("spin_", "tips"), [(NOTICEABLE_SPIN, None),
                                             (NOTICEABLE_SPIN * 1.001, NOTICEABLE_SPIN * 1.001)])
def test_tipping_spin(spin_, tips):
    assert tipping_spin(drops(apex("cube.ac", pybullet_spin=spin_), apex())) == tips


def test_apex_findings_without_the_oracle_or_the_seed_wall_speed():
    rows = [r for r in apex("cube.ac", pybullet=False) if r.engine != bounce.SEED_WALL_SPEED]
    found = apex_findings(rows)
    assert found["off_worst"] == 1e-3 and found["cube_off_worst"] == 1e-3
    assert "literal_worst" not in found and "pybullet_cube_spin" not in found
    assert tipping_spin(rows) is None


def test_rounding_series():
    points = [CostPoint("refsim", "rk4", h, 0.64, ROUNDING, 1.0) for h in (1e-2, 1e-3)]
    points += [CostPoint("refsim", "euler", h, 0.6, err, 1.0)
               for h, err in ((1e-2, 0.1), (1e-3, ROUNDING))]
    points += [CostPoint("pybullet", "pybullet", 1e-2, math.nan, math.nan, 1.0)]
    assert rounding_series(CostStudy(0.8, "sphere-2k.ac", 3, points), ROUNDING) == \
        ["rk4", "pybullet"]      # a series with no finite error has none above rounding


def step(bodies, ratio, warmup=20, rotation="off", stages=None) -> list[StepCost]:
    """refsim's and pybullet's rows of one timed scene, refsim ``ratio``
    times slower."""
    case = {"bodies": bodies, "rotation": rotation, "warmup": warmup, "steps": 50, "repeats": 3}
    return [StepCost(**case, engine=bounce.REFSIM, seconds=ratio * 1e-5,
                     stage_seconds=stages or {}),
            StepCost(**case, engine="pybullet", seconds=1e-5, stage_seconds={})]


@pytest.mark.parametrize(("ratio", "within"), [(STEP_COST_TARGET, True),
                                                (STEP_COST_TARGET * 1.001, False)])
def test_step_cost_target(ratio, within):
    found = step_cost_findings(drops(step(1, 30.0), step(10, 6.0), step(40, ratio)))
    assert found["at_largest"] == [{"rotation": "off", "warmup": 20, "ratio": ratio,
                                    "within_target": within}]
    assert found["ratio_falls"] is True
    assert found["ratios"] == {1: [30.0], 10: [6.0], 40: [ratio]}


def test_step_cost_ratio_must_fall_at_every_count():
    found = step_cost_findings(drops(step(1, 30.0), step(10, 6.0), step(40, 6.0),
                                     step(40, 1.0, warmup=3000)))
    assert found["ratio_falls"] is False            # 6.0 then 6.0: not falling
    assert [r["warmup"] for r in found["at_largest"]] == [20, 3000]
    assert step_cost_findings(step(1, 30.0))["ratio_falls"] is None
    # without the oracle's rows every ratio is nan, and nothing is said to fall
    alone = step_cost_findings([r for r in drops(step(1, 30.0), step(10, 6.0))
                                if r.engine == bounce.REFSIM])
    assert alone["ratio_falls"] is None and all(math.isnan(r) for (r,) in alone["ratios"].values())


def test_step_cost_single_body_stage_and_settled_rows():
    rows = drops(step(1, 30.0), step(1, 20.0, rotation="seed", stages={"a": 1e-5, "b": 3e-5}),
                 step(40, 6.0), step(40, 1.0, warmup=3000))
    found = step_cost_findings(rows)
    assert [r["rotation"] for r in found["single"]] == ["off", "seed"]
    assert found["largest_stage"] == {"rotation": "seed", "stage": "b",
                                      "fraction": 3e-5 / rows[2].seconds}
    assert found["settled"] == [{"warmup": 3000, "refsim_seconds": 1e-5,
                                 "pybullet_seconds": 1e-5}]


def test_thresholds_sit_beside_the_claims():
    assert APEX_RATIO_TARGET == 0.005
    # the findings and the study's fitted orders call the same errors rounding
    assert ROUNDING_ERROR == bounce.ROUNDING_ERROR
    assert apex_findings(apex())["target"] == APEX_RATIO_TARGET


def curve(engine, height) -> DropEnergy:
    return DropEnergy(body="sphere-2k.ac", e=0.8, engine=engine, t=[0.0, 1.0, 2.0],
                      height=height, energy=[])


def test_height_gaps():
    series = [curve(bounce.ANALYTIC, [1.0, 0.25, 0.5]), curve(bounce.REFSIM, [1.0, 0.5, None]),
              curve("pybullet", [1.0, 0.2, 0.3])]
    times = {bounce.ANALYTIC: [0.0, 1.0, 2.0], bounce.REFSIM: [0.0, 1.001, 2.0],
             "pybullet": [0.0, 1.0, 2.01]}
    rows = [ApexRow(**{**r.__dict__, "times": times.get(r.engine, [])}) for r in apex()]
    found = height_gaps(series, rows)
    assert found["refsim_height"] == 0.25 and found["pybullet_height"] == 0.2
    assert found["bounces"] == 2
    assert found["refsim_apex_ms"] == pytest.approx(1.0)
    assert found["pybullet_apex_ms"] == pytest.approx(10.0)
    seeded = [ApexRow(**{**r.__dict__, "rotation": "seed"}) for r in rows]
    assert "bounces" not in height_gaps(series, seeded)
    alone = height_gaps(series[:2], [r for r in rows if r.engine != "pybullet"])
    assert math.isnan(alone["pybullet_height"]) and math.isnan(alone["pybullet_apex_ms"])


def test_rest_findings():
    def drop(e, refsim, pybullet):
        case = {"body": "s", "e": e, "zeno": 3.0}
        return [RestRow(**case, engine=bounce.ANALYTIC, settle=2.0, bounces=5),
                RestRow(**case, engine=bounce.REFSIM, settle=refsim, bounces=5),
                RestRow(**case, engine="pybullet", settle=pybullet[0], bounces=pybullet[1])]

    found = rest_findings(drops(drop(0.5, 2.5, (2.0, 7)), drop(0.8, 2.0, (math.nan, 0))))
    assert found[0]["refsim_offset_ms"] == 500.0 and found[0]["pybullet_bounces_late"] == 2
    assert "pybullet_bounces" not in found[1]
    assert [f["e"] for f in found] == [0.5, 0.8]


def oblique(body="sphere-2k.ac", pybullet=1.0, coulomb=1.25) -> list[ObliqueRow]:
    """One oblique bounce's rows: refsim's and, unless ``pybullet`` is None,
    pybullet's lateral speed."""
    case = {"body": body, "rotation": "off", "e": 0.8, "friction": 0.3, "v_t": 2.0,
            "v_n": 5.0, "seed_analytic": 1.4, "coulomb_point": 1.0, "coulomb_ball": coulomb,
            "ball_slides": False}
    lateral = {bounce.REFSIM: 1.4, "pybullet": pybullet}
    return [ObliqueRow(**case, engine=name, lateral=value, spin=0.0)
            for name, value in lateral.items() if value is not None]


def test_agreement_findings():
    found = agreement_findings(drops(apex(error=1e-3), apex("cube.ac", error=2e-3),
                                     apex(rotation="seed", error=0.5)),
                               drops(oblique(), oblique(pybullet=None), oblique("cube.ac", 0.0)))
    assert found["refsim_worst"] == 2e-3 and found["drops"] == 2
    assert found["pybullet_worst"] == 0.01 and found["pybullet_drops"] == 2
    assert found["coulomb_worst"] == 0.2 and found["coulomb_bounces"] == 1
    assert found["target"] == APEX_RATIO_TARGET and found["step"] == bounce.STEP
    assert agreement_findings([], []) == {"target": APEX_RATIO_TARGET, "step": bounce.STEP}
    # without the oracle's rows there is no oracle figure (not a nan one)
    alone = agreement_findings(apex(pybullet=False), oblique(pybullet=None))
    assert alone["refsim_worst"] == 1e-3 and "pybullet_worst" not in alone
    assert "coulomb_worst" not in alone


def test_divergences_are_classed():
    found = divergences(drops(apex(literal=-0.03), apex("cube.ac", pybullet_spin=1.0)),
                        oblique())
    assert [d["key"] for d in found] == ["pybullet-apex", "literal-wall-flip",
                                         "lateral-friction", "pybullet-tips"]
    assert all(d["class"] == DIVERGENCE_CLASSES[d["key"]] for d in found)
    assert found[1]["seed_speed_error"] == -0.03 and found[3]["spin"] == 1.0
    assert (found[0]["pybullet_error"], found[0]["refsim_error"]) == (0.01, 1e-3)
    assert found[2]["bounces"] == [{"v_t": 2.0, "refsim": 1.4, "pybullet": 1.0,
                                    "coulomb": 1.25}]
    assert divergences([], []) == []


def test_c12_without_refsims_two_series_says_what_it_has():
    with pytest.raises(ValueError, match=r"C12 needs refsim's seed and impulse spin series; "
                                         r"the runs hold \[\('other', 'seed'\), "
                                         r"\('refsim', 'impulse'\)\]"):
        c12([spin("seed", False, engine="other"), spin("impulse", True)])
