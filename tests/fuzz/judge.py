"""The laws a ``refsim`` command must keep, and the root cause of each breach.

docs/design.md, Errors and ``refsim/cli/``: a user's mistake prints exactly one
line ``refsim: error: ...`` naming the file and the line or key, and exits
with status 2; a diverged run exits with 3 naming the step; success is 0 with
nothing on stderr but ``refsim: warning:`` lines; no traceback for user
error, and no half-written output file left behind.

:func:`judge` turns a :class:`~tests.fuzz.execute.Record` into a
:class:`Verdict`: whether the input was accepted or refused with one good
line, and its :class:`Failure` s, one per law broken. A failure's column is
one of :data:`COLUMNS`; its ``signature`` is its root cause, so that
failures can be grouped:

- a traceback: the exception type and the innermost refsim frame
  (``RecursionError in refsim/scenes/loader.py:load_scene``);
- a signal, a hang or a CPU-time overrun: the signal, respectively the
  module (``hang in refsim/x.py``, ``over the CPU limit in refsim/x.py``),
  of the innermost refsim frame of faulthandler's stack dump;
- a bad message: what is wrong with it and the message with paths, numbers
  and quoted names blanked (``names no line or key: <in>/x.ac: no such file``);
- files left, files replaced, bad output: what was left, replaced or wrong.

Columns, per case (a case may count in several):

==============  ===============================================================
traceback       "Traceback" on stderr, or a stray stderr line (not ``refsim:
                error:``/``refsim: warning:``) on a run that exited normally
                and was not a refusal (a refusal's extra lines are a bad message)
signal          ended by a signal refsim was not sent
hang            killed at the case's wall-clock backstop: it waited (for a
                FIFO, a lock) instead of computing
cpu time        stopped by SIGXCPU at the case's CPU-time limit: it computed
                too long (a loaded machine slows a case, it does not make it
                use more CPU time)
bad message     a refusal that is not exactly one line naming the file and the
                line or key, gives a wrong reason, or names the body twice
files left      a temporary or partial file in the output directory
files replaced  an output symlink, device node or FIFO replaced by a file
bad output      accepted what must be refused, or accepted with a result
                that is wrong (zero steps, non-finite values or facts, a body
                outside the cube, convexity changed by a uniform scale)
==============  ===============================================================
"""

from __future__ import annotations

import re
import signal
from dataclasses import dataclass

from tests.fuzz.cases import WHOLE_FILE_MODEL, Case
from tests.fuzz.execute import Record, fill

COLUMNS = ("traceback", "signal", "hang", "cpu time", "bad message", "files left",
           "files replaced", "bad output")

ERROR = "refsim: error: "
WARNING = "refsim: warning: "
INTERRUPTED = "refsim: interrupted"

#: A frame line of a traceback (``File "p", line 3, in f``) or of a
#: faulthandler dump (``File "p", line 3 in f``).
_FRAME = re.compile(r'File "([^"]+)", line (\d+),? in (\S+)')

#: A scene key path as SceneError prints it: ``world.half_size``, ``body[1].position[2]``.
_KEY = r"[A-Za-z_][\w-]*(?:\[\d+\])*(?:\.[A-Za-z_][\w-]*(?:\[\d+\])*)*"


_WHOLE_FILE_KNOWN_FORMAT = "|".join(w for w in WHOLE_FILE_MODEL if "unknown" not in w)


@dataclass(frozen=True)
class Failure:
    """One law broken: its table column, root-cause signature, and what was seen."""

    column: str
    signature: str
    detail: str


@dataclass(frozen=True)
class Verdict:
    """``inconclusive``: a signal case whose command ended before its signal
    could be sent (its file never appeared, or the write was too quick);
    it says nothing about the signal and counts as neither accepted nor
    refused."""

    accepted: bool
    refused_ok: bool
    failures: tuple[Failure, ...]
    inconclusive: bool = False

    def columns(self) -> set[str]:
        return {f.column for f in self.failures}


# -- reading stderr -------------------------------------------------------------------


def _short(path: str) -> str:
    """A frame's file as ``refsim/models/mesh.py`` or ``scipy/spatial/...``."""
    for marker in ("/site-packages/", "/lib/python3"):
        if marker in path:
            return path.split(marker, 1)[1].split("/", 1)[-1] if marker == "/lib/python3" \
                else path.split(marker, 1)[1]
    if "/refsim/" in path:
        return "refsim/" + path.rsplit("/refsim/", 1)[1]
    return path


def innermost_frame(stderr: str, dump: bool) -> str:
    """The innermost refsim frame (``refsim/x.py:function``) of a traceback
    (innermost last) or of a faulthandler dump (``dump``: innermost first);
    the innermost frame of any file when no frame is refsim's."""
    frames = _FRAME.findall(stderr)
    if not dump:
        frames = frames[::-1]
    mine = [f for f in frames if "/refsim/" in f[0] and "/tests/fuzz/" not in f[0]]
    chosen = (mine or frames or [("?", "0", "?")])[0]
    return f"{_short(chosen[0])}:{chosen[2]}"


def hang_site(stack: str) -> str:
    """Where a hang or a CPU-time overrun is: the module of the innermost
    refsim frame of the dump (a slow loop is caught in whichever of its
    helpers it is in at the limit, so the function would split one cause
    into several)."""
    return innermost_frame(stack, dump=True).rsplit(":", 1)[0]


def exception_name(name: str) -> str:
    """An exception's name without its module (``numpy.linalg.LinAlgError``
    and ``LinAlgError`` are one cause), numpy's ``_ArrayMemoryError`` as the
    MemoryError it is."""
    name = name.rsplit(".", 1)[-1]
    return "MemoryError" if name.endswith("MemoryError") else name


def exception_type(stderr: str) -> str:
    """The type of the last exception of a traceback, e.g. ``RecursionError``."""
    block = stderr.rsplit("Traceback (most recent call last):", 1)[-1]
    for line in block.splitlines()[1:]:
        if line and not line.startswith((" ", "\t")):
            return exception_name(line.split(":", 1)[0].strip())
    return "?"


#: numpy's RuntimeWarning texts ("overflow encountered in multiply"): shown as
#: ``refsim: warning:`` lines they say nothing a user can act on.
_NUMPY_WARNING = re.compile(r"(?:overflow|invalid value|divide by zero|underflow) "
                            r"encountered in (?:scalar )?\w+")


def normalize(message: str, places: dict) -> str:
    """``message`` with what varies between cases of one root cause blanked:
    the case's files and other absolute paths (``<path>``), quoted names,
    numbers, the bytes of a decoding error and numpy's warning texts."""
    for key, value in places.items():
        message = message.replace(value, key.strip("{}").join("<>"))
    message = re.sub(r"<(?:in|out)>/[^\s:,'\"()]*", "<path>", message)
    message = re.sub(r"(?<![\w<.])/(?:[\w.+\-]+/)*[\w.+\-]+", "<path>", message)
    message = _NUMPY_WARNING.sub("<numpy warning>", message)
    message = re.sub(r"can't decode byte .*", "can't decode byte …", message)
    message = re.sub(r"'[^']*'", "'…'", message)
    message = re.sub(r'"[^"]*"', '"…"', message)
    message = re.sub(r"0x[0-9a-fA-F]+", "N", message)
    message = re.sub(r"(?<![\w<])[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", "N", message)
    return message[:160]


# -- the laws ---------------------------------------------------------------------------


def _names_location(message: str, case: Case, places: dict) -> bool:
    """Whether a refusal's message names one of the case's paths as it must."""
    for path, what in case.names:
        # stderr escapes a name's undecodable bytes (\\udcff): that spelling names it too
        spelled = fill(path, places)
        escaped = spelled.encode("utf-8", "backslashreplace").decode("utf-8")
        # and a control character in a name is written as its escape (\\n)
        controls = "".join(c if c.isprintable() or c == " " else repr(c)[1:-1]
                           for c in spelled)
        p = "(?:" + "|".join(re.escape(s) for s in (spelled, escaped, controls)) + ")"
        patterns = {
            "line": [rf"^{p}:\d+: ", rf"^{p}: .*(?:{'|'.join(WHOLE_FILE_MODEL)})"],
            "file": [rf"^{p}(?::\d+)?: "],
            "key": [rf"^{p}: {_KEY}: ", rf"^{p}:\d+: ",
                    rf"^{p}: invalid TOML: .*\(at (?:line \d+|end of document)"],
            # A model inside a scene: its line (AC3D) or any reason about
            # the file (trimesh formats), but not "unknown model format":
            # then the scene's key names a file that is no model, and only
            # the scene's file and key say where to look.
            "model": [rf"^{p}:\d+: ", rf"^{p}: .*(?:{_WHOLE_FILE_KNOWN_FORMAT})"],
            "model-file": [rf"^{p}: (?!unknown model format)"],
        }[what]
        if any(re.search(pattern, message) for pattern in patterns):
            return True
    return not case.names


def _refusal(case: Case, record: Record, lines: list[str]) -> list[Failure]:
    o, places = record.outcome, record.places
    errors = [line for line in lines if line.startswith(ERROR)]
    found = []
    if len(lines) != 1 or len(errors) != 1:
        first = next((line for line in lines if not line.startswith(ERROR)), lines[0] if lines
                     else "")
        what = ("argparse usage and error" if first.startswith("usage:")
                else "no error line" if not lines else normalize(first, places))
        found.append(Failure("bad message", f"refusal prints more than one line: {what}",
                             " | ".join(lines)[:300]))
        if len(errors) != 1 or first.startswith("usage:"):
            return found
    # the error line itself, extra lines or not
    message = errors[0][len(ERROR):]
    if o.returncode == 3:
        if not re.match(r"diverged at step \d+, t = ", message):
            found.append(Failure("bad message", "divergence without step and time",
                                 message[:300]))
        if re.search(r"body '([^']*)',.*body '\1'", message):
            found.append(Failure("bad message", "divergence names the body twice",
                                 message[:300]))
        return found
    if not _names_location(message, case, places):
        found.append(Failure("bad message",
                             f"names no file with line or key: {normalize(message, places)}",
                             message[:300]))
    for pattern in case.forbid:
        if re.search(pattern, message):
            found.append(Failure("bad message", f"wrong reason: {normalize(message, places)}",
                                 f"{case.mutator}: {message[:300]}"))
    return found


def _accepted(case: Case, record: Record) -> list[Failure]:
    found = []
    if case.must_refuse:
        found.append(Failure("bad output", f"accepted what must be refused: {case.mutator}",
                             record.outcome.stdout[:300]))
    if record.output_problem:
        found.append(Failure("bad output", f"accepted: {record.output_problem}",
                             record.outcome.stdout[:300]))
    if record.scene_problem:
        found.append(Failure("bad output", f"accepted: {record.scene_problem}",
                             record.outcome.stdout[:300]))
    if record.facts:
        bad = sorted(key for key, value in record.facts.items()
                     if re.search(r"\b(?:nan|inf)\b", value))
        if bad:
            found.append(Failure("bad output", f"info prints non-finite {', '.join(bad)}",
                                 "; ".join(f"{k}: {record.facts[k]}" for k in bad)))
        for key, value in case.facts:
            if record.facts.get(key) != value:
                found.append(Failure(
                    "bad output", f"info: {key} changed by a uniform scale",
                    f"{key} {record.facts.get(key)!r}, the unscaled model {value!r}"))
    return found


def judge(case: Case, record: Record) -> Verdict:
    """The verdict on one case (module docstring)."""
    o, places = record.outcome, record.places
    lines = o.stderr.splitlines()
    failures: list[Failure] = []
    sent = case.interrupt[0] if case.interrupt and o.interrupted else None
    accepted = refused_ok = False
    if o.timed_out:
        failures.append(Failure("hang", f"hang in {hang_site(o.stderr)}",
                                f"killed after {o.elapsed:.1f} s in "
                                f"{innermost_frame(o.stderr, dump=True)}"))
    elif o.cpu_exceeded:
        failures.append(Failure("cpu time", f"over the CPU limit in {hang_site(o.stderr)}",
                                f"stopped after {case.cpu_limit:g} s of CPU time "
                                f"({o.elapsed:.1f} s) in "
                                f"{innermost_frame(o.stderr, dump=True)}"))
    elif o.signal is not None and o.signal != sent:
        name = signal.Signals(o.signal).name
        failures.append(Failure("signal", f"{name} in {innermost_frame(o.stderr, dump=True)}",
                                o.stderr[-300:]))
    elif o.signal is None:
        traced = "Traceback" in o.stderr
        if traced:
            # exit 0 with a traceback: one printed by a library's logger (trimesh)
            logged = "logged traceback, exit 0: " if o.returncode == 0 else ""
            failures.append(Failure(
                "traceback",
                f"{logged}{exception_type(o.stderr)} in {innermost_frame(o.stderr, False)}",
                o.stderr.strip().splitlines()[-1][:300]))
        if sent is not None and o.returncode == 128 + sent and not traced:
            # an interrupt: the command line's own one line, status 128 + the
            # signal's number (130 for Ctrl-C, 143 for SIGTERM), as a shell's
            interrupted = (INTERRUPTED if sent == signal.SIGINT
                           else f"{INTERRUPTED} ({signal.Signals(sent).name})")
            if lines != [interrupted]:
                failures.append(Failure("bad message", "interrupt prints more than its line",
                                        " | ".join(lines)[:300]))
            refused_ok = not failures
        elif o.returncode in (2, 3) and not traced:
            failures += _refusal(case, record, lines)
            refused_ok = not failures
        elif o.returncode == 0:
            stray = [line for line in lines if not line.startswith(WARNING)]
            if stray and not traced:
                failures.append(Failure("traceback",
                                        f"stray stderr line: {normalize(stray[0], places)}",
                                        stray[0][:300]))
            leaked = [line for line in lines
                      if line.startswith(WARNING) and _NUMPY_WARNING.search(line)]
            if leaked:
                failures.append(Failure("bad message",
                                        "numpy RuntimeWarning shown as a refsim warning",
                                        " | ".join(leaked)[:300]))
            failures += _accepted(case, record)
            accepted = True
        elif not traced:
            failures.append(Failure("bad message", f"exit status {o.returncode}",
                                    o.stderr[-300:]))
    for name in record.left:
        kind = "temporary file" if re.match(r"(?:.*/)?\..*\.tmp$", name) else "partial output"
        how = ("after " + signal.Signals(sent).name if sent else "after a hang" if o.timed_out
               else "after the CPU limit" if o.cpu_exceeded
               else "after a crash" if o.signal else f"after exit {o.returncode}")
        failures.append(Failure("files left", f"{kind} left {how}", name))
    for change in record.replaced:
        failures.append(Failure("files replaced", "-o replaced " + change.split(": ", 1)[1]
                                .replace(" -> ", " by "), change))
    # the signal was never sent, or reached a process that had already exited
    if case.interrupt is not None and (not o.interrupted or o.returncode == 0) and not failures:
        return Verdict(False, False, (), inconclusive=True)
    return Verdict(accepted, refused_ok, tuple(failures))
