"""Every figure recorded in results.json appears on the page, as displayed,
and every claim with a verdict is backed by a figure of its section.

"Figure" here means what a reader sees: each table (every cell) and each chart.
The raw arrays in a section's ``results`` are the data behind them.
"""

from __future__ import annotations

from markupsafe import escape


def _table_html(html: str, table_id: str) -> str:
    head = f'<h3 id="{table_id}">'
    assert html.count(head) == 1, table_id
    return html.split(head, 1)[1].split("</table>", 1)[0]


def test_every_table_cell_is_on_the_page(quick_report):
    _, html, results = quick_report
    tables = [t for s in results["sections"].values() for t in s["tables"]]
    assert tables
    for table in tables:
        if not table["rows"] and table["empty"]:
            after = html.split(f'<h3 id="{table["id"]}">', 1)[1].split("<h3", 1)[0]
            assert f"<p>{escape(table['empty'])}</p>" in after and "<table" not in after
            continue
        block = _table_html(html, table["id"])
        links = table["column_links"] or [""] * len(table["columns"])
        for column, link in zip(table["columns"], links, strict=True):
            heading = f'<a href="{escape(link)}">{escape(column)}</a>' if link else escape(column)
            assert f"<th>{heading}</th>" in block, (table["id"], column)
        for row in table["rows"]:
            for cell in row:
                assert f">{escape(cell)}</td>" in block, (table["id"], cell)


def test_every_chart_is_on_the_page(quick_report):
    _, html, results = quick_report
    figures = [f for s in results["sections"].values() for f in s["figures"]]
    assert figures
    for figure in figures:
        block = html.split(f'<figure id="{figure["id"]}">', 1)[1].split("</figure>", 1)[0]
        assert "<svg" in block and escape(figure["title"]) in block


def test_ids_are_unique(quick_report):
    _, _, results = quick_report
    ids = [x["id"] for s in results["sections"].values() for x in s["tables"] + s["figures"]]
    assert len(ids) == len(set(ids))


def test_every_verdict_is_backed_by_a_figure_of_its_section(quick_report):
    _, html, results = quick_report
    measured = [c for c in results["claims"] if c["verdict"] != "not measured yet"]
    assert measured
    for claim in measured:
        section = results["sections"][claim["area"]]
        evidence = {x["id"] for x in section["tables"] + section["figures"]}
        assert claim["evidence"] in evidence, claim["claim"]
        assert claim["measured"] and claim["command"], claim["claim"]
        row = html.split(f'id="claim-{claim["claim"]}"', 1)[1].split("</tr>", 1)[0]
        assert f'verdict-{claim["verdict"]}">{escape(claim["verdict"])}</span>' in row
        assert claim["summary"] and escape(claim["summary"]) in row
        details = row.split("<details>", 1)[1].split("</details>", 1)[0]
        assert escape(claim["measured"]) in details


def test_every_agreement_is_on_the_page_with_its_command(quick_report):
    _, html, results = quick_report
    assert results["agreements"]
    summary = html.split('<section id="agreement">', 1)[1].split("</section>", 1)[0]
    for row in results["agreements"]:
        for key in ("oracle", "check", "result", "command"):
            assert escape(row[key]) in summary, (row["oracle"], key)


def _section_html(html: str, section_id: str) -> str:
    return html.split(f'<section id="{section_id}">', 1)[1].split("</section>", 1)[0]


def test_every_divergence_is_catalogued_with_its_evidence(quick_report):
    _, html, results = quick_report
    catalogue = _section_html(html, "divergences")
    assert results["divergences"]
    ids = {x["id"] for s in results["sections"].values() for x in s["tables"] + s["figures"]}
    for row in results["divergences"]:
        assert escape(row["finding"]) in catalogue and escape(row["kind"]) in catalogue
        assert row["evidence"] in ids, row["title"]


def test_cross_cutting_parts_hold_their_items_once(quick_report):
    _, html, results = quick_report
    items = [x for s in results["sections"].values() for x in s["tables"] + s["figures"]]
    parts = {x["part"] for x in items if x["part"]}
    assert parts == {"speed-accuracy", "stability"}
    for item in items:
        anchor = f'id="{item["id"]}"'
        assert html.count(anchor) == 1, item["id"]
        if item["part"]:
            assert anchor in _section_html(html, item["part"]), item["id"]


def test_every_element_of_the_built_page_is_closed_where_it_was_opened(quick_report):
    from tests.report.test_page import misnested

    _, html, _ = quick_report
    assert misnested(html) == []
