"""The charts' axes and marks as a reader sees them: tick labels that do not
run into each other on a short log axis, a marked line's label inside its
plot."""

from __future__ import annotations

import re

import pytest

from refsim.report.charts import Series, _short_log_ticks, line_chart


@pytest.mark.parametrize(("lo", "hi", "ticks"), [
    (1.0, 6.0, [1.0, 2.0, 5.0]),                   # 1, 2, 5 within the decade
    (0.9, 60.0, [1.0, 2.0, 5.0, 10.0, 20.0, 50.0]),
    (1.1e-4, 3.7e-4, [2e-4, 3e-4]),               # too short for 1, 2, 5: integers
    (2.1, 2.9, []),                                # not even two integers: matplotlib's own
])
def test_short_log_axes_are_ticked_at_round_values(lo, hi, ticks):
    assert _short_log_ticks(lo, hi) == pytest.approx(ticks)


def _texts(svg: str) -> list[str]:
    return re.findall(r">([^<>]+)</text>", svg)


def test_a_short_log_axis_has_plain_labels_at_round_values_only():
    """A wall-time axis from 0.11 to 0.37 ms: matplotlib's default labels it
    at 1.5, 2, 2.5, 3 and 3.5 x 10^-4 in scientific notation, which overlap."""
    svg = line_chart([Series("a", [1.1e-4, 1.5e-4, 2.5e-4, 3.7e-4], [1, 0.1, 0.01, 0.001])],
                     xlabel="wall time (s)", ylabel="error", logx=True, logy=True)
    texts = _texts(svg)
    assert "0.0002" in texts and "0.0003" in texts
    assert not any(t.startswith(("0.00015", "0.00025", "0.00035")) for t in texts)


@pytest.mark.parametrize(("x", "anchor"), [(2000, "end"), (80, "start")])
def test_a_marked_line_is_labelled_on_the_side_with_room(x, anchor):
    """A crossover in the right half of the plot is labelled to its left
    (the text ends at the line), one in the left half to its right."""
    label = f"compiled crossover: {x} triangles"
    svg = line_chart([Series("a", [12, 80, 500, 2000, 5000, 20480], [1, 2, 3, 4, 5, 6])],
                     xlabel="triangles", ylabel="us", logx=True, logy=True,
                     vlines=[(x, label)])
    (style,) = re.findall(r'<text style="([^"]*)"[^>]*>' + re.escape(label), svg)
    assert (f"text-anchor: {anchor}" in style) or (anchor == "start"
                                                    and "text-anchor" not in style)
