"""The report's sweep sections: the conformance matrix (issue 14), the
replays (issue 15) and the advisor (issue 17), and ``--workers``."""

from __future__ import annotations

import json
import re
import sys
from types import SimpleNamespace

import pytest
from markupsafe import escape

from refsim.bundled import bundled_scenes
from refsim.claims import CLAIMS
from refsim.conformance.matrix import conformance_matrix, run_matrix
from refsim.conformance.results import ConformanceResult, tally
from refsim.report import plan
from refsim.report.build import render
from refsim.report.entries import advisor as advisor_entry
from refsim.report.entries import conformance as conformance_entry
from refsim.report.entries import replays as replays_entry
from refsim.report.run import REPORT_SEED, Run
from refsim.report.section import Section, to_json
from refsim.report.sections import advisor as advisor_section
from refsim.report.sections import conformance as conformance_section
from refsim.report.sections.conformance import ENGINE_TITLES, cell_text


def _section(results, key):
    return results["sections"][key]


def _table(results, key, table_id):
    (table,) = [t for t in _section(results, key)["tables"] if t["id"] == table_id]
    return table


# -- the conformance matrix -------------------------------------------------------------------


def test_matrix_has_a_row_per_check_and_a_column_per_engine_that_ran(quick_report):
    _, _, results = quick_report
    matrix = _section(results, "conformance")["results"]["matrix"]
    table = _table(results, "conformance", "conformance-matrix")
    assert table["columns"] == ["check", *(ENGINE_TITLES[e] for e in matrix["engines"])]
    assert [row[0] for row in table["rows"]] == matrix["checks"]
    assert set(matrix["engines"]) | set(matrix["unavailable"]) == set(plan_engines())
    for row in table["rows"]:
        for engine, text in zip(matrix["engines"], row[1:], strict=True):
            cell = matrix["cells"][row[0]].get(engine)
            if cell is None:
                assert text == conformance_section.NO_CAPABILITY
            elif cell["status"] == "passed":
                assert text.startswith(f"pass: {cell['cases']} case")
            elif cell["status"] in ("failed", "xfailed"):
                assert f"{cell['failed']} of {cell['cases']} case" in text


def plan_engines():
    from refsim.conformance.shipped import SHIPPED_ENGINES

    return SHIPPED_ENGINES


def test_matrix_counts_match_an_independent_run(quick_report):
    """The report's cells for the triangle checks are those of run_matrix
    run here directly (shared case sets, no sweep)."""
    _, _, results = quick_report
    table = _table(results, "conformance", "conformance-matrix")
    columns = table["columns"]
    direct, _ = run_matrix(cases=conformance_entry.MATRIX_CASES[0], seed=REPORT_SEED,
                           only="triangles")
    assert direct.checks
    shown = {row[0]: row for row in table["rows"]}
    for check in direct.checks:
        for engine in direct.engines:
            assert shown[check][columns.index(ENGINE_TITLES[engine])] == \
                cell_text(direct.cell(check, engine))


def test_every_engine_page_is_written_and_linked(quick_report):
    out, html, results = quick_report
    matrix = _section(results, "conformance")["results"]["matrix"]
    assert (out / "conformance" / "index.html").is_file()
    assert set(matrix["pages"]) == set(matrix["engines"])
    for engine, page in matrix["pages"].items():
        assert (out / "conformance" / page).is_file()
        data = json.loads((out / "conformance" / page).with_name("conformance.json").read_text())
        assert data["engine"] == engine
        assert f'<a href="conformance/{page}">{ENGINE_TITLES[engine]}</a>' in html


def test_every_engine_divergence_is_in_the_catalogue(quick_report):
    _, _, results = quick_report
    matrix = _section(results, "conformance")["results"]["matrix"]
    listed = [d for d in results["divergences"] if d["section"] == "conformance"]
    assert len(listed) == len(matrix["divergences"]) > 0
    for d, row in zip(matrix["divergences"], listed, strict=True):
        assert row["title"] == f"{ENGINE_TITLES[d['engine']]}: {d['check']}"
        assert all(name in row["kind"] for name in d["classes"])
        assert d["reason"] in row["finding"]


def _result(engine: str, failed: int) -> ConformanceResult:
    check = tally("triangles", "agreement", [None] * 3 + ["touching"] * failed)
    return ConformanceResult(engine=engine, refsim="0", seed=0, cases=3 + failed,
                             capabilities=("triangles",), checks=(check,))


def test_an_unavailable_engine_is_listed_with_its_reason():
    why = "mujoco: not installed (pip install mujoco)"
    matrix = conformance_matrix({"refsim-seed": _result("refsim-seed", 0),
                                 "fcl": _result("fcl", 2)}, unavailable={"mujoco": why})
    record = conformance_entry.MatrixRun(matrix, 5, "", "refsim conform --all")
    ctx = SimpleNamespace(quick=True, run=SimpleNamespace(get=lambda name: record))
    section = conformance_section.build(ctx)
    matrix_table, unavailable = section.tables
    assert matrix_table.columns == ("check", "refsim seed", "FCL")
    ((check, seed, fcl),) = matrix_table.rows
    assert (check, str(seed), str(fcl)) == ("triangles.agreement", "pass: 3 cases",
                                            "FAIL: 2 of 5 cases (touching 2)")
    assert (seed.status, fcl.status) == ("pass", "fail")
    assert {status for status, _ in matrix_table.legend} == {"pass", "declared", "fail", "none"}
    assert unavailable.rows == (("MuJoCo", why),)
    assert [d.title for d in section.divergences] == ["FCL: triangles.agreement"]
    assert "FAILURE (not declared)" in section.divergences[0].kind


def test_the_matrix_through_the_sweep_equals_the_shared_run():
    shared, _ = run_matrix(cases=10, seed=3, only="aabb")
    swept, _ = run_matrix(cases=10, seed=3, only="aabb", backend="inprocess")
    assert shared.cells == swept.cells and shared.divergences == swept.divergences
    assert shared.engines == swept.engines


def test_a_missing_engine_in_the_sweep_is_unavailable_not_an_error():
    specs = {"refsim-corrected": "refsim.engines.refsim_engines:corrected",
             "nothing": "no_such_module_for_refsim:engine"}
    matrix, results = run_matrix(specs, cases=5, seed=0, only="aabb", backend="inprocess")
    assert list(results) == ["refsim-corrected"]
    assert "nothing" in matrix.unavailable and "no_such_module_for_refsim" in \
        matrix.unavailable["nothing"]


# -- replays ------------------------------------------------------------------------------------


def test_replays_are_written_and_shown_at_their_claims(quick_report):
    out, html, results = quick_report
    replays = _section(results, "dynamics")["results"]["replays"]
    assert [r["name"] for r in replays] == [name for name, _, _ in replays_entry.REPLAYS]
    for r in replays:
        assert r["status"] == "written", r["reason"]
        page = out / r["file"]
        assert page.is_file() and page.stat().st_size == r["bytes"] > 0
        assert f'<iframe src="{r["file"]}"' in html
        assert r["frames"] > 1
    claims = {c["claim"]: c for c in results["claims"]}
    assert claims["C11"]["replays"] == ["replay-c11-interpenetration"]
    assert claims["C12"]["replays"] == ["replay-c12-spin"]
    for claim in CLAIMS:
        row = html.split(f'id="claim-{claim}"', 1)[1].split("</tr>", 1)[0]
        assert ('href="#replay-' in row) == (claim in ("C11", "C12"))
    # each replay sits right after the item it illustrates
    dynamics = html.split('<section id="dynamics">', 1)[1]
    assert dynamics.index('id="dynamics-c11"') < dynamics.index('id="replay-c11-interpenetration"')
    assert dynamics.index('id="dynamics-c12-spin"') < dynamics.index('id="replay-c12-spin"')


def test_without_viser_the_report_says_so_in_place(tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "viser", None)          # import viser raises ImportError
    records = Run(quick=True, out_dir=tmp_path).get("replays")
    assert {r.status for r in records} == {"unavailable"}
    assert all("viser" in r.reason for r in records)
    assert list((tmp_path / replays_entry.REPLAY_FOLDER).iterdir()) == []
    from refsim.report.sections.dynamics import _replay

    section = Section(key="dynamics", title="Rigid-body dynamics",
                      replays=[_replay(r) for r in records])
    html = render([section], {"versions": {}, "machine": {"platform": "", "processor": "",
                                                          "cpus": 1},
                              "commit": "", "seed": 0}, quick=True)
    assert "<iframe" not in html
    for r in records:
        assert f"no replay here: {escape(r.reason)}" in html


def test_replays_without_an_output_directory_are_not_written_and_say_so():
    records = Run(quick=True).get("replays")
    assert {r.status for r in records} == {"not written"}
    assert all(r.file == "" and r.reason for r in records)


# -- the advisor --------------------------------------------------------------------------------


def test_the_advisor_lists_every_bundled_scene(quick_report):
    _, html, results = quick_report
    advisor = _section(results, "advisor")["results"]
    assert [s["scene"] for s in advisor["scenes"]] == [p.name for p in bundled_scenes()]
    tolerances = advisor["tolerances"]
    assert len(tolerances) >= 2
    table = _table(results, "advisor", "advisor-advice")
    for scene in advisor["scenes"]:
        if scene["refused"] or scene["skipped"]:
            assert scene["advice"] == []
            assert [r for r in table["rows"] if r[0] == scene["scene"]][0][2] == \
                (f"not advised: {scene['refused']}" if scene["refused"]
                 else f"not advised in this run: {scene['skipped']}")
            continue
        assert [a["tolerance"] for a in scene["advice"]] == tolerances
        rows = [r for r in table["rows"] if r[0] == scene["scene"]]
        assert len(rows) == len(tolerances)
        for a, row in zip(scene["advice"], rows, strict=True):
            rec = a["recommended"]
            assert rec["meets"] is True
            assert row[2].startswith(f"{rec['solver']}, h = ") and str(rec["proxy"]) == row[3]
            assert a["proxy_saving"] == pytest.approx(a["own"]["proxy"] / rec["proxy"])
            assert ("converged" if a["reference"]["converged"] else "not converged") in row[8]
        # one reference per scene; the cost never grows as TOL loosens
        assert len({json.dumps(a["reference"], sort_keys=True) for a in scene["advice"]}) == 1
        by_tolerance = sorted(scene["advice"], key=lambda a: a["tolerance"])
        costs = [a["recommended"]["proxy"] for a in by_tolerance]
        assert costs == sorted(costs, reverse=True)
    assert [s["scene"] for s in advisor["scenes"] if s["refused"]] == ["particles.toml"]
    assert [s["scene"] for s in advisor["scenes"] if s["skipped"]] == \
        list(advisor_entry.ADVISOR_QUICK_SKIP)
    by_name = {s["scene"]: s for s in advisor["scenes"]}
    assert "the scene has no [[body]]" in by_name["particles.toml"]["refused"]
    assert advisor["duration"] == advisor_entry.ADVISOR_DURATION[0]
    assert "Quick run: the first 1 s of each scene" in html


def test_the_advisor_section_lists_a_refused_scene():
    record = advisor_entry.AdvisorRun(
        (advisor_entry.AdvisedScene("p.toml", refused="no bodies"),), (1e-2, 1e-3), 1.0, 1)
    ctx = SimpleNamespace(quick=True, run=SimpleNamespace(get=lambda name: record))
    section = advisor_section.build(ctx)
    assert section.tables[0].rows[0][:3] == ("p.toml", "-", "not advised: no bodies")


# -- workers --------------------------------------------------------------------------------------


def test_the_timed_studies_stay_in_the_reports_process():
    """A study whose records hold timing fields is never sent to a worker
    (it would be timed beside the others), nor one that gathers others'."""
    for name in plan.PARALLEL_ENTRIES:
        study = plan.STUDIES[name]
        assert study.in_report and not study.timed and not study.gathers
    assert {"bounds-cost", "collision-levels", "collision-speed", "particles-drag",
            "dynamics-step-cost"} <= {n for n, s in plan.STUDIES.items() if s.timed}


def test_a_timed_entry_is_refused_by_the_worker_task():
    """A study whose records hold timings, sent to a worker by mistake (its
    ``timed`` flag forgotten), fails with a line naming the flag."""
    from refsim.errors import SweepError
    from refsim.report.tasks import measure_entry

    with pytest.raises(SweepError, match="'particles-drag' holds timings .*timed=True"):
        measure_entry(seed=0, name="particles-drag", quick=True,
                      report_seed=REPORT_SEED)


def test_an_entry_measured_in_a_worker_returns_its_records_to_the_bit():
    from refsim.report.tasks import entry_records, measure_entry

    answer = measure_entry(seed=123, name="solvers-energy", quick=True,
                           report_seed=REPORT_SEED)
    assert json.loads(json.dumps(answer)) == answer          # plain data for the sweep
    records, missing = entry_records(answer)
    assert missing == {}
    here = Run(quick=True).get("solvers-energy")
    assert json.dumps(to_json(records)) == json.dumps(to_json(here))


def test_a_stopped_report_stops_its_workers_at_once(tmp_path):
    """SIGTERM to ``refsim report --workers 2`` while its workers run: it
    ends with one line and status 128 + 15 within seconds, and its workers
    are gone (the quick report's tasks are short; the next test stops long
    ones)."""
    import os
    import signal
    import subprocess
    import time

    import psutil

    process = subprocess.Popen(
        [sys.executable, "-m", "refsim.cli", "report", "--quick", "--workers", "2", "-o",
         str(tmp_path / "r")], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
        env=dict(os.environ, PYTHONWARNINGS="ignore"))
    from tests.helpers import new_workers

    try:
        me = psutil.Process(process.pid)
        deadline = time.monotonic() + 120.0
        while len(new_workers(me, set())) < 2:
            assert time.monotonic() < deadline and process.poll() is None
            time.sleep(0.1)
        workers = new_workers(me, set())
        time.sleep(2.0)                      # the workers are inside their tasks
        start = time.monotonic()
        process.send_signal(signal.SIGTERM)
        _, err = process.communicate(timeout=60.0)
        stopped = time.monotonic() - start
    finally:
        process.kill()
        process.wait(60.0)
    assert process.returncode == 128 + signal.SIGTERM
    assert err.decode().strip().splitlines()[-1] == "refsim: interrupted (SIGTERM)"
    assert stopped < 30.0
    _, alive = psutil.wait_procs(workers, timeout=30.0)
    assert not [p for p in alive if p.status() != psutil.STATUS_ZOMBIE]
    assert not (tmp_path / "r" / "index.html").exists()


def test_cancel_stops_the_sweeps_of_the_background_thread(tmp_path):
    """The advisor's sweep runs in the run's background thread, which
    signals do not reach; cancel() terminates its workers mid-task within
    seconds (before the sweep's tasks have all ended), and the entry raises."""
    import time

    import psutil

    from refsim.sweep import SweepCancelled
    from tests.helpers import new_workers

    me = psutil.Process()
    before = {p.pid for p in me.children(recursive=True)}   # e.g. a Dask fixture's
    run = Run(quick=True, out_dir=tmp_path, workers=2)
    run.prefetch(["advisor"])
    deadline = time.monotonic() + 120.0
    while len(new_workers(me, before)) < 2:
        assert time.monotonic() < deadline
        time.sleep(0.1)
    workers = new_workers(me, before)
    time.sleep(3.0)                          # inside their first advice
    start = time.monotonic()
    run.cancel(timeout=60.0)
    assert time.monotonic() - start < 6.0    # without the cancel event: 15 s here
    _, alive = psutil.wait_procs(workers, timeout=30.0)
    assert not [p for p in alive if p.status() != psutil.STATUS_ZOMBIE]
    # how many tasks ended in the first seconds depends on the machine (a
    # quick advice takes seconds); what matters is that not all of them did
    with pytest.raises(SweepCancelled, match=r"sweep cancelled with \d+ of \d+ tasks done"
                       ) as cancelled:
        run.get("advisor")
    done, total = map(int, re.findall(r"\d+", str(cancelled.value))[:2])
    assert done < total


def test_report_command_takes_workers(tmp_path, capsys):
    from refsim.cli import main

    assert main(["report", "--quick", "-o", str(tmp_path / "r"), "--workers", "0"]) == 2
    assert "--workers must be at least 1" in capsys.readouterr().err
