"""One engine's checks spread over local processes or a Dask cluster.

An engine author with millions of cases wants them on every core, or on a
cluster. :func:`check_engine_sharded` cuts each generated case set the
engine's checks need into shards of whole blocks (a block is
:data:`refsim.conformance.draw.BLOCK` cases drawn from one random stream,
so a shard builds its own cases, the same ones a single run builds) and
runs each shard as a sweep task (:mod:`refsim.sweep`): build the cases, run
every check of that set that judges cases one by one
(:data:`refsim.conformance.checks_geometry.CASE_CHECKS`) and return the
failure records. The fixed sets' checks (ODE problems, rigid scenes) run as
one more task. This process then puts each check together from its
shards' failures (:meth:`~refsim.conformance.checks_geometry.CaseCheck.result`,
the step a single run ends with too), shrinks a failing check with
Hypothesis and applies the expected failures: ``conformance.json`` and
``failures.jsonl`` are the ones a run in one process writes, timings
aside.

The engine is named by its ``module:factory``: each worker loads it itself
(on a Dask cluster the module must be importable on the workers).

Cost: the single run's, divided among the workers, plus one engine load
per task and the failure records sent back.
"""

from __future__ import annotations

import time

from refsim.conformance import draw
from refsim.conformance.checks_geometry import CASE_CHECKS


def shard_ranges(n: int) -> list[tuple[int, int]]:
    """``range(n)`` cut at every block boundary: ``[(start, stop), ...]``."""
    return [(start, min(n, start + draw.BLOCK)) for start in range(0, n, draw.BLOCK)]


def shard_task(*, seed: int, spec: str, set_name: str, cases: int, case_seed: int,
               start: int, stop: int, checks: list) -> dict:
    """A sweep task: the failure records of ``checks`` (keys) on cases
    ``start`` to ``stop - 1`` of set ``set_name`` (the sweep's ``seed`` is
    not used: ``case_seed`` draws the cases)."""
    from refsim.conformance.checks_geometry import _items
    from refsim.conformance.registry import generated_range
    from refsim.engines import load_engine

    engine = load_engine(spec)
    items = _items(generated_range(set_name, cases, case_seed, start, stop))
    out = {}
    for key in checks:
        began = time.perf_counter()
        failures = CASE_CHECKS[key].failures(engine, items, first=start)
        out[key] = {"failures": failures, "seconds": time.perf_counter() - began}
    return {"count": len(items), "checks": out}


def fixed_task(*, seed: int, spec: str, case_seed: int, checks: list) -> dict:
    """A sweep task: the results of ``checks`` (keys), whose case sets are
    fixed (the ODE problems, the rigid scenes), as plain records."""
    from refsim.conformance.registry import GENERATED_SETS, build_cases, check_by_key
    from refsim.conformance.runner import run_check
    from refsim.engines import load_engine

    chosen = [check_by_key(key) for key in checks]
    generated = [c.key for c in chosen if c.cases in GENERATED_SETS]
    if generated:      # their cases would be built at n = 1 below
        raise ValueError(f"fixed_task runs checks of the fixed sets only, not {generated}")
    engine = load_engine(spec)
    sets = build_cases({c.cases for c in chosen}, 1, case_seed)   # n sizes generated sets only
    return {"results": [run_check(c, engine, sets[c.cases]).to_dict(failures=True)
                        for c in chosen]}


def check_engine_sharded(spec: str, *, cases: int, seed: int = 0, only=None,
                         expected_failures=None, backend: str = "processes",
                         workers: int | None = None, scheduler: str | None = None,
                         progress=None):
    """:func:`refsim.conformance.runner.check_engine` of the engine ``spec``
    (``module:factory``) with its cases run as sweep tasks on ``backend``
    ("processes", "dask" or "inprocess"; ``workers`` and ``scheduler`` as
    :func:`refsim.sweep.run_sweep` takes them). ``progress``, a callable
    given a line of text as each stage starts and ends, also turns on the
    sweep's progress lines. Returns the same
    :class:`~refsim.conformance.results.ConformanceResult`, timings aside
    (module docstring)."""
    from refsim import __version__
    from refsim.conformance.expected import apply_expected
    from refsim.conformance.registry import checks_for, generated_range
    from refsim.conformance.results import CheckResult, ConformanceResult
    from refsim.conformance.runner import read_declarations, select_capabilities
    from refsim.engines import engine_name, load_engine
    from refsim.errors import SweepError, check_count
    from refsim.sweep import Task, run_sweep

    cases = check_count("cases", cases, minimum=1)
    seed = check_count("seed", seed, minimum=0)
    engine = load_engine(spec)
    chosen = select_capabilities(engine, only)
    declarations, source = read_declarations(expected_failures)
    checks = checks_for(chosen)
    split = [c for c in checks if c.key in CASE_CHECKS]
    fixed = [c.key for c in checks if c.key not in CASE_CHECKS]
    sets = list(dict.fromkeys(c.cases for c in split))
    tasks = [Task(f"{name}-{start}", shard_task,
                  {"spec": spec, "set_name": name, "cases": cases, "case_seed": seed,
                   "start": start, "stop": stop,
                   "checks": [c.key for c in split if c.cases == name]})
             for name in sets for start, stop in shard_ranges(cases)]
    if fixed:
        tasks.append(Task("fixed", fixed_task, {"spec": spec, "case_seed": seed,
                                                "checks": fixed}))
    say = progress or (lambda text: None)
    say(f"{len(tasks)} tasks: {len(tasks) - bool(fixed)} shards of at most {draw.BLOCK} cases"
        + (", and the fixed sets' checks" if fixed else ""))
    began = time.perf_counter()
    sweep = run_sweep(tasks, backend=backend, workers=workers, scheduler=scheduler,
                      progress=progress is not None, seed=seed)
    if sweep.failures:
        raise SweepError("conformance run failed: " + "; ".join(
            f"{key}: {why}" for key, why in sweep.failures.items()))
    gathered: dict[str, dict] = {}
    for task, value in zip(tasks, sweep.values, strict=True):
        if task.key == "fixed":
            for record in value["results"]:
                result = CheckResult.from_dict(record)
                gathered[result.key] = {"result": result}
            continue
        for key, part in value["checks"].items():
            entry = gathered.setdefault(key, {"failures": [], "count": 0, "seconds": 0.0})
            entry["failures"].extend(part["failures"])      # tasks are in case order
            entry["count"] += value["count"]
            entry["seconds"] += part["seconds"]
    results = []
    for check in checks:
        entry = gathered[check.key]
        if "result" in entry:
            result = entry["result"]
        else:
            say(f"{check.key}: {len(entry['failures'])} failures gathered"
                + (", shrinking one" if entry["failures"] else ""))
            empty = generated_range(check.cases, cases, seed, 0, 0)
            result = CASE_CHECKS[check.key].result(engine, empty, entry["failures"],
                                                   entry["count"], entry["seconds"])
        results.append(apply_expected(result, declarations))
    return ConformanceResult(engine=engine_name(engine), refsim=__version__, seed=seed,
                             cases=cases, capabilities=chosen, checks=tuple(results),
                             spec=spec, expected_failures=source,
                             seconds=time.perf_counter() - began)
