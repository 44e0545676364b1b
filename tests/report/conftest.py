"""One quick report, built once per test session and shared by the report tests."""

from __future__ import annotations

import io
import json

import pytest

from refsim.report.build import build_report


@pytest.fixture(scope="session")
def quick_report(tmp_path_factory):
    """``(out_dir, html, results)`` of ``refsim report --quick``."""
    out = tmp_path_factory.mktemp("report")
    page = build_report(out, quick=True, stream=io.StringIO())
    return out, page.read_text(), json.loads((out / "results.json").read_text())
