"""The dynamics section's cells from constructed records."""

from __future__ import annotations

from refsim.report.sections.dynamics import _stages


def test_the_stage_column_shows_only_the_stages_that_took_time_with_units():
    """The compiled loop runs every stage in one call: the stages it ran are
    not timed one by one and read as 0, which the column leaves out."""
    stages = {"integrate": 0.0, "walls": 0.0, "check": 0.0, "compiled loop": 2.63e-7}
    assert _stages(stages) == "compiled loop: 0.263 us"
    assert _stages({"integrate": 1.5e-6, "walls": 0.0, "check": 2.25e-5}) == \
        "integrate: 1.5 us; check: 22.5 us"
    assert _stages({"integrate": 0.0}) == _stages({}) == "not timed by stage"
