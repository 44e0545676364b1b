"""The ``refsim`` command line.

    refsim info MODEL                  facts about a model file
    refsim report [--quick] [-o DIR]   write the HTML accuracy report

A user's mistake (a missing or malformed file, a bad scene) prints one line
naming the file and the line or key, and exits with status 2; ``--debug``
shows the traceback instead. Anything else is a bug in refsim and keeps its
traceback.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

from refsim.errors import RefsimError

EXIT_USER_ERROR = 2


def _info(args) -> int:
    from refsim.models.facts import describe, format_facts
    from refsim.models.loading import load_model

    for i, path in enumerate(args.models):
        if i:
            print()
        print(format_facts(describe(load_model(path), name=str(path))))
    return 0


def _report(args) -> int:
    from refsim.report.build import build_report

    out = Path(args.output)
    try:
        page = build_report(out, quick=args.quick)
    except OSError as exc:
        raise RefsimError(f"{out}: cannot write the report: {exc.strerror or exc}") from exc
    print(f"wrote {page}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="refsim",
        description="Reference implementation of a 1997 rigid-body N-body simulation, "
                    "checked against FCL, trimesh, scipy and pybullet.")
    parser.add_argument("--debug", action="store_true",
                        help="show the full traceback on errors")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    info = commands.add_parser("info", help="print facts about model files")
    info.add_argument("models", nargs="+", metavar="MODEL",
                      help=".ac (refsim's reader), .obj, .stl, .ply or .off")
    info.set_defaults(run=_info)

    report = commands.add_parser("report", help="write the HTML accuracy report")
    report.add_argument("--quick", action="store_true",
                        help="fewer sizes and repeats (under a minute)")
    report.add_argument("-o", "--output", default="reports/out", metavar="DIR",
                        help="output directory (default: reports/out)")
    report.set_defaults(run=_report)
    return parser


def _one_line_warning(message, category, filename, lineno, file=None, line=None):
    print(f"refsim: warning: {message}", file=sys.stderr if file is None else file)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not args.debug:
        warnings.showwarning = _one_line_warning
    try:
        return args.run(args)
    except RefsimError as exc:
        if args.debug:
            raise
        print(f"refsim: error: {exc}", file=sys.stderr)
        return EXIT_USER_ERROR
    except KeyboardInterrupt:
        print("refsim: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
