"""Every command the report cites reproduces its figure: it is one that
``refsim study`` (or ``refsim info``) accepts, it names an entry of the plan,
and every entry the report runs is cited somewhere."""

from __future__ import annotations

import html as html_lib
import re

import pytest

from refsim.cli import build_parser
from refsim.report.plan import CLAIM_STUDY, STUDIES, claim_command
from refsim.report.run import Run

#: A command as the page prints it: "refsim" and its arguments, up to the
#: end of the sentence or list it stands in.
COMMAND = re.compile(r"refsim (?:study|info) [A-Za-z0-9_./-]+")


def cited(page: str, results: dict) -> list[str]:
    """Every refsim command on the page and in results.json."""
    text = html_lib.unescape(re.sub(r"<[^>]+>", " ", page))
    commands = COMMAND.findall(text)
    commands += [row["command"] for row in results["claims"] + results["agreements"]
                 if row["command"]]
    return commands


def test_no_old_module_commands_remain(quick_report):
    _, page, _ = quick_report
    assert "python -m refsim" not in page and "python -c" not in page


def test_every_cited_command_is_accepted(quick_report):
    _, page, results = quick_report
    commands = cited(page, results)
    assert len(commands) > 40
    parser = build_parser()
    for command in set(commands):
        words = command.split()[1:]
        args = parser.parse_args(words)         # exits (SystemExit) on a bad command
        if words[0] == "study":
            assert args.name in STUDIES and command == f"refsim study {args.name}"


#: Entries the quick report runs empty, so the page shows no table for them
#: (pybullet's settings, one at a time: the full report only).
FULL_REPORT_ONLY = {"dynamics-pybullet-settings"}


def test_every_study_the_report_runs_is_cited(quick_report):
    _, page, results = quick_report
    names = {c.split()[2] for c in cited(page, results) if c.startswith("refsim study")}
    assert names == {name for name, study in STUDIES.items()
                     if study.in_report and name not in FULL_REPORT_ONLY}
    assert all(Run(quick=True).get(name) == [] for name in FULL_REPORT_ONLY)


def test_every_verdict_cites_the_entry_that_backs_it(quick_report):
    _, _, results = quick_report
    assert {row["claim"]: row["command"] for row in results["claims"]} == {
        claim: claim_command(claim) for claim in sorted(CLAIM_STUDY, key=lambda c: int(c[1:]))}


@pytest.mark.parametrize("name", ["no-such-study", "c1"])
def test_an_unknown_study_is_refused(name):
    with pytest.raises(SystemExit):
        build_parser().parse_args(["study", name])
