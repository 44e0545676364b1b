"""The progress line of a sweep or a long run, on stderr: done/total,
failures, time left.

``sweep: 12/16 done, 1 failed, about 0:00:07 left`` is redrawn in place
(carriage return) as results arrive and at least every
``REFRESH_SECONDS`` while they do not. The estimate is the elapsed time
over the tasks finished in this run (results resumed from a store took no
time now and are left out), times the tasks left. Being wall time per task,
not a task's own time, it already accounts for W workers running at once.

The line goes to stderr only, never to stdout (which may carry a result a
script pipes on). On a terminal it is redrawn; elsewhere (a log file, CI, a
pipe) a line redrawn a thousand times is noise, so a sweep that has run for
``LOG_SECONDS`` writes the line as a line of its own, then again at most
every ``LOG_SECONDS``, and once more at the end: a long run off a terminal
is never silent, and a short one writes nothing.

Cost: O(1) per update; a redraw at most every ``MIN_REDRAW_SECONDS``.
"""

from __future__ import annotations

import sys
import time

#: The line is redrawn at most this often: faster than the eye reads, and a
#: sweep of many fast tasks would otherwise spend its time writing to the tty.
MIN_REDRAW_SECONDS = 0.1

#: Without results, the line is still redrawn this often, so that the time
#: shown keeps moving (and the run loop wakes this often to draw it).
REFRESH_SECONDS = 0.5

#: Off a terminal, the line is written (as a line of its own) at most this
#: often, and not before the sweep has run this long.
LOG_SECONDS = 10.0


class Progress:
    """One sweep's progress line (state: counts, start time, last redraw).

    Parameters
    ----------
    total : int
        Tasks in the sweep.
    resumed : int
        Tasks already done when the sweep started (their results were stored).
    enabled : bool
        Draw at all; on a terminal the line is redrawn in place, elsewhere
        written as whole lines every ``LOG_SECONDS`` (module docstring).
    stream : file, optional
        Where to draw; default ``sys.stderr``.
    clock : callable, optional
        Seconds, monotonic; default ``time.monotonic`` (tests pass their own).
    label, unit : str
        The line reads ``{label}: {done}/{total} {unit}``; default a sweep's
        ``sweep: 12/16 done`` (``refsim run``: ``refsim run: 230/1001 frames``).
    delay : float
        On a terminal, draw nothing before this many seconds (s), and at the
        end only if something was drawn: a run that ends sooner leaves no
        line (default 0: a sweep draws at once).
    """

    def __init__(self, total: int, resumed: int = 0, *, enabled: bool = True, stream=None,
                 clock=time.monotonic, label: str = "sweep", unit: str = "done",
                 delay: float = 0.0):
        self.label, self.unit, self.delay = label, unit, delay
        self.stream = sys.stderr if stream is None else stream
        self.enabled = bool(enabled)
        self.terminal = _is_terminal(self.stream)
        self.total = total
        self.resumed = resumed
        self.done = resumed
        self.failed = 0
        self._clock = clock
        self._start = clock()
        self._drawn_at = None
        self._width = 0
        self._logged = False
        self._last_logged = ""

    def update(self, done: int, failed: int, *, force: bool = False) -> None:
        """Record ``done`` finished tasks (resumed ones included; failures
        included) of which ``failed`` failed, and redraw if it is time."""
        self.done, self.failed = done, failed
        now = self._clock()
        if not self.enabled:
            return
        if not self.terminal:
            last = self._start if self._drawn_at is None else self._drawn_at
            if now - last >= LOG_SECONDS:
                self._log(self.line(now))
                self._drawn_at = now
            return
        if self._drawn_at is None and now - self._start < self.delay:
            return
        if not force and self._drawn_at is not None and now - self._drawn_at < MIN_REDRAW_SECONDS:
            return
        self._draw(self.line(now))
        self._drawn_at = now

    def line(self, now: float | None = None) -> str:
        """The text of the line at time ``now`` (default: the clock's now)."""
        now = self._clock() if now is None else now
        text = f"{self.label}: {self.done}/{self.total} {self.unit}"
        if self.failed:
            text += f", {self.failed} failed"
        left = self.seconds_left(now)
        if self.done < self.total:
            text += ", time left unknown" if left is None else f", about {_clock_text(left)} left"
        return text

    def seconds_left(self, now: float) -> float | None:
        """Elapsed time per task finished in this run times the tasks left;
        None before the first task of this run has finished."""
        finished_now = self.done - self.resumed
        if finished_now <= 0:
            return None
        return (now - self._start) / finished_now * (self.total - self.done)

    def close(self) -> None:
        """Draw the final line and end it with a newline (off a terminal:
        write it, if the sweep wrote any line before)."""
        if not self.enabled:
            return
        if not self.terminal:
            final = self.line()
            if self._logged and final != self._last_logged:    # not the same line twice
                self._log(final)
            return
        if self.delay and self._drawn_at is None:
            return
        self._draw(self.line())
        self.stream.write("\n")
        self.stream.flush()

    def _log(self, text: str) -> None:
        self.stream.write(text + "\n")
        self.stream.flush()
        self._logged = True
        self._last_logged = text

    def _draw(self, text: str) -> None:
        pad = " " * max(0, self._width - len(text))     # wipe a longer previous line
        self.stream.write("\r" + text + pad)
        self.stream.flush()
        self._width = len(text)


def _is_terminal(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):               # no isatty, or a closed stream
        return False


def _clock_text(seconds: float) -> str:
    """``H:MM:SS``, rounded up to the second."""
    whole = int(-(-seconds // 1))
    return f"{whole // 3600}:{whole // 60 % 60:02d}:{whole % 60:02d}"
