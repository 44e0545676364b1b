"""Bounces: the analytic answers (exact), reading bounces off a trajectory,
and refsim's wall response against both (seed S5, S7)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from refsim.claims.dynamics import APEX_RATIO_TARGET
from refsim.dynamics import analytic
from refsim.errors import StateError
from refsim.studies.bounce import (
    ANALYTIC,
    APEX_CASE,
    OBLIQUE_CASES,
    REFSIM,
    REST_CASE,
    SEED_WALL_SPEED,
    by_case,
    measure_apex_drop,
    measure_cost,
    measure_drop_energy,
    measure_oblique,
    measure_rest,
    measure_step_cost,
)
from refsim.studies.bounce_scenes import (
    BOUNCES,
    CUBE,
    DROP_HEIGHT,
    GRAVITY,
    SPHERE,
    STEP,
    apex_ratio,
    read_bounces,
)

G = 9.81

# -- the analytic answers -------------------------------------------------------------


def test_apex_heights_are_a_geometric_series():
    h = analytic.apex_heights(2.0, 0.5, 4)
    np.testing.assert_array_equal(h, [2.0, 0.5, 0.125, 0.03125, 0.0078125])
    assert analytic.apex_ratio(0.8) == 0.8 * 0.8


def test_first_impact():
    assert analytic.impact_speed(5.0, 10.0) == 10.0
    assert analytic.fall_time(5.0, 10.0) == 1.0


def test_bounce_times_add_flights_of_twice_the_rebound_time():
    # h0 = 5, g = 10: t0 = 1, v0 = 10; e = 0.5: flights 2*0.5, 2*0.25, ...
    t = analytic.bounce_times(5.0, 10.0, 0.5, 4)
    np.testing.assert_allclose(t, [1.0, 2.0, 2.5, 2.75], rtol=0, atol=1e-15)
    np.testing.assert_allclose(analytic.apex_times(5.0, 10.0, 0.5, 3), [1.5, 2.25, 2.625],
                               atol=1e-15)
    np.testing.assert_allclose(analytic.bounce_times(5.0, 10.0, 1.0, 3), [1.0, 3.0, 5.0])


def test_zeno_time_is_the_limit_of_the_bounce_times():
    # t0 (1 + 2e/(1-e)) = t0 (1+e)/(1-e): e = 0.5 -> 3 t0.
    assert analytic.time_to_rest(5.0, 10.0, 0.5) == 3.0
    for e in (0.5, 0.8, 0.9):
        zeno = analytic.time_to_rest(DROP_HEIGHT, G, e)
        t0 = analytic.fall_time(DROP_HEIGHT, G)
        assert zeno == pytest.approx(t0 * (1 + e) / (1 - e), rel=1e-15)
        assert analytic.bounce_times(DROP_HEIGHT, G, e, 2000)[-1] == pytest.approx(zeno,
                                                                                  rel=1e-12)
    assert analytic.time_to_rest(1.0, G, 1.0) == math.inf


def test_settling_bounce_and_time():
    # e = 0.5: apexes 1/4, 1/16, 1/64, ... of h0; below 1e-2 after bounce 4 (1/256).
    assert analytic.bounces_until(0.5, 1e-2) == 4
    assert analytic.bounces_until(0.5, 1.0 / 16.0) == 2      # e^4 = 1/16 is not below
    assert analytic.time_to_settle(5.0, 10.0, 0.5, 1e-2) == 2.75


def test_height_and_energy_over_time():
    h0, g, e = 5.0, 10.0, 0.5
    times = analytic.bounce_times(h0, g, e, 3)
    np.testing.assert_allclose(analytic.height(times, h0, g, e), 0.0, atol=1e-13)
    apex_t = analytic.apex_times(h0, g, e, 3)
    np.testing.assert_allclose(analytic.height(apex_t, h0, g, e),
                               analytic.apex_heights(h0, e, 3)[1:], rtol=1e-13)
    assert analytic.height(0.0, h0, g, e) == h0
    energy = analytic.energy([0.0, 0.99, 1.0, 1.5, 2.1], h0, g, e, mass=2.0)
    np.testing.assert_allclose(energy, [100.0, 100.0, 25.0, 25.0, 6.25])


def test_lateral_velocity_seed_and_coulomb():
    assert analytic.lateral_velocity_seed(5.0, 0.3) == pytest.approx(3.5, abs=1e-15)
    # Sliding: 5 - 0.3 * 1.8 * 2 = 3.92.
    assert analytic.lateral_velocity_coulomb(5.0, -2.0, 0.3, 0.8) == pytest.approx(3.92)
    assert analytic.lateral_velocity_coulomb(-5.0, 2.0, 0.3, 0.8) == pytest.approx(-3.92)
    # Sticking stops a point mass.
    assert analytic.lateral_velocity_coulomb(1.0, 2.0, 0.3, 0.8) == 0.0
    # A ball leaves rolling at 5/7 v_t when friction could stop the contact point.
    assert analytic.lateral_velocity_coulomb_ball(2.0, 2.0, 0.3, 0.8) == pytest.approx(10 / 7)
    assert analytic.lateral_velocity_coulomb_ball(5.0, 2.0, 0.3, 0.8) == pytest.approx(3.92)
    assert analytic.sliding_throughout(5.0, 2.0, 0.3, 0.8)
    assert not analytic.sliding_throughout(2.0, 2.0, 0.3, 0.8)


# -- reading bounces ---------------------------------------------------------------------


def test_read_bounces_recovers_the_analytic_series():
    """Sampled at 1 ms, the analytic trajectory gives back its own apexes
    (the parabola through three samples of a parabola is exact)."""
    h0, e = DROP_HEIGHT, 0.8
    t = np.arange(0.0, 6.0, 1e-3)
    y = analytic.height(t, h0, G, e)
    vy = np.gradient(y, t)
    bounces = read_bounces(t, y, vy, 0.0)
    expected = analytic.apex_heights(h0, e, 4)
    np.testing.assert_allclose(bounces.apex_heights[:5], expected, rtol=1e-9)
    np.testing.assert_allclose(bounces.apex_times[1:5], analytic.apex_times(h0, G, e, 4),
                               atol=1e-9)
    # A bounce is read at the first frame moving up: up to one frame late,
    # and np.gradient's central difference straddles the bounce for one more.
    np.testing.assert_allclose(bounces.bounce_times[:4], analytic.bounce_times(h0, G, e, 4),
                               atol=2e-3)
    assert apex_ratio(bounces.apex_heights, 3) == pytest.approx(e * e, rel=1e-9)


# -- refsim against the analytic answer and pybullet ----------------------------------------


@pytest.fixture(scope="module")
def simulate():
    import refsim

    return refsim.simulate


#: refsim's default wall response flips the speed the body had at the wall
#: (DEVIATION D1) and RK4 integrates free fall (a quadratic in t) exactly, so
#: the apex ratio equals e^2 up to rounding: a few ulps per step over a few
#: thousand steps is far below 1e-9 relative. The report says "to rounding";
#: this is that claim, not only the 0.5% tolerance (APEX_RATIO_TARGET).
ROUNDING_LEVEL = 1e-9


def drop(model, e, **kwargs) -> dict:
    """The rows of one drop by engine name (analytic, refsim, refsim with
    the seed's wall speed)."""
    return {r.engine: r for r in measure_apex_drop(model, e, **kwargs)}


@pytest.mark.parametrize("e", [0.5, 0.8, 0.9])
def test_refsim_apex_ratio_meets_the_target(simulate, e):
    """refsim's accuracy goal: with RK4 at h = 1e-3, the mean apex ratio over the
    first BOUNCES bounces is within APEX_RATIO_TARGET (0.5%) of e^2."""
    row = drop(SPHERE, e, step=STEP, solver="rk4")[REFSIM]
    print(f"refsim e={e}: apex ratio {row.ratio:.6f} (e^2 {e * e:.6f}), "
          f"relative error {row.error:.2e}; heights {row.heights}")
    assert row.error <= APEX_RATIO_TARGET
    assert row.error <= ROUNDING_LEVEL
    assert row.max_spin == 0.0                   # rotation "off"


def test_refsim_apex_times_follow_the_analytic_ones(simulate):
    """Bounce k+1 comes 2 e^k v0 / g after bounce k; refsim's apex times are
    off by at most a step per bounce."""
    rows = drop(SPHERE, 0.8)
    error = np.abs(np.subtract(rows[REFSIM].times, rows[ANALYTIC].times))
    assert error.max() <= (BOUNCES + 1) * STEP


@pytest.mark.parametrize("e", [0.5, 0.8, 0.9])
def test_seed_literal_wall_speed_also_meets_the_target(simulate, e):
    """The seed's literal flip (speed at the penetrated position) gains about
    delta / h0 per bounce, delta <= v h: 0.2% here, inside the 0.5% target,
    and above e^2 (it adds energy)."""
    row = drop(SPHERE, e)[SEED_WALL_SPEED]
    print(f"refsim, seed's wall speed, e={e}: apex ratio {row.ratio:.6f}, "
          f"relative error {row.error:.2e}")
    assert row.error <= APEX_RATIO_TARGET
    assert row.ratio > e * e


def test_one_drop_is_one_row_per_engine_under_its_name(simulate):
    """Long form: the analytic row first (e^2 itself, error 0), then one
    row per engine received, each carrying the drop's fields."""
    rows = measure_apex_drop(SPHERE, 0.5, bounces=2)
    assert [r.engine for r in rows] == [ANALYTIC, REFSIM, SEED_WALL_SPEED]
    assert {tuple(getattr(r, f) for f in APEX_CASE) for r in rows} == \
        {(SPHERE, "off", 0.5, STEP, "rk4")}
    closed = rows[0]
    assert (closed.ratio, closed.first_ratio, closed.error, closed.max_spin) == \
        (0.25, 0.25, 0.0, 0.0)
    assert closed.heights == [DROP_HEIGHT, 1.0, 0.25]
    assert all(len(r.heights) == len(r.times) == 3 for r in rows)
    assert list(by_case(rows, APEX_CASE).values()) == [{r.engine: r for r in rows}]


class Renamed:
    """An engine that is another under a new name (a study must take the
    engines it is given, and name its rows after them)."""

    def __init__(self, engine, name):
        self._engine, self.name = engine, name

    def simulate(self, scene):
        return self._engine.simulate(scene)

    def step_time(self, scene, steps, warmup=0):
        return 1e-5


def test_a_study_runs_the_engines_it_receives(simulate):
    from refsim.engines.registry import build

    twin = Renamed(build(REFSIM), "twin")
    rows = measure_rest(restitutions=(0.5,), engines=[build(REFSIM), twin])
    assert [r.engine for r in rows] == [ANALYTIC, REFSIM, "twin"]
    assert (rows[1].settle, rows[1].bounces) == (rows[2].settle, rows[2].bounces)
    assert measure_rest(restitutions=(0.5,), engines=[])[0].engine == ANALYTIC
    with pytest.raises(StateError, match="at least one engine"):
        measure_drop_energy(engines=[])
    # two engines under one name cannot be told apart in the records
    with pytest.raises(StateError, match="two rows of engine 'refsim' for one case"):
        by_case(measure_rest(restitutions=(0.5,), engines=[build(REFSIM), build(REFSIM)]),
                REST_CASE)


def test_the_energy_curves_are_one_per_engine_after_the_analytic_one(simulate):
    from refsim.engines.registry import build

    curves = measure_drop_energy(duration=1.5, engines=[build(REFSIM), Renamed(build(REFSIM),
                                                                                 "twin")])
    assert [c.engine for c in curves] == [ANALYTIC, REFSIM, "twin"]
    closed, ours, twin = curves
    assert closed.t == ours.t == twin.t and ours.height == twin.height
    # before the first impact (0.9 s from 4 m) refsim's free fall is the parabola
    before = [i for i, t in enumerate(ours.t) if t < 0.85]
    np.testing.assert_allclose([ours.height[i] for i in before],
                               [closed.height[i] for i in before], rtol=0, atol=1e-12)
    assert ours.energy[0] == pytest.approx(closed.energy[0], rel=1e-12)


def test_the_cost_study_has_a_series_per_refsim_solver_and_per_other_engine(simulate):
    from refsim.engines.registry import build

    study = measure_cost((1 / 125,), ("euler", "rk4"),
                         engines=[build(REFSIM), build(SEED_WALL_SPEED), Renamed(build(REFSIM),
                                                                                 "twin")])
    assert [(p.engine, p.solver) for p in study.points] == [
        (REFSIM, "euler"), (REFSIM, "rk4"), (SEED_WALL_SPEED, "rk4, seed wall speed"),
        ("twin", "twin")]
    by_series = {p.solver: p for p in study.points}
    # the other engine runs the study's solver (rk4): refsim's rk4 point, bit for bit
    assert by_series["twin"].ratio == by_series["rk4"].ratio
    # RK4 integrates free flight exactly; Euler at 1/125 s does not
    assert by_series["rk4"].error <= ROUNDING_LEVEL < by_series["euler"].error


def test_step_cost_rows_are_refsims_then_each_engines():
    from refsim.claims.dynamics import step_cost_pairs

    rows = measure_step_cost(counts=(1,), rotations=("off",), steps=3, warmup=1, repeats=1,
                             engines=[Renamed(None, "pybullet")])
    assert [(r.engine, r.bodies, r.warmup) for r in rows] == [(REFSIM, 1, 1),
                                                              ("pybullet", 1, 1)]
    assert rows[0].seconds > 0 and rows[1].seconds == 1e-5 and rows[1].stage_seconds == {}
    (pair,) = step_cost_pairs(rows)
    assert pair["ratio"] == rows[0].seconds / 1e-5
    assert pair["stage_seconds"] is rows[0].stage_seconds


def test_cube_face_down_bounces_like_the_sphere(simulate):
    """Without rotation the seed's box-based wall test sees the same interval
    problem for a face-down cube as for the sphere: same ratio target."""
    assert drop(CUBE, 0.8, rotation="off")[REFSIM].error <= APEX_RATIO_TARGET


def test_seed_rotation_spins_a_face_down_cube(simulate):
    """With the seed's rotation model the first bounce is still exact, but
    its single contact vertex (one of four tied, AMBIGUITY A4) gives a torque
    Pi x I that a symmetric bounce should not have: the cube spins and its
    later apexes leave e^2 (measured 5% at e = 0.8; reported, not a target)."""
    row = drop(CUBE, 0.8, rotation="seed")[REFSIM]
    assert row.first_ratio == pytest.approx(0.64, rel=1e-9)
    assert row.max_spin > 1.0
    assert row.error > APEX_RATIO_TARGET


def test_refsim_lateral_velocity_is_the_seed_s_damping(simulate):
    """The seed's friction keeps (1 - friction) of the lateral velocity,
    whatever the normal speed (not Coulomb's mu (1 + e) |v_n| loss)."""
    rows = measure_oblique(models=(SPHERE,))
    assert [r.engine for r in rows] == [REFSIM] * len(OBLIQUE_CASES)
    for row in rows:
        assert row.lateral == pytest.approx(row.seed_analytic, rel=1e-12)
        assert row.spin == 0.0                      # rotation "off"


@pytest.mark.oracle
def test_pybullet_lateral_velocity_is_coulomb_s(simulate, oracle):
    """pybullet's friction is Coulomb's: a ball sliding through the impact
    loses mu (1 + e) |v_n|; one that can reach rolling leaves at 5/7 v_t.

    Tolerance: the impact is resolved in one step, during which gravity adds
    g h to the normal impulse (1% of v_n = 2 m/s at h = 1e-3, so 1% of the
    friction loss), and pybullet solves friction alongside restitution
    iteratively; 2% of v_t covers both.
    """
    from refsim.oracles.pybullet_adapter import PybulletOracle

    with oracle(PybulletOracle) as pybullet:           # skip when pybullet is missing
        rows = measure_oblique(models=(SPHERE,), engines=[pybullet])
    assert [r.engine for r in rows] == ["pybullet"] * len(OBLIQUE_CASES)
    for row in rows:
        print(row)
        assert row.lateral == pytest.approx(row.coulomb_ball, abs=0.02 * row.v_t)


def test_refsim_time_to_rest_matches_the_analytic_settling(simulate):
    """Apexes stay below REST_FRACTION h0 after the same bounce as the
    analytic series, within a few steps per bounce of its time."""
    for d in by_case(measure_rest(restitutions=(0.5,)), REST_CASE).values():
        closed, ours = d[ANALYTIC], d[REFSIM]
        assert ours.bounces == closed.bounces
        assert ours.settle == pytest.approx(closed.settle, abs=2 * closed.bounces * STEP)
        assert ours.settle < ours.zeno
    assert GRAVITY == G
