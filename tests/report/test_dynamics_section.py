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


def test_the_findings_read_whole_without_the_engines_that_did_not_run():
    """A study given only some engines (no pybullet, no seed wall speed, no
    refsim) still words its findings: each sentence about an engine is left
    out with it, and nothing about the others changes."""
    from refsim.claims.dynamics import apex_findings, rest_findings
    from refsim.report.sections.dynamics import _apex_findings, _rest_findings
    from refsim.studies.bounce import ANALYTIC, REFSIM, SEED_WALL_SPEED, ApexRow, RestRow

    drop = {"body": "sphere-2k.ac", "rotation": "off", "e": 0.8, "step": 1e-3, "solver": "rk4"}

    def row(engine, error):
        return ApexRow(**drop, engine=engine, heights=[], times=[], ratio=0.64,
                       first_ratio=0.64, error=error, max_spin=0.0)

    both = _apex_findings(apex_findings([row(ANALYTIC, 0.0), row(REFSIM, 1e-12),
                                         row(SEED_WALL_SPEED, 2e-3)]))
    alone = _apex_findings(apex_findings([row(ANALYTIC, 0.0), row(REFSIM, 1e-12)]))
    assert "literal flip" in both and "inside a 0.5% tolerance" in both
    assert "literal flip" not in alone
    assert alone == both.split("; the seed's literal flip")[0] + "."
    assert "rounding" in alone

    case = {"body": "s", "e": 0.5, "zeno": 3.0}
    closed = RestRow(**case, engine=ANALYTIC, settle=2.0, bounces=5)
    ours = RestRow(**case, engine=REFSIM, settle=2.001, bounces=5)
    assert _rest_findings(rest_findings([closed])) == \
        "e = 0.5: the analytic series settles after bounce 5."
    assert _rest_findings(rest_findings([closed, ours])) == (
        "e = 0.5: the analytic series settles after bounce 5, refsim after bounce 5 "
        "(1 ms from the analytic time).")
