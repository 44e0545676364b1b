"""``refsim conform``: one engine through the conformance kit, or the
shipped engines side by side."""

from __future__ import annotations

import os
import sys

from refsim.cli.common import EXIT_CHECK_FAILED, one_line, output_directory


def conform_command(args) -> int:
    """``refsim conform``: one engine through the conformance kit, or the
    shipped engines side by side (``--all``). Exit 0 when every check passed
    (declared expected failures aside), 1 when one failed; user errors
    (a bad spec, a missing engine, a malformed expected-failures file) are
    RefsimErrors and exit 2 (``main``)."""
    from refsim.conformance.expected import read_expected
    from refsim.conformance.matrix import make_directory, run_matrix, write_engine_pages
    from refsim.conformance.results import summary_table
    from refsim.conformance.runner import DEFAULT_CASES, check_engine, select_capabilities
    from refsim.engines import CAPABILITIES, load_engine
    from refsim.errors import OptionError, check_count
    from refsim.oracles import OracleUnavailable

    if (args.engine is None) == (not args.all):
        raise OptionError("give one engine as MODULE:FACTORY, or --all for the shipped ones")
    if args.all and args.expected_failures:
        raise OptionError("--expected-failures is for one engine; --all uses each shipped "
                          "engine's own file (refsim/conformance/expected/)")
    cases = check_count("--cases", DEFAULT_CASES if args.cases is None else args.cases, 1)
    seed = check_count("--seed", args.seed, minimum=0)
    out = output_directory(args.output, "conform", "its JSON record and pages")
    if args.only is not None and args.only not in CAPABILITIES:
        raise OptionError(f"--only {args.only!r}: not a capability (capabilities: "
                          f"{', '.join(CAPABILITIES)})")
    if args.workers is not None and args.scheduler is not None:
        raise OptionError("give --workers (local processes) or --scheduler (a Dask "
                          "cluster), not both")
    backend = ("dask" if args.scheduler is not None
               else "processes" if args.workers is not None else None)
    workers = None if args.workers is None else check_count("--workers", args.workers, 1)

    def say(text: str) -> None:
        print(f"refsim conform: {text}", file=sys.stderr, flush=True)

    if args.all:
        make_directory(out)
        # in this process: a line as each engine's checks start and end; on
        # workers: the sweep's line
        matrix, results = run_matrix(cases=cases, seed=seed, out_dir=out, only=args.only,
                                     backend=backend, workers=workers,
                                     scheduler=args.scheduler, progress=backend is not None,
                                     announce=say if backend is None else None)
        print(matrix.table())
        for name, reason in matrix.unavailable.items():
            print(f"refsim: warning: {name} not run: {one_line(reason)}", file=sys.stderr)
        for d in matrix.divergences:
            print(f"  {d.engine:17} {d.check:22} {d.status:8} {d.reason}")
        wrote = f"wrote {out / 'index.html'}, {out / 'matrix.json'} and a page per engine"
        if matrix.unavailable:
            # a matrix with engines missing is not the check asked for
            from refsim.oracles import install_hint

            print(f"{wrote}; not run: {', '.join(sorted(matrix.unavailable))} (see the "
                  f"warnings; {install_hint(matrix.unavailable)})")
            return EXIT_CHECK_FAILED
        print(wrote)
        return 0 if matrix.ok else EXIT_CHECK_FAILED
    # MODULE is looked up in the current directory first, as `python -m`
    # does: a user's myengine.py beside them is found without PYTHONPATH
    if os.getcwd() not in sys.path:
        sys.path.insert(0, os.getcwd())
    try:
        engine = load_engine(args.engine)
    except (OracleUnavailable, ImportError) as exc:
        raise OptionError(f"engine {args.engine!r}: {exc}") from None
    # every user error is found before any work or any output
    select_capabilities(engine, args.only)
    if args.expected_failures:
        read_expected(args.expected_failures)
    make_directory(out)
    if backend is None:
        result = check_engine(engine, cases=cases, seed=seed, only=args.only,
                              expected_failures=args.expected_failures, spec=args.engine,
                              progress=say)
    else:
        from refsim.conformance.shards import check_engine_sharded

        result = check_engine_sharded(args.engine, cases=cases, seed=seed, only=args.only,
                                      expected_failures=args.expected_failures,
                                      backend=backend, workers=workers,
                                      scheduler=args.scheduler, progress=say)
    print(summary_table(result))
    json_path, page = write_engine_pages(result, out)
    expected = sum(c.status == "xfailed" for c in result.checks)
    verdict = (f"failed: {', '.join(result.failed_checks())}" if not result.ok
               else "no check failed") + (f" ({expected} expected failures)" if expected else "")
    print(f"{result.engine}: {verdict}; wrote {json_path} and {page}")
    return 0 if result.ok else EXIT_CHECK_FAILED


def add_conform_command(commands) -> None:
    """``refsim conform`` (refsim.conformance)."""
    conform = commands.add_parser(
        "conform", help="check an engine against refsim's ground truth",
        description="Run an engine (MODULE:FACTORY, a callable returning it; see "
                    "refsim.engines) through every check its capabilities call for, "
                    "against answers that depend on no float engine. Writes "
                    "DIR/conformance.json and a self-contained DIR/index.html, prints a "
                    "table. --all runs the shipped engines and writes their matrix. "
                    "Exit status 0: every check passed (declared expected failures "
                    "aside); 1: a check failed, or --all left out an engine whose package "
                    "is missing; 2: a usage error.")
    conform.add_argument("engine", nargs="?", metavar="MODULE:FACTORY",
                         help="the engine, e.g. refsim.engines.refsim_engines:corrected")
    conform.add_argument("--all", action="store_true",
                         help="the shipped engines side by side (each with its own "
                              "expected failures)")
    conform.add_argument("-o", "--output", default="conformance", metavar="DIR",
                         help="output directory (default: conformance)")
    conform.add_argument("--cases", type=int, metavar="N",
                         help="cases in each generated set: triangle pairs, mesh poses, "
                              "boxes (default 200)")
    conform.add_argument("--seed", type=int, default=0, metavar="S",
                         help="seed of the cases and of the Hypothesis searches (default 0)")
    conform.add_argument("--only", metavar="CAPABILITY",
                         help="check one capability: triangles, pairs, collide, aabb, ode "
                              "or rigid")
    conform.add_argument("--workers", type=int, metavar="N",
                         help="run on N local processes: one engine's cases in shards of "
                              "12000, or with --all the engines side by side (the results "
                              "are the same as in one process)")
    conform.add_argument("--scheduler", metavar="ADDRESS",
                         help="run on a Dask cluster, e.g. tcp://host:8786, as --workers "
                              "does (pip install 'refsim[sweep]'; the engine's module must be "
                              "importable on the workers)")
    conform.add_argument("--expected-failures", metavar="FILE",
                         help="declared divergences, one a line: "
                              "'capability.check[class,...]  reason'")
    conform.set_defaults(run=conform_command)
