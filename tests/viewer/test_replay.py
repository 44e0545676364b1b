"""Standalone replays (refsim.viewer.replay, refsim.viewer.demos, refsim
replay): whole files within their size budget, a recording that plays for
the runs' duration, the settings on the page, and one-line errors."""

from __future__ import annotations

import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import refsim
from refsim.cli import main
from refsim.viewer import demos
from refsim.viewer.replay import (
    ReplayRun,
    frame_at,
    kept_frames,
    load_runs,
    named_settings,
    read_recording,
    run_from_scene,
    timeline,
    write_replay,
)

#: viser's client alone is about 0.8 MB: a page below this size is broken.
CLIENT_BYTES = 500_000


def _short(name: str, duration: float, **dynamics):
    scene = refsim.load_scene(name)
    scene = replace(scene, integration=replace(scene.integration, duration=duration))
    return replace(scene, dynamics=replace(scene.dynamics, **dynamics)) if dynamics else scene


@pytest.fixture(scope="module")
def spin_runs():
    runs = []
    for model in ("seed", "impulse"):
        scene = _short("spinning-cube.toml", 1.0, rotation=model)
        runs.append(run_from_scene(model, scene, refsim.simulate(scene)))
    return runs


def _check_page(path: Path, duration: float) -> dict:
    text = path.read_text()
    assert text.startswith("<!doctype html>") and text.rstrip().endswith("</html>")
    recording = read_recording(text)
    assert recording["durationSeconds"] == pytest.approx(duration)
    assert 'id="refsim-replay"' in text
    return recording


def test_side_by_side_replay(spin_runs, tmp_path):
    info = write_replay(spin_runs, tmp_path / "spin.html")
    assert info.path.stat().st_size == info.bytes
    assert CLIENT_BYTES < info.bytes <= info.max_bytes
    assert info.stride == 1 and info.frames == info.timeline_frames == 1001
    recording = _check_page(info.path, 1.0)
    assert len(recording["messages"]) > 1000             # a pose update per frame
    text = info.path.read_text()
    for shown in ("seed", "impulse", "rk4", "spinning-cube.toml", "side by side"):
        assert shown in text
    assert "wrote" in info.summary() and "stride 1" in info.summary()
    # the panel names the settings in words: no snake_case key is shown
    panel = text.split('<div id="refsim-replay">', 1)[1]
    keys = re.findall(r"<tr><td>([^<]*)</td>", panel)
    assert "body response" in keys and "collision level" in keys and "box update" in keys
    assert not [k for k in keys if "_" in k]


def test_settings_are_named_in_words_in_a_fixed_order():
    settings = {"wall_speed": "wall", "aabb": "auto", "solver": "rk4", "zeta_extra": 1,
                "body_response": "seed", "scene_toml": "[world]", "scene": "a.toml"}
    assert named_settings(settings) == [
        ("scene", "a.toml"), ("solver", "rk4"), ("body response", "seed"),
        ("box update", "auto"), ("wall speed", "wall"), ("zeta extra", 1)]


def test_a_tight_budget_widens_the_stride(spin_runs, tmp_path):
    full = write_replay(spin_runs, tmp_path / "full.html")
    budget = full.bytes - (full.bytes - CLIENT_BYTES) // 20     # well under the full page
    budget = min(budget, full.bytes - 20_000)
    info = write_replay(spin_runs, tmp_path / "tight.html", max_bytes=budget)
    assert info.bytes <= budget < full.bytes
    assert info.stride > 1
    assert info.frames == len(kept_frames(info.timeline_frames, info.stride))
    _check_page(info.path, 1.0)                          # still ends at the last frame
    assert f"stride {info.stride}" in info.path.read_text()


def test_a_budget_below_the_client_is_refused(spin_runs, tmp_path):
    with pytest.raises(refsim.RefsimError, match="without its frames"):
        write_replay(spin_runs, tmp_path / "x.html", max_bytes=100_000)
    assert list(tmp_path.iterdir()) == []


def test_a_given_stride(spin_runs, tmp_path):
    info = write_replay(spin_runs, tmp_path / "s.html", stride=100)
    assert info.stride == 100 and info.frames == 11       # 0, 100, ..., 1000
    with pytest.raises(refsim.StateError, match="stride"):
        write_replay(spin_runs, tmp_path / "s.html", stride=0)


def test_an_unwritable_path_leaves_nothing(spin_runs, tmp_path):
    with pytest.raises(refsim.OutputError, match="cannot write"):
        write_replay(spin_runs, tmp_path / "missing" / "x.html")
    assert list(tmp_path.iterdir()) == []


def test_overlay_with_boxes(spin_runs, tmp_path):
    info = write_replay(spin_runs, tmp_path / "overlay.html", overlay=True, boxes=True)
    assert info.overlay and "overlaid" in info.path.read_text()
    names = {m[1].get("name") for m in read_recording(info.path.read_text())["messages"]}
    assert {"/run0/boxes", "/run1/boxes", "/run0/world-cube"} <= names
    assert "/run1/world-cube" not in names               # one cube when overlaid


def test_timeline_merges_runs_of_different_strides():
    a = np.array([0.0, 0.5, 1.0])
    b = np.array([0.0, 0.25, 0.5, 0.75])
    runs = [type("R", (), {"trajectory": type("T", (), {"t": t})})() for t in (a, b)]
    times = timeline(runs)
    assert times.tolist() == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert frame_at(a, times).tolist() == [0, 0, 1, 1, 2]
    assert frame_at(b, times).tolist() == [0, 1, 2, 3, 3]     # holds its last frame
    assert kept_frames(5, 2).tolist() == [0, 2, 4] and kept_frames(6, 4).tolist() == [0, 4, 5]


def test_a_run_needs_one_mesh_per_body(spin_runs):
    run = spin_runs[0]
    with pytest.raises(refsim.RefsimError, match="2 meshes for 1 body"):
        ReplayRun("x", run.trajectory, run.meshes * 2, 5.0)


# -- the command line ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    folder = tmp_path_factory.mktemp("runs")
    for name in ("bounce", "head-on"):
        scene = _short(f"{name}.toml", 0.5)
        refsim.simulate(scene, every=10).save(folder / f"{name}.npz")
    return folder


def test_replay_command(recorded, tmp_path, capsys):
    out = tmp_path / "r.html"
    code = main(["replay", str(recorded / "bounce.npz"), str(recorded / "head-on.npz"),
                 "--scene", "bounce.toml", "--scene", "head-on.toml", "-o", str(out)])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    assert printed.out.startswith(f"wrote {out}: 2 runs side by side")
    assert printed.out.count("\n") == 1
    _check_page(out, 0.5)


def _one_line_error(capsys, argv, expected: str) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("refsim: error: ")
    assert expected in err
    assert "Traceback" not in err
    return err


def test_replay_without_a_scene_says_how_to_give_one(recorded, tmp_path, capsys):
    _one_line_error(capsys, ["replay", str(recorded / "bounce.npz"), "-o",
                             str(tmp_path / "r.html")], "--scene SCENE.toml")
    assert not (tmp_path / "r.html").exists()


def test_replay_with_the_wrong_scene(recorded, tmp_path, capsys):
    _one_line_error(capsys, ["replay", str(recorded / "bounce.npz"), "--scene",
                             "head-on.toml", "-o", str(tmp_path / "r.html")],
                    "the run's bodies (ball) are not those of scene")


def test_replay_of_a_missing_file(tmp_path, capsys):
    _one_line_error(capsys, ["replay", str(tmp_path / "nope.npz"), "--scene", "bounce.toml",
                             "-o", str(tmp_path / "r.html")], "no such file")


def test_replay_of_a_particle_run(tmp_path, capsys):
    np.savez(tmp_path / "p.npz", t=np.zeros(1), position=np.zeros((1, 2, 3)),
             status=np.array("complete"))
    _one_line_error(capsys, ["replay", str(tmp_path / "p.npz"), "--scene", "bounce.toml",
                             "-o", str(tmp_path / "r.html")], "a particle run")


def test_replay_with_a_scene_count_that_fits_no_run(recorded, tmp_path, capsys):
    _one_line_error(capsys, ["replay", str(recorded / "bounce.npz"), str(recorded / "bounce.npz"),
                             str(recorded / "bounce.npz"), "--scene", "bounce.toml",
                             "--scene", "bounce.toml", "-o", str(tmp_path / "r.html")],
                    "once per run")


def test_a_run_recording_its_scene_needs_no_scene_argument(recorded, tmp_path):
    traj = refsim.Trajectory.load(recorded / "bounce.npz")
    traj.settings["scene"] = str(refsim.load_scene("bounce.toml").path)
    traj.save(tmp_path / "with-scene.npz")
    [run] = load_runs([tmp_path / "with-scene.npz"])
    assert run.label == "with-scene" and run.settings["scene"].endswith("bounce.toml")


def test_a_changed_scene_is_reported(recorded):
    scene = refsim.load_scene("bounce.toml")
    moved = replace(scene, bodies=(replace(scene.bodies[0], position=(0.0, 1.0, 0.0)),))
    with pytest.warns(UserWarning, match="another version of the scene"):
        load_runs([recorded / "bounce.npz"], [moved])


# -- the demos ------------------------------------------------------------------------------


def test_demo_replays_are_valid_standalone_files(tmp_path):
    c12 = demos.demo_c12(tmp_path / "c12.html", duration=0.6)
    c11 = demos.demo_c11(tmp_path / "c11.html", duration=0.6)
    for info, duration in ((c12, 0.6), (c11, 0.6)):
        assert CLIENT_BYTES < info.bytes <= info.max_bytes
        _check_page(info.path, duration)
    assert "rotation = seed" in c12.path.read_text()
    assert "body_response = impulse" in c11.path.read_text()


def test_wall_bounce_demo_takes_any_rigid_engine_of_the_registry(tmp_path):
    # refsim's corrected model stands in for an external engine
    info = demos.demo_wall_bounce(tmp_path / "bounce.html", engine="refsim-corrected",
                                  duration=0.5)
    assert info.runs == ("refsim", "refsim corrected")
    _check_page(info.path, 0.5)


def test_wall_bounce_demo_refuses_a_missing_engine_before_simulating(tmp_path, monkeypatch):
    from refsim.oracles import OracleUnavailable

    from refsim.engines import registry

    def build(name, **settings):
        raise OracleUnavailable(f"{name} is not installed")

    simulated = []
    monkeypatch.setattr(registry, "build", build)
    monkeypatch.setattr("refsim.dynamics.simulate.simulate",
                        lambda scene, **kw: simulated.append(scene))
    with pytest.raises(OracleUnavailable, match="pybullet is not installed"):
        demos.demo_wall_bounce(tmp_path / "bounce.html", duration=0.5)
    assert simulated == [] and not (tmp_path / "bounce.html").exists()


@pytest.mark.oracle
def test_wall_bounce_demo_beside_pybullet(tmp_path, oracle):
    from refsim.oracles.pybullet_adapter import PybulletOracle

    oracle(PybulletOracle).close()                        # skips without pybullet
    info = demos.demo_wall_bounce(tmp_path / "bounce.html", duration=0.5)
    assert info.runs == ("refsim", "pybullet")
    text = info.path.read_text()
    _check_page(info.path, 0.5)
    assert "pybullet" in text and "engine" in text


# -- runs of `refsim run` record their scene ----------------------------------------------

#: A cube of the scene's own folder, dropped for ten steps.
OWN_MODEL_SCENE = """
[integration]
solver = "rk4"
step = 0.001
duration = 0.01

[[body]]
name = "box"
model = "my-cube.ac"
position = [0.0, 0.5, 0.0]
velocity = [0.5, 0.0, 0.0]
"""


@pytest.fixture
def own_model_run(tmp_path):
    from refsim.bundled import models_dir

    folder = tmp_path / "scene"
    folder.mkdir()
    (folder / "my-cube.ac").write_bytes((models_dir() / "cube.ac").read_bytes())
    scene = folder / "drop.toml"
    scene.write_text(OWN_MODEL_SCENE)
    run = tmp_path / "drop.npz"
    assert main(["run", str(scene), "-o", str(run)]) == 0
    return run


def test_a_run_of_refsim_run_replays_without_a_scene(own_model_run, tmp_path, capsys,
                                                     monkeypatch):
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)                  # the model resolves beside the scene file
    out = elsewhere / "drop.html"
    assert main(["replay", str(own_model_run), "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    assert printed.splitlines()[-1].startswith(f"wrote {out}: 1 run, 11 of 11 frames")
    assert CLIENT_BYTES < out.stat().st_size
    recording = _check_page(out, 0.01)
    assert len(recording["messages"]) > 11           # a pose update per frame
    text = out.read_text()
    assert "drop.toml" in text and "scene_toml" not in text and "my-cube.ac" not in text


def test_the_recorded_scene_is_the_file_as_run(own_model_run):
    traj = refsim.Trajectory.load(own_model_run)
    assert traj.settings["scene_toml"] == OWN_MODEL_SCENE
    assert traj.settings["scene"] == str(own_model_run.parent / "scene" / "drop.toml")


def test_a_recorded_scene_whose_model_is_gone_says_to_name_the_scene(own_model_run, tmp_path,
                                                                     capsys):
    (own_model_run.parent / "scene" / "my-cube.ac").unlink()
    err = _one_line_error(capsys, ["replay", str(own_model_run), "-o",
                                   str(tmp_path / "r.html")], "--scene SCENE.toml")
    assert err.startswith(f"refsim: error: {own_model_run}: the scene the run records cannot "
                          "be rebuilt (")
    assert "model 'my-cube.ac' not found" in err
    assert not (tmp_path / "r.html").exists()
