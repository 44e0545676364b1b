"""The MuJoCo oracle's conventions (refsim.oracles.mujoco_adapter): frames,
quaternions, body-frame angular velocity, the one-step damper, a missing
MuJoCo."""

from __future__ import annotations

import math
import sys
import xml.etree.ElementTree as ET
from dataclasses import replace

import numpy as np
import pytest
from refsim.oracles import OracleUnavailable
from refsim.oracles.mujoco_adapter import engine

from refsim.conformance import cases_rigid as R
from refsim.errors import OptionError
from refsim.scenes.loader import scene_from_dict
from refsim.types import rotation_about_axis

TILT = rotation_about_axis([1.0, 2.0, 3.0], 0.7)
W = np.array([0.3, -2.0, 1.0])


def _free_scene(velocity=(0.0, 0.0, 0.0), duration=1.0, step=1e-3):
    """The l-beam (centre of mass off its origin), tilted and spinning, far
    from every wall, gravity negligible."""
    return scene_from_dict({
        "world": {"gravity": 1e-12, "half_size": 50.0},
        "integration": {"step": step, "duration": duration},
        "body": [{"model": "l-beam.ac", "orientation": TILT.tolist(),
                  "velocity": list(velocity), "angular_velocity": W.tolist()}]})


def test_initial_state_reads_back_in_refsims_conventions():
    mj = engine()
    trajectory = mj.simulate(_free_scene(duration=0.01))
    np.testing.assert_allclose(trajectory.orientation[0, 0], TILT, atol=1e-15)
    np.testing.assert_allclose(trajectory.angular_velocity[0, 0], W, atol=1e-15)
    np.testing.assert_allclose(trajectory.position[0, 0], 0.0, atol=1e-15)


def test_free_body_keeps_its_centre_of_mass_and_angular_momentum():
    mj = engine()
    trajectory = mj.simulate(_free_scene())
    c = mj.properties[0].center
    com = trajectory.position[:, 0] + np.einsum("fij,j->fi", trajectory.orientation[:, 0], c)
    # the scene's velocity (zero) is the centre of mass's, so the centre
    # stays (read as the origin's it would drift |w x R c| ~ 0.4 m in this
    # second), and the recorded velocity is the centre's too
    assert np.abs(com - com[0]).max() < 1e-3
    assert np.abs(trajectory.velocity[:, 0]).max() < 2e-3
    props = mj.properties[0]
    inertia = props.axes @ np.diag(props.inertia) @ props.axes.T
    momentum = [r @ inertia @ r.T @ w for r, w in zip(trajectory.orientation[:, 0],
                                                      trajectory.angular_velocity[:, 0],
                                                      strict=True)]
    # angular momentum is conserved (semi-implicit Euler: to about 1e-3) and
    # the body-frame angular velocity was converted both ways
    drift = np.abs(np.array(momentum) - momentum[0]).max() / np.linalg.norm(momentum[0])
    assert drift < 5e-3
    assert np.abs(trajectory.angular_velocity[-1, 0] - W).max() > 0.5    # it precesses


def test_model_carries_the_one_step_damper_and_inward_walls():
    mj = engine()
    for h, e in ((1e-3, 0.8), (5e-4, 0.5)):
        scene = R._scene("cube.ac", e, 0.3, 1.0, 0.01)
        scene = replace(scene, integration=replace(scene.integration, step=h,
                                                   duration=10 * h))
        root = ET.fromstring(mj.mjcf(scene))
        pairs = root.findall("./contact/pair")
        assert len(pairs) == 6
        for pair in pairs:
            stiffness, damping = map(float, pair.get("solref").split())
            assert stiffness == 0.0 and damping == pytest.approx(-(1 + e) / h)
            assert float(pair.get("solreffriction").split()[1]) == pytest.approx(-1 / h)
            assert pair.get("solimp") == "0.9999 0.9999 0.001 0.5 2.0"
            assert pair.get("friction").split()[:2] == ["0.3", "0.3"]
            assert float(pair.get("margin")) == 0.0
        option = root.find("option")
        gravity = [float(g) for g in option.get("gravity").split()]
        assert gravity == [0.0, -9.81, 0.0] and option.get("cone") == "elliptic"
        assert option.get("integrator") == "Euler"
        walls = [g for g in root.iter("geom") if g.get("type") == "plane"]
        for wall in walls:
            position = np.array(wall.get("pos").split(), float)
            inward = np.array(wall.get("zaxis").split(), float)
            assert position @ inward == -5.0                 # the normal points at the centre


def test_friction_settings_reach_the_model():
    """The friction options docs/decisions/mujoco-friction.md measured: off
    (MuJoCo's defaults, condim 3) unless asked for; condim 4 carries the
    torsional coefficient mu times the cube's spin lever (a unit square's
    mean lever arm, 0.3826); a given solreffriction replaces the one-step
    damper; condim 2 or 5 is refused."""
    scene = R._scene("cube.ac", 0.5, 0.5, 0.0, 0.01)
    option = ET.fromstring(engine().mjcf(scene)).find("option")
    assert float(option.get("impratio")) == 1.0 and option.get("noslip_iterations") == "0"
    root = ET.fromstring(engine(condim=4, impratio=10.0, noslip_iterations=5,
                                solreffriction=(0.02, 1.0)).mjcf(scene))
    option = root.find("option")
    assert float(option.get("impratio")) == 10.0 and option.get("noslip_iterations") == "5"
    for pair in root.findall("./contact/pair"):
        assert pair.get("condim") == "4"
        assert float(pair.get("friction").split()[2]) == pytest.approx(0.5 * 0.38260, abs=1e-4)
        assert pair.get("solreffriction") == "0.02 1.0"
    for condim in (2, 5):                            # refused as the engine is made
        with pytest.raises(OptionError,
                           match=rf"^engine mujoco: condim must be 3, 4 or 6, not {condim}$"):
            engine(condim=condim)


def test_a_drop_bounces_and_reports_the_floor_contact():
    cases = R.rigid_cases()
    drop = cases.of_kind("drop")[1]                          # the sphere, e = 0.8
    trajectory = engine().simulate(drop.scene)
    first = [e for e in trajectory.events if e.other == "y-"][0]
    assert first.time == pytest.approx(math.sqrt(2 * 2.0 / 9.81), abs=2e-3)
    ratio, _ = R.apex_ratio(drop, trajectory)
    assert abs(ratio / 0.64 - 1) < 0.005


def test_missing_mujoco_raises_oracle_unavailable(monkeypatch):
    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(OracleUnavailable, match="'mujoco' is not installed"):
        engine()
