"""Study records and claim verdicts as plain text, for ``refsim study``.

One generic printer for every record of :mod:`refsim.studies` (and the
plan's records that gather them): a list of records is a table, one column
per field; a single record is a list of ``field: value`` lines, its nested
records printed below it; a mapping of records is one block per key. Floats
are printed with six significant digits, long arrays by their length and
ends. Timing fields (marked by :func:`refsim.studies.timing_field`) carry a
``*`` in their heading: they vary from run to run.
"""

from __future__ import annotations

import math
from dataclasses import fields, is_dataclass

from refsim.studies import is_timing

#: Arrays and lists longer than this are shown by their length and ends.
SHOWN_ITEMS = 20

#: The mark of a timing field's heading, and what it means.
TIMING_MARK = "*"
TIMING_NOTE = f"{TIMING_MARK} timing: varies from run to run"


def _is_record(value) -> bool:
    return is_dataclass(value) and not isinstance(value, type)


def _is_records(value) -> bool:
    return isinstance(value, list | tuple) and bool(value) and all(map(_is_record, value))


def cell(value) -> str:
    """One value as text: floats to 6 significant digits, sequences in
    brackets (long ones by length and ends), mappings in braces."""
    if hasattr(value, "tolist"):            # numpy arrays and scalars
        value = value.tolist()
    if isinstance(value, bool) or value is None:
        return str(value)
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.6g}"
    if isinstance(value, list | tuple):
        if len(value) > SHOWN_ITEMS:
            return (f"[{len(value)} values: {cell(value[0])}, {cell(value[1])}, ..., "
                    f"{cell(value[-1])}]")
        return "[" + ", ".join(cell(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{cell(k)}: {cell(v)}" for k, v in value.items()) + "}"
    if _is_record(value):
        return f"{type(value).__name__}(" + ", ".join(
            f"{f.name}={cell(getattr(value, f.name))}" for f in fields(value)) + ")"
    return str(value)


def _heading(f) -> str:
    return f.name + (TIMING_MARK if is_timing(f) else "")


def table(records) -> str:
    """Records of one type as a table: a heading per field, a row per record."""
    columns = fields(records[0])
    rows = [[_heading(f) for f in columns]]
    rows += [[cell(getattr(r, f.name)) for f in columns] for r in records]
    widths = [max(len(row[i]) for row in rows) for i in range(len(columns))]
    return "\n".join("  ".join(text.ljust(w) for text, w in zip(row, widths, strict=True))
                     .rstrip() for row in rows)


def format_records(value, title: str = "") -> str:
    """``value`` (a record, a list of records, a mapping, or a plain value)
    as text, under ``title`` when given."""
    blocks = []
    if _is_records(value) and len({type(v) for v in value}) == 1:
        blocks.append(table(value))
    elif _is_records(value):
        blocks += [format_records(v) for v in value]
    elif _is_record(value):
        lines, nested = [], []
        for f in fields(value):
            item = getattr(value, f.name)
            if _is_record(item) or _is_records(item) or (
                    isinstance(item, dict) and item and all(map(_is_record, item.values()))):
                nested.append(format_records(item, _heading(f)))
            else:
                lines.append(f"{_heading(f)}: {cell(item)}")
        blocks += ["\n".join(lines)] if lines else []
        blocks += nested
    elif isinstance(value, dict) and value and all(map(_is_record, value.values())):
        blocks += [format_records(v, cell(k)) for k, v in value.items()]
    elif isinstance(value, list | tuple) and not value:
        blocks.append("(none)")
    else:
        blocks.append(cell(value))
    text = "\n\n".join(b for b in blocks if b)
    return f"== {title}\n{text}" if title else text


def format_claim(result) -> str:
    """A :class:`refsim.claims.result.ClaimResult`: the verdict, then each
    fact it rests on."""
    head = f"{result.claim}: {result.verdict}" + (" (rests on timings)" if result.timing else "")
    return "\n".join([head, *(f"  {key}: {cell(value)}" for key, value in result.facts.items())])
