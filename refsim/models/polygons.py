"""Large planar polygons: the families the triangulation is measured on (seed S1).

Each function returns the corners (k, 3) of one polygon in the plane z = 0,
counter-clockwise, from closed formulas (and, for ``random_star``, a seeded
generator), so the same call gives the same polygon on every run. They are
the typical shapes of a big AC3D surface, and the ones that stress ear
clipping differently (:mod:`refsim.models.ear_index`, Cost):

- ``circle``: convex; every corner an ear; the clipping is a fan.
- ``star``: tips and notches alternating; half the corners reflex, long
  slivers for ears.
- ``comb``: teeth of width 1 with notches between; the reflex corners in a row.
- ``spiral``: a band wound five times; reflex corners along the inner arm.
- ``random_star``: a random radius at every corner: nearly half the corners
  reflex, every ear a sliver through them (the hard typical case).
- ``collinear_square``: a unit square with its corners spread along the sides:
  all but four corners straight.
- ``spiked_circle``: a circle with a zero-width spike towards the centre at
  every other corner, each visiting its base point twice (repeated points).
- ``bridged_annulus``: a ring with a hole, the hole joined to the outline by a
  zero-width bridge, as modellers export a face with a hole (repeated points).

``KINDS`` maps each name to its function. Cost: O(k) each.
"""

from __future__ import annotations

import numpy as np


def _plane(xy: np.ndarray) -> np.ndarray:
    """(k, 2) -> (k, 3) with z = 0."""
    return np.column_stack([xy, np.zeros(len(xy))])


def _angles(k: int) -> np.ndarray:
    return 2.0 * np.pi * np.arange(k) / k


def circle(k: int) -> np.ndarray:
    """``k`` corners on the unit circle."""
    t = _angles(k)
    return _plane(np.column_stack([np.cos(t), np.sin(t)]))


def star(k: int, inner: float = 0.35) -> np.ndarray:
    """``k // 2`` tips on the unit circle, notches at radius ``inner`` between
    (``k`` rounded down to even)."""
    k -= k % 2
    t = np.pi / 2 + _angles(k)
    r = np.where(np.arange(k) % 2 == 0, 1.0, inner)
    return _plane(np.column_stack([r * np.cos(t), r * np.sin(t)]))


def comb(k: int) -> np.ndarray:
    """``k // 4`` teeth of width 1 and height 2 on a base of height 1, notches
    of width 1 between them: exactly ``4 (k // 4)`` corners."""
    teeth = k // 4
    width = 2 * teeth - 1
    xy = [(0.0, 0.0), (float(width), 0.0)]
    for j in range(teeth - 1, -1, -1):
        xy += [(2.0 * j + 1, 3.0), (2.0 * j, 3.0)]
        if j > 0:
            xy += [(2.0 * j, 1.0), (2.0 * j - 1, 1.0)]
    return _plane(np.array(xy))


def spiral(k: int, turns: float = 5.0) -> np.ndarray:
    """A band between the spirals ``r = 1 + t`` and ``r = 0.5 + t``, ``t`` up to
    ``2 pi turns``: out along the outer edge, back along the inner one."""
    n = k // 2
    t = np.linspace(0.0, 2.0 * np.pi * turns, n)
    outer = np.column_stack([(1.0 + t) * np.cos(t), (1.0 + t) * np.sin(t)])
    inner = np.column_stack([(0.5 + t) * np.cos(t), (0.5 + t) * np.sin(t)])[::-1]
    return _plane(np.vstack([outer, inner]))


def random_star(k: int, seed: int = 0) -> np.ndarray:
    """``k`` corners at sorted random angles with random radii in [0.2, 1]:
    star-shaped about the origin, so simple (the largest angular gap of a few
    thousand uniform angles is far below half a turn; checked)."""
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 2.0 * np.pi, k))
    if np.diff(np.append(t, t[0] + 2.0 * np.pi)).max() >= np.pi:
        raise ValueError("random_star: angular gap of half a turn; use more corners")
    r = rng.uniform(0.2, 1.0, k)
    return _plane(np.column_stack([r * np.cos(t), r * np.sin(t)]))


def collinear_square(k: int) -> np.ndarray:
    """The unit square with ``k // 4`` evenly spaced corners per side."""
    m = k // 4
    s = np.arange(m) / m
    zero, one = np.zeros(m), np.ones(m)
    return _plane(np.vstack([np.column_stack([s, zero]), np.column_stack([one, s]),
                             np.column_stack([1.0 - s, one]), np.column_stack([zero, 1.0 - s])]))


def spiked_circle(k: int) -> np.ndarray:
    """``2 (k // 4)`` base corners on the unit circle, every other one followed
    by a spike to half its radius and back to the base point: ``4 (k // 4)``
    corners, each spiked base point visited twice, each spike tip a zero turn."""
    n = 2 * (k // 4)
    t = _angles(n)
    p = np.column_stack([np.cos(t), np.sin(t)])
    xy = []
    for j in range(n):
        xy.append(p[j])
        if j % 2 == 0:
            xy += [0.5 * p[j], p[j]]
    return _plane(np.array(xy))


def bridged_annulus(k: int, hole: float = 0.5) -> np.ndarray:
    """The unit disc minus the disc of radius ``hole``, both outlines regular
    polygons, joined along the positive x axis: the outline from (1, 0) round
    and back to (1, 0), across to the hole, round the hole clockwise, and back
    across. ``k`` corners (at least 8), two points visited twice."""
    n_out = (k - 2) // 2
    n_in = k - 2 - n_out
    t_out, t_in = _angles(n_out), _angles(n_in)
    outer = np.column_stack([np.cos(t_out), np.sin(t_out)])
    inner = hole * np.column_stack([np.cos(t_in), np.sin(t_in)])
    inner_cw = np.vstack([inner[:1], inner[:0:-1]])
    return _plane(np.vstack([outer, outer[:1], inner_cw, inner[:1]]))


KINDS = {
    "circle": circle,
    "star": star,
    "comb": comb,
    "spiral": spiral,
    "random_star": random_star,
    "collinear_square": collinear_square,
    "spiked_circle": spiked_circle,
    "bridged_annulus": bridged_annulus,
}
