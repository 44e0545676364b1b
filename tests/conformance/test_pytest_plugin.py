"""The pytest plugin: one test per check on a shipped engine, failures with
their minimal example, and nothing at all without ``--refsim-engine``."""

from __future__ import annotations

# pytester's in-process runs restore sys.modules afterwards: what the inner
# runs import must be imported here first, or the next run imports numpy (or
# numba) a second time, which both refuse. numba imports part of itself only
# at its first compile (its typing registries), so one small function is
# compiled here too: otherwise a later test in the same process fails with
# numba's "duplicate registration".
import sys
from pathlib import Path

import hypothesis  # noqa: F401
import numba
import numpy  # noqa: F401

import refsim.conformance.registry  # noqa: F401
import refsim.conformance.runner  # noqa: F401
import refsim.engines.refsim_engines  # noqa: F401
import tests.conformance.broken_engines  # noqa: F401
from refsim.conformance.expected import shipped_expected_failures

numba.njit(lambda x: x + 1.0)(1.0)

SEED_ENGINE = "refsim.engines.refsim_engines:seed"


def test_plugin_runs_one_test_per_check_of_a_shipped_engine(pytester):
    pytester.makepyfile(test_own="def test_own():\n    assert True\n")
    expected = shipped_expected_failures("refsim-seed")
    result = pytester.runpytest(f"--refsim-engine={SEED_ENGINE}", "--refsim-cases=10",
                                f"--refsim-expected-failures={expected}", "-v", "-rx")
    # the user's own test, and the seed engine's 24 checks: its eleven declared
    # divergences (S9 five times, S5/S7 twice, C12, S8 three times) are xfails
    # with their reasons; the incline it cannot pose (world.mu) is skipped
    result.assert_outcomes(passed=13, xfailed=11, skipped=1)
    result.stdout.fnmatch_lines([
        "*collected 25 items",
        "refsim conformance: 24 checks of refsim-seed (refsim.engines.refsim_engines:seed): "
        "triangles.reference, triangles.agreement, *, rigid.bounce_times",
        "*refsim-conformance*triangles.agreement PASSED*",
        "*refsim-conformance*rigid.spin_to_rest XFAIL*",
        "*refsim conformance: refsim.engines.refsim_engines:seed*",
        "rigid.oblique_bounce * 5 * 0 * 5 *bug 1, known-divergence 4*xfailed",
        "XFAIL *rigid.spin_to_rest - claim C12*",
    ])


def test_a_failing_check_shows_its_minimal_example(pytester):
    result = pytester.runpytest(
        "--refsim-engine=tests.conformance.broken_engines:box_ignores_translation",
        "--refsim-cases=12")
    result.assert_outcomes(failed=2)
    result.stdout.fnmatch_lines([
        "*aabb.encloses: 12 of 12 cases failed (bug *",
        '*minimal example (shrunk): {"shrunk": true, "class": "bug"*',
    ])
    assert '"vertices": [[0.0, 0.0, 0.0]], "R": [[1.0, 0.0, 0.0]' in result.stdout.str()


def test_declared_classes_only_and_only_option(pytester):
    pytester.makefile(".txt", expected="aabb.encloses[tolerance]  only rounding\n")
    result = pytester.runpytest(
        "--refsim-engine=tests.conformance.broken_engines:box_ignores_translation",
        "--refsim-cases=12", "--refsim-expected-failures=expected.txt")
    # "bug" failures are outside the declared class: still failures
    result.assert_outcomes(failed=2)
    result.stdout.fnmatch_lines(["*declared: declared for tolerance only; also bug*"])
    ode = pytester.runpytest(f"--refsim-engine={SEED_ENGINE}", "--refsim-only=ode")
    ode.assert_outcomes(passed=3)


def test_without_the_option_nothing_changes(pytester):
    pytester.makepyfile(test_own="def test_own():\n    assert True\n")
    result = pytester.runpytest("-v")
    result.assert_outcomes(passed=1)
    assert "refsim-conformance" not in result.stdout.str()
    assert "refsim conformance" not in result.stdout.str()
    help_text = pytester.runpytest("--help").stdout.str()
    assert "--refsim-engine=MODULE:FACTORY" in help_text


def test_plain_pytest_finds_the_plugin_and_the_users_module(pytester):
    # the `pytest` script itself (not `python -m pytest`, which puts the
    # current directory on sys.path): the entry point loads the plugin, and
    # the plugin finds myengine.py beside the user
    pytester.makepyfile(myengine="""
        class Heun:
            name = "heun"
            ode_order = 2

            def ode_step(self, f, t, y, h):
                k1 = f(t, y)
                return y + h / 2 * (k1 + f(t + h, y + h * k1))


        def make_engine():
            return Heun()
    """)
    script = Path(sys.executable).parent / "pytest"
    result = pytester.run(str(script), "-p", "no:cacheprovider",
                          "--refsim-engine=myengine:make_engine", "-v")
    assert result.ret == 0, result.stdout.str() + result.stderr.str()
    result.stdout.fnmatch_lines([
        "*collected 2 items",
        "refsim conformance: 2 checks of heun (myengine:make_engine): ode.order, ode.evaluations",
        "*ode.order PASSED*",
        "*ode.evaluations PASSED*",
    ])


def test_a_bad_engine_is_a_usage_error(pytester):
    result = pytester.runpytest("--refsim-engine=nope:thing")
    assert result.ret == 4                         # pytest's usage error
    result.stderr.fnmatch_lines(
        ["*--refsim-engine nope:thing: engine 'nope:thing': cannot import*"])
