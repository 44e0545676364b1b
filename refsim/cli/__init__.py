"""The ``refsim`` command line.

    refsim info MODEL                  facts about a model file
    refsim info --bundled              the bundled models and scenes, by name
    refsim run SCENE [-o OUT.npz] [--every K]
                                       simulate a scene (bodies or particles), write frames
    refsim report [--quick | --full] [-o DIR] [--workers N]
                                       write the HTML accuracy report
    refsim study NAME [--quick] [--seed S]
                                       run one of the report's studies, print its
                                       records and the verdicts they back
    refsim view SCENE [--port N]       the scene in the browser, re-run from its controls
    refsim replay RUN.npz ... -o OUT.html
                                       recorded runs as one standalone replay page
    refsim advise SCENE [--tolerance TOL] [-o DIR] [--json]
                                       the cheapest fidelity settings within TOL

A user's mistake (a missing or malformed file, a bad scene) prints one line
naming the file and the line or key, and exits with status 2; ``--debug``
shows the traceback instead. A run that diverges prints one line naming the
step and time, writes the frames computed before it, and exits with status 3.
Anything else is a bug in refsim and keeps its traceback. Output files are
written whole or not at all (a temporary file, then ``os.replace``). Output
cut short by its reader (``refsim info X | head -1``) ends quietly with
status 1. ``refsim --version`` prints the installed version.
"""

from __future__ import annotations

from refsim.cli.app import build_parser, main, version
from refsim.cli.common import (
    EXIT_BROKEN_PIPE,
    EXIT_CHECK_FAILED,
    EXIT_DIVERGED,
    EXIT_USER_ERROR,
    one_line,
)

__all__ = ["EXIT_BROKEN_PIPE", "EXIT_CHECK_FAILED", "EXIT_DIVERGED", "EXIT_USER_ERROR",
           "build_parser", "main", "one_line", "version"]
