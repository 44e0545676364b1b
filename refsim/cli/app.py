"""The entry point: the parser of every command, and :func:`main`, which
turns a user's mistake into one line and an exit status, and a signal
into a quiet end (:mod:`refsim.cli`)."""

from __future__ import annotations

import argparse
import contextlib
import gc
import os
import sys
import warnings

from refsim.cli.advise import add_advise_command, advise_command
from refsim.cli.common import (
    EXIT_BROKEN_PIPE,
    EXIT_DIVERGED,
    EXIT_USER_ERROR,
    add_max_steps,
    one_line,
)
from refsim.cli.conform import add_conform_command, conform_command
from refsim.cli.run import info_command, run_command
from refsim.cli.views import add_study_command, add_viewer_commands, report_command, study_command
from refsim.errors import DivergenceError, RefsimError
from refsim.kernels import TIERED_ENV, compile_notices
from refsim.signals import Interrupted, signals_raise


class _Parser(argparse.ArgumentParser):
    """argparse with its usage errors on the one line every refsim error has,
    ``refsim: error: ...`` (argparse prints the usage first, then
    ``refsim run: error: ...``)."""

    def error(self, message: str):
        self.exit(EXIT_USER_ERROR,
                  f"refsim: error: {one_line(message)} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="refsim",
        description="Reference implementation of a 1997 rigid-body N-body simulation, "
                    "checked against FCL, coal, trimesh, scipy, pybullet, MuJoCo and Drake.")
    parser.add_argument("--debug", action="store_true",
                        help="show the full traceback on errors")
    parser.add_argument("--version", action="version", version=f"refsim {version()}",
                        help="print refsim's version and exit")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    info = commands.add_parser(
        "info", help="print facts about model files",
        description="Print each MODEL's triangles, vertices, convexity, closedness, bounds "
                    "and centroids. A bare file name (cube.ac) that is not in the current "
                    "directory names a bundled model; --bundled lists the bundled models "
                    "and scenes.")
    info.add_argument("models", nargs="*", metavar="MODEL",
                      help=".ac (refsim's reader), .obj, .stl, .ply or .off")
    info.add_argument("--bundled", action="store_true",
                      help="list the bundled models and scenes, one name a line (each can "
                           "be named so from any directory)")
    info.set_defaults(run=info_command)

    run = commands.add_parser(
        "run", help="simulate a scene and write its frames (.npz)",
        description="Simulate SCENE for its [integration] duration and write an .npz. "
                    "Rigid bodies: t (frames,), position, velocity, angular_velocity "
                    "(frames, bodies, 3), orientation (frames, bodies, 3, 3), names, events, "
                    "stages, stage_seconds, settings (with the scene file's path and text, "
                    "for refsim replay; see refsim.Trajectory.load). "
                    "Particles: t, step (frames,), position and velocity (frames, N, 3), "
                    "the scene's settings as JSON (scene) and status.")
    run.add_argument("scene", metavar="SCENE",
                     help="a scene file (TOML) with [[body]] tables or a [particles] table")
    run.add_argument("-o", "--output", metavar="OUT.npz",
                     help="output file, named .npz (default: the scene's name with .npz, "
                          "here)")
    run.add_argument("--every", type=int, metavar="K",
                     help="store every K-th step (default: at most about 1000 frames for "
                          "bodies, 200 for particles); the last step is always stored")
    run.add_argument("--duration", type=float, metavar="SECONDS",
                     help="simulate this long instead of the scene's [integration] duration")
    add_max_steps(run)
    run.set_defaults(run=run_command)

    report = commands.add_parser(
        "report", help="write the HTML accuracy report (the quick one unless --full)",
        description="Measure and write the HTML accuracy report. By default the quick "
                    "report: fewer sizes, repeats and seconds, about a minute and a half "
                    "on two idle cores once numba has compiled. --full measures "
                    "everything (about twelve minutes with --workers 2 on two cores).")
    size = report.add_mutually_exclusive_group()
    size.add_argument("--quick", dest="full", action="store_false",
                      help="the quick report (the default)")
    size.add_argument("--full", dest="full", action="store_true",
                      help="every size, repeat and scene: the report the README quotes")
    report.set_defaults(full=False)          # the first of the two flags would set True
    report.add_argument("-o", "--output", default="reports/out", metavar="DIR",
                        help="output directory (default: reports/out)")
    report.add_argument("--workers", type=int, metavar="N",
                        help="run the report's sweeps (the conformance matrix, the replays, "
                             "the advisor) on N local processes; the results are the same "
                             "(default: in this process)")
    report.set_defaults(run=report_command)
    add_study_command(commands)
    add_viewer_commands(commands)
    add_conform_command(commands)
    add_advise_command(commands)
    return parser


def _one_line_warning(message, category, filename, lineno, file=None, line=None):
    print(f"refsim: warning: {one_line(message)}", file=sys.stderr if file is None else file)


def version() -> str:
    """refsim's version: the installed distribution's, else the package's own
    ``__version__`` (a source tree on the path without an install)."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as installed_version

    try:
        return installed_version("refsim")
    except PackageNotFoundError:
        from refsim import __version__

        return __version__


def main(argv: list[str] | None = None) -> int:
    """Run the command of ``argv`` (default: the process's arguments) and
    return its exit status. Output cut short by its reader (a pipe into
    ``head``) ends quietly with :data:`EXIT_BROKEN_PIPE`, as Python's
    documentation of SIGPIPE advises: standard output is pointed at
    ``os.devnull`` so that the interpreter's final flush cannot fail again."""
    unraisable_hook = sys.unraisablehook
    try:
        status = _main(argv)
        sys.stdout.flush()          # a broken pipe shows here, not at exit
        return status
    except BrokenPipeError:
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        except (OSError, ValueError):   # a stream with no descriptor (a test's capture)
            pass
        return EXIT_BROKEN_PIPE
    finally:
        if sys.unraisablehook is not unraisable_hook:     # _quiet_finalizers ran
            try:
                gc.collect()        # what the signal cut short is freed while quiet
            finally:
                sys.unraisablehook = unraisable_hook


#: Commands that make many calls of the tiered kernel families
#: (:class:`refsim.kernels.Tier`): on a cold numba cache they compile them
#: in a background process (:mod:`refsim.warm`) while their first calls
#: run readable.
LONG_COMMANDS = (conform_command,)


#: Commands that time refsim's kernels (the advice's wall-time saving among
#: them): they run without the tiered start
#: (``REFSIM_TIERED_START=0``, inherited by their worker processes), so
#: that on a cold cache they compile first and time the compiled kernels,
#: not readable calls made while the compile was pending.
TIMED_COMMANDS = (report_command, study_command, advise_command)


def _main(argv: list[str] | None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not args.debug:
        warnings.showwarning = _one_line_warning
    try:
        # SIGTERM and SIGHUP unwind like Ctrl-C, so temporary files are removed
        # `info` computes nothing numba compiles: it does not pay numba's import
        with signals_raise(), (contextlib.nullcontext() if args.run is info_command
                               else compile_notices(sys.stderr)):
            if args.run in TIMED_COMMANDS:
                os.environ[TIERED_ENV] = "0"
            elif args.run in LONG_COMMANDS:
                from refsim.warm import start_in_background

                start_in_background(sys.stderr)
            return args.run(args)
    except DivergenceError as exc:
        if args.debug:
            raise
        print(f"refsim: error: {one_line(exc)}", file=sys.stderr)
        return EXIT_DIVERGED
    except RefsimError as exc:
        if args.debug:
            raise
        print(f"refsim: error: {one_line(exc)}", file=sys.stderr)
        return EXIT_USER_ERROR
    except Interrupted as exc:
        _quiet_finalizers()
        print(f"refsim: interrupted ({exc.name})", file=sys.stderr)
        return exc.exit_status
    except KeyboardInterrupt:
        _quiet_finalizers()
        print("refsim: interrupted", file=sys.stderr)
        return 130


def _drop(unraisable) -> None:
    """An unraisable exception not reported (see :func:`_quiet_finalizers`)."""


def _quiet_finalizers() -> None:
    """After an interruption, errors raised in finalizers are not reported.

    A signal can arrive inside a constructor, as numba compiles for example:
    llvmlite's ``OutputString.__init__`` cut short before it sets
    ``_owned`` fails in ``__del__`` when the unwound stack frees it, and
    Python prints that as "Exception ignored in ..." with a traceback after
    the one line an interruption gets. The process is ending; nothing is
    left for such a report to explain. :func:`main` restores the hook.
    """
    sys.unraisablehook = _drop
