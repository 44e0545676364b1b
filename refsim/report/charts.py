"""Charts as inline SVG text (matplotlib, deterministic output).

matplotlib draws log-log axes, contours (stability regions) and legends well
and writes SVG directly. Its SVG carries a date and random element ids unless
told otherwise; here the date is dropped and the id salt fixed, so that the
same numbers give the same bytes on every run.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Series:
    """One line or set of points: ``label``, ``x``, ``y`` and matplotlib style."""

    label: str
    x: Sequence[float]
    y: Sequence[float]
    style: str = "o-"


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    matplotlib.rcParams.update({
        "svg.hashsalt": "refsim",
        "svg.fonttype": "none",        # text stays text: smaller, searchable
        "font.size": 9,
        "axes.grid": True,
        "grid.alpha": 0.3,
        "figure.dpi": 100,
    })
    import matplotlib.pyplot as plt

    return plt


def to_svg(fig) -> str:
    """The figure as an ``<svg>`` element (no XML prolog), then closed."""
    plt = _pyplot()
    buffer = io.StringIO()
    fig.savefig(buffer, format="svg", bbox_inches="tight", metadata={"Date": None})
    plt.close(fig)
    text = buffer.getvalue()
    return text[text.index("<svg"):]


def line_chart(series: Sequence[Series], *, xlabel: str, ylabel: str, title: str = "",
               logx: bool = False, logy: bool = False, vlines: Sequence[tuple[float, str]] = (),
               size: tuple[float, float] = (6.0, 3.8)) -> str:
    """Lines or points; ``vlines`` marks x positions with a label (a crossover)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=size)
    for s in series:
        ax.plot(np.asarray(s.x, float), np.asarray(s.y, float), s.style, label=s.label,
                markersize=4, linewidth=1.2)
    if logx:
        ax.set_xscale("log")
    if logy:
        ax.set_yscale("log")
    for x, label in vlines:
        ax.axvline(x, color="0.3", linestyle=":", linewidth=1)
        _mark(ax, x, label)
    _readable_ticks(ax)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    if any(s.label for s in series):
        ax.legend(fontsize=8)
    return to_svg(fig)


def _mark(ax, x: float, label: str) -> None:
    """``label`` beside the vertical line at ``x``, at the foot of the plot
    and on the side with more room, so that it stays inside the axes."""
    ax.autoscale_view()
    fraction = ax.transAxes.inverted().transform(ax.transData.transform((x, 0)))[0]
    left = fraction > 0.5
    ax.annotate(label, (x, 0.0), xycoords=("data", "axes fraction"),
                xytext=(-4 if left else 4, 4), textcoords="offset points", fontsize=8,
                ha="right" if left else "left", va="bottom",
                bbox={"boxstyle": "square,pad=0.15", "facecolor": "white", "edgecolor": "none",
                      "alpha": 0.8})


#: A log axis spanning fewer decades than this is labelled in plain numbers
#: at 1, 2 and 5 times each power of ten (1 to 9 where those are too few);
#: a longer one at the powers alone. matplotlib's default labels a short log
#: axis at linear steps in full scientific notation, and those labels run
#: into each other.
SHORT_LOG_AXIS = 2.0


def _short_log_ticks(lo: float, hi: float) -> list[float]:
    """Ticks for a log axis from ``lo`` to ``hi`` (few decades): 1, 2, 5 per
    decade, or every integer multiple when that gives fewer than two."""
    decades = range(int(np.floor(np.log10(lo))), int(np.ceil(np.log10(hi))) + 1)
    for multiples in ((1, 2, 5), range(1, 10)):
        ticks = [m * 10.0**k for k in decades for m in multiples if lo <= m * 10.0**k <= hi]
        if len(ticks) >= 2:
            return ticks
    return []


def _readable_ticks(ax) -> None:
    """Tick labels that do not overlap on a log axis: none on minor ticks,
    and on a short axis plain numbers at a few round values."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter

    ax.autoscale_view()
    for axis, (lo, hi) in ((ax.xaxis, ax.get_xlim()), (ax.yaxis, ax.get_ylim())):
        if axis.get_scale() != "log" or not (0 < lo < hi):
            continue
        axis.set_minor_formatter(NullFormatter())
        ticks = _short_log_ticks(lo, hi) if np.log10(hi / lo) < SHORT_LOG_AXIS else []
        if ticks:
            axis.set_major_locator(FixedLocator(ticks))
            axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))


def contour_chart(x: np.ndarray, y: np.ndarray, fields: Sequence[tuple[str, np.ndarray]],
                  level: float, *, xlabel: str, ylabel: str, title: str = "",
                  size: tuple[float, float] = (5.0, 4.5)) -> str:
    """For each (label, z) draw the curve z = level (e.g. |R(z)| = 1)."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=size)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, (label, z) in enumerate(fields):
        color = colors[i % len(colors)]
        ax.contour(x, y, z, levels=[level], colors=[color], linewidths=1.2)
        ax.plot([], [], color=color, label=label)
    ax.axhline(0, color="0.5", linewidth=0.6)
    ax.axvline(0, color="0.5", linewidth=0.6)
    ax.set_aspect("equal")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    ax.legend(fontsize=8, loc="upper left")
    return to_svg(fig)


def bar_chart(labels: Sequence[str], values: Sequence[float], *, ylabel: str,
              title: str = "", logy: bool = False, size: tuple[float, float] = (6.0, 3.2)) -> str:
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=size)
    ax.bar(range(len(values)), values, color="#4477aa")
    ax.set_xticks(range(len(values)), labels, rotation=45, ha="right",
                  rotation_mode="anchor")
    if logy:
        ax.set_yscale("log")
    ax.set_ylabel(ylabel)
    if title:
        ax.set_title(title)
    return to_svg(fig)
