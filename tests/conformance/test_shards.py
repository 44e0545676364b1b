"""One engine's checks in shards (refsim.conformance.shards): the result put
together from shards is the single run's, whatever the split."""

from __future__ import annotations

import json

import pytest

from refsim.cli import main
from refsim.conformance import draw
from refsim.conformance.cases_boxes import box_cases
from refsim.conformance.cases_meshes import pose_cases
from refsim.conformance.cases_triangles import triangle_cases
from refsim.conformance.runner import check_engine
from refsim.conformance.shards import check_engine_sharded, shard_ranges
from refsim.engines import load_engine

SEVERAL = "tests.conformance.broken_engines:several_flaws"
BOX = "tests.conformance.broken_engines:box_ignores_translation"


def _without_timings(record: dict) -> dict:
    record = dict(record, seconds=None, case_seconds=None)
    record["checks"] = [dict(c, seconds=None) for c in record["checks"]]
    return record


@pytest.mark.parametrize("build", [triangle_cases, pose_cases, box_cases])
def test_a_range_of_a_set_is_that_part_of_the_whole_set(build, monkeypatch):
    monkeypatch.setattr(draw, "BLOCK", 12)
    whole = build(30, 5)
    part = build(30, 5, 12, 24)
    items = lambda s: getattr(s, "pairs", None) or s.cases          # noqa: E731
    assert len(items(part)) == 12
    assert [str(c.to_dict()) for c in items(part)] == \
        [str(c.to_dict()) for c in items(whole)[12:24]]


def test_shards_are_whole_blocks_covering_every_case(monkeypatch):
    monkeypatch.setattr(draw, "BLOCK", 12)
    assert shard_ranges(30) == [(0, 12), (12, 24), (24, 30)]
    assert shard_ranges(12) == [(0, 12)]


def test_the_result_from_shards_is_the_single_run(monkeypatch):
    """Three shards per generated set, every case-by-case check failing
    somewhere, a fixed ODE check beside them: counts, classes, examples, the
    shrunk case and every failure record are those of one run."""
    monkeypatch.setattr(draw, "BLOCK", 12)
    single = check_engine(load_engine(SEVERAL), cases=36, seed=2, spec=SEVERAL)
    sharded = check_engine_sharded(SEVERAL, cases=36, seed=2, backend="inprocess")
    assert {c.key for c in single.checks if c.failed} >= {
        "triangles.agreement", "collide.agreement", "aabb.tight", "ode.order"}
    assert _without_timings(sharded.to_dict(failures=True)) == \
        _without_timings(single.to_dict(failures=True))
    shrunk = [e for c in single.checks for e in c.examples if e.get("shrunk")]
    assert shrunk                                    # the search ran, and was put back


def test_conform_with_workers_writes_what_one_process_writes(tmp_path, capsys):
    assert main(["conform", BOX, "--cases", "24", "-o", str(tmp_path / "one")]) == 1
    assert main(["conform", BOX, "--cases", "24", "--workers", "2",
                 "-o", str(tmp_path / "two")]) == 1
    one, two = (json.loads((tmp_path / d / "conformance.json").read_text())
                for d in ("one", "two"))
    assert _without_timings(one) == _without_timings(two)
    assert (tmp_path / "one" / "failures.jsonl").read_text() == \
        (tmp_path / "two" / "failures.jsonl").read_text()
