"""The command line: facts for a model, one clear line for a user's mistake."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from refsim.bundled import models_dir
from refsim.cli import EXIT_USER_ERROR, main
from refsim.errors import ModelError


def test_info_prints_the_facts(capsys):
    assert main(["info", str(models_dir() / "cube.ac")]) == 0
    out = capsys.readouterr().out
    facts = dict(line.split("  ", 1) for line in out.splitlines())
    assert facts["triangles"].strip() == "12"
    assert facts["vertices"].strip() == "8"
    assert facts["convex"].strip() == "yes"
    assert facts["closed"].strip() == "yes"
    assert facts["bounds min"].strip() == "(-0.5, -0.5, -0.5)"
    assert facts["centroid (volume)"].strip() == "(0, 0, 0)"


def test_info_on_a_nonconvex_model(capsys):
    assert main(["info", str(models_dir() / "torus.ac")]) == 0
    out = capsys.readouterr().out
    assert "convex" in out and "no" in out.split("convex", 1)[1].splitlines()[0]


def test_missing_file_is_one_line_without_traceback(tmp_path, capsys):
    missing = tmp_path / "absent.ac"
    assert main(["info", str(missing)]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(missing) in err and "Traceback" not in err


def test_malformed_file_names_the_line(tmp_path, capsys):
    bad = tmp_path / "bad.ac"
    bad.write_text("AC3Db\nOBJECT poly\nnumvert 1\n0 0 zero\n")
    assert main(["info", str(bad)]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.startswith("refsim: error: ") and f"{bad}:4" in err
    assert err.count("\n") == 1


def test_debug_shows_the_exception(tmp_path):
    bad = tmp_path / "bad.ac"
    bad.write_text("not an ac3d file\n")
    with pytest.raises(ModelError):
        main(["--debug", "info", str(bad)])


def test_console_script_exit_status_and_stderr(tmp_path):
    # The installed entry point, in a fresh interpreter: what a user sees.
    result = subprocess.run([sys.executable, "-m", "refsim.cli", "info",
                             str(tmp_path / "absent.ac")], capture_output=True, text=True)
    assert result.returncode == EXIT_USER_ERROR
    assert result.stdout == ""
    assert result.stderr.startswith("refsim: error: ") and "Traceback" not in result.stderr


def test_report_into_an_unwritable_place_is_a_user_error(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert main(["report", "--quick", "-o", str(blocker / "out")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert "cannot write the report" in err and "Traceback" not in err


def test_study_prints_records_and_the_verdict_they_back(capsys):
    assert main(["study", "bounds-error", "--quick"]) == 0
    out = capsys.readouterr().out
    header = out.splitlines()[0].split()
    assert header[:6] == ["mesh", "n_triangles", "convex", "motion", "frames", "wrong_frames"]
    assert "\nC2: partly\n" in out                # the quick run's verdict, as the report's
    assert "  convex_wrong_frames: 0\n" in out


def test_a_timing_command_turns_the_tiered_start_off_and_a_long_one_warms(capsys, monkeypatch,
                                                                          tmp_path):
    # a study times refsim's kernels: the compiled ones, not readable calls
    # made while a compile is pending (refsim.kernels.Tier)
    from refsim import warm

    started = []
    monkeypatch.setattr(warm, "start_in_background", lambda stream: started.append(stream))
    monkeypatch.setenv("REFSIM_TIERED_START", "1")
    assert main(["study", "models-facts", "--quick"]) == 0
    assert os.environ["REFSIM_TIERED_START"] == "0" and started == []
    monkeypatch.setenv("REFSIM_TIERED_START", "1")
    assert main(["conform", "refsim.engines.refsim_engines:corrected", "--only", "ode",
                 "--cases", "2", "-o", str(tmp_path / "c")]) == 0
    assert len(started) == 1 and os.environ["REFSIM_TIERED_START"] == "1"
    capsys.readouterr()


def test_study_marks_timing_fields(capsys):
    assert main(["study", "particles-drag", "--quick"]) == 0
    out = capsys.readouterr().out
    assert "cost_ratio*: " in out and "same_terminal_distance: 13.7563\n" in out
    assert "C5: " in out and "(rests on timings)" in out


def test_study_needs_a_known_name(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["study", "no-such-study"])
    assert exit_info.value.code == EXIT_USER_ERROR
    assert "invalid choice" in capsys.readouterr().err


def test_study_without_its_oracle_is_a_user_error(capsys, monkeypatch):
    from refsim.oracles import OracleUnavailable

    from refsim.engines import registry

    shipped = registry.build

    def build(name, **settings):
        if name == "trimesh-mesh":
            raise OracleUnavailable("oracle engine 'trimesh' is not installed")
        return shipped(name, **settings)

    monkeypatch.setattr(registry, "build", build)
    assert main(["study", "bounds-agreement", "--quick"]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert "bounds-agreement" in err and "trimesh" in err and "Traceback" not in err


@pytest.mark.parametrize("argv, phrase", [
    (["run", "bounce.toml", "--every", "2.5"], "argument --every: invalid int value: '2.5' "
                                               "(see refsim run --help)"),
    (["frobnicate"], "argument COMMAND: invalid choice: 'frobnicate'"),
])
def test_a_usage_error_is_the_same_one_line_as_any_error(argv, phrase, capsys):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.startswith("refsim: error: ") and phrase in err and err.count("\n") == 1


# Found by the second fuzz campaign: each refusal is one line naming its cause.

def test_a_newline_in_a_file_name_is_written_as_its_escape(tmp_path, capsys):
    bad = tmp_path / "new\nline.ac"
    bad.write_text("junk\n")
    assert main(["info", str(bad)]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err == (f"refsim: error: {tmp_path}/new\\nline.ac:1: not an AC3D file: the first "
                   "line must be 'AC3D' and a hex version, e.g. 'AC3Db'\n")


def _scene_naming(tmp_path, model: str):
    scene = tmp_path / "s.toml"
    scene.write_text(f'[[body]]\nmodel = "{model}"\nposition = [0.0, 0.0, 0.0]\n')
    return scene


def test_a_scenes_model_that_is_a_fifo_is_refused_as_such_not_reported_missing(
        tmp_path, capsys):
    import os
    os.mkfifo(tmp_path / "m.ac")
    scene = _scene_naming(tmp_path, "m.ac")
    assert main(["run", str(scene), "-o", str(tmp_path / "out.npz")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err == (f"refsim: error: {scene}: body[0].model: {tmp_path}/m.ac: not a regular "
                   "file (a FIFO)\n")
    assert not (tmp_path / "out.npz").exists()


def test_a_model_name_too_long_for_the_system_is_refused_at_its_key(tmp_path, capsys):
    scene = _scene_naming(tmp_path, "x" * 5000 + ".ac")
    assert main(["run", str(scene), "-o", str(tmp_path / "out.npz")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err == (f"refsim: error: {scene}: body[0].model: model '{'x' * 60}'... cannot be "
                   "looked up: File name too long\n")


def test_a_rotation_that_overflows_is_refused_without_a_numpy_warning(tmp_path, capsys):
    model = tmp_path / "m.ac"
    model.write_text("AC3Db\nOBJECT world\nkids 1\nOBJECT poly\nrot 1e300 0 0 0 1e300 0 0 0 "
                     "1e300\nnumvert 3\n1e10 0 0\n0 1 0\n0 0 1\nnumsurf 1\nSURF 0x10\nmat 0\n"
                     "refs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n")
    assert main(["info", str(model)]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err == (f"refsim: error: {model}:4: a vertex's world coordinates overflow (not "
                   "finite) after applying rot/loc\n")


def test_a_duration_shorter_than_the_scenes_step_names_the_scene_and_its_step(tmp_path, capsys):
    from refsim.bundled import scenes_dir
    scene = scenes_dir() / "bounce.toml"
    assert main(["run", str(scene), "-o", str(tmp_path / "o.npz"),
                 "--duration", "0.0005"]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == (
        f"refsim: error: {scene}: integration.step: the step 0.001 is longer than --duration "
        "0.0005: no whole step fits\n")
    assert main(["run", str(scene), "-o", str(tmp_path / "o.npz"),
                 "--duration", "nan"]) == EXIT_USER_ERROR
    assert capsys.readouterr().err.startswith("refsim: error: --duration nan: ")


def test_a_body_wider_than_float64_is_refused_without_a_numpy_warning(tmp_path, capsys):
    model = tmp_path / "wide.ac"
    model.write_text("AC3Db\nOBJECT poly\nnumvert 3\n-1e308 0 0\n1e308 1 0\n0 0 1\nnumsurf 1\n"
                     "SURF 0x10\nmat 0\nrefs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n")
    scene = tmp_path / "s.toml"
    scene.write_text('[[body]]\nmodel = "wide.ac"\nposition = [0.0, 0.0, 0.0]\n')
    assert main(["run", str(scene), "-o", str(tmp_path / "o.npz")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "warning" not in err
    assert err.startswith(f"refsim: error: {scene}: body[0].model: model wide.ac at scale 1 is "
                          "larger than the world cube: its box spans inf x ")


# What a new user tries first.

def test_version_prints_the_installed_version(capsys):
    import tomllib
    from pathlib import Path

    declared = tomllib.loads((Path(__file__).resolve().parents[1] / "pyproject.toml")
                             .read_text())["project"]["version"]
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out == f"refsim {declared}\n"


def test_output_cut_short_by_its_reader_ends_quietly():
    # Far more than a pipe holds (64 KiB on Linux), so the command is still
    # writing when the reader closes its end after the first line.
    argv = [sys.executable, "-m", "refsim.cli", "info", *["cube.ac"] * 400]
    proc = subprocess.Popen(argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    first = proc.stdout.readline()
    proc.stdout.close()
    err = proc.stderr.read()
    proc.stderr.close()
    assert proc.wait(timeout=120) == 1
    assert first.split() == ["model", "cube.ac"]
    assert err == ""


def test_info_of_a_directory_says_it_is_one(tmp_path, capsys):
    assert main(["info", str(tmp_path)]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == (f"refsim: error: {tmp_path}: a directory, not a model "
                                       "file (.ac, .obj, .stl, .ply, .off)\n")


@pytest.mark.parametrize("argv, written", [
    (["replay", "spin.npz", "-o", "spin.txt"], "writes .html or .htm files; name the output "
                                              "with the suffix .html"),
    (["report", "--quick", "-o", "report.html"], "refsim report writes a directory"),
    (["study", "bounds-error", "--quick", "-o", "study.json"], "refsim study writes a directory"),
    (["conform", "--all", "-o", "matrix.json"], "refsim conform writes a directory"),
    (["advise", "bounce.toml", "-o", "advice.toml"], "refsim advise writes a directory"),
])
def test_an_output_the_command_does_not_write_is_refused_before_any_work(
        argv, written, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.startswith(f"refsim: error: {argv[-1]}: cannot write: ") and written in err
    assert err.count("\n") == 1
    assert list(tmp_path.iterdir()) == []


def test_a_directory_named_like_a_file_is_still_a_directory(tmp_path, capsys):
    out = tmp_path / "study.json"
    out.mkdir()
    assert main(["study", "bounds-error", "--quick", "-o", str(out)]) == 0
    assert "\nC2: partly\n" in capsys.readouterr().out


# Bundled models and scenes by bare name.

def test_a_missing_path_to_a_bundled_model_names_the_bare_name(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)                      # no models/ folder here
    assert main(["info", "models/sphere-2k.ac"]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == (
        "refsim: error: models/sphere-2k.ac: no such file (a bundled model of that name "
        "exists: use 'sphere-2k.ac')\n")
    assert main(["info", "sphere-2k.ac"]) == 0
    assert capsys.readouterr().out.splitlines()[0].split() == ["model", "sphere-2k.ac"]


def test_a_missing_path_to_a_bundled_scene_names_the_bare_name(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["run", "scenes/spinning-cube.toml", "-o", "spin.npz"]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == (
        "refsim: error: scenes/spinning-cube.toml: no such file (a bundled scene of that name "
        "exists: use 'spinning-cube.toml')\n")
    assert list(tmp_path.iterdir()) == []


def test_a_missing_path_with_no_bundled_namesake_gets_no_hint(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["info", "models/no-such-model.ac"]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == "refsim: error: models/no-such-model.ac: no such file\n"


def test_a_missing_name_close_to_a_bundled_one_gets_the_close_names(tmp_path, monkeypatch,
                                                                    capsys):
    monkeypatch.chdir(tmp_path)
    assert main(["info", "tors.ac"]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == (
        "refsim: error: tors.ac: no such file (bundled models with a similar name: "
        "'torus.ac'; refsim info --bundled lists them all)\n")
    assert main(["info", "sphere.obj"]) == EXIT_USER_ERROR        # the stem is compared too
    err = capsys.readouterr().err
    assert "bundled models with a similar name: 'sphere-" in err and err.count("\n") == 1
    assert main(["run", "spining-cube.toml"]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == (
        "refsim: error: spining-cube.toml: no such file (bundled scenes with a similar name: "
        "'spinning-cube.toml'; refsim info --bundled lists them all)\n")
    scene = _scene_naming(tmp_path, "sphere.ac")
    assert main(["run", str(scene), "-o", str(tmp_path / "out.npz")]) == EXIT_USER_ERROR
    assert capsys.readouterr().err.endswith(
        "; bundled models with a similar name: 'sphere-5k.ac', 'sphere-2k.ac', "
        "'sphere-20k.ac'; refsim info --bundled lists them all\n")
    assert sorted(p.name for p in tmp_path.iterdir()) == [scene.name]


def test_a_scenes_model_path_to_a_bundled_model_names_the_bare_name(tmp_path, capsys):
    scene = _scene_naming(tmp_path, "models/cube.ac")
    assert main(["run", str(scene), "-o", str(tmp_path / "out.npz")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.startswith(f"refsim: error: {scene}: body[0].model: model 'models/cube.ac' "
                          "not found (looked in ")
    assert err.endswith("; a bundled model of that name exists: use 'cube.ac'\n")


def test_info_bundled_lists_every_bundled_model_and_scene(capsys):
    from refsim.bundled import scenes_dir

    assert main(["info", "--bundled"]) == 0
    names = capsys.readouterr().out.splitlines()
    models = sorted(p.name for p in models_dir().glob("*.ac"))
    scenes = sorted(p.name for p in scenes_dir().glob("*.toml"))
    assert names == models + scenes
    assert {"cube.ac", "sphere-2k.ac", "torus.ac", "bounce.toml",
            "spinning-cube.toml"} <= set(names)


@pytest.mark.parametrize("argv, phrase", [
    (["info"], "give one or more MODEL files, or --bundled"),
    (["info", "--bundled", "cube.ac"], "give it without MODEL files"),
])
def test_info_needs_models_or_bundled(argv, phrase, capsys):
    assert main(argv) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.startswith("refsim: error: ") and phrase in err and err.count("\n") == 1


# A core-only install: one line naming the missing package and the extra.

@pytest.mark.parametrize("module", ["matplotlib", "jinja2"])
def test_report_without_its_extra_names_the_package_and_the_extra(module, tmp_path, capsys,
                                                                 monkeypatch):
    monkeypatch.setitem(sys.modules, module, None)         # import MODULE -> ImportError
    out = tmp_path / "rep"
    assert main(["report", "--quick", "-o", str(out)]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == (f"refsim: error: the report needs {module}, which is "
                                       "not installed: pip install 'refsim[report]'\n")
    assert not out.exists()


def test_replay_without_viser_names_the_extra(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "viser", None)
    out = tmp_path / "r.html"
    assert main(["replay", str(tmp_path / "run.npz"), "-o", str(out)]) == EXIT_USER_ERROR
    assert capsys.readouterr().err == ("refsim: error: the viewer needs viser, which is not "
                                       "installed: pip install 'refsim[viewer]'\n")
    assert not out.exists()


def test_the_oracles_hint_is_for_an_installed_refsim(monkeypatch):
    from refsim.oracles import OracleUnavailable, import_engine

    monkeypatch.setitem(sys.modules, "pybullet", None)
    with pytest.raises(OracleUnavailable) as info:
        import_engine("pybullet", "pybullet")
    assert str(info.value).startswith("oracle engine 'pybullet' is not installed "
                                      "(pip install 'refsim[oracles]'): ")


@pytest.mark.parametrize(("scene", "frames"), [("spinning-cube.toml", 6),   # h = 1e-3
                                               ("particles.toml", 4)])      # h = 2e-3
def test_a_long_run_writes_its_progress_off_a_terminal(scene, frames, tmp_path, capsys,
                                                       monkeypatch):
    """``refsim run`` piped to a log is never silent: its frames so far, as
    whole lines, at most every LOG_SECONDS (here 0, so every frame), and
    nothing on stdout but the closing line."""
    from refsim.sweep import progress

    monkeypatch.setattr(progress, "LOG_SECONDS", 0.0)
    out = tmp_path / "run.npz"
    assert main(["run", scene, "-o", str(out), "--duration", "0.05", "--every", "10"]) == 0
    captured = capsys.readouterr()
    assert captured.out.startswith(f"wrote {out}") and captured.out.count("\n") == 1
    lines = [line for line in captured.err.splitlines() if line.startswith("refsim run: ")]
    assert lines[0].startswith(f"refsim run: 1/{frames} frames, about ")
    assert lines[-1] == f"refsim run: {frames}/{frames} frames"
    assert [int(line.split()[2].split("/")[0]) for line in lines] == \
        list(range(1, frames + 1))


def test_a_short_run_writes_no_progress(tmp_path, capsys):
    out = tmp_path / "run.npz"
    assert main(["run", "spinning-cube.toml", "-o", str(out), "--duration", "0.05"]) == 0
    assert "refsim run: " not in capsys.readouterr().err


@pytest.mark.parametrize(("flags", "quick"), [([], True), (["--quick"], True),
                                              (["--full"], False)])
def test_the_report_is_the_quick_one_unless_full_is_asked(flags, quick, tmp_path, capsys,
                                                          monkeypatch):
    """A newcomer's first ``refsim report`` (and ``make report``) shows the
    quick report within about a minute; the full one is asked for."""
    from refsim.report import build

    asked = []
    monkeypatch.setattr(build, "build_report",
                        lambda out, *, quick, workers: asked.append(quick) or out / "index.html")
    assert main(["report", *flags, "-o", str(tmp_path / "r")]) == 0
    assert asked == [quick]
    with pytest.raises(SystemExit) as stopped:              # a usage error, from argparse
        main(["report", "--quick", "--full", "-o", str(tmp_path / "r")])
    assert stopped.value.code == EXIT_USER_ERROR
    assert capsys.readouterr().err == ("refsim: error: argument --full: not allowed with "
                                       "argument --quick (see refsim report --help)\n")
