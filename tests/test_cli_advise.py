"""``refsim advise``: the text, the JSON document, the files it writes, and
one line with exit status 2 for a user's mistake."""

from __future__ import annotations

import json
import subprocess
import sys
import tomllib

import pytest

from refsim.advisor.advice import DEFAULT_TOLERANCE
from refsim.advisor.reference import MAX_REFERENCE_STEPS
from refsim.advisor.runner import TIMING_REPEATS
from refsim.cli import EXIT_USER_ERROR, build_parser, main
from refsim.scenes.loader import scene_from_dict

#: A cube dropped onto the floor for 0.6 s: one wall impact (a short run).
SCENE = """\
[world]
half_size = 1.25
restitution = 0.6

[integration]
solver = "midpoint"
step = 0.002
duration = 0.6

[dynamics]
rotation = "off"
body_response = "off"

[[body]]
name = "box"
model = "cube.ac"
position = [0.0, 0.2, 0.0]
velocity = [0.5, 0.0, 0.0]
"""

#: The keys of the --json document (refsim.advisor.view.advice_document).
DOCUMENT_KEYS = {"format", "scene", "tolerance", "duration", "scene_duration",
                 "sample_interval", "energy_scale", "energy_allowance", "count_allowance",
                 "reference", "recommended", "own", "proxy_saving", "wall_saving", "runs",
                 "pruned", "computed", "resumed", "units", "toml", "chart"}
ROW_KEYS = {"solver", "step", "level", "aabb", "roles", "steps", "proxy", "force_evaluations",
            "narrow_phase_calls", "box_visits", "wall_seconds", "wall_repeats",
            "position_error", "event_error", "events", "event_note", "energy_drift",
            "energy_gap", "count_gap", "error_ratio", "meets", "diverged"}
REFERENCE_KEYS = {"solver", "step", "check_step", "level", "aabb", "converged", "stop",
                  "horizon", "uncertainty", "position_gap", "event_gap", "resolution",
                  "energy_gap", "count_gap", "energy_spread", "count_spread", "impacts",
                  "halvings", "aim"}


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    path = tmp_path_factory.mktemp("advise") / "drop.toml"
    path.write_text(SCENE)
    return path


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """One store for the module: the runs are made once, then resumed."""
    return tmp_path_factory.mktemp("advise-store") / "store"


def test_json_is_one_document_with_the_documented_keys(scene, store, capsys):
    assert main(["advise", str(scene), "--json", "--repeats", "1", "--store", str(store)]) == 0
    out = capsys.readouterr().out
    document = json.loads(out)                   # the whole of stdout is one document
    assert set(document) == DOCUMENT_KEYS
    assert document["format"] == "refsim advise 1"
    assert document["tolerance"] == DEFAULT_TOLERANCE and document["chart"] is None
    assert set(document["recommended"]) == ROW_KEYS
    assert set(document["reference"]) == REFERENCE_KEYS
    assert all(set(row) == ROW_KEYS for row in document["runs"])
    assert document["recommended"]["meets"] is True
    assert document["reference"]["converged"] is True
    snippet = tomllib.loads(document["toml"])
    assert snippet["integration"]["step"] == document["recommended"]["step"]
    assert snippet["collision"]["level"] == document["recommended"]["level"]
    # strict JSON: no NaN or Infinity anywhere
    json.loads(out, parse_constant=lambda name: pytest.fail(f"non-standard JSON {name}"))


def test_text_shows_the_snippet_the_table_and_a_text_chart(scene, store, capsys):
    assert main(["advise", str(scene), "--repeats", "1", "--store", str(store)]) == 0
    out = capsys.readouterr().out
    snippet = out.split("paste into the scene:\n", 1)[1].split("\n\n[collision]", 1)[0]
    assert tomllib.loads(snippet)["integration"]["solver"] in (
        "euler", "averaged-euler", "backwards-euler", "midpoint", "rk4")
    assert "runs: 0 simulated" in out             # every run came from the store
    assert "role" in out and "pos err m" in out
    assert "work-precision: proxy" in out and "* recommended" in out
    # the proxy is defined before the table that shows it
    assert out.index("\nproxy: a run's cost counted, not timed: force evaluations x bodies") \
        < out.index("\nrole ")


def test_an_output_directory_gets_the_snippet_the_document_and_the_svg(scene, store,
                                                                       tmp_path, capsys):
    out_dir = tmp_path / "out"
    assert main(["advise", str(scene), "--repeats", "1", "--store", str(store),
                 "-o", str(out_dir)]) == 0
    shown = capsys.readouterr().out
    svg = out_dir / "drop-work-precision.svg"
    assert f"work-precision chart: {svg}" in shown and "work-precision: proxy" not in shown
    assert svg.read_text().lstrip().startswith("<?xml") and "<svg" in svg.read_text()
    document = json.loads((out_dir / "drop-advice.json").read_text())
    assert document["chart"] == str(svg)
    data = tomllib.loads(scene.read_text())
    for table, keys in tomllib.loads((out_dir / "drop-advice.toml").read_text()).items():
        data.setdefault(table, {}).update(keys)
    merged = scene_from_dict(data, scene)
    assert merged.integration.step == document["recommended"]["step"]


def test_without_matplotlib_the_chart_is_written_as_text(scene, store, tmp_path, capsys,
                                                         monkeypatch):
    import refsim.advisor.view

    monkeypatch.setattr(refsim.advisor.view, "svg_available", lambda: False)
    out_dir = tmp_path / "out"
    assert main(["advise", str(scene), "--repeats", "1", "--store", str(store),
                 "-o", str(out_dir)]) == 0
    captured = capsys.readouterr()
    assert "refsim: warning: the SVG chart needs matplotlib" in captured.err
    assert "pip install 'refsim[report]'" in captured.err
    assert (out_dir / "drop-work-precision.txt").read_text().startswith("work-precision")
    assert not (out_dir / "drop-work-precision.svg").exists()


@pytest.mark.parametrize("argv", [
    ["--tolerance", "0"],
    ["--tolerance", "-0.01"],
    ["--tolerance", "nan"],
    ["--tolerance", "inf"],
    ["--tolerance", "one"],
    ["--workers", "0"],
    ["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"],
    ["--repeats", "0"],
    ["--duration", "0.6003"],
])
def test_a_bad_option_is_one_line_and_exit_2(scene, argv, capsys):
    try:
        status = main(["advise", str(scene), *argv])
    except SystemExit as exit:                    # argparse: not a number at all
        status = exit.code
    assert status == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith(("refsim: error: ", "refsim advise: error: "))


def test_a_bad_scene_is_one_line_and_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("[world]\nhalf_size = -1\n")
    for scene in (str(tmp_path / "absent.toml"), str(bad), "particles.toml"):
        assert main(["advise", scene]) == EXIT_USER_ERROR
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith("refsim: error: ")
    assert main(["advise", "particles.toml"]) == EXIT_USER_ERROR
    assert "no [[body]]" in capsys.readouterr().err


def test_an_output_path_that_is_a_file_is_refused(scene, tmp_path, capsys):
    file = tmp_path / "file"
    file.write_text("")
    assert main(["advise", str(scene), "-o", str(file)]) == EXIT_USER_ERROR
    assert "not a directory" in capsys.readouterr().err


def test_the_help_states_the_study_defaults():
    advise = build_parser()._subparsers._group_actions[0].choices["advise"]
    text = advise.format_help().replace("\n", " ")
    assert f"default {DEFAULT_TOLERANCE:g}" in text
    assert f"default {TIMING_REPEATS})" in text
    assert MAX_REFERENCE_STEPS == 2**19 and "default 2^19" in text


def test_an_interrupted_advise_resumes_from_its_store(scene, tmp_path):
    """Stopped (SIGTERM, which the command unwinds like Ctrl-C; SIGINT is
    ignored by a process started in the background) after the first run is
    stored; the next advise reads it back."""
    import signal
    import time

    store = tmp_path / "store"
    argv = [sys.executable, "-m", "refsim.cli", "advise", str(scene), "--repeats", "1",
            "--duration", "3", "--store", str(store)]
    process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               text=True)
    deadline = time.monotonic() + 120.0
    while not list((store / "results").glob("*.json")) and time.monotonic() < deadline:
        assert process.poll() is None, process.stderr.read()
        time.sleep(0.05)
    process.send_signal(signal.SIGTERM)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 128 + signal.SIGTERM
    assert err.strip().splitlines()[-1] == "refsim: interrupted (SIGTERM)"
    stored = len(list((store / "results").glob("*.json")))
    assert stored >= 1
    result = subprocess.run([*argv, "--json"], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    document = json.loads(result.stdout)
    assert document["resumed"] == stored
    assert document["computed"] == len(document["runs"]) - stored


def test_the_console_script_exits_2_on_a_bad_tolerance(scene):
    result = subprocess.run([sys.executable, "-m", "refsim.cli", "advise", str(scene),
                             "--tolerance", "0"], capture_output=True, text=True)
    assert result.returncode == EXIT_USER_ERROR
    assert result.stderr.count("\n") == 1 and "--tolerance" in result.stderr


def test_an_advice_says_how_many_runs_it_has_made_as_it_goes(scene, store, capsys,
                                                             monkeypatch):
    """Each round's sweep shows only its own runs; off a terminal the advice
    also says, after a round, how many runs it has so far (here every round:
    LOG_SECONDS is 0), so that a long advice is never silent."""
    from refsim.sweep import progress

    monkeypatch.setattr(progress, "LOG_SECONDS", 0.0)
    assert main(["advise", str(scene), "--repeats", "1", "--store", str(store)]) == 0
    said = [line for line in capsys.readouterr().err.splitlines()
            if line.startswith("advise: ")]
    counts = [int(line.split()[1]) for line in said]
    assert len(said) >= 2 and counts == sorted(counts) and counts[0] > 0
    assert all(" from the store), " in line and line.endswith(" elapsed") for line in said)
