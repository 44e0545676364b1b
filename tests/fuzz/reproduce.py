"""A case's reproducer: its input files and a shell script that runs it.

:func:`write_reproducer` writes, under a directory of its own, ``in/`` (the
mutant and any other input file, byte for byte) and ``repro.sh``, which makes
a fresh temporary directory, copies ``in/`` there, makes the special nodes
(FIFOs, symlinks, a device node, an unreadable file), changes to ``out/`` and
runs the command the campaign ran, with its CPU-time limit and wall-clock
backstop (and, for a permission
case, without root's file-permission override, through ``setpriv``). It then
prints the exit status and what is left in ``out/``. The command is
``${REFSIM:-refsim}``: put the project's ``.venv/bin`` on PATH, or set
``REFSIM=.venv/bin/refsim``.

The same case can also be rebuilt from its id alone:
``python -m tests.fuzz.campaign --replay ID``.
"""

from __future__ import annotations

import math
import os
import re
import shlex
from pathlib import Path

from tests.fuzz.cases import Case
from tests.fuzz.runner import UNPRIVILEGED, WALL_FACTOR


def shell_word(text: str) -> str:
    """``text`` as one shell word, its ``{in}``/``{out}`` placeholders as
    ``"$work/in"``/``"$work/out"``."""
    parts = []
    for token in re.split(r"(\{in\}|\{out\})", text):
        if token == "{in}":
            parts.append('"$work/in"')
        elif token == "{out}":
            parts.append('"$work/out"')
        elif token:
            parts.append(shlex.quote(token))
    return "".join(parts) or "''"


def _local(path: str, dest: Path) -> Path:
    """Where a ``{in}`` path of the case is kept in the reproducer's ``in/``."""
    return dest / "in" / path.removeprefix("{in}/")


def write_reproducer(case: Case, dest: Path, signature: str = "") -> Path:
    """Write ``case``'s reproducer under ``dest`` (module docstring); the script's path."""
    dest.mkdir(parents=True, exist_ok=True)
    (dest / "in").mkdir(exist_ok=True)
    for path, data in case.files:
        if path.startswith("{in}/"):
            target = _local(path, dest)
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(data)
    make = []
    for special in case.specials:
        where = shell_word(special.path)
        if special.kind == "dir":
            make.append(f"mkdir -p {where}")
        elif special.kind == "readonly-dir":
            make.append(f"mkdir -p {where} && chmod 555 {where}")
        elif special.kind == "fifo":
            make.append(f"mkfifo {where}")
        elif special.kind == "symlink":
            make.append(f"ln -s {shell_word(special.target)} {where}")
        elif special.kind == "locked-dir":
            local = _local(special.path, dest)
            local.mkdir(parents=True, exist_ok=True)
            (local / special.target).write_bytes(special.content)
            make.append(f"chmod 000 {where}")
        elif special.kind == "device":
            make.append(f"mknod {where} c 1 3        # a copy of /dev/null's device numbers")
        elif special.kind in ("unreadable", "file"):
            _local(special.path, dest).write_bytes(special.content)
            if special.kind == "unreadable":
                make.append(f"chmod 000 {where}")
    user = " ".join(UNPRIVILEGED) + " " if case.unprivileged else ""
    # the campaign's limits: CPU time (soft, so SIGXCPU ends it), then the
    # wall-clock backstop; exec keeps the subshell's pid for the signal cases
    cpu, wall = math.ceil(case.cpu_limit), WALL_FACTOR * case.cpu_limit
    command = (f"(ulimit -S -t {cpu}; exec timeout -s KILL {wall:g} {user}"
               "\"${REFSIM:-refsim}\" " + " ".join(shell_word(a) for a in case.argv) + ")")
    if case.interrupt is None:
        run = [command, 'echo "exit status: $?"']
    else:
        signum, pattern, delay = case.interrupt
        # job control, so that the background command keeps SIGINT (a
        # non-interactive shell ignores it in background jobs)
        run = ["set -m", f"{command} &", "pid=$!", "n=0",
               f"while ! ls {pattern} >/dev/null 2>&1 && [ $n -lt 60000 ]; do "
               "sleep 0.001; n=$((n + 1)); done",
               *([f"sleep {delay:g}"] if delay else []),
               f"kill -{signum} $pid", "wait $pid", 'echo "exit status: $?"']
    lines = [
        "#!/bin/sh",
        f"# refsim fuzz case {case.id}: {case.family} {case.mutator} on {case.subject}",
        *([f"# found: {signature}"] if signature else []),
        "# Needs refsim on PATH (the project's .venv/bin) or REFSIM=/path/to/refsim.",
        "set -u",
        'here=$(cd "$(dirname "$0")" && pwd)',
        "work=$(mktemp -d)",
        'cp -R "$here/in" "$work/in"',
        'mkdir "$work/out"',
        *make,
        'cd "$work/out"',
        *run,
        'ls -la "$work/out"',
    ]
    script = dest / "repro.sh"
    script.write_bytes(("\n".join(lines) + "\n").encode("utf-8", "surrogateescape"))
    os.chmod(script, 0o755)
    return script
