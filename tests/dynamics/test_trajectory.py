"""Trajectory files: the frames streamed to disk are the frames kept in
memory, bit for bit (also after a divergence); loading a file that is not a
trajectory raises a RefsimError that names the file and the entry."""

from __future__ import annotations

import json

import numpy as np
import pytest

import refsim
from refsim.dynamics.simulate import simulate
from refsim.dynamics.trajectory import ENTRIES, FRAME_ENTRIES
from refsim.errors import DivergenceError, NpzFileError, RefsimError
from refsim.scenes.loader import scene_from_dict
from refsim.storage.frames import SpillSink
from refsim.storage.npz import write_npz

#: Two bodies that rotate, meet and hit the walls: every stage of the loop runs.
TWO_BODIES = {
    "world": {"half_size": 2.0, "restitution": 0.8},
    "integration": {"solver": "rk4", "step": 0.002, "duration": 0.3},
    "collision": {"level": "exact"},
    "dynamics": {"rotation": "seed", "body_response": "seed"},
    "body": [
        {"name": "a", "model": "icosahedron.ac", "position": [-1.0, 0.0, 0.0],
         "velocity": [2.0, 1.0, 0.0], "angular_velocity": [0.0, 0.0, 3.0]},
        {"name": "b", "model": "cube.ac", "position": [1.0, 0.5, 0.0],
         "velocity": [-2.0, 0.0, 0.5]},
    ],
}

#: Euler with k h / m = 3: each step multiplies v by (1 - 3) = -2, and the
#: energy passes the divergence bound after a few dozen steps.
DIVERGING = {
    "world": {"half_size": 5.0, "gravity": 0.0, "drag": 3000.0, "restitution": 1.0},
    "integration": {"solver": "euler", "step": 1e-3, "duration": 1.0},
    "collision": {"level": "none"},
    "dynamics": {"rotation": "off", "body_response": "off"},
    "body": [{"name": "fast", "model": "cube.ac", "velocity": [1.0, 0.0, 0.0]}],
}


def _same_frames(a, b):
    for name in FRAME_ENTRIES:
        x, y = np.asarray(getattr(a, name)), np.asarray(getattr(b, name))
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert np.array_equal(x, y), name        # bit for bit: no tolerance


@pytest.mark.parametrize("every", [1, 7])
def test_streamed_frames_are_the_memory_frames(tmp_path, every):
    scene = scene_from_dict(TWO_BODIES)
    kept = simulate(scene, every=every)
    out = tmp_path / "out.npz"
    with SpillSink(out) as sink:
        streamed = simulate(scene, every=every, sink=sink)
        # 150 steps: frame 0, every 7th, and the last (150 is not a multiple of 7)
        assert streamed.n_frames == kept.n_frames == (151 if every == 1 else 23)
        _same_frames(streamed, kept)
        streamed.save(out)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.npz"]
    loaded = refsim.Trajectory.load(out)
    _same_frames(loaded, kept)
    assert loaded.names == ("a", "b") and loaded.events == kept.events
    assert loaded.settings == kept.settings and loaded.settings["every"] == every


def test_a_divergence_keeps_the_same_frames_streamed_or_not(tmp_path):
    scene = scene_from_dict(DIVERGING)
    with pytest.raises(DivergenceError) as memory:
        simulate(scene, every=3)
    with SpillSink(tmp_path / "out.npz") as sink:
        with pytest.raises(DivergenceError) as streamed:
            simulate(scene, every=3, sink=sink)
        assert streamed.value.step == memory.value.step > 5
        partial = streamed.value.partial
        # frames 0, 3, ..., up to the last multiple of 3 before the step that diverged
        assert partial.n_frames == memory.value.partial.n_frames == \
            (memory.value.step - 1) // 3 + 1
        _same_frames(partial, memory.value.partial)
        partial.save(tmp_path / "out.npz")
    _same_frames(refsim.Trajectory.load(tmp_path / "out.npz"), memory.value.partial)


def test_save_and_load_round_trip_a_memory_trajectory(tmp_path):
    kept = simulate(scene_from_dict(TWO_BODIES), every=10)
    path = kept.save(tmp_path / "t.npz")
    loaded = refsim.Trajectory.load(path)
    _same_frames(loaded, kept)
    assert loaded.stages == kept.stages and loaded.stage_seconds == kept.stage_seconds
    with np.load(path) as data:                     # what numpy sees: the same entries
        assert data.files == list(ENTRIES)


# -- files that are not trajectories ---------------------------------------------------


def _entries(tmp_path):
    """The entries of a small saved trajectory, as arrays."""
    path = simulate(scene_from_dict(TWO_BODIES), every=25).save(tmp_path / "good.npz")
    with np.load(path) as data:
        return {name: data[name] for name in data.files}


def _write(tmp_path, entries, name="bad.npz"):
    path = tmp_path / name
    with open(path, "wb") as handle:
        write_npz(handle, entries, compressed=False)
    return path


def _load_error(path) -> NpzFileError:
    with pytest.raises(NpzFileError) as info:
        refsim.Trajectory.load(path)
    assert isinstance(info.value, RefsimError) and str(path) in str(info.value)
    assert "\n" not in str(info.value)
    return info.value


def test_a_missing_file(tmp_path):
    error = _load_error(tmp_path / "absent.npz")
    assert str(error) == f"{tmp_path / 'absent.npz'}: no such file"


def test_a_truncated_file(tmp_path):
    path = simulate(scene_from_dict(TWO_BODIES), every=10).save(tmp_path / "t.npz")
    path.write_bytes(path.read_bytes()[:-100])
    assert "truncated" in str(_load_error(path))


def test_a_file_of_another_format(tmp_path):
    path = tmp_path / "scene.npz"
    path.write_text("[world]\nhalf_size = 1.0\n")
    assert "not an .npz file" in str(_load_error(path))


def test_a_particle_file_is_not_a_trajectory(tmp_path):
    path = _write(tmp_path, {"t": np.zeros(2), "step": np.zeros(2, np.int64),
                             "position": np.zeros((2, 4, 3)), "velocity": np.zeros((2, 4, 3))})
    error = _load_error(path)
    assert error.entry == "angular_velocity" and "missing" in str(error)


@pytest.mark.parametrize(("entry", "value", "match"), [
    ("position", lambda e: e["position"][:, :, :2], r"expected float \(7, 2, 3\)"),
    ("orientation", lambda e: e["orientation"][:-1], r"\(7 frames of 2 bodies\)"),
    ("t", lambda e: e["t"].reshape(-1, 1), "1-d float array of times"),
    ("names", lambda e: np.array([1, 2]), "body names"),
    ("events", lambda e: np.array("[{"), "not valid JSON"),
    ("events", lambda e: np.array('[{"kind": "wall"}]'), "not a list of events"),
    ("settings", lambda e: np.array("[]"), "expected a JSON dict, got list"),
    ("stage_seconds", lambda e: np.zeros(2), "expected a JSON string"),
])
def test_wrong_content_names_the_entry(tmp_path, entry, value, match):
    entries = _entries(tmp_path)
    assert len(entries["t"]) == 7                   # 150 steps, every 25th and the first
    entries[entry] = value(entries)
    error = _load_error(_write(tmp_path, entries))
    assert error.entry == entry
    assert str(error).startswith(f"{tmp_path / 'bad.npz'}: entry {entry!r}: ")
    with pytest.raises(NpzFileError, match=match):
        refsim.Trajectory.load(tmp_path / "bad.npz")


def test_a_good_file_written_by_hand_loads(tmp_path):
    # the entries alone make a trajectory, whoever wrote them
    entries = _entries(tmp_path)
    entries["settings"] = np.array(json.dumps({"note": "by hand"}))
    loaded = refsim.Trajectory.load(_write(tmp_path, entries, "hand.npz"))
    assert loaded.n_frames == 7 and loaded.settings == {"note": "by hand"}
