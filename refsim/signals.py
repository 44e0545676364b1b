"""SIGTERM and SIGHUP as exceptions, so that they unwind like Ctrl-C.

Python turns SIGINT into ``KeyboardInterrupt``, which unwinds the stack and
runs every ``finally`` and ``except BaseException`` on the way: the
temporary and spill files of :mod:`refsim.storage.writing` and :mod:`refsim.storage.frames` are
removed. SIGTERM (``kill``, a batch system's time limit) and SIGHUP (a
closed terminal) kill the process by default without any of that, leaving
the hidden files behind. :func:`signals_raise` installs handlers that raise
:class:`Interrupted`, a ``KeyboardInterrupt``, so the same clean-up runs;
the command line then exits with status 128 + the signal's number, as a
shell reports a process killed by it.

After the first signal both handlers ignore further ones, so a second
``kill`` cannot cut the clean-up short (SIGKILL still ends the process).

Only the command line installs these (an application that imports refsim
keeps its own handlers). A signal that is ignored when they are installed
stays ignored (``nohup refsim run ...`` survives a closed terminal). Python
runs signal handlers in the main thread only; elsewhere this is a no-op.
"""

from __future__ import annotations

import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager

try:
    # The C functions behind signal.getsignal and signal.signal, without
    # their conversions of numbers to enums, which cost ten times the call
    # itself: held_signals swaps handlers at every Simulation.run call and
    # every Simulation.advance call but the compiled loop's short ones
    # (docs/decisions/compiled-loop.md, "One step per call"). They take and
    # return the same handlers (SIG_DFL and SIG_IGN as plain numbers).
    from _signal import getsignal as _getsignal  # type: ignore[import-not-found]
    from _signal import signal as _setsignal
except ImportError:  # an interpreter without CPython's _signal module
    _getsignal, _setsignal = signal.getsignal, signal.signal

#: The signals :func:`signals_raise` turns into :class:`Interrupted`.
RAISED = tuple(getattr(signal, name) for name in ("SIGTERM", "SIGHUP")
               if hasattr(signal, name))                    # no SIGHUP on Windows


class Interrupted(KeyboardInterrupt):
    """The process received ``signum`` (SIGTERM or SIGHUP) and is unwinding."""

    def __init__(self, signum: int):
        self.signum = int(signum)
        self.name = signal.Signals(signum).name
        super().__init__(f"interrupted ({self.name})")

    @property
    def exit_status(self) -> int:
        """128 + the signal's number (the shell's convention)."""
        return 128 + self.signum


#: The signal :func:`_raise` turned into :class:`Interrupted`, kept until
#: :func:`signals_raise` ends: Python drops an exception raised while a
#: finalizer runs (a ``__del__`` called by the garbage collector, such as an
#: unclosed ``ZipFile``'s or llvmlite's), and passes it to
#: ``sys.unraisablehook`` (which :func:`signals_raise` keeps quiet for it);
#: with further signals ignored, nothing would then stop the work.
_delivered: list[int] = []


def _raise(signum, frame):
    for s in RAISED:
        signal.signal(s, signal.SIG_IGN)          # once: let the clean-up finish
    _delivered.append(int(signum))
    raise Interrupted(signum)


def raise_if_interrupted() -> None:
    """Raise :class:`Interrupted` again for a signal whose first one was
    dropped by a finalizer (see ``_delivered``); nothing otherwise. Long
    work calls it between its blocks: :meth:`SignalHold.check` (the
    simulation), and the particle system after each readable step and each
    fused block, whichever kernel and tier runs it."""
    if _delivered:
        raise Interrupted(_delivered[0])


@contextmanager
def signals_raise() -> Iterator[None]:
    """Within the body, SIGTERM and SIGHUP raise :class:`Interrupted`; the
    previous handlers are restored afterwards. Call from the main thread."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.getsignal(s) for s in RAISED}
    previous_hook = sys.unraisablehook

    def unraisable(args) -> None:
        # an Interrupted a finalizer dropped is raised again
        # (raise_if_interrupted): the one line the command prints says it.
        # Once the command has caught it, refsim.cli.app's
        # _quiet_finalizers drops every later report instead.
        if not isinstance(args.exc_value, Interrupted):
            previous_hook(args)

    for s, handler in previous.items():
        if handler is not signal.SIG_IGN:
            signal.signal(s, _raise)
    sys.unraisablehook = unraisable
    try:
        yield
        raise_if_interrupted()                   # the body ended though a signal came
    finally:
        _delivered.clear()
        sys.unraisablehook = previous_hook
        for s, handler in previous.items():
            # None: a handler installed outside Python, not restorable from here
            signal.signal(s, signal.SIG_DFL if handler is None else handler)


class SignalHold:
    """Signals held by :func:`held_signals`, acted on at :meth:`check`; the
    context manager that :func:`held_signals` returns (a class rather than a
    generator, which costs more to enter: it is entered at every
    ``Simulation.advance`` call)."""

    def __init__(self) -> None:
        self.caught: list[int] = []
        self._previous: dict[int, object] = {}
        self._signums: tuple[int, ...] = ()

    def __enter__(self) -> SignalHold:
        if threading.current_thread() is threading.main_thread():
            self._signums = tuple(s for s in (signal.SIGINT, *RAISED)
                                  if callable(_getsignal(s)))
            self._install()
        return self

    def __exit__(self, *exc_info) -> None:
        self._restore()
        if self.caught:                          # came after the last check
            signal.raise_signal(self.caught[0])

    def _hold(self, signum, frame) -> None:
        self.caught.append(signum)

    def _install(self) -> None:
        self._previous = {s: _setsignal(s, self._hold) for s in self._signums}

    def _restore(self) -> None:
        for s, handler in self._previous.items():
            _setsignal(s, handler)                  # what _setsignal returned
        self._previous = {}

    def check(self) -> None:
        """At a point where the caller's state is whole: act on the first
        signal that came while held, as its own handler would have (a
        ``KeyboardInterrupt`` or :class:`Interrupted` raised from here); a
        handler that returns lets the work go on, held again. Also raises
        again a signal a finalizer dropped (:func:`raise_if_interrupted`)."""
        if not self.caught:
            raise_if_interrupted()
            return
        signum = self.caught[0]
        self.caught.clear()
        self._restore()
        signal.raise_signal(signum)              # runs its handler before returning
        self._install()


def held_signals() -> SignalHold:
    """Within the body (``with held_signals() as hold:``), the signals whose
    handler is Python code (Ctrl-C's, and SIGTERM and SIGHUP under
    :func:`signals_raise`) are held until the body calls
    :meth:`SignalHold.check`, so that work which moves state in native code
    and then counts it (the compiled simulation loop) is never cut between
    the two. A signal left to the system (SIG_DFL, SIG_IGN, or a handler
    installed outside Python) is not touched. In threads other than the main
    one nothing is held (Python runs handlers in the main thread). A signal
    that came after the last check is raised on leaving."""
    return SignalHold()
