"""The classes a check cannot decide by comparing numbers alone: an engine
that crashes ("crash", with the case's input and the traceback's last line,
never hidden by a declaration of "bug"), an answer the check cannot measure
("unmeasurable", with the reason), an engine that declares another contact
law ("law", naming it); and the strict JSON record, valid against the schema
refsim ships."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import jsonschema
import numpy as np
import pytest

from refsim.cli import main
from refsim.conformance import cases_rigid as R
from refsim.conformance.checks_bounces import check_rigid_apex_ratio, check_rigid_no_spin
from refsim.conformance.results import ConformanceResult, conformance_schema
from refsim.dynamics import analytic
from tests.conformance.broken_engines import RigidStub

CRASHING = "tests.conformance.broken_engines:crashing_triangles"

#: The crashing engine's message, as its traceback's last line shows it.
CRASH_LINE = "ZeroDivisionError: degenerate edge in my_engine.clip()"


def _drops(*names):
    scenes = tuple(s for s in R.rigid_scenes() if s.name in names)
    assert [s.name for s in scenes] == list(names)
    return R.RigidCases(scenes=scenes)


def bouncer(cases, restitution):
    """A stub's answer: the drop of the case set's scene as :func:`bouncing`
    gives it, with ``restitution(rigid_scene)``."""
    def answer(scene):
        rigid = next(s for s in cases.scenes if s.scene is scene)
        return bouncing(rigid, restitution(rigid))

    return answer


def bouncing(scene, e: float) -> SimpleNamespace:
    """The scene's drop as a ball of restitution ``e`` bounces, in closed
    form (parabolas between impacts), sampled at the scene's frames: the
    body keeps its orientation; its lowest vertex falls from the drop height."""
    g, h0 = R.GRAVITY, scene.height
    step, duration = scene.scene.integration.step, scene.scene.integration.duration
    t = np.arange(round(duration / step) + 1) * step
    low, v_y = np.empty_like(t), np.empty_like(t)
    fall = math.sqrt(2.0 * h0 / g)
    speed, start = e * g * fall, fall                  # after the first impact
    for k, time in enumerate(t):
        if time < fall:
            low[k], v_y[k] = h0 - 0.5 * g * time ** 2, -g * time
            continue
        while speed > 0.0 and time > start + 2.0 * speed / g:
            start, speed = start + 2.0 * speed / g, e * speed
        s = time - start
        low[k], v_y[k] = (speed * s - 0.5 * g * s * s, speed - g * s) if speed > 0 else (0.0, 0.0)
    frames = len(t)
    orientation = np.broadcast_to(np.asarray(scene.scene.bodies[0].orientation, dtype=np.float64),
                                  (frames, 1, 3, 3)).copy()
    still = SimpleNamespace(t=t, position=np.zeros((frames, 1, 3)), orientation=orientation)
    offset = R.lowest_height(scene, still)                # the lowest vertex at y = 0
    position = np.zeros((frames, 1, 3))
    position[:, 0, 1] = low - offset
    velocity = np.zeros((frames, 1, 3))
    velocity[:, 0, 1] = v_y
    return SimpleNamespace(t=t, position=position, velocity=velocity,
                           angular_velocity=np.zeros((frames, 1, 3)), orientation=orientation)


# -- crash ------------------------------------------------------------------------------


def test_a_crash_is_counted_with_its_input_and_message_and_not_xfailed_by_bug(tmp_path, capsys):
    declared = tmp_path / "bug.txt"
    declared.write_text("triangles.agreement[bug,tolerance,touching,coplanar]  float test\n")
    out = tmp_path / "out"
    assert main(["conform", CRASHING, "--cases", "12", "-o", str(out),
                 "--expected-failures", str(declared)]) == 1
    printed = capsys.readouterr().out
    row = next(line for line in printed.splitlines() if line.startswith("triangles.agreement"))
    record = json.loads((out / "conformance.json").read_text())
    check = next(c for c in record["checks"] if c["check"] == "agreement")
    crashes = check["classes"]["crash"]
    assert crashes > 0 and f"crash {crashes}" in row and row.endswith("failed")
    assert check["status"] == "failed"
    assert check["reason"].startswith("declared for bug, tolerance, touching, coplanar only; "
                                      "also crash")
    example = next(e for e in check["examples"] if e["class"] == "crash")
    assert example["error"] == CRASH_LINE
    assert example["a"][0][0] > 0.0 and len(example["b"]) == 3     # the input that crashed
    assert "my_engine.clip()" in example["traceback"]
    jsonschema.validate(record, conformance_schema())


@pytest.mark.parametrize("declaration, status, code", [
    ("triangles.agreement  float test", "failed", 1),      # class-wide: all but crash
    ("triangles.agreement[crash,tolerance,touching,coplanar,bug]  it raises", "xfailed", 0),
])
def test_only_a_named_crash_is_accepted(tmp_path, capsys, declaration, status, code):
    declared = tmp_path / "expected.txt"
    declared.write_text(declaration + "\n")
    out = tmp_path / "out"
    assert main(["conform", CRASHING, "--cases", "12", "-o", str(out),
                 "--expected-failures", str(declared)]) == code
    capsys.readouterr()
    check = json.loads((out / "conformance.json").read_text())["checks"][1]
    assert check["status"] == status and check["classes"]["crash"] > 0
    if status == "failed":
        assert check["reason"] == "a crash is accepted only when named; also crash: float test"


def test_a_rigid_engine_that_raises_or_answers_the_wrong_shape_crashes_per_scene():
    cases = _drops("drop-sphere-e0.5", "drop-cube-e0.5")

    def raises(scene):
        raise RuntimeError("solver diverged")

    result = check_rigid_apex_ratio(RigidStub("raises", raises), cases)
    assert result.classes == {"crash": 2} and result.status == "failed"
    assert [e["scene"] for e in result.examples] == ["drop-sphere-e0.5", "drop-cube-e0.5"]
    assert {e["error"] for e in result.examples} == {"RuntimeError: solver diverged"}

    def flat(scene):
        frames = bouncer(cases, lambda s: s.e)(scene)
        frames.velocity = frames.velocity[:, 0]                    # (F, 3): no body axis
        return frames

    result = check_rigid_no_spin(RigidStub("flat", flat), cases)
    assert result.classes == {"crash": 2}
    frames = len(bouncing(cases.scenes[0], 0.5).t)
    assert result.examples[0]["error"] == (
        f"ValueError: drop-sphere-e0.5: trajectory.velocity has shape ({frames}, 3), "
        f"expected ({frames}, 1, 3)")


# -- unmeasurable and law -----------------------------------------------------------------


def test_the_closed_form_bounce_meets_the_apex_check():
    # the stub's bounce itself is right: e's own ratio passes
    cases = _drops("drop-sphere-e0.5")
    result = check_rigid_apex_ratio(RigidStub("ideal", bouncer(cases, lambda s: s.e)), cases)
    assert result.status == "passed"
    ratio = result.measured["drop-sphere-e0.5"]["ratio"]
    assert abs(ratio / analytic.apex_ratio(0.5) - 1.0) < 1e-3


def test_a_bounce_that_stops_is_unmeasurable_with_its_reason():
    cases = _drops("drop-sphere-e0.5")
    result = check_rigid_apex_ratio(RigidStub("stops", bouncer(cases, lambda s: 0.0)), cases)
    assert result.classes == {"unmeasurable": 1}
    example = result.examples[0]
    duration = cases.scenes[0].scene.integration.duration
    assert example["reason"] == ("0 apexes after the release, 3 needed (the body bounced "
                                 f"fewer times in {duration:g} s)")
    assert math.isnan(example["apex_ratio"])
    record = ConformanceResult(engine="stops", refsim="0", seed=0, cases=1,
                               capabilities=("rigid",), checks=(result,)).to_json()

    def refuse(token):
        raise ValueError(f"not strict JSON: {token}")

    data = json.loads(record, parse_constant=refuse)        # no NaN or Infinity token
    assert data["checks"][0]["examples"][0]["apex_ratio"] == "NaN"
    assert data["checks"][0]["measured"]["drop-sphere-e0.5"]["ratio"] == "NaN"
    jsonschema.validate(data, conformance_schema())


def test_a_declared_contact_law_is_law_not_bug():
    cases = _drops("drop-sphere-e0.8")
    softer = bouncer(cases, lambda s: 0.9 * s.e)          # apexes 19 % short
    plain = check_rigid_apex_ratio(RigidStub("plain", softer), cases)
    assert plain.classes == {"bug": 1}
    declared = check_rigid_apex_ratio(RigidStub("hc", softer, contact_law="hunt-crossley"),
                                      cases)
    assert declared.classes == {"law": 1}
    example = declared.examples[0]
    assert example["contact_law"] == "hunt-crossley"
    assert example["apex_ratio"] == pytest.approx(0.81 * 0.64, rel=1e-3)
    # a law is no excuse where the check assumes none: no_spin holds it
    assert check_rigid_no_spin(RigidStub("hc", softer, contact_law="hunt-crossley"),
                               cases).status == "passed"


def test_the_schema_rejects_what_it_should():
    schema = conformance_schema()
    good = json.loads(ConformanceResult(engine="e", refsim="0", seed=0, cases=1,
                                        capabilities=("rigid",), checks=()).to_json())
    jsonschema.validate(good, schema)
    for broken in ({**good, "seed": -1}, {**good, "capabilities": ["wings"]},
                   {**good, "seconds": "nan"}, {**good, "checks": [{"check": "x"}]}):
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(broken, schema)
