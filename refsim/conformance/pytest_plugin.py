"""The conformance kit as a pytest plugin: one test per check.

    pytest --refsim-engine mypackage.engines:make_engine [--refsim-cases N]
           [--refsim-seed S] [--refsim-only CAPABILITY]
           [--refsim-expected-failures FILE]

adds, to whatever else pytest collects, a test per check the engine's
capabilities call for (``-k refsim-conformance`` runs them alone), counted
in pytest's "collected N items" and named on the line after it. ``MODULE``
is looked up in the current directory and the rootdir first, as ``refsim
conform`` does, so the plain ``pytest`` script finds a ``myengine.py``
beside the user. A check
that fails shows its counts, classes and minimal example; a declared
expected failure (:mod:`refsim.conformance.expected`) is an ``xfail`` with
its reason; a check the engine does not support (``ode.stability`` without
``ode_stability``) is not collected, and one whose scenes the engine cannot
pose (:class:`refsim.errors.UnposableKey`) is skipped with the key. After
the run the summary table of ``refsim conform`` is printed.

It is registered as a ``pytest11`` entry point (pyproject.toml), so it loads
wherever refsim is installed. Without ``--refsim-engine`` it only adds its
options: nothing is collected, imported or changed (refsim's own suite runs
as before). Its import costs nothing: the kit is imported when the option
is given.

In the manner of scikit-learn's ``parametrize_with_checks`` (one test per
check, expected failures declared) and the Array API test suite (one option
names the module under test; failures show a minimal input).

Cost: that of the checks (:mod:`refsim.conformance.runner`); each case set is
built once per session and shared by the tests that need it.
"""

from __future__ import annotations

import os
import sys

import pytest

#: Where the session's results are kept for the terminal summary.
_RESULTS = pytest.StashKey[list]()
#: The line naming the checks collected.
_COLLECTED = pytest.StashKey[str]()


def pytest_addoption(parser):
    group = parser.getgroup("refsim", "refsim conformance kit")
    group.addoption("--refsim-engine", metavar="MODULE:FACTORY", default=None,
                    help="run the conformance checks on this engine (a callable returning it)")
    group.addoption("--refsim-cases", type=int, metavar="N", default=None,
                    help="cases in each generated set (default 200)")
    group.addoption("--refsim-seed", type=int, metavar="S", default=0,
                    help="seed of the cases and the Hypothesis searches (default 0)")
    group.addoption("--refsim-only", metavar="CAPABILITY", default=None,
                    help="check one capability only")
    group.addoption("--refsim-expected-failures", metavar="FILE", default=None,
                    help="declared divergences: 'capability.check[classes]  reason' a line")


class ConformanceFailure(Exception):
    """A check that failed; carries its CheckResult for the report."""

    def __init__(self, result):
        super().__init__(result.key)
        self.result = result


class CheckItem(pytest.Item):
    """One check of the engine under test."""

    def __init__(self, *, check, **kwargs):
        super().__init__(**kwargs)
        self.check = check

    def runtest(self):
        from refsim.conformance.expected import apply_expected
        from refsim.conformance.runner import run_check

        suite = self.parent
        result = apply_expected(run_check(self.check, suite.engine,
                                          suite.case_set(self.check.cases)),
                                suite.declarations)
        self.config.stash.setdefault(_RESULTS, []).append(result)
        if result.status == "failed":
            raise ConformanceFailure(result)
        if result.status == "xfailed":
            pytest.xfail(result.reason)
        if result.status == "n/a":          # e.g. a scene key the engine cannot pose
            pytest.skip(result.reason)

    def repr_failure(self, excinfo, style=None):
        if isinstance(excinfo.value, ConformanceFailure):
            from refsim.conformance.results import strict_json

            r = excinfo.value.result
            classes = ", ".join(f"{k} {v}" for k, v in r.classes.items())
            lines = [f"{r.key}: {r.failed} of {r.cases} cases failed ({classes})"]
            if r.reason:
                lines.append(f"declared: {r.reason}")
            for example in r.examples[:3]:
                label = "minimal example (shrunk)" if example.get("shrunk") else "example"
                lines.append(f"{label}: {strict_json(example, indent=None)[:2000].rstrip()}")
            return "\n".join(lines)
        return super().repr_failure(excinfo, style=style)

    def reportinfo(self):
        return self.path, None, f"refsim conformance: {self.name}"


class ConformanceSuite(pytest.Collector):
    """The engine, its declarations and the case sets, shared by its checks."""

    def __init__(self, *, spec, options, **kwargs) -> None:
        super().__init__(**kwargs)
        self.spec = spec
        self.options = options
        self._sets: dict = {}
        self.engine = None
        self.declarations: dict = {}

    def load(self):
        from refsim.conformance.expected import read_expected
        from refsim.engines import load_engine
        from refsim.errors import RefsimError
        from refsim.oracles import OracleUnavailable

        # MODULE is looked up in the current directory and the rootdir first,
        # as `refsim conform` and `python -m pytest` do: under the plain
        # `pytest` script neither is on sys.path
        for folder in (str(self.config.rootpath), os.getcwd()):
            if folder not in sys.path:
                sys.path.insert(0, folder)
        try:
            self.engine = load_engine(self.spec)
            file = self.options["expected"]
            self.declarations = read_expected(file) if file else {}
        except (RefsimError, OracleUnavailable, ImportError) as exc:
            raise pytest.UsageError(f"--refsim-engine {self.spec}: {exc}") from None

    def case_set(self, name: str):
        from refsim.conformance.registry import build_cases
        from refsim.conformance.runner import DEFAULT_CASES

        if name not in self._sets:
            cases = self.options["cases"] or DEFAULT_CASES
            self._sets.update(build_cases([name], cases, self.options["seed"]))
        return self._sets[name]

    def collect(self):
        from refsim.conformance.registry import checks_for
        from refsim.conformance.runner import select_capabilities
        from refsim.errors import RefsimError

        self.load()
        try:
            chosen = select_capabilities(self.engine, self.options["only"])
        except RefsimError as exc:
            raise pytest.UsageError(f"--refsim-engine {self.spec}: {exc}") from None
        for check in checks_for(chosen):
            if check.requires and not callable(getattr(self.engine, check.requires, None)):
                continue
            yield CheckItem.from_parent(self, name=check.key, check=check)


def pytest_collection_modifyitems(session, config, items):
    spec = config.getoption("refsim_engine")
    if not spec:
        return
    options = {"cases": config.getoption("refsim_cases"),
               "seed": config.getoption("refsim_seed"),
               "only": config.getoption("refsim_only"),
               "expected": config.getoption("refsim_expected_failures")}
    suite = ConformanceSuite.from_parent(session, name=f"refsim-conformance[{spec}]",
                                         spec=spec, options=options)
    checks = list(suite.collect())
    items.extend(checks)
    # counted in pytest's "collected N items" line, and named
    config.hook.pytest_collectreport(report=pytest.CollectReport(
        suite.nodeid, "passed", None, checks))
    config.stash[_COLLECTED] = (f"refsim conformance: {len(checks)} checks of "
                                f"{suite.engine.name} ({spec}): "
                                f"{', '.join(c.check.key for c in checks)}")


@pytest.hookimpl(trylast=True)
def pytest_collection_finish(session):
    """The checks collected, named after pytest's "collected N items"."""
    line = session.config.stash.get(_COLLECTED, None)
    reporter = session.config.pluginmanager.get_plugin("terminalreporter")
    if line is not None and reporter is not None:
        reporter.write_line(line)


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    results = config.stash.get(_RESULTS, None)
    if not results:
        return
    from refsim.conformance.results import ConformanceResult, summary_table

    engine = config.getoption("refsim_engine")
    table = ConformanceResult(engine=engine, refsim="", seed=0, cases=0, capabilities=(),
                              checks=tuple(results))
    terminalreporter.section(f"refsim conformance: {engine}")
    terminalreporter.write_line(summary_table(table))
