"""The slide, the elastic tumble and the bounce times: their closed forms,
their tolerances, and what each check makes of trajectories built in closed
form (right, and wrong in known ways)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from refsim.conformance import cases_rigid as R
from refsim.conformance.checks_bounces import (
    BOUNCE_TIME_STEPS,
    bounce_times,
    check_rigid_bounce_times,
)
from refsim.conformance.checks_contact import (
    SLIDE_WINDOW,
    check_rigid_slide_to_roll,
    slide_facet_shift,
    slide_tolerance,
    slide_window,
)
from refsim.conformance.checks_rotation import (
    _contacts,
    check_rigid_elastic_tumble,
    tumble_tolerance,
)
from refsim.conformance.rigid_runs import CONTACT_STEPS, energy_tolerance
from refsim.dynamics import analytic
from tests.conformance.broken_engines import RigidStub
from tests.conformance.test_crash_law_json import bouncer, bouncing


def _cases(*names):
    scenes = tuple(s for s in R.rigid_scenes() if s.name in names)
    assert [s.name for s in scenes] == list(names)
    return R.RigidCases(scenes=scenes)


# -- the slides ------------------------------------------------------------------------


def test_the_slides_and_their_closed_forms():
    """A smooth solid ball (k^2 = 2/5 d^2) would stop slipping at 2 v0 / (7
    mu g) = 0.2912 s and roll at 5/7 v0; the sphere mesh's own k^2 / d^2 is
    0.3985, so 0.2905 s and 2.1451 m/s. The cube stops at v0 / (mu g) after
    v0^2 / (2 mu g)."""
    slides = {s.name: s for s in R.rigid_cases().of_kind("slide")}
    ball, box = slides["slide-ball"], slides["slide-box"]
    for slide in (ball, box):
        body = slide.scene.bodies[0]
        assert body.velocity == (3.0, 0.0, 0.0) and body.angular_velocity == (0.0, 0.0, 0.0)
        assert slide.scene.world.friction == 0.3 and slide.scene.world.restitution == 0.0
        vertices = R._body(body.model.name)[0]
        assert body.position[1] + vertices[:, 1].min() == pytest.approx(-R.HALF_SIZE)
    a = 0.3 * 9.81
    answer = R.slide_answer(ball)
    _, _, inertia = R._body(R.SPHERE)
    ratio = answer["depth"] ** 2 / inertia[2, 2]                   # d^2 / k^2
    assert ratio == pytest.approx(1.0 / 0.39852482, rel=1e-6)
    assert answer["slip_end_time"] == pytest.approx(3.0 / (a * (1.0 + ratio)), rel=1e-12)
    assert answer["slip_end_time"] == pytest.approx(2 * 3.0 / (7 * a), rel=3e-3)
    assert answer["speed_after"] == pytest.approx(3.0 / (1.0 + 1.0 / ratio), rel=1e-12)
    assert answer["speed_after"] == pytest.approx(5 / 7 * 3.0, rel=3e-3)
    # the rolling speed is what the slip's deceleration leaves at its end
    assert answer["speed_after"] == pytest.approx(3.0 - a * answer["slip_end_time"], rel=1e-12)
    cube = R.slide_answer(box)
    assert cube == {"deceleration": a, "slip_end_time": 3.0 / a, "speed_after": 0.0,
                    "depth": 0.5, "distance": 9.0 / (2 * a)}
    # each run goes on past the slip's end
    assert ball.scene.integration.duration > answer["slip_end_time"] + 0.1
    assert box.scene.integration.duration > cube["slip_end_time"] + 0.1


def test_the_slide_tolerance_is_the_facets_share_plus_the_steps():
    """2 CONTACT_STEPS h / T over the window, plus what the facets do: 0 for
    the cube's face; for the sphere-2k model its centre rises and falls by
    1.9 mm as it turns, shifting the fitted deceleration by 0.85 %."""
    slides = {s.name: s for s in R.rigid_cases().of_kind("slide")}
    for name, facets in (("slide-ball", 0.0085484), ("slide-box", 0.0)):
        slide = slides[name]
        start, stop = slide_window(slide)
        assert start == CONTACT_STEPS * 1e-3
        assert stop == SLIDE_WINDOW * R.slide_answer(slide)["slip_end_time"]
        assert slide_facet_shift(slide, start, stop) == pytest.approx(facets, abs=1e-6)
        assert slide_tolerance(slide) == pytest.approx(
            facets + 2 * CONTACT_STEPS * 1e-3 / (stop - start), abs=1e-6)
    assert slide_tolerance(slides["slide-ball"]) == pytest.approx(0.02397, abs=1e-5)


def sliding(scene, mu_factor: float = 1.0) -> SimpleNamespace:
    """The slide in closed form (:func:`refsim.conformance.cases_rigid.slide_answer`)
    with friction ``mu_factor`` times the scene's: the centre's speed and
    the spin, sampled at the scene's frames; the body keeps its orientation."""
    answer = R.slide_answer(scene)
    step, duration = scene.scene.integration.step, scene.scene.integration.duration
    t = np.arange(round(duration / step) + 1) * step
    v0 = scene.scene.bodies[0].velocity[0]
    a = mu_factor * answer["deceleration"]
    _, _, inertia = R._body(scene.scene.bodies[0].model.name)
    rolls = answer["speed_after"] > 0.0
    spin_rate = a * answer["depth"] / inertia[2, 2] if rolls else 0.0
    end = v0 / (a + spin_rate * answer["depth"])
    s = np.minimum(t, end)
    frames = len(t)
    velocity = np.zeros((frames, 1, 3))
    velocity[:, 0, 0] = v0 - a * s
    angular_velocity = np.zeros((frames, 1, 3))
    angular_velocity[:, 0, 2] = -spin_rate * s
    position = np.zeros((frames, 1, 3))
    position[:, 0, :] = scene.scene.bodies[0].position
    position[:, 0, 0] += v0 * s - 0.5 * a * s * s + (v0 - a * end) * (t - s)
    orientation = np.broadcast_to(np.eye(3), (frames, 1, 3, 3)).copy()
    return SimpleNamespace(t=t, position=position, velocity=velocity,
                           angular_velocity=angular_velocity, orientation=orientation)


def _slider(cases, mu_factor):
    def answer(scene):
        return sliding(next(s for s in cases.scenes if s.scene is scene), mu_factor)

    return answer


def test_the_closed_form_slide_passes_and_a_weak_friction_fails():
    cases = _cases("slide-ball", "slide-box")
    exact = check_rigid_slide_to_roll(RigidStub("ideal", _slider(cases, 1.0)), cases)
    assert exact.status == "passed"
    for name, m in exact.measured.items():
        assert abs(m["deceleration_over_mu_g"] - 1.0) < 1e-9, name
        # read at the first frame below CONTACT_STEPS steps of the slip rate
        assert abs(m["slip_end_time"] - m["closed_form_slip_end_time"]) <= 2e-3, name
    ball = exact.measured["slide-ball"]
    assert ball["speed_at_slip_end"] == pytest.approx(ball["closed_form_speed_after"],
                                                      abs=0.3 * 9.81 * 2e-3)
    box = exact.measured["slide-box"]
    assert box["distance"] == pytest.approx(box["closed_form_distance"], rel=1e-12)
    # 5 % less friction: beyond twice the ball's 2.4 % and the cube's 0.44 %
    weak = check_rigid_slide_to_roll(RigidStub("weak", _slider(cases, 0.95)), cases)
    assert weak.classes == {"bug": 2}
    assert weak.measured["slide-ball"]["deceleration_over_mu_g"] == pytest.approx(0.95)
    # 3 % less: within twice the ball's tolerance, beyond the cube's
    weaker = check_rigid_slide_to_roll(RigidStub("3 %", _slider(cases, 0.97)), cases)
    assert {n: m["deceleration_over_mu_g"] for n, m in weaker.measured.items()} == \
        pytest.approx({"slide-ball": 0.97, "slide-box": 0.97})
    assert weaker.classes == {"tolerance": 1, "bug": 1}


# -- the elastic tumble ----------------------------------------------------------------


def test_the_tumble_scene_and_its_tolerance():
    """The brick's centre 3 m above the floor, spinning at (1, 3, 2) rad/s,
    e = 1, no friction, 5 s; the energy check's 2 m g v_max h per impact over
    the starting energy (m g 3 + w.Iw / 2)."""
    tumble = R.rigid_cases().of_kind("tumble")[0]
    body = tumble.scene.bodies[0]
    assert body.model.name == "brick.ac" and body.position == (0.0, -2.0, 0.0)
    assert body.angular_velocity == (1.0, 3.0, 2.0)
    world = tumble.scene.world
    assert (world.restitution, world.friction, world.gravity) == (1.0, 0.0, 9.81)
    assert tumble.scene.integration.duration == pytest.approx(5.0)
    moments = np.array([0.36 + 0.09, 1 + 0.09, 1 + 0.36]) / 12
    start = 9.81 * 3.0 + 0.5 * float(np.dot(moments, [1.0, 9.0, 4.0]))
    assert tumble_tolerance(tumble, 4) == pytest.approx(4 * energy_tolerance(tumble) / start,
                                                        rel=1e-12)
    # v_max: the fall from 2.7 m plus the spin at the brick's reach
    reach = math.sqrt(0.25 + 0.09 + 0.0225)
    v_max = math.sqrt(2 * 9.81 * 2.7) + math.sqrt(14.0) * reach
    assert tumble_tolerance(tumble, 1) == pytest.approx(2 * 9.81 * v_max * 1e-3 / start,
                                                        rel=1e-12)
    assert tumble_tolerance(tumble, 0) == tumble_tolerance(tumble, 1)


def test_an_elastic_bounce_passes_the_tumble_check_and_a_gain_fails():
    """A brick that bounces without turning at e = 1 keeps its energy (3
    impacts in 5 s from 2.7 m); one that leaves each impact 5 % faster
    gains 10 % of its kinetic energy at each."""
    cases = _cases("tumble-brick")
    kept = check_rigid_elastic_tumble(RigidStub("elastic", bouncer(cases, lambda s: 1.0)),
                                      cases)
    m = kept.measured["tumble-brick"]
    assert kept.status == "passed" and m["impacts"] == 3
    assert m["largest_energy_change"] < 1e-12
    gains = check_rigid_elastic_tumble(RigidStub("gains", bouncer(cases, lambda s: 1.05)),
                                       cases)
    assert gains.classes == {"bug": 1}
    assert gains.measured["tumble-brick"]["largest_energy_change"] > 0.1
    law = check_rigid_elastic_tumble(RigidStub("hc", bouncer(cases, lambda s: 1.05),
                                               contact_law="hunt-crossley"), cases)
    assert law.classes == {"law": 1} and law.examples[0]["contact_law"] == "hunt-crossley"


def test_contacts_are_runs_of_frames_off_free_flight():
    def contacts(v):
        velocity = np.zeros((len(v), 1, 3))
        velocity[:, 0, 1] = v
        return _contacts(SimpleNamespace(t=t, velocity=velocity))

    t = np.arange(10) * 1e-3
    free = -9.81 * t
    assert contacts(free) == 0
    v = free.copy()
    v[4:] += 0.5
    v[5:] += 0.5                        # one contact over two steps (3 -> 5)
    v[8:] += 2.0                        # another in one step (7 -> 8)
    assert contacts(v) == 2
    v[7:] += 0.5e-3 * 9.81e-3           # within FLIGHT_TOL of free flight
    assert contacts(v) == 2
    v[1:] += 1.0                        # one more, from the first step
    assert contacts(v) == 3


# -- bounce times ----------------------------------------------------------------------


def test_the_closed_form_drop_bounces_at_the_closed_form_times():
    cases = _cases("drop-sphere-e0.5", "drop-cube-e0.8")
    exact = check_rigid_bounce_times(RigidStub("ideal", bouncer(cases, lambda s: s.e)), cases)
    assert exact.status == "passed"
    for scene in cases.scenes:
        m = exact.measured[scene.name]
        closed = analytic.bounce_times(2.0, 9.81, scene.e, 3)
        assert m["closed_form"] == pytest.approx(closed.tolist(), rel=1e-15)
        assert m["largest_miss"] < 1e-9, scene.name
        assert m["tolerance"] == BOUNCE_TIME_STEPS * 1e-3
    # t1 = sqrt(2 H / g), then 2 e^k v1 / g apart
    v1 = math.sqrt(2 * 9.81 * 2.0)
    assert closed[0] == pytest.approx(math.sqrt(4.0 / 9.81))
    assert np.diff(closed) == pytest.approx([2 * 0.8 * v1 / 9.81, 2 * 0.64 * v1 / 9.81])


def _later(cases, delay):
    """The closed-form drop with every frame's time moved ``delay`` later."""
    def answer(scene):
        trajectory = bouncer(cases, lambda s: s.e)(scene)
        trajectory.t = trajectory.t + delay
        return trajectory

    return answer


def test_bounces_late_by_a_fraction_of_a_step_are_tolerance_then_bug():
    cases = _cases("drop-cube-e0.8")
    h = 1e-3
    within = check_rigid_bounce_times(RigidStub("late", _later(cases, 1.5e-2 * h)), cases)
    assert within.classes == {"tolerance": 1}
    assert within.measured["drop-cube-e0.8"]["misses_in_steps"] == pytest.approx(
        [0.015] * 3, abs=1e-6)
    # the bounce found at the end of its step: 0.45 h late, as refsim's
    # corrected model was before its wall stage placed the impact in the step
    late = check_rigid_bounce_times(RigidStub("late", _later(cases, 0.45 * h)), cases)
    assert late.classes == {"bug": 1}
    softer = check_rigid_bounce_times(RigidStub("hc", bouncer(cases, lambda s: 0.9 * s.e),
                                                contact_law="hunt-crossley"), cases)
    assert softer.classes == {"law": 1}


def test_a_drop_that_stops_bouncing_is_unmeasurable():
    cases = _cases("drop-sphere-e0.5")
    stops = check_rigid_bounce_times(RigidStub("stops", bouncer(cases, lambda s: 0.0)), cases)
    assert stops.classes == {"unmeasurable": 1}
    duration = cases.scenes[0].scene.integration.duration
    assert stops.examples[0]["reason"] == (
        f"0 flights after a bounce, 3 needed (the body bounced fewer times in {duration:g} s)")


def test_the_arc_fit_reads_a_bounce_between_frames():
    """A bounce 0.3 of a step after a frame: the flight after it, sampled at
    the frames, extrapolates back to the instant itself."""
    scene = _cases("drop-sphere-e0.8").scenes[0]
    trajectory = bouncing(scene, scene.e)
    times = bounce_times(scene, trajectory)
    closed = analytic.bounce_times(2.0, 9.81, 0.8, 3)
    assert len(times) >= 3
    assert times[:3] == pytest.approx(closed.tolist(), abs=1e-12)
    # the first impact falls between frames
    assert 0.1 < (closed[0] / 1e-3) % 1.0 < 0.9
