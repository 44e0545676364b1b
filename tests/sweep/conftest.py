"""A Dask cluster of separate processes on 127.0.0.1, for the sweep tests,
and a bound on every sweep test's time.

``dask scheduler`` and one ``dask worker`` command with two worker
processes (one thread each, under nannies that restart a killed worker),
each command in its own session so that it and every process it starts can
be stopped as a group. Readiness is polled (the scheduler file, then the
workers through a client), every wait is bounded, and the fixture checks at
the end that none of the processes it started is left running.

A sweep that hangs (a worker that never answers) would hang the test run:
each test here is bounded by ``HANG_SECONDS``, after which every thread's
stack is printed and the test process exits (the cluster's processes then
stop by themselves: ``--death-timeout``, ``--idle-timeout``).
"""

from __future__ import annotations

import faulthandler
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

ROOT = Path(__file__).resolve().parents[2]

#: Bounded waits: a cold start of a scheduler or of two workers (imports
#: included) takes a few seconds on the 2-core machine; ten times that is a
#: hang, not slowness.
START_SECONDS = 60.0
STOP_SECONDS = 15.0
POLL_SECONDS = 0.05

#: The longest a sweep test may take: the slowest takes a few seconds (20 s
#: on a loaded machine); minutes mean a hang.
HANG_SECONDS = 180.0

#: A scheduler that somehow outlives the tests stops itself after this much
#: idleness, and its workers follow it (``--death-timeout``).
IDLE_TIMEOUT = "300s"


@pytest.fixture(autouse=True)
def hang_guard():
    """Print the stacks and exit when a test outlives ``HANG_SECONDS``."""
    faulthandler.dump_traceback_later(HANG_SECONDS, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


def _dask(*args: str, log: Path) -> subprocess.Popen:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]))
    with open(log, "wb") as out:
        return subprocess.Popen([sys.executable, "-m", "distributed.cli.dask_" + args[0],
                                 *args[1:]], cwd=ROOT, env=env, stdout=out,
                                stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                start_new_session=True)


def _stop(process: subprocess.Popen) -> None:
    """SIGTERM the process's group, SIGKILL it if still there after a while."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(process.pid, sig)
        except ProcessLookupError:
            return
        try:
            process.wait(STOP_SECONDS)
            return
        except subprocess.TimeoutExpired:
            continue


def _family(process: subprocess.Popen) -> list[psutil.Process]:
    try:
        parent = psutil.Process(process.pid)
        return [parent, *parent.children(recursive=True)]
    except psutil.NoSuchProcess:
        return []


def _running(processes) -> list[psutil.Process]:
    left = []
    for p in processes:
        try:
            if p.is_running() and p.status() != psutil.STATUS_ZOMBIE:
                left.append(p)
        except psutil.NoSuchProcess:
            pass
    return left


def _scheduler_address(scheduler, scheduler_file, log) -> str:
    """The address the scheduler writes to its file, once the file holds
    all of it: the scheduler creates the file before it has written it, so
    a file that exists may still be empty (seen on a loaded machine)."""
    deadline = time.monotonic() + START_SECONDS
    while True:
        assert scheduler.poll() is None, log.read_text()
        assert time.monotonic() < deadline, "the scheduler did not start"
        try:
            return json.loads(scheduler_file.read_text())["address"]
        except (FileNotFoundError, json.JSONDecodeError, KeyError):
            time.sleep(POLL_SECONDS)


@pytest.fixture(scope="session")
def dask_scheduler(tmp_path_factory):
    """The address of a scheduler with two single-thread workers."""
    from distributed import Client

    folder = tmp_path_factory.mktemp("dask")
    scheduler_file = folder / "scheduler.json"
    scheduler = _dask("scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
                      "--dashboard-address", "127.0.0.1:0",
                      "--scheduler-file", str(scheduler_file), "--idle-timeout", IDLE_TIMEOUT,
                      log=folder / "scheduler.log")
    workers = None
    started = []
    try:
        address = _scheduler_address(scheduler, scheduler_file, folder / "scheduler.log")
        workers = _dask("worker", "--scheduler-file", str(scheduler_file), "--nworkers", "2",
                        "--nthreads", "1", "--host", "127.0.0.1", "--no-dashboard",
                        "--local-directory", str(folder), "--death-timeout", "60",
                        log=folder / "workers.log")
        with Client(address, timeout=START_SECONDS, set_as_default=False) as client:
            client.wait_for_workers(2, timeout=START_SECONDS)
        yield address
    finally:
        for process in (workers, scheduler):
            if process is not None:
                started += _family(process)
                _stop(process)
        psutil.wait_procs(_running(started), timeout=STOP_SECONDS)
        left = _running(started)
        assert not left, f"processes left running: {left}"
