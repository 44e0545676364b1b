"""Exact orientation predicates with a floating-point filter.

What: the signs of the two determinants every triangle test in refsim is
built on,

    orient3d(a, b, c, d) = sign det [a - d; b - d; c - d]      (rows, 3 x 3)
    orient2d(a, b, c)    = sign det [a - c; b - c]              (rows, 2 x 2)

``orient3d`` is +1 when ``d`` lies below the plane through ``a, b, c`` (the
side from which ``a, b, c`` appear clockwise), -1 above, 0 on it;
``orient2d`` is +1 when ``a, b, c`` turn counter-clockwise, -1 clockwise, 0
when collinear. Only the sign is ever used, and the sign is exact.

Seed section: S4, level 3 ("exact overlap ... using edge-triangle
intersection tests"). The seed notes that "numerical issues do arise
concerning intersecting nearly parallel edges and plains" (claim C4). This
module is refsim's answer to that remark, its policy for near-degenerate
input: **exact predicates, filtered**.

Reference: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and
Fast Robust Geometric Predicates", Discrete & Computational Geometry 18
(1997), section 4 (the error bounds ``ccwerrboundA`` and ``o3derrboundA`` of
the first, non-adaptive stage, in :mod:`refsim.rounding`).

The filter
----------
The determinant is evaluated in float64 in the order Shewchuk's first stage
uses. He proves that the rounded result differs from the true determinant by
less than ``O3D_ERRBOUND_A * permanent``, where the permanent is the same
expansion with every term made non-negative (evaluated in floats as well; the
constant absorbs the rounding of the differences, the products, the sums and
of the bound itself). So when ``|det| > bound`` the float sign is the true
sign. Otherwise (near-degenerate or exactly degenerate input) the sign is
recomputed exactly: every float is a dyadic rational ``n / 2**k``, so
multiplying all coordinates by the largest denominator turns them into
Python integers without changing the sign of either determinant, and integer
arithmetic is exact. Shewchuk's adaptive stages B to D are not reproduced;
the exact fallback is slower than his expansions but simple to check, and it
fires rarely (``refsim.studies.triangles.measure_filter_fallback``).

DEVIATION (from Shewchuk): his analysis assumes no underflow or overflow. We
trust the filter only when every nonzero coordinate has magnitude in
``[FILTER_MIN_ABS, FILTER_MAX_ABS]``; then every difference, product and sum
of the expansion stays in float64's normal range (see the constants). Input
outside that range is answered by the exact path alone.

Three predicate sets share one interface (:class:`Predicates`), so that the
triangle tests are written once and run with any of them:

- ``FILTERED``: filter, then exact (refsim's default; needs in-range input);
- ``EXACT``: exact arithmetic always (input outside the filter's range);
- ``FLOAT``: the plain float sign, no filter (the unrobust test of 1997,
  kept only to measure claim C4).

Cost: O(1) each; a filtered call is a few dozen float operations, the exact
fallback a few dozen operations on integers of up to ~3 x 2100 bits.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

from refsim.errors import StateError
from refsim.rounding import O2D_ERRBOUND_A, O3D_ERRBOUND_A

#: Smallest nonzero coordinate magnitude the filter trusts. A nonzero
#: difference of two such floats is at least 2**-292 (one ulp of 2**-240), a
#: product of three differences at least 2**-876: all above the smallest
#: normal float, 2**-1022, so no rounding step leaves Shewchuk's relative-error
#: model. (About 5.7e-73; coordinates in metres never come near it.)
FILTER_MIN_ABS = 2.0 ** -240

#: Largest coordinate magnitude the filter trusts. Differences are then at
#: most 2**300, products of three at most 2**900, the six-term permanent below
#: 2**903: far below float64's overflow at 2**1024. (About 1e90.)
FILTER_MAX_ABS = 2.0 ** 299


def in_filter_range(values: Sequence[float]) -> bool:
    """True when every value is 0 or has magnitude in the filter's range."""
    for x in values:
        m = abs(x)
        if m != 0.0 and not (FILTER_MIN_ABS <= m <= FILTER_MAX_ABS):
            return False
    return True


def _sign(x) -> int:
    return (x > 0) - (x < 0)


def _scaled_integers(values: Sequence[float]) -> list[int]:
    """The values times their common power-of-two denominator, as exact ints.

    Every finite float is ``n / 2**k``; scaling all of them by the same
    positive factor leaves the sign of any determinant of their differences
    unchanged (the determinants are homogeneous).
    """
    ratios = [float(v).as_integer_ratio() for v in values]
    denominator = max(d for _, d in ratios)
    return [n * (denominator // d) for n, d in ratios]


# --------------------------------------------------------------------------
# orient3d
# --------------------------------------------------------------------------

def orient3d_terms(a, b, c, d):
    """Float determinant and permanent of orient3d, in Shewchuk's evaluation
    order (the permanent bounds the determinant's rounding error)."""
    adx, ady, adz = a[0] - d[0], a[1] - d[1], a[2] - d[2]
    bdx, bdy, bdz = b[0] - d[0], b[1] - d[1], b[2] - d[2]
    cdx, cdy, cdz = c[0] - d[0], c[1] - d[1], c[2] - d[2]
    bdxcdy, cdxbdy = bdx * cdy, cdx * bdy
    cdxady, adxcdy = cdx * ady, adx * cdy
    adxbdy, bdxady = adx * bdy, bdx * ady
    det = (adz * (bdxcdy - cdxbdy)
           + bdz * (cdxady - adxcdy)
           + cdz * (adxbdy - bdxady))
    permanent = ((abs(bdxcdy) + abs(cdxbdy)) * abs(adz)
                 + (abs(cdxady) + abs(adxcdy)) * abs(bdz)
                 + (abs(adxbdy) + abs(bdxady)) * abs(cdz))
    return det, permanent


def orient3d_exact(a, b, c, d) -> int:
    """Sign of orient3d computed in exact integer arithmetic."""
    ax, ay, az, bx, by, bz, cx, cy, cz, dx, dy, dz = _scaled_integers(
        (*a[:3], *b[:3], *c[:3], *d[:3]))
    adx, ady, adz = ax - dx, ay - dy, az - dz
    bdx, bdy, bdz = bx - dx, by - dy, bz - dz
    cdx, cdy, cdz = cx - dx, cy - dy, cz - dz
    det = (adz * (bdx * cdy - cdx * bdy)
           + bdz * (cdx * ady - adx * cdy)
           + cdz * (adx * bdy - bdx * ady))
    return _sign(det)


def orient3d_filtered(a, b, c, d) -> tuple[int, bool]:
    """``(sign, certified)``: the exact sign, and whether the float filter
    alone decided it (``False`` means the exact fallback ran).

    The points must be in the filter's range (:func:`in_filter_range`).
    """
    det, permanent = orient3d_terms(a, b, c, d)
    bound = O3D_ERRBOUND_A * permanent
    if det > bound or -det > bound:
        return (1 if det > 0 else -1), True
    return orient3d_exact(a, b, c, d), False


def orient3d_filtered_sign(a, b, c, d) -> int:
    """Exact sign of orient3d via the filter (in-range input only)."""
    det, permanent = orient3d_terms(a, b, c, d)
    bound = O3D_ERRBOUND_A * permanent
    if det > bound:
        return 1
    if -det > bound:
        return -1
    return orient3d_exact(a, b, c, d)


def orient3d_float(a, b, c, d) -> int:
    """Sign of the float determinant, unfiltered (NOT robust; for C4 only)."""
    det, _ = orient3d_terms(a, b, c, d)
    return _sign(det)


def orient3d(a, b, c, d) -> int:
    """Exact orientation of point ``d`` relative to the plane through a, b, c.

    Parameters
    ----------
    a, b, c, d : sequence of 3 floats
        Finite coordinates.

    Returns
    -------
    int
        +1 if ``d`` is below the plane (``a, b, c`` clockwise seen from
        ``d``), -1 if above, 0 if the four points are coplanar. Exact.

    Raises
    ------
    StateError
        If a coordinate is not finite.
    """
    values = _checked((a, b, c, d), 3)
    if in_filter_range(values):
        return orient3d_filtered_sign(a, b, c, d)
    return orient3d_exact(a, b, c, d)


# --------------------------------------------------------------------------
# orient2d
# --------------------------------------------------------------------------

def _orient2d_terms(a, b, c):
    detleft = (a[0] - c[0]) * (b[1] - c[1])
    detright = (a[1] - c[1]) * (b[0] - c[0])
    return detleft - detright, abs(detleft) + abs(detright)


def orient2d_exact(a, b, c) -> int:
    """Sign of orient2d computed in exact integer arithmetic."""
    ax, ay, bx, by, cx, cy = _scaled_integers((*a[:2], *b[:2], *c[:2]))
    return _sign((ax - cx) * (by - cy) - (ay - cy) * (bx - cx))


def orient2d_filtered(a, b, c) -> tuple[int, bool]:
    """``(sign, certified)`` as :func:`orient3d_filtered`, in the plane."""
    det, permanent = _orient2d_terms(a, b, c)
    bound = O2D_ERRBOUND_A * permanent
    if det > bound or -det > bound:
        return (1 if det > 0 else -1), True
    return orient2d_exact(a, b, c), False


def orient2d_filtered_sign(a, b, c) -> int:
    """Exact sign of orient2d via the filter (in-range input only)."""
    det, permanent = _orient2d_terms(a, b, c)
    bound = O2D_ERRBOUND_A * permanent
    if det > bound:
        return 1
    if -det > bound:
        return -1
    return orient2d_exact(a, b, c)


def orient2d_float(a, b, c) -> int:
    """Sign of the float determinant, unfiltered (NOT robust; for C4 only)."""
    det, _ = _orient2d_terms(a, b, c)
    return _sign(det)


def orient2d(a, b, c) -> int:
    """Exact orientation of the planar points a, b, c.

    Returns +1 for a counter-clockwise turn, -1 for clockwise, 0 when
    collinear. Raises :class:`StateError` for a non-finite coordinate.
    """
    values = _checked((a, b, c), 2)
    if in_filter_range(values):
        return orient2d_filtered_sign(a, b, c)
    return orient2d_exact(a, b, c)


def _checked(points, dim: int) -> list[float]:
    values = []
    for p in points:
        if len(p) != dim:
            raise StateError(f"expected {dim} coordinates per point, got {len(p)}")
        for x in p:
            x = float(x)
            if x != x or x in (float("inf"), float("-inf")):
                raise StateError("non-finite coordinate in an orientation predicate")
            values.append(x)
    return values


# --------------------------------------------------------------------------
# predicate sets
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class Predicates:
    """A pair of orientation predicates the triangle tests are written over.

    ``orient3d(a, b, c, d) -> int`` and ``orient2d(a, b, c) -> int`` return
    signs in {-1, 0, +1}. ``exact`` says whether the signs are the true ones.
    """

    name: str
    orient3d: Callable[..., int]
    orient2d: Callable[..., int]
    exact: bool


#: Filter then exact fallback: refsim's policy (input in the filter's range).
FILTERED = Predicates("filtered", orient3d_filtered_sign, orient2d_filtered_sign, True)

#: Exact integer arithmetic always: input outside the filter's range.
EXACT = Predicates("exact", orient3d_exact, orient2d_exact, True)

#: The plain float sign: what a 1997 implementation computed. Not robust.
FLOAT = Predicates("float", orient3d_float, orient2d_float, False)
