"""The command line says when numba compiles (refsim.kernels.compile_notices)."""

from __future__ import annotations

import io
import os
import subprocess
import sys

import numba

from refsim.kernels import compile_notices


def test_a_compile_is_announced_before_and_counted_after(monkeypatch):
    monkeypatch.setenv("REFSIM_COMPILE_NOTICE", "1")

    @numba.njit(cache=False)
    def twice(x):
        return 2 * x

    stream = io.StringIO()
    with compile_notices(stream):
        assert twice(3) == 6
        assert twice(4) == 8                   # compiled once
    lines = stream.getvalue().splitlines()
    assert lines[0].startswith("refsim: compiling kernels for this machine")
    assert lines[1].startswith("refsim: compiled 1 kernel in ") and len(lines) == 2


def test_nothing_is_said_when_nothing_compiles_or_when_asked(monkeypatch):
    @numba.njit(cache=False)
    def thrice(x):
        return 3 * x

    thrice(1)                                   # compiled before the body
    stream = io.StringIO()
    monkeypatch.setenv("REFSIM_COMPILE_NOTICE", "1")
    with compile_notices(stream):
        assert thrice(2) == 6
    monkeypatch.setenv("REFSIM_COMPILE_NOTICE", "0")

    @numba.njit(cache=False)
    def four_times(x):
        return 4 * x

    with compile_notices(stream):
        assert four_times(2) == 8
    assert stream.getvalue() == ""


def test_refsim_info_on_an_empty_numba_cache_says_nothing(tmp_path):
    """A command that compiles nothing prints no notice, cache empty or not,
    and does not import numba."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), REFSIM_COMPILE_NOTICE="1")
    result = subprocess.run([sys.executable, "-c",
                             "import sys; from refsim.cli import main; "
                             "status = main(['info', 'cube.ac']); "
                             "print('numba' in sys.modules, file=sys.stderr); sys.exit(status)"],
                            capture_output=True, text=True, env=env, timeout=120)
    assert result.returncode == 0
    assert result.stderr == "False\n"
