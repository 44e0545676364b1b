"""``refsim conform``: files written, the table, exit status 0 / 1 / 2, one
line for a user's mistake and nothing written."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from refsim.cli import EXIT_USER_ERROR, main

CORRECTED = "refsim.engines.refsim_engines:corrected"
BOX = "tests.conformance.broken_engines:box_ignores_translation"


def test_passing_engine_exits_0_and_writes_json_and_page(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["conform", CORRECTED, "--only", "ode", "-o", str(out), "--seed", "3"]) == 0
    printed = capsys.readouterr().out
    assert printed.splitlines()[0].split() == ["check", "cases", "passed", "failed", "classes",
                                               "status"]
    assert "ode.order" in printed and "refsim-corrected: no check failed; wrote" in printed
    record = json.loads((out / "conformance.json").read_text())
    assert record["engine"] == "refsim-corrected" and record["seed"] == 3
    assert record["spec"] == CORRECTED and record["capabilities"] == ["ode"]
    assert [c["check"] for c in record["checks"]] == ["order", "stability", "evaluations"]
    assert all(c["status"] == "passed" for c in record["checks"])
    assert (out / "index.html").read_text().startswith("<!DOCTYPE html>")
    assert sorted(p.name for p in out.iterdir()) == ["conformance.json", "failures.jsonl",
                                                      "index.html"]
    assert (out / "failures.jsonl").read_text() == ""      # nothing failed


def test_every_failure_is_a_line_of_failures_jsonl(tmp_path):
    """Not only the few examples of conformance.json: every failing case,
    with its input, the engine's answer, the truth and the gap."""
    out = tmp_path / "out"
    assert main(["conform", BOX, "--cases", "24", "-o", str(out)]) == 1
    record = json.loads((out / "conformance.json").read_text())
    lines = [json.loads(line) for line in (out / "failures.jsonl").read_text().splitlines()]
    failed = {f"{c['capability']}.{c['check']}": c["failed"] for c in record["checks"]}
    assert failed["aabb.encloses"] > 2               # more than the examples keep
    for key, count in failed.items():
        mine = [line for line in lines if line["check"] == key]
        assert len(mine) == count
        assert [line["case"] for line in mine] == sorted({line["case"] for line in mine})
    first = next(line for line in lines if line["check"] == "aabb.encloses")
    assert {"vertices", "R", "t", "lo", "hi", "exact_lo", "exact_hi", "excess_metres",
            "class"} <= set(first)
    assert first["excess_metres"] > 0


def test_failing_engine_exits_1_unless_declared(tmp_path, capsys):
    assert main(["conform", BOX, "--cases", "12", "-o", str(tmp_path / "a")]) == 1
    printed = capsys.readouterr().out
    assert "failed: aabb.encloses, aabb.tight" in printed
    declared = tmp_path / "expected.txt"
    declared.write_text("# the box forgets t\naabb.encloses  forgets the translation\n"
                        "aabb.tight  forgets the translation\n")
    assert main(["conform", BOX, "--cases", "12", "-o", str(tmp_path / "b"),
                 "--expected-failures", str(declared)]) == 0
    record = json.loads((tmp_path / "b" / "conformance.json").read_text())
    assert [c["status"] for c in record["checks"]] == ["xfailed", "xfailed"]
    assert record["checks"][0]["reason"] == "forgets the translation"


@pytest.mark.parametrize("args, phrase", [
    (["conform", "nope:thing"], "cannot import 'nope'"),
    (["conform", "refsim.engines.refsim_engines"], "expected 'module:factory'"),
    (["conform", "refsim.engines.refsim_engines:nothing"], "has no callable 'nothing'"),
    (["conform", "tests.conformance.broken_engines:missing"], "'nothing-here' is not installed"),
    (["conform", CORRECTED, "--only", "wings"], "--only 'wings': not a capability"),
    (["conform", "refsim.oracles.fcl_adapter:engine", "--only", "rigid"],
     "has no 'rigid' capability (it has: triangles, pairs, collide)"),
    (["conform", CORRECTED, "--cases", "0"], "--cases must be at least 1"),
    (["conform"], "give one engine as MODULE:FACTORY, or --all"),
    (["conform", CORRECTED, "--all"], "give one engine as MODULE:FACTORY, or --all"),
])
def test_user_errors_exit_2_with_one_line_and_write_nothing(tmp_path, capsys, args, phrase):
    out = tmp_path / "out"
    assert main([*args, "-o", str(out)]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.startswith("refsim: error: ") and err.count("\n") == 1, err
    assert phrase in err and "Traceback" not in err
    assert not out.exists()


def test_malformed_expected_failures_names_its_line(tmp_path, capsys):
    bad = tmp_path / "expected.txt"
    bad.write_text("# fine\naabb.tight  fine\naabb.wide  oops\n")
    assert main(["conform", BOX, "-o", str(tmp_path / "out"),
                 "--expected-failures", str(bad)]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert f"{bad}:3: unknown check 'aabb.wide'" in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_all_runs_the_shipped_engines_with_a_capability(tmp_path, capsys):
    out = tmp_path / "all"
    assert main(["conform", "--all", "--only", "ode", "-o", str(out)]) == 0
    captured = capsys.readouterr()
    printed = captured.out
    # the progress, on stderr: each engine's checks as they start and end
    progress = captured.err.splitlines()
    assert progress[0] == "refsim conform: case sets: building ode"
    assert "refsim conform: refsim-seed: ode.order: running" in progress
    assert progress.index("refsim conform: refsim-seed: ode.order: running") < \
        progress.index("refsim conform: refsim-corrected: ode.order: running")
    assert all(line.startswith("refsim conform: ") for line in progress)
    header = printed.splitlines()[0].split()
    assert header == ["check", "refsim-seed", "refsim-corrected"]    # the two with "ode"
    matrix = json.loads((out / "matrix.json").read_text())
    assert matrix["engines"] == ["refsim-seed", "refsim-corrected"]
    assert matrix["cells"]["ode.order"]["refsim-seed"]["status"] == "passed"
    assert (out / "refsim-seed" / "conformance.json").is_file()
    assert 'href="refsim-corrected/index.html"' in (out / "index.html").read_text()


def test_all_on_two_local_processes_gives_the_same_cells(tmp_path, capsys):
    cells = []
    for extra in ([], ["--workers", "2"]):
        out = tmp_path / ("serial" if not extra else "workers")
        assert main(["conform", "--all", "--only", "aabb", "--cases", "15", "-o", str(out),
                     *extra]) == 0
        matrix = json.loads((out / "matrix.json").read_text())
        cells.append({check: {engine: (cell["status"], cell.get("passed"), cell.get("cases"))
                              for engine, cell in row.items()}
                      for check, row in matrix["cells"].items()})
    capsys.readouterr()
    assert cells[0] == cells[1]
    assert set(cells[0]["aabb.encloses"]) == {"refsim-seed", "refsim-corrected", "trimesh"}
    assert cells[0]["aabb.encloses"]["refsim-seed"] == ("passed", 15, 15)


@pytest.mark.parametrize("args, phrase", [
    (["--all", "--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], "not both"),
    (["refsim.engines.refsim_engines:corrected", "--workers", "2", "--scheduler",
      "tcp://127.0.0.1:1"], "not both"),
    (["--all", "--workers", "0"], "--workers"),
    (["refsim.engines.refsim_engines:corrected", "--workers", "0"], "--workers"),
])
def test_workers_and_scheduler_are_exclusive(tmp_path, capsys, args, phrase):
    assert main(["conform", *args, "-o", str(tmp_path / "x")]) == EXIT_USER_ERROR
    err = capsys.readouterr().err
    assert err.startswith("refsim: error: ") and phrase in err and err.count("\n") == 1


def test_console_script_in_a_fresh_interpreter(tmp_path):
    result = subprocess.run([sys.executable, "-m", "refsim.cli", "conform", "nope:thing",
                             "-o", str(tmp_path / "x")], capture_output=True, text=True)
    assert result.returncode == EXIT_USER_ERROR
    assert result.stderr.count("\n") == 1 and "Traceback" not in result.stderr


def test_same_inputs_give_the_same_record_but_timings(tmp_path, capsys):
    records = []
    for run in ("a", "b"):
        assert main(["conform", BOX, "--cases", "12", "-o", str(tmp_path / run)]) == 1
        records.append(json.loads((tmp_path / run / "conformance.json").read_text()))
    capsys.readouterr()

    def without_timings(value):
        if isinstance(value, dict):
            return {k: without_timings(v) for k, v in value.items()
                    if k not in ("seconds", "case_seconds")}
        if isinstance(value, list):
            return [without_timings(v) for v in value]
        return value

    first, second = map(without_timings, records)
    assert first == second                      # the Hypothesis search is seeded too
    assert first["checks"][0]["examples"][0]["shrunk"] is True
    assert (tmp_path / "a" / "index.html").read_text() == \
        (tmp_path / "b" / "index.html").read_text()


def test_all_with_an_engine_missing_says_so_last_and_exits_1(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "pybullet", None)       # import pybullet -> ImportError
    monkeypatch.setitem(sys.modules, "mujoco", None)
    out = tmp_path / "all"
    assert main(["conform", "--all", "--only", "ode", "-o", str(out)]) == 1
    printed = capsys.readouterr()
    assert printed.out.splitlines()[-1] == (
        f"wrote {out / 'index.html'}, {out / 'matrix.json'} and a page per engine; not run: "
        "mujoco, pybullet (see the warnings; pip install 'refsim[oracles]')")
    warned = [line for line in printed.err.splitlines() if " not run: " in line]
    assert [line.split()[2] for line in warned] == ["pybullet", "mujoco"]
    assert all("pip install 'refsim[oracles]'" in line for line in warned)
    matrix = json.loads((out / "matrix.json").read_text())
    assert sorted(matrix["unavailable"]) == ["mujoco", "pybullet"]
