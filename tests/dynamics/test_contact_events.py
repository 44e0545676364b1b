"""Contact events carry what the contact did: the impulse on the body and
where it acted (refsim.dynamics.trajectory.Event), judged against Newton's
impact law, the same on both kernels, and kept by the .npz."""

from __future__ import annotations

import math

import numpy as np
import pytest

import refsim
from refsim.conformance import cases_rigid as R
from refsim.dynamics.trajectory import Trajectory
from refsim.scenes.loader import scene_from_dict

CORRECTED = {"rotation": "impulse", "body_response": "impulse", "wall_response": "impulse"}


def drop(kernel: str, e: float = 0.5, mass: float = 2.0):
    """A ball (radius 0.25, a vertex at its bottom) dropped 1.75 m onto the
    floor, frictionless."""
    scene = scene_from_dict({
        "world": {"restitution": e, "friction": 0.0},
        "integration": {"solver": "euler", "step": 1e-3, "duration": 0.7},
        "dynamics": CORRECTED,
        "body": [{"shape": "sphere", "radius": 0.25, "frequency": 6, "mass": mass,
                  "position": [0.0, -3.0, 0.0]}]})
    return refsim.simulate(scene, every=1) if kernel != "compiled" else \
        _compiled(scene)


def _compiled(scene):
    sim = refsim.Simulation(scene, kernel="compiled")
    assert sim.loop is None                       # the compiled loop takes these steps
    sim.record()
    sim.run(scene.integration.n_steps)
    return sim.trajectory()


@pytest.mark.parametrize("kernel", ["readable", "compiled"])
def test_a_floor_impact_records_newtons_impulse_at_the_contact(kernel):
    """``J = m (1 + e) v`` upward, v the impact speed; the velocity jump of
    the event's step says the same: the impulse and the step's gravity
    ``g h``, exactly (the impulse acts at the instant of the crossing, and
    the ball falls before it and rises after it under the same gravity,
    :func:`refsim.dynamics.walls.bounce_advance`); the point is the ball's
    bottom vertex on the floor."""
    tr = drop(kernel)
    (event,) = [e for e in tr.events if e.kind == "wall"]
    assert event.other == "y-"
    i = int(np.flatnonzero(tr.t >= event.time - 1e-12)[0])      # the event's frame
    v_before, v_after = tr.velocity[i - 1, 0, 1], tr.velocity[i, 0, 1]
    J = np.array(event.impulse)
    assert J[1] == pytest.approx(2.0 * (v_after - v_before + 9.81 * 1e-3), rel=1e-12)
    speed = math.sqrt(2 * 9.81 * 1.75)
    assert J[1] == pytest.approx(2.0 * 1.5 * speed, rel=2e-3)   # found up to a step late
    assert abs(J[0]) + abs(J[2]) < 1e-12
    assert event.point == pytest.approx((0.0, -5.0, 0.0), abs=1e-9)


def test_both_kernels_record_the_same_impulses_bit_for_bit():
    a, b = drop("readable"), drop("compiled")
    assert [e.impulse for e in a.events] == [e.impulse for e in b.events]
    assert [e.point for e in a.events] == [e.point for e in b.events]


def test_a_body_contact_records_the_strikes_impulse():
    """The kit's frictionless strike on a free rod (e = 1): the rod's event
    impulse is the impulse solution's J (Stronge, ch. 2) along -y, at the
    strike point 1.5 m off the rod's centre."""
    from refsim.engines.refsim_engines import corrected

    scene = next(s for s in R.rigid_cases().of_kind("strike") if s.e == 1.0)
    tr = corrected().simulate(scene.scene)
    (event,) = [e for e in tr.events if e.kind == "body"]
    answer = R.strike_answer(scene)
    rod = scene.scene.bodies[0]
    J = rod.mass * answer["rod_velocity"]                 # the rod's momentum after
    assert (event.body, event.other) == ("rod", "ball")
    assert event.impulse == pytest.approx((0.0, J, 0.0), abs=1e-9 * abs(J))
    assert event.point[0] == pytest.approx(R.STRIKE_OFFSET, abs=1e-9)
    assert event.point[1] == pytest.approx(R.ROD_HALF_WIDTH, abs=2e-3)   # found 1.3 mm in


def test_impulses_survive_the_npz_and_the_seed_law_has_none(tmp_path):
    tr = drop("readable")
    tr.save(tmp_path / "drop.npz")
    assert Trajectory.load(tmp_path / "drop.npz").events == tr.events
    seed = scene_from_dict({"integration": {"step": 1e-3, "duration": 0.7},
                            "body": [{"shape": "box", "position": [0.0, -3.0, 0.0]}]})
    (event,) = refsim.simulate(seed).events
    assert event.impulse is None and event.point is None
