"""A small progress bar for long report runs (stderr; plain lines when piped)."""

from __future__ import annotations

import sys
import time


class Progress:
    """``with Progress(total) as p: p.step("label")`` after each unit of work."""

    def __init__(self, total: int, stream=None, width: int = 30):
        self.total = total
        self.done = 0
        self.width = width
        self.stream = stream if stream is not None else sys.stderr
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.start = time.perf_counter()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()

    def announce(self, label: str) -> None:
        """Say what is being worked on now."""
        self._draw(label)

    def step(self, label: str = "") -> None:
        self.done += 1
        self._draw(label)

    def _draw(self, label: str) -> None:
        filled = int(self.width * self.done / max(self.total, 1))
        bar = "#" * filled + "-" * (self.width - filled)
        elapsed = time.perf_counter() - self.start
        line = f"[{bar}] {self.done}/{self.total} {elapsed:6.1f}s {label}"
        if self.tty:
            self.stream.write("\r" + line.ljust(100)[:100])
        else:
            self.stream.write(line + "\n")
        self.stream.flush()
