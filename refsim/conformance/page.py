"""The conformance pages: one engine's results, and the matrix of engines, as
self-contained HTML (inline CSS, no script, no network: a page opens from
disk or an archive as it is).

Views only: they arrange the records of :mod:`refsim.conformance.results`
and :mod:`refsim.conformance.matrix` and compute nothing. Every text is
escaped (``html.escape``); examples are shown as the JSON they are stored as.

Cost: O(size of the records).
"""

from __future__ import annotations

import html
import json

#: Characters of an example's JSON shown on the page (the JSON file has all).
EXAMPLE_CHARS = 4000

_CSS = """
body { font: 14px/1.45 system-ui, sans-serif; margin: 2em auto; max-width: 72em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.15em; margin-top: 2em; }
table { border-collapse: collapse; margin: 1em 0; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: left; vertical-align: top; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
.passed { background: #e3f4e1; } .failed { background: #f9d6d5; }
.xfailed { background: #fbefd0; } .xpassed { background: #e6eef9; } .na { background: #eee; }
pre { background: #f6f6f6; padding: 0.6em; font-size: 12px; white-space: pre-wrap;
      overflow-wrap: anywhere; }
.meta { color: #555; }
"""


def _status_class(status: str) -> str:
    return "na" if status == "n/a" else status


def _e(text) -> str:
    return html.escape(str(text))


def _json(value) -> str:
    """A record as JSON, one top-level key a line (its value on that line)."""
    from refsim.conformance.results import plain

    value = plain(value)
    if isinstance(value, dict):
        text = "{\n" + ",\n".join(f" {json.dumps(k)}: {json.dumps(v, allow_nan=False)}"
                                  for k, v in value.items()) + "\n}"
    else:
        text = json.dumps(value, allow_nan=False)
    if len(text) > EXAMPLE_CHARS:
        text = text[:EXAMPLE_CHARS] + "\n... (cut; conformance.json has it all)"
    return _e(text)


def _document(title: str, body: str) -> str:
    return (f"<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            f"<title>{_e(title)}</title><style>{_CSS}</style></head>"
            f"<body>{body}</body></html>\n")


def engine_page(result) -> str:
    """The page of one :class:`~refsim.conformance.results.ConformanceResult`."""
    from refsim.conformance.registry import CHECKS, TRUTH_CHECKS
    from refsim.conformance.results import CLASS_DEFINITIONS

    docs = {c.key: c.doc for c in CHECKS}
    expected = sum(c.status == "xfailed" for c in result.checks)
    verdict = ("no check failed" if result.ok else "a check failed") + \
        (f" ({expected} expected failures)" if expected else "")
    parts = [f"<h1>Conformance of {_e(result.engine)}</h1>",
             f"<p class=\"meta\">refsim {_e(result.refsim)} &middot; engine "
             f"{_e(result.spec or result.engine)} &middot; seed {result.seed} &middot; "
             f"{result.cases} cases per generated set &middot; capabilities "
             f"{_e(', '.join(result.capabilities))} &middot; expected failures "
             f"{_e(result.expected_failures or 'none')} &middot; {_e(verdict)}</p>",
             "<table><tr><th>check</th><th>cases</th><th>passed</th><th>failed</th>"
             "<th>classes</th><th>status</th><th>reason</th></tr>"]
    for c in result.checks:
        classes = ", ".join(f"{k} {v}" for k, v in c.classes.items()) or "-"
        truth = " (the kit's ground truth: the engine is not called)" \
            if c.key in TRUTH_CHECKS else ""
        parts.append(f"<tr class=\"{_status_class(c.status)}\"><td><a href=\"#{_e(c.key)}\">"
                     f"{_e(c.key)}</a>{_e(truth)}</td><td class=\"n\">{c.cases}</td>"
                     f"<td class=\"n\">{c.passed}</td><td class=\"n\">{c.failed}</td>"
                     f"<td>{_e(classes)}</td><td>{_e(c.status)}</td><td>{_e(c.reason)}</td></tr>")
    parts.append("</table>")
    occurring = [k for k in CLASS_DEFINITIONS if any(k in c.classes for c in result.checks)]
    if occurring:
        parts.append("<p>Classes of the failing cases:</p><dl>" + "".join(
            f"<dt>{_e(k)}</dt><dd>{_e(CLASS_DEFINITIONS[k])}</dd>" for k in occurring)
            + "</dl>")
    for c in result.checks:
        parts.append(f"<h2 id=\"{_e(c.key)}\">{_e(c.key)}: {_e(c.status)}</h2>")
        parts.append(f"<p>{_e(docs.get(c.key, ''))}</p>")
        if c.reason:
            parts.append(f"<p><b>Reason:</b> {_e(c.reason)}</p>")
        if c.measured:
            parts.append(f"<p>Measured:</p><pre>{_json(c.measured)}</pre>")
        for n, example in enumerate(c.examples, start=1):
            label = "minimal failing case (shrunk by Hypothesis)" if example.get("shrunk") \
                else f"failing case {n}"
            parts.append(f"<p>{_e(label)}, class {_e(example.get('class', '?'))}:</p>"
                         f"<pre>{_json(example)}</pre>")
    return _document(f"refsim conformance: {result.engine}", "".join(parts))


def matrix_page(matrix) -> str:
    """The page of a :class:`~refsim.conformance.matrix.Matrix`: engines as
    columns, checks as rows, each cell its status and counts, each engine's
    name a link to its own page; then the divergences."""
    parts = [f"<h1>Conformance matrix</h1><p class=\"meta\">refsim {_e(matrix.refsim)} "
             f"&middot; seed {matrix.seed} &middot; {matrix.cases} cases per generated set</p>",
             "<table><tr><th>check</th>"]
    for engine in matrix.engines:
        page = matrix.pages.get(engine)
        name = f"<a href=\"{_e(page)}\">{_e(engine)}</a>" if page else _e(engine)
        parts.append(f"<th>{name}</th>")
    parts.append("</tr>")
    for check in matrix.checks:
        parts.append(f"<tr><td>{_e(check)}</td>")
        for engine in matrix.engines:
            cell = matrix.cell(check, engine)
            if cell is None:
                parts.append("<td></td>")
                continue
            text = "n/a" if cell.status == "n/a" else \
                f"{cell.status} {cell.passed}/{cell.cases}"
            parts.append(f"<td class=\"{_status_class(cell.status)}\">{_e(text)}</td>")
        parts.append("</tr>")
    parts.append("</table><h2>Divergences</h2><table><tr><th>engine</th><th>check</th>"
                 "<th>status</th><th>classes</th><th>reason</th></tr>")
    for d in matrix.divergences:
        classes = ", ".join(f"{k} {v}" for k, v in d.classes.items())
        parts.append(f"<tr class=\"{_status_class(d.status)}\"><td>{_e(d.engine)}</td>"
                     f"<td>{_e(d.check)}</td><td>{_e(d.status)}</td><td>{_e(classes)}</td>"
                     f"<td>{_e(d.reason)}</td></tr>")
    parts.append("</table>")
    return _document("refsim conformance matrix", "".join(parts))
