"""Hostile calls of refsim's public API, each in a supervised worker process.

The law (docs/design.md, Errors and Public API; ``refsim/errors.py``): a call
either returns or raises a :class:`refsim.errors.RefsimError`; an error about
a value is also a ValueError, one about a type also a TypeError (a plain
RefsimError is neither, which ``except ValueError`` code misses); a
:class:`~refsim.errors.DivergenceError` is the one exception besides
OutputError (an OSError) that is neither. No other exception type escapes,
no call tries a multi-GB allocation (MemoryError under the worker's
address-space limit), none crashes the interpreter or hangs. Where a probe
passes an argument the contract forbids (``must_refuse``), returning is a
failure too; where it states a law about the result (``check``, e.g. a
symmetric answer, a uniform scale keeping convexity), a False check is a
failure.

A probe is one Python expression over the fixtures of :data:`PRELUDE`, so it
is its own reproducer: ``python -m tests.fuzz.api_worker --probe "EXPR"``
runs the prelude and the expression and prints what happened.

:class:`ProbeRunner` keeps one worker (``python -m tests.fuzz.api_worker
--serve``) with the prelude loaded and an address-space limit above what it
already maps; each probe has a CPU-time limit (the worker's ``RLIMIT_CPU``,
set before each probe to the CPU time used so far plus the limit: SIGXCPU
then ends the worker) and a much larger wall-clock backstop, for a probe
that waits instead of computing (a hang). A worker that crashes, hangs or
overruns its CPU limit is replaced (its stack, from faulthandler, names the
frame).
"""

from __future__ import annotations

import argparse
import faulthandler
import json
import os
import resource
import select
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from dataclasses import dataclass
from pathlib import Path

from tests.fuzz.judge import Failure, exception_name, hang_site, innermost_frame
from tests.fuzz.runner import (
    DUMP_GRACE,
    ENV,
    ROOT,
    WALL_FACTOR,
    close_quietly,
    cpu_rlimit,
    die_with_parent,
    stop_server,
)

#: Bytes a probe may map beyond what the worker maps after its prelude:
#: more than any honest call with the fixtures needs, far less than "GB".
PROBE_MEMORY = 2 * 2**30

#: Seconds of CPU time a probe may use before it counts as over its CPU limit.
PROBE_CPU_LIMIT = 10.0

#: The fixtures every probe may use. Files that cannot be made portably in a
#: probe (a FIFO, a symlink loop, a deep TOML file) are made here, in a
#: temporary directory TMP.
PRELUDE = r'''
import math, os, pathlib, tempfile
import numpy as np
import refsim
from refsim import (Mesh, load_model, aabb_linear, IncrementalAABB, triangles_intersect,
                    bodies_collide, intersecting_pairs, SOLVERS, integrate, load_scene,
                    simulate, Simulation, ParticleConfig, ParticleSystem, Trajectory)
from refsim.scenes.loader import scene_from_dict
from refsim.types import rotation_about_axis
from tests.fuzz.execute import scene_absurdity

CUBE, SPHERE = load_model("cube.ac"), load_model("sphere-2k.ac")
TETRA, TORUS = load_model("tetrahedron.ac"), load_model("torus.ac")
ID = (np.eye(3), np.zeros(3))
ROT = rotation_about_axis([1.0, 2.0, 3.0], 0.7)
LEVELS = ("sphere", "aabb", "triangle-aabb", "exact")
BOUNCE, HEADON = load_scene("bounce.toml"), load_scene("head-on.toml")
SPIN, PARTICLES = load_scene("spinning-cube.toml"), load_scene("particles.toml")

def decay(t, y):
    return -y

# ProbeRunner gives each worker a directory it removes; a standalone --probe makes one
TMP = os.environ.get("REFSIM_FUZZ_FIXTURES") or tempfile.mkdtemp(prefix="refsim-api-")
def _file(name, data):
    path = os.path.join(TMP, name)
    with open(path, "wb") as handle:
        handle.write(data)
    return path
def _node(name, make):
    path = os.path.join(TMP, name)
    make(path)
    return path

CUBE_AC = _file("cube.ac", open(refsim.bundled.models_dir() / "cube.ac", "rb").read())
COLLINEAR_AC = _file("line.ac", b"AC3Db\nOBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n2 0 0\n"
                     b"numsurf 1\nSURF 0x0\nrefs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n")
JUNK_AC = _file("junk.ac", b"\x00\xff junk")
EMPTY_AC = _file("empty.ac", b"")
LATIN1_OBJ = _file("latin1.obj", b"# caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
NOTES = _file("notes.txt", b"hello\n")
DIR_AC = _node("dir.ac", os.mkdir)
FIFO_AC = _node("pipe.ac", os.mkfifo)
LOOP_AC = _node("loop.ac", lambda p: os.symlink(p, p))
SCENE_FILE = _file("scene.toml", open(refsim.bundled.scenes_dir() / "bounce.toml", "rb").read())
DEEP_TOML = _file("deep.toml", b"x = " + b"[" * 500 + b"]" * 500 + b"\n")
LATIN1_TOML = _file("latin1.toml", b"# caf\xe9\n[[body]]\nmodel = \"cube.ac\"\n")
DIR_TOML = _node("dir.toml", os.mkdir)
FIFO_TOML = _node("pipe.toml", os.mkfifo)
ZERO_TOML = _node("zero.toml", lambda p: os.symlink("/dev/zero", p))
LOOP_TOML = _node("loop.toml", lambda p: os.symlink(p, p))
GOOD_NPZ = str(simulate(BOUNCE, duration=0.002).save(os.path.join(TMP, "good.npz")))
PARTIAL_NPZ = os.path.join(TMP, "partial.npz"); np.savez(PARTIAL_NPZ, t=np.zeros(2))
PICKLE_NPZ = os.path.join(TMP, "pickle.npz"); np.savez(PICKLE_NPZ, t=np.array([{}], dtype=object))
JUNK_NPZ = _file("junk.npz", b"not a zip file")
FIFO_NPZ = _node("pipe.npz", os.mkfifo)

# Compile the kernels the probes reach (or load them from numba's cache)
# before the worker says it is ready: a first compilation takes tens of
# seconds on a cold cache and must not count against a probe's CPU-time limit.
_TOUCH = (np.eye(3), np.array([1.0, 0.0, 0.0]))
bodies_collide(CUBE, ID, CUBE, _TOUCH)
for _method in ("bvh", "seed"):
    intersecting_pairs(CUBE, ID, CUBE, _TOUCH, method=_method)
aabb_linear(CUBE, ID), IncrementalAABB(CUBE).update(ID)
ParticleSystem(ParticleConfig(count=2)).run(1)

def body_scene(model="sphere-2k.ac", **body):
    """Two bodies of one model, head on, with ``body``'s keys on both."""
    bodies = [dict(model=model, name=n, position=[x, 0.0, 0.0], **body)
              for n, x in (("a", -2.0), ("b", 2.0))]
    return scene_from_dict({"body": bodies, "collision": {"level": "exact"},
                            "integration": {"step": 0.001, "duration": 0.01}})
'''


# -- the worker ---------------------------------------------------------------------------


def _prelude_namespace() -> dict:
    namespace: dict = {"__name__": "__probe__"}
    exec(compile(PRELUDE, "<prelude>", "exec"), namespace)
    return namespace


def _innermost_refsim_frame(exc: BaseException) -> str:
    """``refsim/x.py:function`` of the innermost refsim frame of ``exc``'s
    traceback (the innermost frame of any file when none is refsim's)."""
    frames = traceback.extract_tb(exc.__traceback__)
    mine = [f for f in frames if "/refsim/" in f.filename and "/tests/" not in f.filename]
    frame = (mine or frames)[-1] if frames else None
    if frame is None:
        return "?"
    name = frame.filename
    name = "refsim/" + name.rsplit("/refsim/", 1)[1] if "/refsim/" in name else name
    return f"{name}:{frame.name}"


def _exception_facts(exc: BaseException) -> dict:
    from refsim.errors import DivergenceError, OutputError, RefsimError

    return {"status": "raised", "type": type(exc).__qualname__,
            "frame": _innermost_refsim_frame(exc),
            "module": type(exc).__module__,
            "refsim": isinstance(exc, RefsimError),
            "value_error": isinstance(exc, ValueError),
            "type_error": isinstance(exc, TypeError),
            "allowed_other": isinstance(exc, DivergenceError | OutputError),
            "memory": isinstance(exc, MemoryError),
            "message": str(exc)[:300],
            "traceback": traceback.format_exc()[-3000:]}


def run_probe(namespace: dict, code: str, check: str | None) -> dict:
    """Evaluate one probe in ``namespace``; a dict of what happened."""
    start = time.monotonic()
    local = dict(namespace)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")      # warnings are not the law tested here
            result = eval(compile(code, "<probe>", "eval"), local)
    except BaseException as exc:  # every exception is data here
        facts = _exception_facts(exc)
        facts["seconds"] = time.monotonic() - start
        return facts
    facts = {"status": "ok", "repr": repr(result)[:200], "check": None,
             "seconds": time.monotonic() - start}
    if check is not None:
        local["_result"] = result
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                facts["check"] = bool(eval(compile(check, "<check>", "eval"), local))
        except BaseException as exc:  # a check that raises is a broken law too
            facts["check"] = False
            facts["check_error"] = f"{type(exc).__name__}: {str(exc)[:200]}"
    return facts


def _limit_cpu(seconds: float | None) -> None:
    """Let this process use ``seconds`` more of CPU time before SIGXCPU
    (None: no limit). Only the soft limit moves, so it can be raised again."""
    _, hard = resource.getrlimit(resource.RLIMIT_CPU)
    soft = hard
    if seconds is not None:
        usage = resource.getrusage(resource.RUSAGE_SELF)
        soft, _ = cpu_rlimit(seconds, used=usage.ru_utime + usage.ru_stime)
        if hard != resource.RLIM_INFINITY:
            soft = min(soft, hard)
    resource.setrlimit(resource.RLIMIT_CPU, (soft, hard))


def serve() -> None:
    """The worker: the prelude, a memory limit, then one probe per stdin line,
    each under the CPU-time limit its request names (``cpu``, seconds).

    Results go to the original stdout; anything a probe prints goes to
    stderr, with faulthandler's dumps (a crash, SIGUSR1 at the wall-clock
    backstop, SIGXCPU at the CPU-time limit, of which the worker then dies).
    """
    die_with_parent()
    results = os.dup(1)
    os.dup2(2, 1)
    faulthandler.enable(sys.stderr, all_threads=True)
    faulthandler.register(signal.SIGUSR1, file=sys.stderr, all_threads=True)
    faulthandler.register(signal.SIGXCPU, file=sys.stderr, all_threads=True, chain=True)
    resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
    namespace = _prelude_namespace()
    with open("/proc/self/status") as status:
        size = next(int(line.split()[1]) * 1024 for line in status
                    if line.startswith("VmSize:"))
    limit = size + PROBE_MEMORY
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    os.write(results, (json.dumps({"ready": os.getpid(), "limit": limit}) + "\n").encode())
    for line in sys.stdin:
        request = json.loads(line)
        _limit_cpu(request.get("cpu"))
        facts = run_probe(namespace, request["code"], request.get("check"))
        _limit_cpu(None)
        os.write(results, (json.dumps(facts) + "\n").encode())


# -- the parent's side --------------------------------------------------------------------


@dataclass(frozen=True)
class Probe:
    """One call: ``function`` (the public name it probes, for counting),
    ``code`` (a Python expression over the prelude's fixtures), whether the
    contract forbids its arguments (``must_refuse``, with ``why``), and a
    law about a successful result (``check``, an expression over
    ``_result``; ``law`` says it in words). ``must_accept``: every argument
    is one the contract allows, so refusing is a failure too. ``bad``: the
    names of the forbidden arguments."""

    function: str
    code: str
    must_refuse: bool = False
    why: str = ""
    check: str | None = None
    law: str = ""
    must_accept: bool = False
    bad: tuple[str, ...] = ()

    def reproducer(self) -> str:
        return f"python -m tests.fuzz.api_worker --probe {_shell_quote(self.code)}"


def _shell_quote(text: str) -> str:
    import shlex

    return shlex.quote(text)


@dataclass(frozen=True)
class ProbeOutcome:
    """What a probe did: the worker's facts, or a crash (``signal``), a
    hang (``timed_out``: killed at the wall-clock backstop) or a CPU-time
    overrun (``cpu_exceeded``: the worker died of SIGXCPU) with
    faulthandler's stack in ``stack``."""

    facts: dict
    signal: int | None = None
    timed_out: bool = False
    stack: str = ""
    seconds: float = 0.0
    cpu_exceeded: bool = False


class ProbeRunner:
    """One worker process and the probes sent to it (module docstring):
    each may use ``cpu_limit`` seconds of CPU time, and is killed as a hang
    after ``wall_limit`` seconds (default: WALL_FACTOR times ``cpu_limit``)."""

    def __init__(self, cpu_limit: float = PROBE_CPU_LIMIT, log: Path | None = None,
                 python: str = sys.executable, wall_limit: float | None = None):
        self.cpu_limit = cpu_limit
        self.wall_limit = WALL_FACTOR * cpu_limit if wall_limit is None else wall_limit
        self.python = python
        self._base = Path(tempfile.mkdtemp(prefix="refsim-api-"))   # fixtures; removed by close
        self.log = Path(log) if log else self._base / "worker.log"
        self.starts = 0
        self._process = None
        self._start()

    def _start(self) -> None:
        self._err = open(self.log, "ab")
        fixtures = tempfile.mkdtemp(prefix="fixtures-", dir=self._base)
        self._process = subprocess.Popen(
            [self.python, "-m", "tests.fuzz.api_worker", "--serve"], cwd=ROOT,
            env=dict(ENV, REFSIM_FUZZ_FIXTURES=fixtures),
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self._err)
        self._buffer = b""
        self.starts += 1
        ready = self._line(300.0)
        if ready is None or "ready" not in ready:
            raise RuntimeError(f"the API worker did not start (see {self.log})")

    def _line(self, seconds: float) -> dict | None:
        deadline = time.monotonic() + seconds
        fd = self._process.stdout.fileno()
        while b"\n" not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0 or not select.select([fd], [], [], left)[0]:
                return None
            chunk = os.read(fd, 65536)
            if not chunk:
                return {"eof": True}
            self._buffer += chunk
        line, self._buffer = self._buffer.split(b"\n", 1)
        return json.loads(line)

    def _stack_since(self, offset: int) -> str:
        self._err.flush()
        with open(self.log, "rb") as handle:
            handle.seek(offset)
            return handle.read()[-20000:].decode("utf-8", "replace")

    def run(self, probe: Probe) -> ProbeOutcome:
        offset = self.log.stat().st_size
        start = time.monotonic()
        request = {"code": probe.code, "check": probe.check, "cpu": self.cpu_limit}
        self._process.stdin.write((json.dumps(request) + "\n").encode())
        self._process.stdin.flush()
        facts = self._line(self.wall_limit)
        if facts is not None and "eof" not in facts:
            return ProbeOutcome(facts, seconds=time.monotonic() - start)
        timed_out = facts is None
        if timed_out:
            self._process.send_signal(signal.SIGUSR1)
            time.sleep(DUMP_GRACE)
            self._process.kill()
        code = self._process.wait()
        cpu_exceeded = code == -signal.SIGXCPU and not timed_out
        stack = self._stack_since(offset)
        self._close_pipes()
        self._start()
        return ProbeOutcome({}, signal=None if timed_out or cpu_exceeded else -code,
                            timed_out=timed_out, stack=stack,
                            seconds=time.monotonic() - start, cpu_exceeded=cpu_exceeded)

    def _close_pipes(self) -> None:
        close_quietly(self._process.stdin, self._process.stdout, self._err)

    def close(self) -> None:
        if self._process is not None:
            stop_server(self._process)
        self._close_pipes()
        shutil.rmtree(self._base, ignore_errors=True)


_BIG_CUBE = "Mesh(CUBE.vertices * 1e308, CUBE.faces)"

#: The API findings of the earlier manual campaign, one probe each: the
#: campaign runs them before its random probes (so every campaign confirms or
#: clears each), and the slice (tests/fuzz/test_fuzz_slice.py) marks them.
KNOWN_PROBES = {
    "qhull-1e155": Probe("Mesh", "Mesh(SPHERE.vertices * 1e155, SPHERE.faces).is_convex"),
    "bvh-best-1e155": Probe("bodies_collide", "bodies_collide(Mesh(SPHERE.vertices * 1e155, "
                                              "SPHERE.faces), ID, CUBE, ID)"),
    "sphere-overflow": Probe(
        "bodies_collide", f"bodies_collide({_BIG_CUBE}, (np.eye(3), np.full(3, 2.5e307)), "
                          f"{_BIG_CUBE}, (np.eye(3), np.full(3, -2.5e307)), level='sphere')",
        check="_result is True", law="says apart for overlapping cubes"),
    "level-bogus": Probe("bodies_collide", "bodies_collide(CUBE, ID, CUBE, ID, level='bogus')",
                         must_refuse=True, bad=("level",)),
    "kernel-bogus": Probe("intersecting_pairs", "intersecting_pairs(CUBE, ID, CUBE, ID, "
                                                "kernel='bogus')", must_refuse=True,
                          bad=("kernel",)),
    "none-mesh": Probe("bodies_collide", "bodies_collide(None, ID, CUBE, ID)", must_refuse=True,
                       bad=("mesh_a",)),
    "particles-1e10": Probe("ParticleSystem.run", "ParticleSystem(ParticleConfig(count=10**10))",
                            must_refuse=True, bad=("count",)),
    "integrate-1e9-steps": Probe("integrate", "integrate(decay, [1.0], 0.0, 1e9, 1.0)"),
    "trajectory-missing": Probe("Trajectory.load", "Trajectory.load('missing.npz')",
                                must_refuse=True, bad=("path",)),
    "trajectory-partial": Probe("Trajectory.load", "Trajectory.load(PARTIAL_NPZ)",
                                must_refuse=True, bad=("path",)),
    "aabb-kernel-bogus": Probe("aabb_linear", "aabb_linear(CUBE, ID, kernel='bogus')",
                               must_refuse=True, bad=("kernel",)),
    "run-negative": Probe("ParticleSystem.run", "ParticleSystem(ParticleConfig(count=5)).run(-5)",
                          must_refuse=True, why="run(-5)", bad=("steps",)),
    "duration-negative": Probe("simulate", "simulate(BOUNCE, duration=-1.0)", must_refuse=True,
                               why="duration=-1.0", bad=("duration",)),
    "every-fraction": Probe("simulate", "simulate(BOUNCE, duration=0.01, every=2.5)",
                            must_refuse=True, why="every=2.5", bad=("every",)),
    "toml-nested-500": Probe("load_scene", "load_scene(DEEP_TOML)", must_refuse=True,
                             bad=("path",)),
    "step-y-none": Probe("SOLVERS[name].step", "SOLVERS['rk4'].step(decay, 0.0, None, 0.1)",
                         must_refuse=True, bad=("y",)),
    "obj-latin1": Probe("load_model", "load_model(LATIN1_OBJ)", must_accept=True),
    "collinear-body": Probe("simulate", "simulate(body_scene(model=COLLINEAR_AC), "
                                        "duration=0.01)"),
}


_SHARED: dict[float, ProbeRunner] = {}


def shared_runner(cpu_limit: float) -> ProbeRunner:
    """One worker per process and CPU-time limit, for test modules that
    share it (the slice and the property tests: one start-up instead of
    two). It is closed when the process exits."""
    if cpu_limit not in _SHARED:
        import atexit

        _SHARED[cpu_limit] = ProbeRunner(cpu_limit=cpu_limit)
        atexit.register(_SHARED[cpu_limit].close)
    return _SHARED[cpu_limit]


# -- the law ----------------------------------------------------------------------------


def judge_probe(probe: Probe, outcome: ProbeOutcome) -> list[Failure]:
    """The failures of one probe, in the campaign's columns: "traceback" (an
    exception outside refsim's hierarchy, MemoryError included), "signal",
    "hang" (killed at the wall-clock backstop), "cpu time" (stopped at the
    CPU-time limit), "bad message" (a RefsimError that is neither a ValueError nor a
    TypeError, OSError or DivergenceError), "bad output" (returned where it
    must refuse, refused where it must accept, or broke its law)."""
    if outcome.timed_out:
        return [Failure("hang", f"hang in {hang_site(outcome.stack)}",
                        f"{probe.function}: killed after {outcome.seconds:.1f} s in "
                        f"{innermost_frame(outcome.stack, dump=True)}")]
    if outcome.cpu_exceeded:
        return [Failure("cpu time", f"over the CPU limit in {hang_site(outcome.stack)}",
                        f"{probe.function}: stopped at the CPU-time limit after "
                        f"{outcome.seconds:.1f} s in "
                        f"{innermost_frame(outcome.stack, dump=True)}")]
    if outcome.signal is not None:
        name = signal.Signals(outcome.signal).name if outcome.signal > 0 else "exit"
        return [Failure("signal", f"{name} in {innermost_frame(outcome.stack, dump=True)}",
                        probe.code[:300])]
    facts = outcome.facts
    if facts["status"] == "raised":
        where = facts["frame"]
        if not facts["refsim"]:
            return [Failure("traceback", f"{exception_name(facts['type'])} in {where}",
                            f"{facts['type']}: {facts['message']}"[:300])]
        if not (facts["value_error"] or facts["type_error"] or facts["allowed_other"]):
            return [Failure("bad message", f"plain {facts['type']} (neither ValueError nor "
                            f"TypeError) in {where}", facts["message"][:300])]
        if probe.must_accept:
            return [Failure("bad output", f"{probe.function} refuses a valid call: "
                            f"{facts['type']} in {where}", facts["message"][:300])]
        return []
    found = []
    if probe.must_refuse:
        names = ", ".join(sorted(probe.bad)) or "argument"
        found.append(Failure("bad output", f"{probe.function} accepts a forbidden {names}",
                             f"{probe.why}: returned {facts['repr']}"[:300]))
    if probe.check is not None and facts["check"] is False:
        found.append(Failure("bad output", f"{probe.function}: {probe.law}",
                             facts.get("check_error", f"returned {facts['repr']}")[:300]))
    return found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tests.fuzz.api_worker",
        description="Run API probes: --serve (the campaign's worker) or --probe EXPR "
                    "(one probe, after the prelude, reported with its traceback).")
    parser.add_argument("--serve", action="store_true")
    parser.add_argument("--probe", metavar="EXPR")
    parser.add_argument("--check", metavar="EXPR", help="a law over _result")
    args = parser.parse_args(argv)
    if args.serve:
        serve()
        return 0
    if args.probe is None:
        parser.error("give --serve or --probe EXPR")
    faulthandler.enable()
    facts = run_probe(_prelude_namespace(), args.probe, args.check)
    if facts["status"] == "raised":
        print(facts.pop("traceback"), end="")
    print(json.dumps(facts, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
