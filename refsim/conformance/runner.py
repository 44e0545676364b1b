"""Run an engine through every check its capabilities call for.

:func:`check_engine` is the one entry point behind the command line
(``refsim conform``), the pytest plugin and notebooks: it finds the engine's
capabilities (:func:`refsim.engines.capabilities`), builds the case sets
those checks need (or takes them ready-made, so that several engines share
one set of exact answers), runs each check, and applies the declared
expected failures (:mod:`refsim.conformance.expected`).

An exception raised while a case is run (the engine crashed, or returned
something of the wrong type or shape) is that case's failure, class
"crash", with the case's input and the traceback's last line; the other
cases run on. An exception outside any one case (reading an attribute the
check needs, say ``ode_order``) is the whole check's one "crash": one
broken capability does not hide the others.

Cost: the sum of the checks' costs plus the case sets' (see each module).
"""

from __future__ import annotations

import time

from refsim.conformance.expected import apply_expected, read_expected
from refsim.conformance.registry import CHECKS, build_cases, checks_for
from refsim.conformance.results import CheckResult, ConformanceResult, Crash, attempt
from refsim.errors import OptionError, check_count

#: Cases in each generated set unless told otherwise: enough to meet the
#: touching and near-degenerate failures of a float engine (a few per cent
#: of the near-degenerate families), small enough to run in seconds.
DEFAULT_CASES = 200


def select_capabilities(engine, only=None) -> tuple[str, ...]:
    """The engine's capabilities, or those of ``only`` (a name or a list of
    names) after checking the engine has them."""
    from refsim.engines import CAPABILITIES, capabilities, declarations, engine_name

    declarations(engine)                       # a bad declaration: one line, before any case
    has = capabilities(engine)
    if not has:
        raise OptionError(f"engine {engine_name(engine)!r} provides none of the "
                          f"capabilities {', '.join(CAPABILITIES)}")
    if only is None:
        return has
    wanted = (only,) if isinstance(only, str) else tuple(only)
    for capability in wanted:
        if capability not in CAPABILITIES:
            raise OptionError(f"unknown capability {capability!r} (capabilities: "
                              f"{', '.join(CAPABILITIES)})")
        if capability not in has:
            raise OptionError(f"engine {engine_name(engine)!r} has no {capability!r} "
                              f"capability (it has: {', '.join(has)})")
    return tuple(c for c in has if c in wanted)


def needed_case_sets(capabilities) -> tuple[str, ...]:
    return tuple(dict.fromkeys(c.cases for c in checks_for(capabilities)))


def _crashed(check, crash: Crash, seconds: float) -> CheckResult:
    example = crash.example(case="none: the check itself")
    return CheckResult(capability=check.capability, check=check.name, cases=1, passed=0,
                       failed=1, classes={"crash": 1}, status="failed", seconds=seconds,
                       examples=[example], failures=[example])


def run_check(check, engine, case_set) -> CheckResult:
    """One check; an exception outside its cases becomes its failure (module
    docstring)."""
    start = time.perf_counter()
    result = attempt(check.run, engine, case_set)
    if isinstance(result, Crash):
        return _crashed(check, result, time.perf_counter() - start)
    return result


def read_declarations(expected_failures) -> tuple[dict, str]:
    """The declarations of ``expected_failures`` (a file, a dict already
    parsed, or None) and where they came from, for the record."""
    if isinstance(expected_failures, dict):
        return expected_failures, "<declarations>"
    if expected_failures is not None:
        return read_expected(expected_failures), str(expected_failures)
    return {}, ""


def check_engine(engine, *, cases: int = DEFAULT_CASES, seed: int = 0, only=None,
                 expected_failures=None, case_sets: dict | None = None,
                 spec: str = "", progress=None) -> ConformanceResult:
    """Every applicable check of ``engine`` (module docstring).

    Parameters
    ----------
    engine
        Any object with a ``name`` and capabilities of :mod:`refsim.engines`.
    cases : int
        Cases in each generated set (triangle pairs, mesh poses, boxes).
    seed : int
        Seed of the generated sets and of the Hypothesis searches.
    only : str or list of str, optional
        Check these capabilities only.
    expected_failures : path or dict, optional
        A file of declarations (:mod:`refsim.conformance.expected`), or the
        declarations already parsed.
    case_sets : dict, optional
        Ready-made case sets (:func:`refsim.conformance.registry.build_cases`,
        built with the same ``cases`` and ``seed``), to share between engines.
    spec : str
        The ``module:factory`` the engine came from, for the record.
    progress : callable, optional
        Called with a line of text as each case set and each check starts
        and ends (the command line prints them on stderr).

    Returns
    -------
    ConformanceResult
    """
    from refsim import __version__
    from refsim.engines import engine_name

    name = engine_name(engine)
    cases = check_count("cases", cases, minimum=1)
    seed = check_count("seed", seed, minimum=0)
    chosen = select_capabilities(engine, only)
    declarations, source = read_declarations(expected_failures)
    start = time.perf_counter()
    sets = dict(case_sets or {})
    case_seconds = {}
    say = progress or (lambda text: None)
    for set_name in needed_case_sets(chosen):
        if set_name not in sets:
            say(f"case set {set_name}: building (or reading from the cache)")
            before = time.perf_counter()
            sets.update(build_cases([set_name], cases, seed))
            case_seconds[set_name] = time.perf_counter() - before
            say(f"case set {set_name}: {len(sets[set_name])} cases, "
                f"{case_seconds[set_name]:.1f} s")
    results = []
    for check in checks_for(chosen):
        say(f"{check.key}: running")
        result = apply_expected(run_check(check, engine, sets[check.cases]), declarations)
        say(f"{check.key}: {result.status}, {result.seconds:.1f} s")
        results.append(result)
    return ConformanceResult(engine=name, refsim=__version__, seed=seed, cases=cases,
                             capabilities=chosen, checks=tuple(results), spec=spec,
                             expected_failures=source,
                             seconds=time.perf_counter() - start,
                             case_seconds=case_seconds)


def check_keys() -> tuple[str, ...]:
    return tuple(c.key for c in CHECKS)
