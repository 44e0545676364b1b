"""The page's template on constructed sections: what a reader sees for an
empty table, a coloured cell, a verdict and its numbers, without building a
report."""

from __future__ import annotations

import re

from refsim.report.build import render
from refsim.report.section import Cell, Section, Table, Verdict

ENVIRONMENT = {"versions": {"python": "3"}, "machine": {"platform": "p", "processor": "x",
                                                        "cpus": 2},
               "commit": "c", "seed": 0}


def page(*tables, verdicts=()) -> str:
    section = Section(key="bounds", title="Bounds", tables=list(tables), verdicts=list(verdicts))
    return render([section], ENVIRONMENT, quick=True)


def after_heading(html: str, table_id: str) -> str:
    return html.split(f'<h3 id="{table_id}">', 1)[1].split("<h3", 1)[0].split("</section>")[0]


def test_a_table_without_rows_shows_its_sentence_not_an_empty_table():
    empty = Table(id="none-here", title="Engines that could not be run",
                  columns=("engine", "why"), rows=(), caption="Left out of the matrix.",
                  empty="None: every shipped engine ran.")
    block = after_heading(page(empty), "none-here")
    assert "<p>None: every shipped engine ran.</p>" in block
    assert "<table" not in block and "Left out of the matrix." not in block


def test_a_table_with_rows_is_a_table_with_its_caption():
    some = Table(id="some", title="Engines that could not be run", columns=("engine", "why"),
                 rows=(("MuJoCo", "not installed"),), caption="Left out of the matrix.",
                 empty="None: every shipped engine ran.")
    block = after_heading(page(some), "some")
    assert "<td>MuJoCo</td>" in block and "Left out of the matrix." in block
    assert "every shipped engine ran" not in block


def test_status_cells_are_coloured_and_the_legend_names_each_colour():
    table = Table(id="matrix", title="Matrix", columns=("check", "engine"),
                  rows=(("a", Cell("pass: 3 cases", "pass")),
                        ("b", Cell("1 of 1 case fails as declared (bug 1)", "declared"))),
                  legend=(("pass", "passes every case"), ("declared", "fails as declared")))
    block = after_heading(page(table), "matrix")
    assert '<td class="status status-pass">pass: 3 cases</td>' in block
    assert '<td class="status status-declared">1 of 1 case fails as declared (bug 1)</td>' \
        in block
    legend = block.split('<p class="legend">', 1)[1].split("</p>", 1)[0]
    assert re.findall(r'status-(\w+)">', legend) == ["pass", "declared"]


def test_a_verdict_is_a_badge_then_a_sentence_then_the_numbers_behind_a_click():
    verdict = Verdict("C1", measured="1.03 against 1 (spread 0.1: within it)",
                      verdict="undecided", evidence="bounds-cost", command="refsim study x",
                      timing=True, summary="Too close to call in this run.")
    html = page(verdicts=[verdict])
    row = html.split('id="claim-C1"', 1)[1].split("</tr>", 1)[0]
    badge = row.index('<span class="badge verdict-undecided">undecided</span>')
    sentence = row.index("Too close to call in this run.")
    details = row.index("<details>")
    assert badge < sentence < details
    hidden = row[details:].split("</details>", 1)[0]
    assert "1.03 against 1" in hidden and "refsim study x" in hidden
    assert "1.03 against 1" not in row[:details]


#: Elements HTML closes by itself, or that the page never closes by design.
VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source",
        "track", "wbr", "p", "li", "tr", "td", "th", "option"}


def misnested(html: str) -> list[str]:
    """The tags of ``html`` that close an element other than the innermost
    open one, or that stay open at the end (``p``, ``li`` and table cells,
    which HTML may leave open, aside)."""
    from html.parser import HTMLParser

    problems: list[str] = []
    stack: list[str] = []

    class Nesting(HTMLParser):
        def handle_starttag(self, tag, attrs):
            if tag not in VOID:
                stack.append(tag)

        def handle_endtag(self, tag):
            if tag in VOID:
                return
            if not stack or stack[-1] != tag:
                problems.append(f"</{tag}> closes <{stack[-1] if stack else 'nothing'}> "
                                f"at line {self.getpos()[0]}")
                if tag in stack:
                    del stack[len(stack) - 1 - stack[::-1].index(tag):]
                return
            stack.pop()

    Nesting().feed(html)
    return problems + [f"<{tag}> never closed" for tag in stack]


def test_the_nesting_check_finds_a_table_left_open():
    assert misnested("<section><table><tr><td>a</table></section>") == []
    assert misnested("<section><table><p>x</p><table><tr><td>a</table></section>") == \
        ["</section> closes <table> at line 1"]


def test_every_element_of_the_page_is_closed_where_it_was_opened():
    verdict = Verdict("C1", measured="1.03", verdict="confirmed", evidence="some",
                      summary="It holds.")
    some = Table(id="some", title="A table", columns=("a", "b"), rows=(("1", "2"),))
    assert misnested(page(some, verdicts=[verdict])) == []
