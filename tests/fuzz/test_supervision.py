"""The supervisors' limits (tests.fuzz.runner, tests.fuzz.api_worker): a child
that computes is stopped by its CPU-time limit and counted in the "cpu time"
column; a child that waits uses no CPU time and is not, and only the much
larger wall-clock backstop stops it, as a "hang". Small limits, so that
these take a few seconds; the children here are plain Python, not refsim."""

from __future__ import annotations

import signal
import sys

import pytest

from tests.fuzz.api_worker import Probe, ProbeRunner, judge_probe
from tests.fuzz.cases import Case
from tests.fuzz.execute import Record
from tests.fuzz.judge import judge
from tests.fuzz.runner import Command, ExecRunner, cpu_rlimit

#: What the console script's shim (runner.SHIM) does with the signals: a
#: stack dump on SIGUSR1 (the backstop's, before SIGKILL) and on SIGXCPU (the
#: CPU-time limit, then death by it).
SIGNALS = ("import faulthandler, signal\n"
           "faulthandler.register(signal.SIGUSR1, all_threads=True)\n"
           "faulthandler.register(signal.SIGXCPU, all_threads=True, chain=True)\n")

#: A child that computes until it is stopped; the loop is one line (line 5),
#: so that the dump names that line wherever the signal lands in it.
SPIN = SIGNALS + "def spin():\n    while True: pass\nspin()\n"

#: The CPU-time limit of these children (RLIMIT_CPU counts whole seconds).
CPU_LIMIT = 1.0

#: Seconds a waiting child sleeps: longer than CPU_LIMIT, inside its backstop.
NAP = 2.5


def sleeping(seconds: float) -> str:
    """A child that waits ``seconds``, using no CPU time."""
    return SIGNALS + f"import time\ntime.sleep({seconds})\n"


class PythonRunner(ExecRunner):
    """ExecRunner's supervision of a plain Python program (``argv[0]``)."""

    def argv(self, command: Command) -> list[str]:
        return [self.python, "-c", command.argv[0]]


def _run(tmp_path, program: str, wall_limit: float):
    command = Command(argv=(program,), cwd=tmp_path, stdout=tmp_path / "stdout",
                      stderr=tmp_path / "stderr", cpu_limit=CPU_LIMIT, wall_limit=wall_limit)
    outcome = PythonRunner(sys.executable).run(command)
    case = Case("t", "args", "t", "t", ("info",), cpu_limit=CPU_LIMIT)
    failures = judge(case, Record("t", outcome, {"{in}": "/nowhere", "{out}": str(tmp_path)}))
    return outcome, [(f.column, f.signature) for f in failures.failures]


def test_the_cpu_rlimit_rounds_up_to_whole_seconds_and_leaves_a_grace():
    assert cpu_rlimit(1.0) == (1, 2)
    assert cpu_rlimit(0.2) == (1, 2)
    assert cpu_rlimit(3.0, used=12.3) == (16, 17)


def test_a_command_that_computes_is_stopped_at_its_cpu_limit(tmp_path):
    outcome, failures = _run(tmp_path, SPIN, wall_limit=60.0)
    assert outcome.cpu_exceeded and not outcome.timed_out
    assert outcome.returncode == -signal.SIGXCPU
    assert outcome.elapsed >= CPU_LIMIT                # one thread: wall >= CPU time
    assert '"<string>", line 5 in spin' in outcome.stderr     # faulthandler's dump
    assert failures == [("cpu time", "over the CPU limit in <string>")]


def test_a_command_that_waits_is_not_stopped_by_its_cpu_limit(tmp_path):
    outcome, failures = _run(tmp_path, sleeping(NAP), wall_limit=60.0)
    assert (outcome.returncode, outcome.cpu_exceeded, outcome.timed_out) == (0, False, False)
    assert outcome.elapsed >= NAP > CPU_LIMIT
    assert failures == []


def test_a_command_that_waits_past_its_wall_clock_backstop_is_a_hang(tmp_path):
    outcome, failures = _run(tmp_path, sleeping(600), wall_limit=2.0)
    assert outcome.timed_out and not outcome.cpu_exceeded
    assert outcome.returncode == -signal.SIGKILL
    assert 2.0 <= outcome.elapsed < 60
    assert [column for column, _ in failures] == ["hang"]
    assert failures[0][1] == "hang in <string>" and "in <module>" in outcome.stderr


@pytest.fixture(scope="module")
def probe_runner():
    runner = ProbeRunner(cpu_limit=CPU_LIMIT, wall_limit=60.0)
    yield runner
    runner.close()


def test_a_probe_that_waits_is_not_stopped_by_its_cpu_limit(probe_runner):
    probe = Probe("sleep", f"__import__('time').sleep({NAP})", must_accept=True)
    outcome = probe_runner.run(probe)
    assert outcome.facts["status"] == "ok" and outcome.facts["seconds"] >= NAP > CPU_LIMIT
    assert not outcome.cpu_exceeded and not outcome.timed_out
    assert judge_probe(probe, outcome) == []


def test_a_probe_that_computes_is_stopped_at_its_cpu_limit(probe_runner):
    probe = Probe("any", "any(iter(int, 1))")                 # zeros, forever
    outcome = probe_runner.run(probe)
    assert outcome.cpu_exceeded and not outcome.timed_out and outcome.signal is None
    assert [(f.column, f.signature) for f in judge_probe(probe, outcome)] == [
        ("cpu time", "over the CPU limit in <probe>")]
    after = probe_runner.run(Probe("sum", "sum(range(10))"))    # a new worker
    assert after.facts == {**after.facts, "status": "ok", "repr": "45"}
