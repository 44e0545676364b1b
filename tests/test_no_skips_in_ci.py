"""The suite-wide hook (conftest.py): with REFSIM_NO_SKIPS=1, as in CI, a
skip in any form fails; without it, a skip stays a skip."""

from __future__ import annotations

from pathlib import Path

ROOT_CONFTEST = Path(__file__).resolve().parents[1] / "conftest.py"

SKIPPING = {
    "test_in_body": "import pytest\ndef test_it():\n    pytest.skip('engine missing')\n",
    "test_marked": ("import pytest\n@pytest.mark.skipif(True, reason='no engine')\n"
                    "def test_it():\n    pass\n"),
    "test_at_import": ("import pytest\npytest.importorskip('no_such_module_for_refsim')\n"
                       "def test_it():\n    pass\n"),
}


def _run(pytester, monkeypatch, strict: bool):
    pytester.makeconftest(ROOT_CONFTEST.read_text())
    pytester.makepyfile(**SKIPPING)
    monkeypatch.delenv("CI", raising=False)
    if strict:
        monkeypatch.setenv("REFSIM_NO_SKIPS", "1")
    else:
        monkeypatch.delenv("REFSIM_NO_SKIPS", raising=False)
    return pytester.runpytest_inprocess("-p", "no:cacheprovider", "--continue-on-collection-errors")


def test_skips_fail_where_every_check_must_run(pytester, monkeypatch):
    result = _run(pytester, monkeypatch, strict=True)
    # the body skip fails; the skipif (setup) and importorskip (collection) error
    result.assert_outcomes(failed=1, errors=2)
    result.stdout.fnmatch_lines(["*every check must run*engine missing*"])


def test_skips_stay_skips_locally(pytester, monkeypatch):
    result = _run(pytester, monkeypatch, strict=False)
    result.assert_outcomes(skipped=3)
