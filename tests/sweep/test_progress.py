"""The progress line: counts and time left, redrawn on a terminal, written
as lines every LOG_SECONDS elsewhere."""

from __future__ import annotations

import io

from refsim.sweep.progress import LOG_SECONDS, Progress


class Terminal(io.StringIO):
    def isatty(self):
        return True


class Clock:
    def __init__(self):
        self.now = 100.0

    def __call__(self):
        return self.now


def test_the_line_shows_counts_failures_and_time_left():
    clock, stream = Clock(), Terminal()
    shown = Progress(10, resumed=2, stream=stream, clock=clock)
    assert shown.line() == "sweep: 2/10 done, time left unknown"
    clock.now += 4.0
    shown.update(4, 1)                   # 2 finished in this run in 4 s: 2 s each, 6 left
    assert shown.seconds_left(clock.now) == 12.0
    assert stream.getvalue() == "\rsweep: 4/10 done, 1 failed, about 0:00:12 left"
    clock.now += 3600.5
    shown.update(9, 1)                   # 7 in 3604.5 s, 1 left: 514.9 s, rounded up
    assert shown.line().endswith("9/10 done, 1 failed, about 0:08:35 left")
    shown.update(10, 1, force=True)
    shown.close()
    assert stream.getvalue().endswith("\rsweep: 10/10 done, 1 failed\n")


def test_redraws_are_limited_and_a_shorter_line_wipes_a_longer_one():
    clock, stream = Clock(), Terminal()
    shown = Progress(3, stream=stream, clock=clock)
    shown.update(1, 1)
    shown.update(2, 1)                   # within MIN_REDRAW_SECONDS: not drawn
    assert stream.getvalue().count("\r") == 1
    clock.now += 1.0
    shown.update(2, 0)
    last = stream.getvalue().split("\r")[-1]
    assert last.rstrip() == "sweep: 2/3 done, about 0:00:01 left"
    assert len(last) == len("sweep: 1/3 done, 1 failed, about 0:00:00 left")


def test_nothing_is_drawn_when_disabled_or_off_a_terminal_for_a_short_sweep():
    for stream, enabled in ((io.StringIO(), True), (Terminal(), False), (io.StringIO(), False)):
        clock = Clock()
        shown = Progress(2, stream=stream, enabled=enabled, clock=clock)
        shown.update(1, 0, force=True)
        clock.now += LOG_SECONDS - 0.5           # a sweep shorter than LOG_SECONDS
        shown.update(2, 0, force=True)
        shown.close()
        assert stream.getvalue() == ""


def test_off_a_terminal_a_long_sweep_writes_a_line_every_log_seconds_and_at_the_end():
    """A log file or a pipe gets whole lines (no carriage returns): the
    first once the sweep has run LOG_SECONDS, then at most every
    LOG_SECONDS however many results arrive, and the final counts."""
    clock, stream = Clock(), io.StringIO()
    shown = Progress(4, stream=stream, clock=clock)
    clock.now += LOG_SECONDS
    shown.update(1, 0)
    for _ in range(3):
        clock.now += 1.0
        shown.update(2, 0)                       # within LOG_SECONDS of the last line
    clock.now += LOG_SECONDS
    shown.update(3, 1)
    shown.close()
    assert "\r" not in stream.getvalue()
    assert stream.getvalue().splitlines() == [
        "sweep: 1/4 done, about 0:00:30 left",
        "sweep: 3/4 done, 1 failed, about 0:00:08 left",
    ]                                # the closing line, the same, is not written again
    clock.now += 1.0
    shown.update(4, 1)
    shown.close()
    assert stream.getvalue().splitlines()[-1] == "sweep: 4/4 done, 1 failed"


def test_a_delayed_line_stays_hidden_on_a_terminal_for_a_short_run():
    """``refsim run``'s line: nothing for a run shorter than the delay, not
    even at the end; after it, redrawn with the run's own words."""
    clock, stream = Clock(), Terminal()
    shown = Progress(1001, stream=stream, clock=clock, label="refsim run", unit="frames",
                     delay=2.0)
    clock.now += 1.9
    shown.update(500, 0)
    shown.close()
    assert stream.getvalue() == ""
    clock, stream = Clock(), Terminal()
    shown = Progress(1001, stream=stream, clock=clock, label="refsim run", unit="frames",
                     delay=2.0)
    clock.now += 2.5
    shown.update(500, 0)                 # 500 frames in 2.5 s: 501 left, 2.505 s
    assert stream.getvalue() == "\rrefsim run: 500/1001 frames, about 0:00:03 left"
    shown.update(1001, 0, force=True)
    shown.close()
    assert stream.getvalue().endswith("\rrefsim run: 1001/1001 frames\n")


def test_a_counted_sink_passes_every_frame_on_and_reports_the_count():
    import numpy as np

    from refsim.storage.frames import CountedSink, MemorySink

    clock, log = Clock(), io.StringIO()
    shown = Progress(3, stream=log, clock=clock, label="refsim run", unit="frames")
    sink = CountedSink(MemorySink(), shown)
    for k in range(3):
        clock.now += LOG_SECONDS
        sink.append({"t": np.float64(k)})
    shown.close()
    assert sink.n_frames == 3 and np.array_equal(sink.arrays()["t"], [0.0, 1.0, 2.0])
    assert log.getvalue().splitlines() == [
        "refsim run: 1/3 frames, about 0:00:20 left",
        "refsim run: 2/3 frames, about 0:00:10 left",
        "refsim run: 3/3 frames"]            # the closing line is not written twice
