"""Engines side by side: the data of one table (engines as columns, checks as
rows) and the divergences as records the report can list.

:func:`conformance_matrix` arranges results that exist; :func:`run_matrix`
produces them: it builds each case set once (the exact answers are shared by
every engine), runs each engine through its checks with its declared
expected failures, and writes each engine's pages (``DIR/<engine>/
conformance.json`` and ``index.html``), the matrix (``DIR/matrix.json``) and
its page (``DIR/index.html``). ``refsim conform --all -o DIR`` calls it for
the shipped engines (:data:`refsim.conformance.shipped.SHIPPED_ENGINES`).

A :class:`Divergence` is one engine's failing or expected-failing check:
its classes, its declared reason (or none, for a failure nobody declared)
and its first example. The report lists them; it computes nothing.

Cost: the sum of the engines' runs, with each case set built once.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass, field
from pathlib import Path


@dataclass(frozen=True)
class Cell:
    """One check of one engine: status and counts."""

    status: str
    cases: int
    passed: int
    failed: int
    classes: dict
    #: What the check measured per case or scene (CheckResult.measured).
    measured: dict = field(default_factory=dict)
    #: Why the check did not apply (``n/a``: e.g. a scene key the engine
    #: cannot pose), or the declaration's reason (CheckResult.reason).
    reason: str = ""


@dataclass(frozen=True)
class Divergence:
    """A failing (``failed``) or declared (``xfailed``) check of one engine."""

    engine: str
    check: str
    status: str
    classes: dict
    reason: str
    example: dict | None


@dataclass(frozen=True)
class Matrix:
    """The table: ``engines`` (columns), ``checks`` (rows, in the registry's
    order), ``cells[(check, engine)]``, each engine's page (relative path),
    the divergences, and the engines that could not be loaded (name ->
    reason)."""

    engines: tuple
    checks: tuple
    cells: dict
    pages: dict
    divergences: tuple
    refsim: str
    seed: int
    cases: int
    unavailable: dict = field(default_factory=dict)
    seconds: dict = field(default_factory=dict)

    def cell(self, check: str, engine: str) -> Cell | None:
        return self.cells.get((check, engine))

    @property
    def ok(self) -> bool:
        """No check of any engine failed (expected failures aside)."""
        return not any(c.status == "failed" for c in self.cells.values())

    def status_counts(self, engine: str) -> dict:
        """How many of ``engine``'s checks ended in each status
        (:data:`refsim.conformance.results.STATUSES`, those that occur, in that order)."""
        from refsim.conformance.results import STATUSES

        found = [c.status for (_, e), c in self.cells.items() if e == engine]
        return {status: found.count(status) for status in STATUSES if status in found}

    def to_dict(self) -> dict:
        return {"refsim": self.refsim, "seed": self.seed, "cases": self.cases,
                "engines": list(self.engines), "checks": list(self.checks),
                "cells": {check: {engine: asdict(self.cells[(check, engine)])
                                  for engine in self.engines if (check, engine) in self.cells}
                          for check in self.checks},
                "pages": dict(self.pages), "unavailable": dict(self.unavailable),
                "divergences": [asdict(d) for d in self.divergences],
                "seconds": dict(self.seconds)}

    def to_json(self) -> str:
        from refsim.conformance.results import strict_json

        return strict_json(self.to_dict())

    def table(self) -> str:
        """Plain text: a row per check, a column per engine, each cell
        ``status passed/cases`` (blank where the engine lacks the capability)."""
        rows = [("check", *self.engines)]
        for check in self.checks:
            row = [check]
            for engine in self.engines:
                c = self.cell(check, engine)
                row.append("" if c is None else ("n/a" if c.status == "n/a"
                                                 else f"{c.status} {c.passed}/{c.cases}"))
            rows.append(tuple(row))
        widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
        lines = ["  ".join(cell.ljust(w) for cell, w in zip(r, widths, strict=True)).rstrip()
                 for r in rows]
        lines.insert(1, "  ".join("-" * w for w in widths))
        return "\n".join(lines)


def conformance_matrix(results, pages: dict | None = None, unavailable: dict | None = None,
                       seconds: dict | None = None) -> Matrix:
    """The matrix of ``results`` (ConformanceResults, or a dict name ->
    result), with each engine's page path from ``pages``."""
    from refsim.conformance.registry import CHECK_KEYS

    results = list(results.values()) if isinstance(results, dict) else list(results)
    if not results:
        raise ValueError("a matrix needs at least one engine's results")
    cells, divergences = {}, []
    for result in results:
        for c in result.checks:
            cells[(c.key, result.engine)] = Cell(c.status, c.cases, c.passed, c.failed,
                                                 dict(c.classes), dict(c.measured), c.reason)
            if c.status in ("failed", "xfailed"):
                divergences.append(Divergence(
                    engine=result.engine, check=c.key, status=c.status, classes=dict(c.classes),
                    reason=c.reason or "not declared",
                    example=c.examples[0] if c.examples else None))
    present = {key for key, _ in cells}
    first = results[0]
    return Matrix(engines=tuple(r.engine for r in results),
                  checks=tuple(k for k in CHECK_KEYS if k in present), cells=cells,
                  pages=dict(pages or {}), divergences=tuple(divergences),
                  refsim=first.refsim, seed=first.seed, cases=first.cases,
                  unavailable=dict(unavailable or {}), seconds=dict(seconds or {}))


def write_engine_pages(result, out_dir) -> tuple[Path, Path]:
    """``out_dir/conformance.json``, ``out_dir/failures.jsonl`` (every
    failing case, one a line: :meth:`ConformanceResult.failure_lines`) and
    ``out_dir/index.html`` of one engine's result, each written whole or not
    at all (:mod:`refsim.storage.writing`); ``out_dir`` is created if missing. Returns
    the JSON record's path and the page's."""
    from refsim.conformance.page import engine_page
    from refsim.storage.writing import write_atomic, write_text_atomic

    out_dir = make_directory(out_dir)
    write_atomic(out_dir / "failures.jsonl",
                 lambda handle: handle.writelines(result.failure_lines()))
    return (write_text_atomic(out_dir / "conformance.json", result.to_json()),
            write_text_atomic(out_dir / "index.html", engine_page(result)))


def make_directory(path) -> Path:
    """``path`` as a directory, created with its parents if missing;
    :class:`~refsim.errors.OutputError` naming it when that fails (a file in
    the way, no permission)."""
    from refsim.storage.writing import output_error

    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise output_error(path, exc.strerror or str(exc)) from None
    return path


def load_shipped(name: str, spec: str):
    """The engine of ``spec``, or the one-line reason it cannot be loaded
    (a missing package: :class:`refsim.oracles.OracleUnavailable`, or a
    spec that does not resolve)."""
    from refsim.engines import load_engine
    from refsim.errors import RefsimError
    from refsim.oracles import OracleUnavailable

    try:
        return load_engine(spec), None
    except (OracleUnavailable, RefsimError, ImportError) as exc:
        return None, f"{name}: {exc}"


#: ``engine_task``'s ``expected`` that means "the engine's own bundled file".
SHIPPED_EXPECTED = "shipped"


def engine_task(*, seed: int, name: str, spec: str, cases: int, case_seed: int,
                only: str | None = None, expected: str | None = SHIPPED_EXPECTED) -> dict:
    """One engine of the matrix as a sweep task (:mod:`refsim.sweep`): load
    ``spec``, build the case sets it needs (seeded by ``case_seed``, so that
    every engine meets the same cases; the sweep's ``seed`` is not used) and
    run its checks.

    ``expected``: a declarations file, None for none, or
    :data:`SHIPPED_EXPECTED` for the engine's bundled file. Returns plain
    data: ``{"result": ConformanceResult.to_dict()}``, ``{"unavailable":
    reason}`` when the engine cannot be loaded, or ``{"absent": capability}``
    when it lacks ``only``.
    """
    from refsim.conformance.expected import shipped_expected_failures
    from refsim.conformance.runner import check_engine
    from refsim.engines import capabilities

    engine, reason = load_shipped(name, spec)
    if engine is None:
        return {"unavailable": reason}
    if only is not None and only not in capabilities(engine):
        return {"absent": only}
    file = shipped_expected_failures(engine.name) if expected == SHIPPED_EXPECTED else expected
    result = check_engine(engine, cases=cases, seed=case_seed, only=only,
                          expected_failures=file, spec=spec)
    return {"result": result.to_dict(failures=True)}


def run_matrix(specs: dict | None = None, *, cases: int, seed: int = 0, out_dir=None,
               only=None, expected: dict | None = None, backend: str | None = None,
               workers: int | None = None, scheduler: str | None = None,
               progress: bool = False, cancel=None,
               announce=None) -> tuple[Matrix, dict]:
    """Run every engine of ``specs`` (name -> ``module:factory``; default the
    shipped engines) with shared case sets, and write the pages under ``out_dir``
    when given (module docstring).

    ``expected`` maps a name to its expected-failures file (None for none);
    by default each shipped engine's bundled file. ``only`` limits the run to
    one capability; an engine without it is left out of the matrix. An
    engine that cannot be loaded is left out and named in
    ``Matrix.unavailable``.

    ``backend`` (with ``workers``, ``scheduler``, ``progress`` and
    ``cancel``, as :func:`refsim.sweep.run_sweep` takes them): run each engine as a sweep
    task (:func:`engine_task`), in this process ("inprocess"), on local
    processes or on a Dask cluster. Each task builds its own case sets from
    the same seed, so the cells are those of the shared run, on every
    backend; only the timings differ.

    Returns the matrix and the results by engine name.
    """
    from refsim.conformance.shipped import SHIPPED_ENGINES

    specs = dict(SHIPPED_ENGINES if specs is None else specs)
    if backend is not None:
        return _run_matrix_sweep(specs, cases=cases, seed=seed, out_dir=out_dir, only=only,
                                 expected=expected, backend=backend, workers=workers,
                                 scheduler=scheduler, progress=progress, cancel=cancel)
    from refsim.conformance.expected import shipped_expected_failures
    from refsim.conformance.registry import build_cases
    from refsim.conformance.runner import check_engine, needed_case_sets
    from refsim.engines import capabilities

    engines, unavailable = {}, {}
    for name, spec in specs.items():
        engine, reason = load_shipped(name, spec)
        if engine is None:
            unavailable[name] = reason
        elif only is None or only in capabilities(engine):
            engines[name] = engine
    if not engines:
        from refsim.errors import OptionError

        raise OptionError("no engine to run: " + ("; ".join(unavailable.values())
                                                  or f"none has the capability {only!r}"))
    needed: set[str] = set()
    for engine in engines.values():
        caps = capabilities(engine) if only is None else (only,)
        needed.update(needed_case_sets(caps))
    say = announce or (lambda text: None)
    start = time.perf_counter()
    say(f"case sets: building {', '.join(sorted(needed))}")
    shared = build_cases(needed, cases, seed)
    seconds = {"cases": time.perf_counter() - start}
    results, pages = {}, {}
    for name, engine in engines.items():
        file = expected.get(name) if expected is not None else \
            shipped_expected_failures(engine.name)
        result = check_engine(engine, cases=cases, seed=seed, only=only,
                              expected_failures=file, case_sets=shared, spec=specs[name],
                              progress=lambda text, name=name: say(f"{name}: {text}"))
        results[name] = result
        seconds[name] = result.seconds
        if out_dir is not None:
            write_engine_pages(result, Path(out_dir) / name)
            pages[result.engine] = f"{name}/index.html"
    return _finish(results, pages, unavailable, seconds, out_dir), results


def _finish(results: dict, pages: dict, unavailable: dict, seconds: dict, out_dir) -> Matrix:
    """The matrix of ``results``, with its page and JSON written under ``out_dir``."""
    matrix = conformance_matrix(results, pages, unavailable, seconds)
    if out_dir is not None:
        from refsim.conformance.page import matrix_page
        from refsim.storage.writing import write_text_atomic

        make_directory(out_dir)
        write_text_atomic(Path(out_dir) / "matrix.json", matrix.to_json())
        write_text_atomic(Path(out_dir) / "index.html", matrix_page(matrix))
    return matrix


def _run_matrix_sweep(specs: dict, *, cases: int, seed: int, out_dir, only, expected,
                      backend: str, workers, scheduler, progress: bool,
                      cancel=None) -> tuple[Matrix, dict]:
    """:func:`run_matrix` with one sweep task per engine (its ``backend``)."""
    from refsim.conformance.results import ConformanceResult
    from refsim.errors import OptionError, SweepError
    from refsim.sweep import Task, run_sweep

    tasks = [Task(f"conform-{name}", engine_task,
                  {"name": name, "spec": spec, "cases": cases, "case_seed": seed, "only": only,
                   "expected": (SHIPPED_EXPECTED if expected is None
                                else None if expected.get(name) is None
                                else str(expected[name]))})
             for name, spec in specs.items()]
    sweep = run_sweep(tasks, backend=backend, workers=workers, scheduler=scheduler,
                      progress=progress, seed=seed, cancel=cancel)
    if sweep.failures:
        raise SweepError("conformance run failed: " + "; ".join(
            f"{key}: {why}" for key, why in sweep.failures.items()))
    results, pages, unavailable, seconds = {}, {}, {}, {}
    for name, answer in zip(specs, sweep.values, strict=True):
        if "unavailable" in answer:
            unavailable[name] = answer["unavailable"]
        elif "result" in answer:
            result = ConformanceResult.from_dict(answer["result"])
            results[name] = result
            seconds[name] = result.seconds
            if out_dir is not None:
                write_engine_pages(result, Path(out_dir) / name)
                pages[result.engine] = f"{name}/index.html"
    if not results:
        raise OptionError("no engine to run: " + ("; ".join(unavailable.values())
                                                  or f"none has the capability {only!r}"))
    return _finish(results, pages, unavailable, seconds, out_dir), results
