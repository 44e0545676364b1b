"""``refsim run``: a scene's frames in an .npz (particles or rigid bodies); one
line for a mistake or a diverging run; never a partial file."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from refsim.bundled import scenes_dir
from refsim.cli import EXIT_DIVERGED, EXIT_USER_ERROR, main
from refsim.particles.config import ParticleConfig

TINY = """
[world]
half_size = 1.0
drag = 0.1
restitution = 0.7
friction = 0.2

[integration]
solver = "rk4"
step = 0.01
duration = 1.0

[particles]
count = 12
seed = 5
box_lo = [-0.5, -0.5, -0.5]
box_hi = [0.5, 0.5, 0.5]
speed_min = 1.0
speed_max = 4.0
"""

#: Quadratic drag k/m = 50 with speeds of 5 m/s and a 0.1 s Euler step:
#: h k |v| / m = 25, far outside Euler's stable h k/m <= 2; the speed squares
#: every step and overflows within ten steps.
DIVERGING = """
[world]
drag = 50.0
drag_model = "quadratic"

[integration]
solver = "euler"
step = 0.1
duration = 10.0

[particles]
count = 5
speed_min = 5.0
"""


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def files(directory):
    return sorted(p.name for p in directory.iterdir())


def test_run_writes_the_frames(tmp_path, capsys):
    scene = write(tmp_path, TINY)
    out = tmp_path / "out.npz"
    assert main(["run", str(scene), "-o", str(out), "--every", "10"]) == 0
    assert "wrote" in capsys.readouterr().out
    with np.load(out) as data:
        t, position, velocity = data["t"], data["position"], data["velocity"]
        settings = json.loads(str(data["scene"]))
        status = str(data["status"])
        step = data["step"]
    # 100 steps, every 10th stored, plus the initial state
    assert t.shape == (11,) and position.shape == (11, 12, 3) and velocity.shape == (11, 12, 3)
    assert np.array_equal(step, np.arange(0, 101, 10))
    assert np.allclose(t, step * 0.01, rtol=0, atol=1e-15) and t[-1] == pytest.approx(1.0)
    assert position.dtype == np.float64 and velocity.dtype == np.float64
    assert status == "complete"
    # the first frame is the configured initial state, bit for bit
    config = ParticleConfig(**settings["particles"])
    x0, v0 = config.initial_state()
    assert np.array_equal(position[0], x0) and np.array_equal(velocity[0], v0)
    # the wall response keeps every particle inside the closed cube
    assert np.abs(position).max() <= 1.0
    assert settings["world"]["half_size"] == 1.0 and settings["integration"]["solver"] == "rk4"
    assert settings["every"] == 10
    assert files(tmp_path) == ["out.npz", "scene.toml"]


def test_default_stride_stores_about_200_frames(tmp_path):
    scene = write(tmp_path, TINY.replace("step = 0.01", "step = 0.001"))   # 1000 steps
    out = tmp_path / "out.npz"
    assert main(["run", str(scene), "-o", str(out)]) == 0
    with np.load(out) as data:
        t, step = data["t"], data["step"]
    assert 100 <= len(t) <= 200
    assert step[0] == 0 and step[-1] == 1000       # the last step is always stored


def test_frames_match_the_particle_system(tmp_path):
    from refsim.particles.system import ParticleSystem
    from refsim.scenes.loader import load_scene

    scene = write(tmp_path, TINY)
    out = tmp_path / "out.npz"
    assert main(["run", str(scene), "-o", str(out), "--every", "30"]) == 0
    system = ParticleSystem(load_scene(scene).particles)
    system.run(100)
    with np.load(out) as data:
        assert list(data["step"]) == [0, 30, 60, 90, 100]
        assert np.array_equal(data["position"][-1], system.positions)
        assert np.array_equal(data["velocity"][-1], system.velocities)


def test_bundled_particle_scene_is_runnable(tmp_path):
    # The bundled scene, shortened to 20 steps: the same tables, the same checks.
    text = (scenes_dir() / "particles.toml").read_text().replace("duration = 4.0",
                                                               "duration = 0.04")
    out = tmp_path / "p.npz"
    assert main(["run", str(write(tmp_path, text)), "-o", str(out)]) == 0
    with np.load(out) as data:
        assert data["position"].shape == (21, 10_000, 3)


def test_a_bad_scene_is_one_line_and_no_file(tmp_path, capsys):
    scene = write(tmp_path, TINY.replace("count = 12", "count = 0"))
    out = tmp_path / "out.npz"
    assert main(["run", str(scene), "-o", str(out)]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "particles.count" in err and str(scene) in err
    assert "Traceback" not in err
    assert files(tmp_path) == ["scene.toml"]


RIGID = """
[world]
half_size = 2.0
restitution = 0.8

[integration]
solver = "rk4"
step = 0.002
duration = 0.6

[collision]
level = "exact"

[dynamics]
rotation = "seed"
body_response = "seed"

[[body]]
name = "a"
model = "icosahedron.ac"
position = [-1.0, 0.0, 0.0]
velocity = [2.0, 1.0, 0.0]
angular_velocity = [0.0, 0.0, 3.0]

[[body]]
name = "b"
model = "cube.ac"
position = [1.0, 0.5, 0.0]
velocity = [-2.0, 0.0, 0.5]
"""


def test_a_rigid_body_scene_writes_its_trajectory(tmp_path, capsys):
    from refsim.dynamics.trajectory import Trajectory

    scene = write(tmp_path, RIGID)
    out = tmp_path / "out.npz"
    assert main(["run", str(scene), "-o", str(out), "--every", "10"]) == 0
    assert capsys.readouterr().out.startswith(f"wrote {out}: 31 frames of 2 bodies")
    trajectory = Trajectory.load(out)
    assert trajectory.names == ("a", "b")
    assert trajectory.position.shape == (31, 2, 3)
    assert trajectory.orientation.shape == (31, 2, 3, 3)
    np.testing.assert_allclose(trajectory.t, np.arange(31) * 0.02, atol=1e-12)
    np.testing.assert_array_equal(trajectory.position[0], [[-1.0, 0.0, 0.0], [1.0, 0.5, 0.0]])
    assert np.all(np.abs(trajectory.position) < 2.0)          # inside the world cube
    # two bodies, rotation on, level "exact": every stage runs
    assert trajectory.stages == ("integrate", "rotation", "check", "bounds", "walls",
                                 "broad-phase", "narrow-phase", "body-response")
    assert any(e.kind == "body" for e in trajectory.events)   # they do meet
    assert files(tmp_path) == ["out.npz", "scene.toml"]


def test_a_diverging_rigid_run_keeps_its_frames(tmp_path, capsys, monkeypatch):
    import refsim.dynamics.simulate as runs
    from refsim.dynamics.trajectory import Trajectory
    from refsim.errors import DivergenceError

    real = runs.simulate

    def diverging(scene, every=None, **kwargs):
        # kwargs: the sink the command line streams the frames to
        partial = real(scene, every=every, duration=0.1, **kwargs)
        raise DivergenceError("energy grew without bound", step=51, time=0.102, body="b",
                              partial=partial)

    monkeypatch.setattr(runs, "simulate", diverging)
    scene = write(tmp_path, RIGID)
    out = tmp_path / "out.npz"
    assert main(["run", str(scene), "-o", str(out), "--every", "10"]) == EXIT_DIVERGED
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("refsim: error: diverged at step 51, t = 0.102, body 'b', energy "
                          "grew without bound; wrote the 6 frames")
    assert err.count("'b'") == 1 and str(out) in err        # the body named once
    assert Trajectory.load(out).n_frames == 6


def test_a_duration_that_is_not_whole_steps_names_the_key(tmp_path, capsys):
    scene = write(tmp_path, TINY.replace("duration = 1.0", "duration = 1.005"))
    assert main(["run", str(scene), "-o", str(tmp_path / "out.npz")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "integration.duration" in err
    assert files(tmp_path) == ["scene.toml"]


def test_every_must_be_positive(tmp_path, capsys):
    scene = write(tmp_path, TINY)
    assert main(["run", str(scene), "-o", str(tmp_path / "o.npz"), "--every", "0"]) == \
        EXIT_USER_ERROR
    assert "--every" in capsys.readouterr().err
    assert files(tmp_path) == ["scene.toml"]


def test_a_missing_output_directory_is_one_line(tmp_path, capsys):
    scene = write(tmp_path, TINY)
    out = tmp_path / "absent" / "out.npz"
    assert main(["run", str(scene), "-o", str(out)]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot write" in err


def test_divergence_names_step_and_time_and_keeps_the_frames(tmp_path, capsys):
    scene = write(tmp_path, DIVERGING)
    out = tmp_path / "out.npz"
    assert main(["run", str(scene), "-o", str(out), "--every", "3"]) == EXIT_DIVERGED
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "warning" not in err
    assert "diverged at step" in err and "t = " in err and str(out) in err
    with np.load(out) as data:
        step, position, status = data["step"], data["position"], str(data["status"])
    diverged_at = int(err.split("diverged at step ", 1)[1].split(",", 1)[0])
    assert status.startswith(f"diverged at step {diverged_at}")
    # every stored frame is finite and before the divergence, at the stride
    assert np.isfinite(position).all() and step[-1] < diverged_at
    assert list(step) == list(range(0, step[-1] + 1, 3))
    assert diverged_at - step[-1] <= 3
    assert files(tmp_path) == ["out.npz", "scene.toml"]


def test_an_interrupted_write_leaves_no_file(tmp_path, monkeypatch):
    import refsim.cli as cli
    import refsim.storage.npz

    def interrupted(*args, **kwargs):
        raise KeyboardInterrupt

    # Ctrl-C while the .npz is assembled from the spilled frames: neither the
    # temporary .npz nor the spill files stay
    monkeypatch.setattr(refsim.storage.npz, "npy_header", interrupted)
    scene = write(tmp_path, TINY)
    out = tmp_path / "out.npz"
    assert cli.main(["run", str(scene), "-o", str(out)]) == 130
    assert files(tmp_path) == ["scene.toml"]


def test_an_existing_output_survives_a_failed_run(tmp_path):
    scene = write(tmp_path, TINY.replace("count = 12", "count = -3"))
    out = tmp_path / "out.npz"
    out.write_bytes(b"old")
    assert main(["run", str(scene), "-o", str(out)]) == EXIT_USER_ERROR
    assert out.read_bytes() == b"old"


def test_console_script_run(tmp_path):
    scene = write(tmp_path, TINY)
    result = subprocess.run([sys.executable, "-m", "refsim.cli", "run", str(scene), "-o",
                             str(tmp_path / "o.npz")], capture_output=True, text=True)
    assert result.returncode == 0 and result.stderr == ""
    assert result.stdout.startswith("wrote ")


def test_a_scene_with_bodies_and_particles_is_refused(tmp_path, capsys):
    scene = write(tmp_path, TINY + '\n[[body]]\nmodel = "cube.ac"\n')
    assert main(["run", str(scene), "-o", str(tmp_path / "out.npz")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "both" in err and "particles" in err
    assert files(tmp_path) == ["scene.toml"]


def _free(monkeypatch, free_bytes):
    """Pretend every file system has ``free_bytes`` free."""
    import shutil

    monkeypatch.setattr(shutil, "disk_usage",
                        lambda path: shutil._ntuple_diskusage(10**13, 10**13 - free_bytes,
                                                              free_bytes))


def test_frames_beyond_the_free_disk_are_refused_before_running(tmp_path, capsys,
                                                                monkeypatch):
    # 2e6 particles, 101 frames of 96 MB: about 19.4 GB on disk at the end
    # (the spilled frames and the .npz made from them); 1 GB free. The
    # smallest stride that fits: 2 F 96e6 + overhead <= 1e9 needs F <= 5
    # frames, 1 + ceil(100 / k) <= 5, k >= 25.
    _free(monkeypatch, 10**9)
    scene = write(tmp_path, TINY.replace("count = 12", "count = 2000000"))
    out = tmp_path / "o.npz"
    assert main(["run", str(scene), "-o", str(out), "--every", "1"]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert str(out) in err and "101 frames of 2000000 particles" in err
    assert "19.4 GB on disk" in err and "1.0 GB free" in err
    assert "--every 25 or more" in err
    assert files(tmp_path) == ["scene.toml"]


def test_a_stride_that_fits_is_not_refused(tmp_path, monkeypatch):
    # the stride the refusal above names: 5 frames of 12 particles fit in 1 MB
    _free(monkeypatch, 10**6)
    scene = write(tmp_path, TINY)
    out = tmp_path / "o.npz"
    assert main(["run", str(scene), "-o", str(out), "--every", "25"]) == 0
    with np.load(out) as data:
        assert list(data["step"]) == [0, 25, 50, 75, 100]


def test_a_frame_too_large_for_the_disk_names_the_count(tmp_path, capsys, monkeypatch):
    # 1e7 particles: one frame is 480 MB, two frames 960 MB, plus the .npz;
    # with 1 GB free no --every helps, the scene's particles.count does
    _free(monkeypatch, 10**9)
    scene = write(tmp_path, TINY.replace("count = 12", "count = 10000000"))
    assert main(["run", str(scene), "-o", str(tmp_path / "o.npz")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert f"{scene}: particles.count" in err and "even 2 frames need 1.9 GB" in err
    assert "--every" not in err
    assert files(tmp_path) == ["scene.toml"]


# -- streamed output: the library's frames, bit for bit; safe output paths -------------


def test_streamed_rigid_frames_are_the_librarys(tmp_path):
    from refsim.dynamics.simulate import simulate
    from refsim.dynamics.trajectory import Trajectory
    from refsim.scenes.loader import load_scene

    scene = write(tmp_path, RIGID)
    out = tmp_path / "out.npz"
    assert main(["run", str(scene), "-o", str(out), "--every", "7"]) == 0
    kept = simulate(load_scene(scene), every=7)           # in memory
    loaded = Trajectory.load(out)
    assert loaded.n_frames == kept.n_frames == 1 + 300 // 7 + 1
    for name in ("t", "position", "velocity", "angular_velocity", "orientation"):
        assert np.array_equal(getattr(loaded, name), getattr(kept, name)), name
    assert files(tmp_path) == ["out.npz", "scene.toml"]


def test_streamed_particle_frames_are_the_librarys(tmp_path):
    from refsim.particles.run import run_particles
    from refsim.scenes.loader import load_scene

    scene = write(tmp_path, TINY)
    out = tmp_path / "out.npz"
    assert main(["run", str(scene), "-o", str(out), "--every", "7"]) == 0
    kept = run_particles(load_scene(scene).particles, 100, 7)   # in memory
    with np.load(out) as data:
        assert data.files == ["t", "step", "position", "velocity", "scene", "status"]
        for name in ("t", "step", "position", "velocity"):
            assert data[name].dtype == getattr(kept, name).dtype
            assert np.array_equal(data[name], getattr(kept, name)), name


def test_output_through_a_symlink_keeps_the_link(tmp_path):
    scene = write(tmp_path, TINY)
    (tmp_path / "runs").mkdir()
    target = tmp_path / "runs" / "run-1.npz"
    target.write_bytes(b"old")
    link = tmp_path / "latest.npz"
    link.symlink_to(target)
    assert main(["run", str(scene), "-o", str(link), "--every", "50"]) == 0
    assert link.is_symlink() and link.resolve() == target.resolve()
    with np.load(target) as data:
        assert list(data["step"]) == [0, 50, 100]
    assert files(tmp_path / "runs") == ["run-1.npz"]
    assert files(tmp_path) == ["latest.npz", "runs", "scene.toml"]


@pytest.mark.parametrize("kind", ["fifo", "device", "directory"])
def test_a_special_output_is_refused_before_running(tmp_path, capsys, monkeypatch, kind):
    import os

    import refsim.particles.run

    def not_run(*args, **kwargs):
        raise AssertionError("ran the scene although its output is refused")

    monkeypatch.setattr(refsim.particles.run, "run_particles", not_run)
    scene = write(tmp_path, TINY)
    if kind == "fifo":
        out = tmp_path / "pipe"
        os.mkfifo(out)
    elif kind == "device":
        out = Path(os.devnull)
    else:
        out = tmp_path / "dir"
        out.mkdir()
    before = os.lstat(out)
    assert main(["run", str(scene), "-o", str(out)]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(f"refsim: error: {out}: cannot write: it is a ")
    assert os.lstat(out).st_mode == before.st_mode and os.lstat(out).st_ino == before.st_ino


#: A file-size limit for the child below. With 1000 particles the spill of
#: position (101 frames, 2.4 MB) passes it part way through the run; with 250
#: each spill file stays under it (606 kB) and the .npz (1.2 MB) passes it
#: while it is assembled.
FILE_SIZE_LIMIT = 10**6


def _limit_file_size():
    import resource
    import signal

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)    # EFBIG instead of a kill
    resource.setrlimit(resource.RLIMIT_FSIZE, (FILE_SIZE_LIMIT, FILE_SIZE_LIMIT))


@pytest.mark.parametrize("count", [1000, 250], ids=["while-spilling", "while-assembling"])
def test_a_full_disk_is_one_line_and_leaves_no_file(tmp_path, count):
    # a real write failure (EFBIG past RLIMIT_FSIZE, as ENOSPC on a full disk)
    scene = write(tmp_path, TINY.replace("count = 12", f"count = {count}"))
    out = tmp_path / "out.npz"
    out.write_bytes(b"old")
    result = subprocess.run([sys.executable, "-m", "refsim.cli", "run", str(scene), "-o",
                             str(out), "--every", "1"], capture_output=True, text=True,
                            preexec_fn=_limit_file_size)
    assert result.returncode == EXIT_USER_ERROR and result.stdout == ""
    assert result.stderr == f"refsim: error: {out}: cannot write: File too large\n"
    assert files(tmp_path) == ["out.npz", "scene.toml"] and out.read_bytes() == b"old"


def test_an_output_suffix_run_does_not_write_is_refused(tmp_path, capsys):
    scene = write(tmp_path, TINY)
    out = tmp_path / "out.txt"
    assert main(["run", str(scene), "-o", str(out)]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == (f"refsim: error: {out}: cannot write: refsim run writes "
                                       ".npz files; name the output with the suffix .npz\n")
    assert files(tmp_path) == ["scene.toml"]
    upper = tmp_path / "OUT.NPZ"                   # the suffix in any case is the format's
    assert main(["run", str(scene), "-o", str(upper), "--every", "50"]) == 0
    with np.load(upper) as data:
        assert data["t"].shape == (3,)


#: A cube for twenty thousand seconds in steps of a millisecond: 2e7 steps,
#: twice the scenes' default limit and within the loop's own.
LONG = """
[integration]
step = 0.001
duration = 20000.0

[[body]]
model = "cube.ac"
"""


def test_a_scene_beyond_the_step_limit_is_refused_saying_how_to_raise_it(tmp_path, capsys):
    from refsim.limits import DEFAULT_MAX_STEPS

    assert DEFAULT_MAX_STEPS == 10_000_000
    scene = write(tmp_path, LONG)
    assert main(["run", str(scene), "-o", str(tmp_path / "o.npz")]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == (
        f"refsim: error: {scene}: integration.duration: duration / step = 20000 / 0.001 = "
        "2e+07 steps exceeds the limit of 1e+07; to run it, raise the limit to 20000000 "
        "(--max-steps of refsim run and view, max_steps= of refsim.load_scene)\n")
    assert files(tmp_path) == ["scene.toml"]


def test_max_steps_lets_a_long_scene_through_validation(tmp_path, capsys, monkeypatch):
    import refsim.cli.run

    taken = []
    monkeypatch.setattr(refsim.cli.run, "_run_bodies",       # validated, then not run
                        lambda scene, text, out, every: taken.append(scene) or 0)
    scene = write(tmp_path, LONG)
    assert main(["run", str(scene), "-o", str(tmp_path / "o.npz"),
                 "--max-steps", "20000000"]) == 0
    assert [s.integration.n_steps for s in taken] == [20_000_000]
    assert main(["run", str(scene), "-o", str(tmp_path / "o.npz"), "--max-steps", "20000000",
                 "--duration", "1000.0"]) == 0
    assert [s.integration.n_steps for s in taken] == [20_000_000, 1_000_000]
    capsys.readouterr()
    # one step short of the scene, and a --duration beyond the limit given, are refused
    for argv in (["--max-steps", "19999999"],
                 ["--max-steps", "20000000", "--duration", "30000.0"]):
        assert main(["run", str(scene), "-o", str(tmp_path / "o.npz"), *argv]) == 2
    first, second = capsys.readouterr().err.splitlines()
    assert "2e+07 steps exceeds the limit of 19999999; to run it, raise the limit to " \
           "20000000 (" in first
    assert second.startswith("refsim: error: --duration 30000.0: duration / step = 30000 / "
                             "0.001 = 3e+07 steps exceeds the limit of 2e+07; to run it, raise "
                             "the limit to 30000000 (")
    assert len(taken) == 2


@pytest.mark.parametrize("argv, expected", [
    (["--max-steps", "20000000", "--duration", "1e12"],
     "--duration 1000000000000.0: duration / step = 1e+12 / 0.001 = 1e+15 steps exceeds the "
     "limit of 2e+07; no run may take more than 100000000 steps (refsim.limits.MAX_STEPS): "
     "lengthen the step or shorten the duration"),
    (["--max-steps", "100000001"], "--max-steps must be at least 1 and at most 100000000, "
                                   "got 100000001"),
    (["--max-steps", "0"], "--max-steps must be at least 1 and at most 100000000, got 0"),
])
def test_a_run_beyond_what_any_limit_allows_is_refused(tmp_path, capsys, argv, expected):
    scene = write(tmp_path, LONG)
    assert main(["run", str(scene), "-o", str(tmp_path / "o.npz"), *argv]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == f"refsim: error: {expected}\n"
    assert files(tmp_path) == ["scene.toml"]
