"""Running one ``refsim`` command line in a subprocess, supervised.

Two backends give the same :class:`Outcome` for a :class:`Command`:

- :class:`ExecRunner`: a fresh interpreter per command, ``python -X
  faulthandler -c SHIM ARGV`` where the shim is the console script
  (``sys.exit(refsim.cli.main())``) plus a memory limit and a stack dump on
  SIGUSR1. What a user runs; about 0.5 to 1.5 s per command.
- :class:`ForkServer`: a warmed interpreter (:mod:`tests.fuzz.zygote`) forks
  one child per command; a few tens of milliseconds of overhead. The
  campaign runs its mutants here and confirms each distinct failure with
  :class:`ExecRunner`.

Supervision, the same for both: a limit on the CPU time the child uses
(``RLIMIT_CPU``: at the limit the kernel sends SIGXCPU, faulthandler prints
where the child is and the child dies of it; the outcome is
``cpu_exceeded``), so that a loaded machine, which slows a command down
without making it do more work, cannot fail a case; a much larger wall-clock
backstop for a child that waits instead of computing (a hang: the child gets
SIGUSR1, so that faulthandler prints where it hangs, then SIGKILL); an
address-space limit (``RLIMIT_AS``, so that a multi-GB allocation fails as a
MemoryError instead of taking the shared machine's memory); and, for the signal cases,
a signal sent as soon as a file matching a pattern appears in the working
directory (the moment an output's temporary file exists).

Each child runs with one BLAS and numba thread (the machine is shared); that
changes no result refsim computes (its bits never go through BLAS).
"""

from __future__ import annotations

import json
import math
import os
import resource
import select
import signal
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

#: The repository root (``python -m tests.fuzz.zygote`` runs from here).
ROOT = Path(__file__).resolve().parents[2]

#: Address-space limit of each command: a refsim process with numba loaded
#: maps about 1 GB; 4 GiB leaves room for any honest input of the bundled
#: sizes and stops an attempt at a multi-GB allocation.
MEMORY_LIMIT = 4 * 2**30

#: Seconds of CPU time a command may use before it counts as over its CPU
#: limit (a limit in CPU time, not wall time: a command on a loaded machine
#: takes longer but uses no more CPU).
CPU_LIMIT = 30.0

#: The wall-clock backstop, as a multiple of the CPU limit: a child that
#: waits (a FIFO's open, a lock) uses no CPU and is stopped only by the
#: clock, after long enough that a child which computes, however little of
#: a core a loaded machine gives it, reaches its CPU limit first.
WALL_FACTOR = 10.0

#: Seconds of CPU time between SIGXCPU (the soft limit: faulthandler dumps
#: the stack and the child dies of the signal) and the kernel's SIGKILL
#: (the hard limit), for a child that would survive SIGXCPU.
CPU_GRACE = 1

#: How much of stdout and stderr is kept (a mutant may make refsim print a lot).
KEEP_BYTES = 256 * 1024

#: Seconds between SIGUSR1 (faulthandler dumps the stack) and SIGKILL at the
#: wall-clock backstop: the dump takes microseconds, but on a loaded machine
#: the process may wait that long to be scheduled (0.2 s lost one dump in 60).
DUMP_GRACE = 0.5

ENV = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
           MKL_NUM_THREADS="1", NUMBA_NUM_THREADS="1")
ENV.pop("REFSIM_MODELS", None)          # the bundled models, always

#: The console script (``refsim = refsim.cli:main``) with a memory limit, no
#: core file, a stack dump on SIGUSR1 and on SIGXCPU (then death by it), a
#: terminal's signal dispositions (:func:`terminal_signals`), and death with
#: its parent (a killed campaign leaves no hanging command behind).
#: ``sys.argv[1]`` is the memory limit in bytes (0: none); the CPU-time
#: limit is set from outside (``prlimit``).
SHIM = ("import ctypes, sys, resource, signal, faulthandler\n"
        "try:\n"
        "    ctypes.CDLL(None).prctl(1, signal.SIGKILL)   # as die_with_parent()\n"
        "except (OSError, AttributeError):\n"
        "    pass\n"
        "for s in (signal.SIGHUP, signal.SIGTERM, signal.SIGQUIT):   # as terminal_signals()\n"
        "    signal.signal(s, signal.SIG_DFL)\n"
        "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
        "limit = int(sys.argv.pop(1))\n"
        "if limit: resource.setrlimit(resource.RLIMIT_AS, (limit, limit))\n"
        "resource.setrlimit(resource.RLIMIT_CORE, (0, 0))\n"
        "faulthandler.register(signal.SIGUSR1, all_threads=True)\n"
        "faulthandler.register(signal.SIGXCPU, all_threads=True, chain=True)\n"
        "from refsim.cli import main\n"
        "sys.exit(main())\n")


#: ``setpriv`` (util-linux) dropping root's file-permission override from the
#: command it runs (the bounding set caps what the new program may hold).
UNPRIVILEGED = ("setpriv", "--bounding-set", "-dac_override,-dac_read_search")

#: Linux capability numbers (linux/capability.h).
CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH = 1, 2


def drop_file_capabilities() -> None:
    """Drop CAP_DAC_OVERRIDE and CAP_DAC_READ_SEARCH from this process (and
    from what it may exec): root then obeys file permissions like any user.

    ``capget``/``capset`` with the version-3 header (two 32-bit words per
    set); both capabilities are in the first word.
    """
    import ctypes

    class Header(ctypes.Structure):
        _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]

    class Data(ctypes.Structure):
        _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32),
                    ("inheritable", ctypes.c_uint32)]

    libc = ctypes.CDLL(None, use_errno=True)
    header, data = Header(0x20080522, 0), (Data * 2)()
    if libc.capget(ctypes.byref(header), data) != 0:
        raise OSError(ctypes.get_errno(), "capget failed")
    keep = ~((1 << CAP_DAC_OVERRIDE) | (1 << CAP_DAC_READ_SEARCH)) & 0xFFFFFFFF
    data[0].effective &= keep
    data[0].permitted &= keep
    data[0].inheritable &= keep
    for cap in (CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH):
        libc.prctl(24, cap)                                  # PR_CAPBSET_DROP
    if libc.capset(ctypes.byref(header), data) != 0:
        raise OSError(ctypes.get_errno(), "capset failed")


def terminal_signals() -> None:
    """The signal dispositions of a command typed at a terminal: SIGHUP,
    SIGTERM and SIGQUIT at their defaults, SIGINT raising KeyboardInterrupt.

    A campaign started with ``nohup`` or in the background (``&``) has
    SIGHUP, respectively SIGINT, ignored, and every process it starts would
    inherit that: the signal cases would then test nothing."""
    for signum in (signal.SIGHUP, signal.SIGTERM, signal.SIGQUIT):
        signal.signal(signum, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.default_int_handler)


def close_quietly(*streams) -> None:
    """Close this side of a server's pipes and logs (a replaced server's
    would otherwise stay open until the interpreter exits); a pipe whose
    reader is gone may refuse to flush, which is no error here."""
    for stream in streams:
        try:
            stream.close()
        except OSError:
            pass


def stop_server(process: subprocess.Popen) -> None:
    """End a server that reads requests from its stdin: close that, wait a
    little, kill it if it is still there."""
    if process.poll() is not None:
        return
    close_quietly(process.stdin)
    try:
        process.wait(10)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def cpu_rlimit(seconds: float, used: float = 0.0) -> tuple[int, int]:
    """``RLIMIT_CPU``'s (soft, hard) pair for a child that has used ``used``
    seconds of CPU and may use ``seconds`` more: SIGXCPU at the soft limit
    (whole seconds, so rounded up), SIGKILL :data:`CPU_GRACE` later."""
    soft = max(1, math.ceil(used + seconds))
    return soft, soft + CPU_GRACE


def die_with_parent() -> None:
    """Have the kernel SIGKILL this process when its parent dies (Linux
    ``prctl(PR_SET_PDEATHSIG)``; elsewhere nothing): a campaign stopped by
    Ctrl-C or a crash leaves no fork server, worker or hanging command."""
    import ctypes

    try:
        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGKILL)   # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        pass


@dataclass(frozen=True)
class Command:
    """``refsim ARGV`` run in ``cwd``.

    ``cpu_limit``: the seconds of CPU time it may use; ``wall_limit``: the
    wall-clock backstop (default :data:`WALL_FACTOR` times ``cpu_limit``).
    ``interrupt = (signum, pattern, delay)`` sends ``signum`` ``delay``
    seconds after a file matching the glob ``pattern`` appears in ``cwd``.
    ``unprivileged`` runs it without the capabilities that let root read
    and search any file (CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH): file
    permissions then apply to it as to any user, while it can still run the
    interpreter (which may live in root's private home).
    """

    argv: tuple[str, ...]
    cwd: Path
    stdout: Path
    stderr: Path
    cpu_limit: float = CPU_LIMIT
    unprivileged: bool = False
    interrupt: tuple[int, str, float] | None = None
    memory: int = MEMORY_LIMIT
    wall_limit: float | None = None

    @property
    def wall(self) -> float:
        """Seconds of wall-clock time before the command counts as a hang."""
        return WALL_FACTOR * self.cpu_limit if self.wall_limit is None else self.wall_limit


@dataclass(frozen=True)
class Outcome:
    """What one command did.

    ``returncode`` is the exit status, or ``-signum`` when a signal ended the
    process (as ``subprocess`` reports it); ``timed_out`` when it was killed
    at its wall-clock backstop (a hang; ``stderr`` then ends with
    faulthandler's stack dump); ``cpu_exceeded`` when it died of SIGXCPU at
    its CPU-time limit (a command that computes too long; the stack dump
    too); ``interrupted`` when the command's own ``interrupt`` signal was
    sent.
    """

    returncode: int
    timed_out: bool
    interrupted: bool
    stdout: str
    stderr: str
    elapsed: float
    cpu_exceeded: bool = False

    @property
    def signal(self) -> int | None:
        """The signal that ended the process, or None."""
        return -self.returncode if self.returncode < 0 else None


def _died_of_cpu_limit(code: int, timed_out: bool) -> bool:
    """Whether a child that ended with ``code`` was stopped by its CPU-time
    limit (SIGXCPU) rather than at the wall-clock backstop."""
    return code == -signal.SIGXCPU and not timed_out


def _read(path: Path) -> str:
    try:
        with open(path, "rb") as handle:
            data = handle.read(KEEP_BYTES + 1)
    except OSError:
        return ""
    text = data[:KEEP_BYTES].decode("utf-8", "replace")
    return text + ("\n[... truncated]" if len(data) > KEEP_BYTES else "")


def _interrupt_due(command: Command) -> bool:
    return any(True for _ in command.cwd.glob(command.interrupt[1]))


def _supervise(command: Command, pid: int, poll) -> tuple[int, bool, bool]:
    """Wait for ``pid`` through ``poll(seconds) -> status or None``; send the
    interrupt when due; at the wall-clock backstop dump the stack and kill it
    (the CPU-time limit is the kernel's, set when the child starts).

    Returns ``(returncode, timed_out, interrupted)``.
    """
    deadline = time.monotonic() + command.wall
    pending = command.interrupt is not None
    seen = None                                   # when the interrupt's file appeared
    while True:
        code = poll(0.002 if pending else 0.05)
        if code is not None:
            return code, False, command.interrupt is not None and not pending
        if pending and seen is None and _interrupt_due(command):
            seen = time.monotonic()
        if pending and seen is not None and time.monotonic() >= seen + command.interrupt[2]:
            try:
                os.kill(pid, command.interrupt[0])
                pending = False
            except ProcessLookupError:            # it ended first: not interrupted
                pass
        if time.monotonic() > deadline:
            for signum, pause in ((signal.SIGUSR1, DUMP_GRACE), (signal.SIGKILL, 0.0)):
                try:
                    os.kill(pid, signum)
                except ProcessLookupError:
                    break
                time.sleep(pause)
            code = None
            while code is None:
                code = poll(1.0)
            return code, True, command.interrupt is not None and not pending


class ExecRunner:
    """Each command in a fresh interpreter (see the module docstring)."""

    name = "exec"

    def __init__(self, python: str = sys.executable):
        self.python = python

    def argv(self, command: Command) -> list[str]:
        return [*(UNPRIVILEGED if command.unprivileged else ()), self.python, "-X",
                "faulthandler", "-c", SHIM, str(command.memory), *command.argv]

    def run(self, command: Command) -> Outcome:
        start = time.monotonic()
        with open(command.stdout, "wb") as out, open(command.stderr, "wb") as err:
            process = subprocess.Popen(
                self.argv(command), cwd=command.cwd, stdin=subprocess.DEVNULL, stdout=out,
                stderr=err, env=ENV)
            try:      # the limit counts the CPU time used before it was set too
                resource.prlimit(process.pid, resource.RLIMIT_CPU,
                                 cpu_rlimit(command.cpu_limit))
            except ProcessLookupError:                # already gone
                pass

            def poll(seconds):
                try:
                    return process.wait(seconds)
                except subprocess.TimeoutExpired:
                    return None

            code, timed_out, interrupted = _supervise(command, process.pid, poll)
        return Outcome(code, timed_out, interrupted, _read(command.stdout),
                       _read(command.stderr), time.monotonic() - start,
                       _died_of_cpu_limit(code, timed_out))

    def close(self) -> None:
        pass


class ForkServer:
    """Commands forked from one warmed interpreter (:mod:`tests.fuzz.zygote`).

    Start-up (imports and the warm-up runs) takes about 10 s. Not thread-safe:
    one server per worker thread.
    """

    name = "fork"

    def __init__(self, python: str = sys.executable, log: Path | None = None):
        self.python = python
        self.log = log
        self._process = None
        self._buffer = b""
        self._start()

    def _start(self) -> None:
        err = open(self.log, "ab") if self.log else subprocess.DEVNULL
        try:
            self._process = subprocess.Popen(
                [self.python, "-m", "tests.fuzz.zygote"], cwd=ROOT, env=ENV,
                stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=err)
        finally:
            if err is not subprocess.DEVNULL:
                err.close()                   # the server holds its own copy
        self._buffer = b""
        ready = self._message(600.0)
        if ready is None or "ready" not in ready:
            raise RuntimeError(f"the fork server did not start (see {self.log})")

    def _message(self, seconds: float | None) -> dict | None:
        """The next JSON line from the server, or None after ``seconds``."""
        deadline = None if seconds is None else time.monotonic() + seconds
        fd = self._process.stdout.fileno()
        while b"\n" not in self._buffer:
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            if not select.select([fd], [], [], left)[0]:
                return None
            chunk = os.read(fd, 65536)
            if not chunk:
                raise RuntimeError("the fork server exited")
            self._buffer += chunk
        line, self._buffer = self._buffer.split(b"\n", 1)
        return json.loads(line)

    def run(self, command: Command) -> Outcome:
        if self._process.poll() is not None:
            self._close_pipes()
            self._start()
        start = time.monotonic()
        request = {"argv": list(command.argv), "cwd": str(command.cwd),
                   "stdout": str(command.stdout), "stderr": str(command.stderr),
                   "unprivileged": command.unprivileged, "memory": command.memory,
                   "cpu": cpu_rlimit(command.cpu_limit)}
        self._process.stdin.write((json.dumps(request) + "\n").encode())
        self._process.stdin.flush()
        pid = self._message(60.0)["pid"]

        def poll(seconds):
            message = self._message(seconds)
            return None if message is None else os.waitstatus_to_exitcode(message["status"])

        code, timed_out, interrupted = _supervise(command, pid, poll)
        return Outcome(code, timed_out, interrupted, _read(command.stdout),
                       _read(command.stderr), time.monotonic() - start,
                       _died_of_cpu_limit(code, timed_out))

    def _close_pipes(self) -> None:
        close_quietly(self._process.stdin, self._process.stdout)

    def close(self) -> None:
        if self._process is not None:
            stop_server(self._process)
            self._close_pipes()
