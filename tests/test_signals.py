"""SIGTERM and SIGHUP unwind ``refsim run`` like Ctrl-C: exit status 128 +
the signal, one line on stderr, no temporary or spill file left, an old
output file untouched. Checked on a real process, signalled while it writes
its .npz and while it runs."""

from __future__ import annotations

import signal
import subprocess
import sys
import time

import pytest

from refsim.signals import Interrupted, signals_raise

#: Longest wait for the child to reach the state the test signals it in:
#: far beyond the few seconds it takes, so only a hang fails the test.
DEADLINE_SECONDS = 120.0

#: Poll interval while waiting for the child (polling, not synchronisation:
#: the test acts on what it sees, whatever the interval).
POLL_SECONDS = 0.01

SCENE = """
[world]
half_size = 1.0

[integration]
solver = "rk4"
step = 0.01
duration = {duration}

[particles]
count = 12
seed = 5
box_lo = [-0.5, -0.5, -0.5]
box_hi = [0.5, 0.5, 0.5]
"""

#: A child that runs ``refsim run`` and stops inside the .npz assembly, at
#: the header of its third entry (``t`` and ``step`` written, ``position``
#: begun): it touches the marker file and waits for a signal there.
CHILD = """
import signal, sys
from pathlib import Path

import refsim.storage.npz
from refsim.cli import main

marker = Path(sys.argv[1])
real = refsim.storage.npz.npy_header
calls = []


def header_then_wait(shape, dtype):
    calls.append(shape)
    if len(calls) == 3:
        marker.touch()
        while True:
            signal.pause()
    return real(shape, dtype)


refsim.storage.npz.npy_header = header_then_wait
sys.exit(main(sys.argv[2:]))
"""

#: A child whose run is signalled inside a constructor, as numba's compiler
#: can be (llvmlite's OutputString): the object, cut short before its
#: ``_owned`` is set, fails in ``__del__`` when the unwound stack frees it.
CHILD_IN_CONSTRUCTOR = """
import signal, sys
from pathlib import Path

import refsim.storage.npz
from refsim.cli import main

marker = Path(sys.argv[1])


class HalfBuilt:
    def __init__(self):
        marker.touch()
        while True:
            signal.pause()
        self._owned = True

    def __del__(self):
        if self._owned:
            pass


def header_in_a_constructor(shape, dtype):
    HalfBuilt()


refsim.storage.npz.npy_header = header_in_a_constructor
sys.exit(main(sys.argv[2:]))
"""

EXPECTED = {
    signal.SIGTERM: (128 + 15, "refsim: interrupted (SIGTERM)\n"),
    signal.SIGHUP: (128 + 1, "refsim: interrupted (SIGHUP)\n"),
    signal.SIGINT: (130, "refsim: interrupted\n"),       # Python's KeyboardInterrupt
}


def _wait_for(child: subprocess.Popen, ready) -> None:
    """Poll until ``ready()``; fail if the child exits first or time runs out."""
    deadline = time.monotonic() + DEADLINE_SECONDS
    while not ready():
        if child.poll() is not None:
            out, err = child.communicate()
            pytest.fail(f"child exited with {child.returncode} before the signal:\n{err}")
        if time.monotonic() > deadline:
            child.kill()
            pytest.fail("child did not reach the point to signal it at")
        time.sleep(POLL_SECONDS)


def _setup(tmp_path, duration: float):
    work = tmp_path / "work"
    work.mkdir()
    scene = work / "scene.toml"
    scene.write_text(SCENE.format(duration=duration))
    out = work / "out.npz"
    out.write_bytes(b"the old output")
    return work, scene, out


def _start_child(tmp_path, script: str, marker_name: str, *args: str):
    """``script`` run as a child with the marker file's path and ``args``:
    ``(the process, the marker it touches when it is where to signal it)``."""
    child_script = tmp_path / "child.py"
    child_script.write_text(script)
    marker = tmp_path / marker_name
    child = subprocess.Popen([sys.executable, str(child_script), str(marker), *args],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    return child, marker


def _signal_and_check(child, signum, work, out):
    child.send_signal(signum)
    _, err = child.communicate(timeout=DEADLINE_SECONDS)
    status, line = EXPECTED[signum]
    assert (child.returncode, err) == (status, line)
    assert sorted(p.name for p in work.iterdir()) == ["out.npz", "scene.toml"]
    assert out.read_bytes() == b"the old output"


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP, signal.SIGINT],
                         ids=["SIGTERM", "SIGHUP", "SIGINT"])
def test_a_signal_during_the_write_leaves_no_file(tmp_path, signum):
    work, scene, out = _setup(tmp_path, duration=1.0)
    child, marker = _start_child(tmp_path, CHILD, "assembling",
                                 "run", str(scene), "-o", str(out), "--every", "1")
    _wait_for(child, marker.exists)
    # mid-write: the temporary .npz and the four spill files are there
    hidden = sorted(p.name for p in work.iterdir() if p.name.startswith(".out.npz."))
    assert len(hidden) == 5
    assert sum(n.endswith(".tmp") for n in hidden) == 1
    assert sum(n.endswith(".spill") for n in hidden) == 4
    _signal_and_check(child, signum, work, out)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
def test_a_signal_during_a_long_run_leaves_no_file(tmp_path, signum):
    # 10^7 steps of 12 particles (minutes): signalled once its frames spill
    work, scene, out = _setup(tmp_path, duration=1e5)
    child = subprocess.Popen(
        [sys.executable, "-m", "refsim.cli", "run", str(scene), "-o", str(out),
         "--every", "1000000"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def spilling():
        return sum(p.name.endswith(".spill") for p in work.iterdir()) == 4

    _wait_for(child, spilling)
    _signal_and_check(child, signum, work, out)


# -- in this process -----------------------------------------------------------------


def test_signals_raise_turns_sigterm_into_interrupted():
    before = signal.getsignal(signal.SIGTERM)
    with pytest.raises(Interrupted) as info:
        with signals_raise():
            signal.raise_signal(signal.SIGTERM)   # the handler runs before this returns
    assert isinstance(info.value, KeyboardInterrupt)
    assert (info.value.signum, info.value.name, info.value.exit_status) == \
        (signal.SIGTERM, "SIGTERM", 143)
    assert str(info.value) == "interrupted (SIGTERM)"
    assert signal.getsignal(signal.SIGTERM) is before


def test_an_ignored_signal_stays_ignored():
    # nohup: SIGHUP ignored before, so it is not turned into an exception
    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        with signals_raise():
            assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
            assert signal.getsignal(signal.SIGTERM) is not signal.SIG_IGN
        assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
    finally:
        signal.signal(signal.SIGHUP, previous)


def test_after_the_first_signal_the_next_ones_are_ignored():
    # so that a second kill cannot cut the clean-up short
    with pytest.raises(Interrupted):
        with signals_raise():
            try:
                signal.raise_signal(signal.SIGHUP)
            finally:
                assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN
                assert signal.getsignal(signal.SIGHUP) is signal.SIG_IGN
                signal.raise_signal(signal.SIGTERM)   # ignored: the finally completes
                finished = True
    assert finished


class _RaisesInItsFinalizer:
    """An object whose finalizer receives SIGTERM: Python drops an exception
    raised there ("Exception ignored"), as it dropped SIGHUP's in an
    unclosed ZipFile's ``__del__`` under load."""

    def __del__(self):
        signal.raise_signal(signal.SIGTERM)


def _dropped_in_a_finalizer() -> None:
    """SIGTERM raised in a finalizer; asserts Python dropped its exception."""
    dropped = []
    hook, sys.unraisablehook = sys.unraisablehook, dropped.append
    try:
        _RaisesInItsFinalizer()                  # its finalizer runs at once
    finally:
        sys.unraisablehook = hook
    assert [type(d.exc_value) for d in dropped] == [Interrupted]


def test_a_signal_a_finalizer_dropped_is_raised_again_between_blocks():
    from refsim.signals import held_signals, raise_if_interrupted

    reached = []
    with pytest.raises(Interrupted) as info:
        with signals_raise():
            _dropped_in_a_finalizer()            # the next line still runs
            reached.append("after the dropped signal")
            with held_signals() as hold:
                hold.check()                     # between blocks: raised again
            reached.append("after check")
    assert reached == ["after the dropped signal"]
    assert info.value.signum == signal.SIGTERM
    raise_if_interrupted()                       # forgotten once signals_raise ends


def test_a_signal_a_finalizer_dropped_ends_the_command_with_its_status():
    with pytest.raises(Interrupted) as info:
        with signals_raise():
            _dropped_in_a_finalizer()
    assert info.value.exit_status == 143


class _RaisesValueErrorInItsFinalizer:
    def __del__(self):
        raise ValueError("a finalizer's own error")


def test_a_signal_a_finalizer_dropped_is_not_reported_and_other_errors_are():
    # the command's one line says the signal; "Exception ignored" and its
    # traceback would be noise (a run under load once printed llvmlite's).
    # Any other exception a finalizer drops still reaches the hook.
    seen = []
    record = seen.append
    hook, sys.unraisablehook = sys.unraisablehook, record
    try:
        with pytest.raises(Interrupted):
            with signals_raise():
                _RaisesValueErrorInItsFinalizer()
                _RaisesInItsFinalizer()
                assert sys.unraisablehook is not record
        assert sys.unraisablehook is record
    finally:
        sys.unraisablehook = hook
    assert [type(u.exc_value) for u in seen] == [ValueError]


def test_held_signals_wait_for_check_and_leave_the_handlers_as_they_were():
    from refsim.signals import held_signals

    before = signal.getsignal(signal.SIGINT)
    reached = []
    with pytest.raises(KeyboardInterrupt):
        with held_signals() as hold:
            signal.raise_signal(signal.SIGINT)       # held: the next line still runs
            reached.append("after the signal")
            hold.check()                             # acted on here
            reached.append("after check")
    assert reached == ["after the signal"]
    assert signal.getsignal(signal.SIGINT) is before
    # a signal that came after the last check is acted on when the block ends
    with pytest.raises(KeyboardInterrupt):
        with held_signals():
            signal.raise_signal(signal.SIGINT)
    assert signal.getsignal(signal.SIGINT) is before


def test_held_signals_leave_a_signal_the_system_handles_alone():
    from refsim.signals import held_signals

    previous = signal.signal(signal.SIGTERM, signal.SIG_IGN)
    try:
        with held_signals() as hold:
            assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN
            hold.check()
    finally:
        signal.signal(signal.SIGTERM, previous)


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_a_signal_inside_a_constructor_gets_one_line(tmp_path, signum):
    # CI once printed llvmlite's "Exception ignored in: OutputString.__del__"
    # traceback after the one line: the signal had come as numba compiled
    work, scene, out = _setup(tmp_path, duration=1.0)
    child, marker = _start_child(tmp_path, CHILD_IN_CONSTRUCTOR, "constructing",
                                 "run", str(scene), "-o", str(out))
    _wait_for(child, marker.exists)
    _signal_and_check(child, signum, work, out)
