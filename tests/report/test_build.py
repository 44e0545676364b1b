"""The report page: self-contained, complete, deterministic, written atomically."""

from __future__ import annotations

import io
import json
import re

import pytest

from refsim.bundled import bundled_models
from refsim.claims import CLAIMS
from refsim.report import build as report_build
from refsim.report.build import AREAS, build_report
from refsim.report.section import Section
from refsim.storage.writing import write_text_atomic


def test_every_area_has_a_section(quick_report):
    _, html, results = quick_report
    for key, title, _ in AREAS:
        assert f'<section id="{key}">' in html
        assert f"<h2>{title}</h2>" in html
        assert key in results["sections"]


def test_pending_sections_say_so_plainly(quick_report):
    _, html, results = quick_report
    for key, status in ((k, v["status"]) for k, v in results["sections"].items()):
        section = html.split(f'<section id="{key}">', 1)[1].split("</section>", 1)[0]
        assert ("Not measured yet" in section) == (status == "pending")


def test_models_section_lists_every_bundled_model(quick_report):
    _, html, results = quick_report
    listed = {m["name"] for m in results["sections"]["models"]["results"]["models"]}
    assert listed == {p.name for p in bundled_models()}
    for name in listed:
        assert f"<td>{name}</td>" in html


def test_every_claim_has_a_row_and_a_verdict(quick_report):
    _, html, results = quick_report
    assert [c["claim"] for c in results["claims"]] == list(CLAIMS)
    for claim in CLAIMS:
        assert f'id="claim-{claim}"' in html
    for row in results["claims"]:
        assert row["verdict"] in {"confirmed", "refuted", "partly", "undecided",
                                  "not measured yet"}
        if row["verdict"] != "not measured yet":
            assert row["measured"] and row["evidence"]
            assert f'id="{row["evidence"]}"' in html  # the evidence exists on the page


#: Words of the project's own planning that have no place in the page's
#: prose (a reader of the report knows no issue tracker, design notes or
#: goals the project set itself).
INTERNAL_WORDS = re.compile(r"\bissues?\b|\bDESIGN\b|DESIGN\.md|\btargets?\b", re.IGNORECASE)


def _prose(html: str) -> str:
    """The page's text as a reader sees it: no charts, style or markup."""
    text = re.sub(r"<svg.*?</svg>|<style>.*?</style>", " ", html, flags=re.S)
    return re.sub(r"<[^>]+>", " ", text)


def test_the_prose_has_no_project_internal_words(quick_report):
    _, html, _ = quick_report
    prose = _prose(html)
    assert "refsim accuracy report" in prose and "The seed's claims" in prose
    assert INTERNAL_WORDS.findall(prose) == []


def test_page_is_self_contained(quick_report):
    _, html, _ = quick_report
    assert "<style>" in html
    assert not re.search(r'(src|href)\s*=\s*"(https?:)?//', html)
    assert "<script" not in html and "<link" not in html


def test_the_entries_are_deterministic_and_the_same_on_workers(tmp_path, quick_report,
                                                              monkeypatch):
    """The report's entries measured again by a run with two workers (the
    untimed studies there, one task each, and the replays as their sweep; the
    timed and gathering entries here after them) give the records the
    report's own run gave, timings aside: the report is deterministic, and its
    workers change no result. Two sweeps are not measured again, the
    conformance matrix and the advisor, the report's longest entries (a
    second build of the whole report would double the suite's longest
    fixture): tests/advisor/test_advisor.py holds the advice equal in one
    process and on two, and tests/conformance/test_cli_conform.py the
    matrix's aabb checks (``--all --workers 2``); the matrix's rigid checks
    on workers are not compared."""
    from refsim.report import plan
    from refsim.report.entries.replays import REPLAYS
    from refsim.report.run import REPORT_SEED, Run
    from tests.report.conftest import ENTRY_RECORDS, records_without_timings

    out, _, _ = quick_report
    first = json.loads((out / ENTRY_RECORDS).read_text())
    again = [name for name in first if name not in ("conformance-matrix", "advisor")]
    assert set(plan.PARALLEL_ENTRIES) <= set(again) and "replays" in again
    sent, runs = [], []                       # what went to the workers, and from which run
    measure_parallel = Run._measure_parallel

    def spy(run, futures):
        runs.append(run)
        sent.extend(futures)
        return measure_parallel(run, futures)

    monkeypatch.setattr(Run, "_measure_parallel", spy)
    run = Run(quick=True, seed=REPORT_SEED, out_dir=tmp_path, workers=2)
    run.prefetch(again)
    try:
        second = {name: records_without_timings(run.get(name)) for name in again}
    finally:
        run.cancel()
    assert runs == [run] and run.missing == {}
    assert sorted(sent) == sorted(plan.PARALLEL_ENTRIES) and len(sent) >= 15
    for name in again:
        assert second[name] == first[name], name
    assert sorted(p.name for p in (tmp_path / "replays").iterdir()) == \
        sorted(f"{name}.html" for name, _, _ in REPLAYS)


def test_timings_are_marked_by_metadata_not_by_name(quick_report):
    """The study records' timing fields are listed, and results whose names
    sound like timings but are not (counts per configuration, apex ratios)
    are compared."""
    _, _, results = quick_report
    paths = {tuple(p) for p in results["timing_paths"]}
    section = ("sections",)
    assert section + ("bounds", "results", "update_cost", "*", "seconds_per_update") in paths
    assert section + ("bounds", "results", "pose_check_seconds") in paths
    assert section + ("collision", "results", "levels", "configurations", "*", "seconds") \
        in paths
    assert section + ("collision", "results", "hierarchy_speed", "ratios") in paths
    assert section + ("solvers", "results", "drag_models", "cost_ratio") in paths
    assert section + ("dynamics", "results", "step_cost", "*", "seconds") in paths
    assert not any("apex_ratios" in p or "answers" in p or "configurations" == p[-1]
                   for p in paths)
    assert all(p[:1] == section and p[2] == "results" for p in paths)
    # a marked path exists in the results it marks
    assert results["sections"]["bounds"]["results"]["update_cost"][0]["seconds_per_update"] > 0


def test_a_failed_build_leaves_no_file(tmp_path, monkeypatch):
    """The sections are trivial here: what is tested is the writing."""
    def broken(*args, **kwargs):
        raise RuntimeError("rendering failed")

    monkeypatch.setattr(report_build, "_build_section",
                        lambda key, title, pending, ctx: Section(key=key, title=title))
    monkeypatch.setattr(report_build, "render", broken)
    with pytest.raises(RuntimeError):
        build_report(tmp_path, quick=True, stream=io.StringIO())
    assert list(tmp_path.iterdir()) == []


def test_write_atomic_replaces_whole_file(tmp_path):
    target = tmp_path / "page.html"
    target.write_text("old")
    write_text_atomic(target, "new")
    assert target.read_text() == "new"
    assert [p.name for p in tmp_path.iterdir()] == ["page.html"]
    assert target.stat().st_mode & 0o044 == 0o044   # readable by others, as open() makes it


def test_divergence_catalogue_rules():
    """Refuted and partly confirmed claims, the seed's own confirmed issues
    (C11, C12), and each section's declared oracle disagreements are listed;
    a confirmed ordinary claim is not."""
    from refsim.report.build import divergence_rows
    from refsim.report.section import Divergence, Section, Verdict

    a = Section("bounds", "A", verdicts=[Verdict("C1", "m1", "confirmed", "fig-a"),
                                         Verdict("C2", "m2", "partly", "fig-b",
                                                 summary="s2")],
                divergences=[Divergence("oracle differs", "oracle disagreement: tolerance",
                                        "3 of 9", "tab-a")])
    b = Section("dynamics", "B", verdicts=[Verdict("C12", "m12", "confirmed", "fig-c"),
                                           Verdict("C11", "m11", "refuted", "fig-d")])
    rows = divergence_rows([a, b])
    titles = [r["title"].split(":")[0] for r in rows]
    assert titles == ["C2", "C11", "C12", "oracle differs"]
    kinds = {r["title"].split(":")[0]: r["kind"] for r in rows}
    assert kinds["C2"] == "seed claim partly" and kinds["C11"] == "seed claim refuted"
    assert kinds["C12"] == "a problem the seed lists itself, confirmed"
    assert rows[0]["timing"] is False
    # a claim's sentence is the finding, its numbers the details; without a
    # sentence the numbers are the finding
    assert (rows[0]["finding"], rows[0]["details"]) == ("s2", "m2")
    assert (rows[1]["finding"], rows[1]["details"]) == ("m11", "")
    assert rows[-1] == {"section": "bounds", "title": "oracle differs",
                        "kind": "oracle disagreement: tolerance", "finding": "3 of 9",
                        "evidence": "tab-a", "details": ""}
