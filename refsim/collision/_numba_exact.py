"""Compiled exact stage of the triangle test (seed S4, level 3): exact
orientation signs by floating-point expansions, and the readable
edge-triangle test written over them, for the pairs the float filter cannot
certify (touching and coplanar contact: cubes face to face, a cube resting on
a sphere).

What: :func:`triangles_intersect_exact` answers the same question as
:func:`refsim.collision.triangle.triangles_intersect`, with the same answer,
for two non-degenerate triangles whose coordinates lie in the filter's range
(``FILTER_MIN_ABS``..``FILTER_MAX_ABS`` or zero); any other pair is reported
undecided and goes to the readable kernel. Every decision is the sign of an
orient3d or orient2d, as in the readable test, and every sign is exact.

Reference: J. R. Shewchuk, "Adaptive Precision Floating-Point Arithmetic and
Fast Robust Geometric Predicates", Discrete & Computational Geometry 18
(1997). Section 2 gives the exact building blocks used here, each written
from the paper's statement: Two-Sum and Fast-Two-Sum (Theorems 6-7), Two-Diff,
Split and Two-Product (Dekker's, Theorems 17-18), Fast-Expansion-Sum with zero
elimination (Theorem 13), Scale-Expansion with zero elimination (Theorem 19).
An expansion is an array of floats, nonoverlapping, in increasing magnitude,
whose exact sum is the value; after zero elimination its sign is the sign of
its last (largest) component. Section 4 gives the predicates as expansions:

- the float filter (his stage A, ``O3D_ERRBOUND_A``, ``O2D_ERRBOUND_A``), as
  :mod:`refsim.collision.predicates` evaluates it;
- when it is unsure, the differences ``a - d`` are formed with Two-Diff. When
  all of them are exact (their tails are zero: always so for coordinates on
  a common grid, such as a cube's), the determinant of the differences is
  formed exactly from Two-Products scaled by the third factor (his stage B,
  without its error estimate: it is exact here, so its sign is final);
- otherwise the determinant of the 4 x 4 (or 3 x 3) lifted matrix is formed
  from the raw coordinates (his ``orient3dexact``/``orient2dexact`` scheme):
  2 x 2 minors by Two-Product and Two-Diff, scaled, summed.
  DEVIATION: his adaptive stages C and D are skipped; the all-exact sum is
  simpler to check and fires only for points that are both near-degenerate
  and off a common grid.

Why the signs are exact (Shewchuk's theorems assume no overflow or
underflow): a coordinate of magnitude in [2**-240, 2**299] is a multiple of
2**-292 and below 2**300, so every difference is a multiple of 2**-292 below
2**301, every product of two coordinates or differences a multiple of
2**-584, of three a multiple of 2**-876 below 2**903, and every component of
every expansion above is such a multiple (each operation's exact result and
its rounding error are), so no nonzero intermediate falls below 2**-876 or
rises above 2**910: far inside float64's normal range (2**-1022 to 2**1024).
Dekker's Split multiplies by 2**27 + 1, still far from overflow. numba
compiles without fast-math, so each operation is rounded once, to nearest
even, as the theorems require (no contraction into fused multiply-adds).

The triangle test mirrors the readable functions of
:mod:`refsim.collision.triangle` one for one (each docstring names its
original): same steps, same order of decisions, the same projection axis.
Points are 3-tuples and triangles 3-tuples of points, passed by value, as in
:mod:`refsim.collision._numba_kernels`.

Cost: a certain filter sign costs a few dozen flops; an exact-difference
orient3d about 200, the all-exact one about 1500 (up to 96 components);
an exact orient2d about 30 or 250. A touching pair of triangles, with every
sign zero, takes about a hundred predicates.

This module imports numba at import time; import it only when the compiled
kernel is chosen (:func:`refsim.collision.triangle_numba.exact_kernels`).
"""

from __future__ import annotations

import numba
import numpy as np

from refsim.collision.predicates import FILTER_MAX_ABS, FILTER_MIN_ABS
from refsim.rounding import O2D_ERRBOUND_A, O3D_ERRBOUND_A

#: :func:`refsim.kernels.sources_digest` of the refsim modules this one imports:
#: an edit there must change this line, so that numba renews its cache of
#: this module (tests/test_kernels.py checks it).
SOURCES_DIGEST = "1944e2d253670386"

#: The expansion operations' signatures, given so that numba compiles each
#: once: the callers pass offsets that are constants, and numba would type
#: each constant as its own literal and compile a version per combination.
EXPANSION_SUM = "intp(float64[::1], intp, intp, intp, intp, intp)"
EXPANSION_SCALE = "intp(float64[::1], intp, intp, float64, intp)"

#: Dekker's splitter for float64: 2**ceil(53 / 2) + 1 (Shewchuk, section 2.5).
SPLITTER = 134217729.0

#: What a pair's answer is (``triangles_intersect_exact``'s ``decided``).
UNDECIDED, DECIDED = False, True


# -- exact float building blocks (Shewchuk 1997, section 2) ---------------------------


@numba.njit(cache=True)
def two_sum(a, b):
    """(x, y) with x = fl(a + b) and x + y = a + b exactly (Knuth; Theorem 7)."""
    x = a + b
    b_virtual = x - a
    a_virtual = x - b_virtual
    b_roundoff = b - b_virtual
    a_roundoff = a - a_virtual
    return x, a_roundoff + b_roundoff


@numba.njit(cache=True)
def fast_two_sum(a, b):
    """(x, y) with x + y = a + b exactly, given |a| >= |b| (Dekker; Theorem 6)."""
    x = a + b
    b_virtual = x - a
    return x, b - b_virtual


@numba.njit(cache=True)
def two_diff(a, b):
    """(x, y) with x = fl(a - b) and x + y = a - b exactly."""
    x = a - b
    b_virtual = a - x
    a_virtual = x + b_virtual
    b_roundoff = b_virtual - b
    a_roundoff = a - a_virtual
    return x, a_roundoff + b_roundoff


@numba.njit(cache=True)
def split(a):
    """(hi, lo), a = hi + lo, each with at most 26 significant bits (Theorem 17)."""
    c = SPLITTER * a
    a_big = c - a
    hi = c - a_big
    return hi, a - hi


@numba.njit(cache=True)
def two_product(a, b):
    """(x, y) with x = fl(a b) and x + y = a b exactly (Dekker; Theorem 18)."""
    x = a * b
    a_hi, a_lo = split(a)
    b_hi, b_lo = split(b)
    err1 = x - a_hi * b_hi
    err2 = err1 - a_lo * b_hi
    err3 = err2 - a_hi * b_lo
    return x, a_lo * b_lo - err3


@numba.njit(cache=True)
def two_one_diff(a1, a0, b):
    """(x2, x1, x0) = (a1 + a0) - b exactly, nonoverlapping (Grow-Expansion)."""
    i, x0 = two_diff(a0, b)
    x2, x1 = two_sum(a1, i)
    return x2, x1, x0


@numba.njit("(float64, float64, float64, float64, float64[::1], intp)", cache=True)
def minor(p0, p1, q0, q1, out, at):
    """The 2 x 2 minor ``p0 q1 - p1 q0`` as an expansion written to ``out``
    from ``at`` on, smallest component first; returns its length (1 to 4).
    Two-Products, then Shewchuk's Two-Two-Diff, then its zero components
    dropped (so that the scalings below skip them: on grid coordinates most
    products are exact and most components zero)."""
    l1, l0 = two_product(p0, q1)
    r1, r0 = two_product(p1, q0)
    j, t0, x0 = two_one_diff(l1, l0, r0)
    x3, x2, x1 = two_one_diff(j, t0, r1)
    n = 0
    for x in (x0, x1, x2, x3):
        if x != 0.0:
            out[at + n] = x
            n += 1
    if n == 0:
        out[at] = 0.0
        n = 1
    return n


@numba.njit(EXPANSION_SUM, cache=True)
def fast_expansion_sum(w, e, e_len, f, f_len, h):
    """``w[h:]`` = ``w[e:e + e_len]`` + ``w[f:f + f_len]``; returns the
    result's length (Fast-Expansion-Sum with zero elimination, Theorem 13).

    Expansions live in one scratch array ``w`` and are named by their offset
    (an array view per operand would be a reference-counted object:
    docs/decisions/triangle-filter-arguments.md). e and f are strongly
    nonoverlapping (what every function here produces under round-to-even);
    so is the result, with no zero component unless it is the single
    component 0. The result must not overlap e or f."""
    if f_len == 1 and w[f] == 0.0:          # shortcuts for a zero term
        for i in range(e_len):
            w[h + i] = w[e + i]
        return e_len
    if e_len == 1 and w[e] == 0.0:
        for i in range(f_len):
            w[h + i] = w[f + i]
        return f_len
    e_i = 0
    f_i = 0
    e_now = w[e]
    f_now = w[f]
    # Merge by increasing magnitude: Q starts as the smallest component.
    if abs(f_now) > abs(e_now):
        q = e_now
        e_i += 1
    else:
        q = f_now
        f_i += 1
    h_len = 0
    if e_i < e_len and f_i < f_len:
        e_now = w[e + e_i]
        f_now = w[f + f_i]
        if abs(f_now) > abs(e_now):
            q, hh = fast_two_sum(e_now, q)
            e_i += 1
        else:
            q, hh = fast_two_sum(f_now, q)
            f_i += 1
        if hh != 0.0:
            w[h + h_len] = hh
            h_len += 1
        while e_i < e_len and f_i < f_len:
            e_now = w[e + e_i]
            f_now = w[f + f_i]
            if abs(f_now) > abs(e_now):
                q, hh = two_sum(q, e_now)
                e_i += 1
            else:
                q, hh = two_sum(q, f_now)
                f_i += 1
            if hh != 0.0:
                w[h + h_len] = hh
                h_len += 1
    while e_i < e_len:
        q, hh = two_sum(q, w[e + e_i])
        e_i += 1
        if hh != 0.0:
            w[h + h_len] = hh
            h_len += 1
    while f_i < f_len:
        q, hh = two_sum(q, w[f + f_i])
        f_i += 1
        if hh != 0.0:
            w[h + h_len] = hh
            h_len += 1
    if q != 0.0 or h_len == 0:
        w[h + h_len] = q
        h_len += 1
    return h_len


@numba.njit(EXPANSION_SCALE, cache=True)
def scale_expansion(w, e, e_len, b, h):
    """``w[h:]`` = b ``w[e:e + e_len]``; returns the result's length
    (Scale-Expansion with zero elimination, Theorem 19). The result must not
    overlap e."""
    if b == 0.0 or (e_len == 1 and w[e] == 0.0):
        w[h] = 0.0
        return 1
    q, hh = two_product(w[e], b)
    h_len = 0
    if hh != 0.0:
        w[h + h_len] = hh
        h_len += 1
    for i in range(1, e_len):
        product1, product0 = two_product(w[e + i], b)
        s, hh = two_sum(q, product0)
        if hh != 0.0:
            w[h + h_len] = hh
            h_len += 1
        q, hh = fast_two_sum(product1, s)
        if hh != 0.0:
            w[h + h_len] = hh
            h_len += 1
    if q != 0.0 or h_len == 0:
        w[h + h_len] = q
        h_len += 1
    return h_len


@numba.njit(cache=True)
def sign_of(x):
    return 1 if x > 0.0 else (-1 if x < 0.0 else 0)


@numba.njit(cache=True)
def det3_sum(w, z0, m0, n0, z1, m1, n1, z2, m2, n2, work, out):
    """``z0 m0 + z1 m1 + z2 m2`` for expansions at offsets m0..m2 of lengths
    n0..n2 (at most 4) and floats z0..z2, written at offset ``out``; returns
    its length (at most 24). Uses ``w[work:work + 40]``."""
    k0 = scale_expansion(w, m0, n0, z0, work)
    k1 = scale_expansion(w, m1, n1, z1, work + 8)
    k01 = fast_expansion_sum(w, work, k0, work + 8, k1, work + 24)
    k2 = scale_expansion(w, m2, n2, z2, work + 16)
    return fast_expansion_sum(w, work + 24, k01, work + 16, k2, out)


# -- exact orient3d and orient2d (Shewchuk 1997, section 4) -------------------------


#: orient3d_expansion's terms: for each 3 x 3 determinant D(p, q, r) of the
#: rows (x, y, z) of the points (0..3 for a..d), its sign in the 4 x 4
#: expansion, and for each of its three terms the row whose z scales the
#: term, the term's sign and the minor it scales (index into MINOR_ROWS).
MINOR_ROWS = ((0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3))
DET3_TERMS = (
    # + D(a,b,c) = z_a m(b,c) - z_b m(a,c) + z_c m(a,b)
    ((0, 1.0, 3), (1, -1.0, 1), (2, 1.0, 0)),
    # - D(a,b,d) = -z_a m(b,d) + z_b m(a,d) - z_d m(a,b)
    ((0, -1.0, 4), (1, 1.0, 2), (3, -1.0, 0)),
    # + D(a,c,d) = z_a m(c,d) - z_c m(a,d) + z_d m(a,c)
    ((0, 1.0, 5), (2, -1.0, 2), (3, 1.0, 1)),
    # - D(b,c,d) = -z_b m(c,d) + z_c m(b,d) - z_d m(b,c)
    ((1, -1.0, 5), (2, 1.0, 4), (3, -1.0, 3)),
)


@numba.njit(cache=True)
def orient3d_expansion(a, b, c, d):
    """Mirrors :func:`refsim.collision.predicates.orient3d_exact`: the sign of
    orient3d, always from the raw coordinates (no rounded difference).

    orient3d(a, b, c, d) = det[a - d; b - d; c - d] is the 4 x 4 determinant
    with rows (x, y, z, 1) of a, b, c, d. Along the last column,
    det = D(a,b,c) - D(a,b,d) + D(a,c,d) - D(b,c,d), where D(p,q,r), the 3 x 3
    determinant of rows (x, y, z), is z_p m(q,r) - z_q m(p,r) + z_r m(p,q)
    with the 2 x 2 minors m(p,q) = x_p y_q - x_q y_p (``DET3_TERMS``;
    Shewchuk's ``orient3dexact`` groups the same terms). Written as loops
    over those tables, so that the compiled code holds each expansion
    operation once. At most 96 components.

    Scratch layout of ``w``: the six minors at 0..23 (4 each), the scaled
    term at 24..31, the 3 x 3 determinant built at 32..55 (two halves), the
    running total in two buffers of 96 at 80 and 176.
    """
    points = (a, b, c, d)
    w = np.empty(272)
    minor_len = np.empty(6, dtype=np.int64)
    for m in range(6):
        p, q = points[MINOR_ROWS[m][0]], points[MINOR_ROWS[m][1]]
        minor_len[m] = minor(p[0], p[1], q[0], q[1], w, 4 * m)
    total, total_len, spare = 80, 0, 176
    for k in range(4):
        det, det_len, det_spare = 32, 0, 56
        for row, sign, m in DET3_TERMS[k]:
            n = scale_expansion(w, 4 * m, minor_len[m], sign * points[row][2], 24)
            if det_len == 0:
                for i in range(n):
                    w[det + i] = w[24 + i]
                det_len = n
            else:
                det_len = fast_expansion_sum(w, det, det_len, 24, n, det_spare)
                det, det_spare = det_spare, det
        if total_len == 0:
            for i in range(det_len):
                w[total + i] = w[det + i]
            total_len = det_len
        else:
            total_len = fast_expansion_sum(w, total, total_len, det, det_len, spare)
            total, spare = spare, total
    return sign_of(w[total + total_len - 1])


@numba.njit(cache=True)
def orient3d_exact(a, b, c, d):
    """Mirrors :func:`refsim.collision.predicates.orient3d_exact`: the exact
    sign of orient3d, by the cheaper route when it is exact.

    The nine differences by Two-Diff; if none has a tail they are the exact
    differences, and det = adz (bdx cdy - cdx bdy) + bdz (cdx ady - adx cdy)
    + cdz (adx bdy - bdx ady) is summed exactly (at most 24 components).
    Otherwise :func:`orient3d_expansion`.
    """
    adx, t0 = two_diff(a[0], d[0])
    ady, t1 = two_diff(a[1], d[1])
    adz, t2 = two_diff(a[2], d[2])
    bdx, t3 = two_diff(b[0], d[0])
    bdy, t4 = two_diff(b[1], d[1])
    bdz, t5 = two_diff(b[2], d[2])
    cdx, t6 = two_diff(c[0], d[0])
    cdy, t7 = two_diff(c[1], d[1])
    cdz, t8 = two_diff(c[2], d[2])
    if (t0 != 0.0 or t1 != 0.0 or t2 != 0.0 or t3 != 0.0 or t4 != 0.0 or t5 != 0.0
            or t6 != 0.0 or t7 != 0.0 or t8 != 0.0):
        return orient3d_expansion(a, b, c, d)
    w = np.empty(76)
    n_bc = minor(bdx, bdy, cdx, cdy, w, 0)       # bdx cdy - bdy cdx
    n_ca = minor(cdx, cdy, adx, ady, w, 4)       # cdx ady - cdy adx
    n_ab = minor(adx, ady, bdx, bdy, w, 8)       # adx bdy - ady bdx
    n = det3_sum(w, adz, 0, n_bc, bdz, 4, n_ca, cdz, 8, n_ab, 12, 52)
    return sign_of(w[52 + n - 1])


@numba.njit(cache=True)
def orient3d(a, b, c, d):
    """Mirrors :func:`refsim.collision.predicates.orient3d_filtered_sign`:
    the float filter (same formula and evaluation order as
    ``predicates.orient3d_terms``), then :func:`orient3d_exact`. Input in the
    filter's range."""
    adx, ady, adz = a[0] - d[0], a[1] - d[1], a[2] - d[2]
    bdx, bdy, bdz = b[0] - d[0], b[1] - d[1], b[2] - d[2]
    cdx, cdy, cdz = c[0] - d[0], c[1] - d[1], c[2] - d[2]
    bdxcdy = bdx * cdy
    cdxbdy = cdx * bdy
    cdxady = cdx * ady
    adxcdy = adx * cdy
    adxbdy = adx * bdy
    bdxady = bdx * ady
    det = adz * (bdxcdy - cdxbdy) + bdz * (cdxady - adxcdy) + cdz * (adxbdy - bdxady)
    permanent = ((abs(bdxcdy) + abs(cdxbdy)) * abs(adz)
                 + (abs(cdxady) + abs(adxcdy)) * abs(bdz)
                 + (abs(adxbdy) + abs(bdxady)) * abs(cdz))
    bound = O3D_ERRBOUND_A * permanent
    if det > bound:
        return 1
    if -det > bound:
        return -1
    return orient3d_exact(a, b, c, d)


@numba.njit(cache=True)
def orient2d_expansion(a, b, c):
    """Mirrors :func:`refsim.collision.predicates.orient2d_exact`: the sign of
    orient2d from the raw coordinates, det = m(a,b) + m(b,c) + m(c,a) with
    the minors m(p,q) = x_p y_q - x_q y_p (the 3 x 3 determinant with rows
    (x, y, 1)). At most 12 components."""
    w = np.empty(32)
    n_ab = minor(a[0], a[1], b[0], b[1], w, 0)
    n_bc = minor(b[0], b[1], c[0], c[1], w, 4)
    n_ca = minor(c[0], c[1], a[0], a[1], w, 8)
    n = fast_expansion_sum(w, 0, n_ab, 4, n_bc, 12)
    n = fast_expansion_sum(w, 12, n, 8, n_ca, 20)
    return sign_of(w[20 + n - 1])


@numba.njit(cache=True)
def orient2d_exact(a, b, c):
    """Mirrors :func:`refsim.collision.predicates.orient2d_exact`: the exact
    sign of orient2d. With exact differences (no Two-Diff tail) the
    determinant ``acx bcy - acy bcx`` is the 4-component expansion of
    :func:`minor`, whose sign is that of its largest nonzero component;
    otherwise :func:`orient2d_expansion`."""
    acx, t0 = two_diff(a[0], c[0])
    acy, t1 = two_diff(a[1], c[1])
    bcx, t2 = two_diff(b[0], c[0])
    bcy, t3 = two_diff(b[1], c[1])
    if t0 != 0.0 or t1 != 0.0 or t2 != 0.0 or t3 != 0.0:
        return orient2d_expansion(a, b, c)
    l1, l0 = two_product(acx, bcy)
    r1, r0 = two_product(acy, bcx)
    j, t, x0 = two_one_diff(l1, l0, r0)
    x3, x2, x1 = two_one_diff(j, t, r1)
    # nonoverlapping, increasing magnitude: the largest nonzero decides
    if x3 != 0.0:
        return sign_of(x3)
    if x2 != 0.0:
        return sign_of(x2)
    if x1 != 0.0:
        return sign_of(x1)
    return sign_of(x0)


@numba.njit(cache=True)
def orient2d(a, b, c):
    """Mirrors :func:`refsim.collision.predicates.orient2d_filtered_sign`:
    the float filter (``predicates._orient2d_terms``), then
    :func:`orient2d_exact`. Input in the filter's range."""
    detleft = (a[0] - c[0]) * (b[1] - c[1])
    detright = (a[1] - c[1]) * (b[0] - c[0])
    det = detleft - detright
    bound = O2D_ERRBOUND_A * (abs(detleft) + abs(detright))
    if det > bound:
        return 1
    if -det > bound:
        return -1
    return orient2d_exact(a, b, c)


# -- the edge-triangle test (refsim.collision.triangle, steps 1-4) -------------------


@numba.njit("(UniTuple(float64, 3), intp)", cache=True)
def drop(p, axis):
    """Mirrors :func:`refsim.collision.triangle._drop`."""
    if axis == 0:
        return (p[1], p[2])
    if axis == 1:
        return (p[2], p[0])
    return (p[0], p[1])


@numba.njit(cache=True)
def normal_signs(a, b, c):
    """Mirrors :func:`refsim.collision.triangle.normal_signs`."""
    return (orient2d(drop(a, 0), drop(b, 0), drop(c, 0)),
            orient2d(drop(a, 1), drop(b, 1), drop(c, 1)),
            orient2d(drop(a, 2), drop(b, 2), drop(c, 2)))


@numba.njit(cache=True)
def projection_axis_of_triangle(a, b, c):
    """Mirrors :func:`refsim.collision.triangle.projection_axis_of_triangle`:
    of the axes along which the exact normal is non-zero, the first with the
    largest float normal component (Python's ``max`` keeps the first). The
    triangle is non-degenerate."""
    signs = normal_signs(a, b, c)
    ux, uy, uz = b[0] - a[0], b[1] - a[1], b[2] - a[2]
    vx, vy, vz = c[0] - a[0], c[1] - a[1], c[2] - a[2]
    n = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx)
    best = -1
    best_value = 0.0
    for k in range(3):
        if signs[k] != 0:
            value = abs(n[k]) if n[k] == n[k] else 0.0
            if best < 0 or value > best_value:
                best = k
                best_value = value
    return best


@numba.njit(cache=True)
def mixed_signs(s1, s2, s3):
    """Mirrors :func:`refsim.collision.triangle._mixed_signs`."""
    return (s1 == 1 or s2 == 1 or s3 == 1) and (s1 == -1 or s2 == -1 or s3 == -1)


@numba.njit(cache=True)
def point_in_triangle_2d(p, a, b, c):
    """Mirrors :func:`refsim.collision.triangle.point_in_triangle_2d`."""
    return not mixed_signs(orient2d(a, b, p), orient2d(b, c, p), orient2d(c, a, p))


@numba.njit(cache=True)
def in_box(x, p, q):
    """Mirrors :func:`refsim.collision.triangle._in_box`."""
    return (min(p[0], q[0]) <= x[0] <= max(p[0], q[0])
            and min(p[1], q[1]) <= x[1] <= max(p[1], q[1]))


@numba.njit(cache=True)
def segments_intersect_2d(p, q, r, s):
    """Mirrors :func:`refsim.collision.triangle.segments_intersect_2d`."""
    d1 = orient2d(r, s, p)
    d2 = orient2d(r, s, q)
    d3 = orient2d(p, q, r)
    d4 = orient2d(p, q, s)
    # Case: proper crossing.
    if d1 * d2 < 0 and d3 * d4 < 0:
        return True
    # Case: an endpoint of one segment lies on the other.
    return ((d1 == 0 and in_box(p, r, s)) or (d2 == 0 and in_box(q, r, s))
            or (d3 == 0 and in_box(r, p, q)) or (d4 == 0 and in_box(s, p, q)))


@numba.njit(cache=True)
def segment_intersects_triangle_2d(p, q, a, b, c):
    """Mirrors :func:`refsim.collision.triangle.segment_intersects_triangle_2d`."""
    if point_in_triangle_2d(p, a, b, c) or point_in_triangle_2d(q, a, b, c):
        return True
    return (segments_intersect_2d(p, q, a, b) or segments_intersect_2d(p, q, b, c)
            or segments_intersect_2d(p, q, c, a))


@numba.njit(cache=True)
def edge_vs_triangle(p, q, sp, sq, t):
    """Mirrors :func:`refsim.collision.triangle._edge_vs_triangle`: segment pq
    vs the non-degenerate triangle t, given the sides of p and q."""
    # Case 4a, no crossing: both endpoints strictly on the same side.
    if sp == sq and sp != 0:
        return False
    # Case 4b, coplanar: exact 2D test in a projection along the normal.
    if sp == 0 and sq == 0:
        axis = projection_axis_of_triangle(t[0], t[1], t[2])
        return segment_intersects_triangle_2d(drop(p, axis), drop(q, axis), drop(t[0], axis),
                                              drop(t[1], axis), drop(t[2], axis))
    # Case 4c, crossing: the line pq on the same side of the three edges.
    a, b, c = t
    return not mixed_signs(orient3d(p, q, a, b), orient3d(p, q, b, c), orient3d(p, q, c, a))


@numba.njit(cache=True)
def strictly_one_side(s0, s1, s2):
    """Mirrors :func:`refsim.collision.triangle._strictly_one_side`."""
    return s0 == s1 and s1 == s2 and s2 != 0


@numba.njit(cache=True)
def triangle_vs_triangle(t1, t2):
    """Mirrors :func:`refsim.collision.triangle._triangle_vs_triangle`, for
    non-degenerate triangles with coordinates in the filter's range."""
    # Step 3a: which side of the other's plane each vertex lies on.
    sides1 = (orient3d(t2[0], t2[1], t2[2], t1[0]), orient3d(t2[0], t2[1], t2[2], t1[1]),
              orient3d(t2[0], t2[1], t2[2], t1[2]))
    sides2 = (orient3d(t1[0], t1[1], t1[2], t2[0]), orient3d(t1[0], t1[1], t1[2], t2[1]),
              orient3d(t1[0], t1[1], t1[2], t2[2]))
    # Step 3b, plane rejection (Moller 1997).
    if strictly_one_side(sides1[0], sides1[1], sides1[2]) or strictly_one_side(
            sides2[0], sides2[1], sides2[2]):
        return False
    # Step 3c: the edges of t1 against t2, then of t2 against t1.
    for i in range(3):
        j = (i + 1) % 3
        if edge_vs_triangle(t1[i], t1[j], sides1[i], sides1[j], t2):
            return True
    for i in range(3):
        j = (i + 1) % 3
        if edge_vs_triangle(t2[i], t2[j], sides2[i], sides2[j], t1):
            return True
    return False


@numba.njit(cache=True)
def in_filter_range(t):
    """Mirrors :func:`refsim.collision.predicates.in_filter_range` for a triangle."""
    for v in range(3):
        for k in range(3):
            m = abs(t[v][k])
            if m != 0.0 and not (FILTER_MIN_ABS <= m <= FILTER_MAX_ABS):
                return False
    return True


@numba.njit(cache=True)
def is_triangle(t):
    """Whether t spans positive area: the test of
    :func:`refsim.collision.triangle.point_set` (a nonzero exact normal)."""
    s = normal_signs(t[0], t[1], t[2])
    return s[0] != 0 or s[1] != 0 or s[2] != 0


@numba.njit(cache=True)
def triangles_intersect_exact(t1, t2):
    """Mirrors :func:`refsim.collision.triangle.triangles_intersect` for the
    pairs it can take: ``(answer, decided)``. Decided when both triangles
    have every coordinate in the filter's range and positive area; then the
    answer is the readable test's. Otherwise ``(False, UNDECIDED)``: the
    caller asks the readable kernel (degenerate triangles, the exact-only
    predicates of out-of-range input)."""
    if not (in_filter_range(t1) and in_filter_range(t2)):
        return False, UNDECIDED
    if not (is_triangle(t1) and is_triangle(t2)):
        return False, UNDECIDED
    return triangle_vs_triangle(t1, t2), DECIDED


# -- array entry points --------------------------------------------------------------


@numba.njit(cache=True)
def intersect_batch(A, B):
    """``(answer, decided)`` of :func:`triangles_intersect_exact` for each pair
    of two finite (k, 3, 3) arrays."""
    k = A.shape[0]
    answer = np.zeros(k, dtype=np.bool_)
    decided = np.zeros(k, dtype=np.bool_)
    for n in range(k):
        a = ((A[n, 0, 0], A[n, 0, 1], A[n, 0, 2]), (A[n, 1, 0], A[n, 1, 1], A[n, 1, 2]),
             (A[n, 2, 0], A[n, 2, 1], A[n, 2, 2]))
        b = ((B[n, 0, 0], B[n, 0, 1], B[n, 0, 2]), (B[n, 1, 0], B[n, 1, 1], B[n, 1, 2]),
             (B[n, 2, 0], B[n, 2, 1], B[n, 2, 2]))
        answer[n], decided[n] = triangles_intersect_exact(a, b)
    return answer, decided


@numba.njit(cache=True)
def intersect_indexed(world_a, faces_a, world_b, faces_b, pairs):
    """``intersect_batch`` for pairs of face indices into two meshes whose
    vertices are already in world space (finite)."""
    k = pairs.shape[0]
    answer = np.zeros(k, dtype=np.bool_)
    decided = np.zeros(k, dtype=np.bool_)
    for n in range(k):
        p, q, r = faces_a[pairs[n, 0], 0], faces_a[pairs[n, 0], 1], faces_a[pairs[n, 0], 2]
        a = ((world_a[p, 0], world_a[p, 1], world_a[p, 2]),
             (world_a[q, 0], world_a[q, 1], world_a[q, 2]),
             (world_a[r, 0], world_a[r, 1], world_a[r, 2]))
        p, q, r = faces_b[pairs[n, 1], 0], faces_b[pairs[n, 1], 1], faces_b[pairs[n, 1], 2]
        b = ((world_b[p, 0], world_b[p, 1], world_b[p, 2]),
             (world_b[q, 0], world_b[q, 1], world_b[q, 2]),
             (world_b[r, 0], world_b[r, 1], world_b[r, 2]))
        answer[n], decided[n] = triangles_intersect_exact(a, b)
    return answer, decided


@numba.njit(cache=True)
def world_point(vertices, v, rotation, translation):
    """Vertex v in world space with refsim's one transform arithmetic
    (:func:`refsim.collision.boxes.world_vertices`): ``(R[k,0] x + R[k,1] y)
    + R[k,2] z + t[k]``, each operation rounded once."""
    x, y, z = vertices[v, 0], vertices[v, 1], vertices[v, 2]
    return (((rotation[0, 0] * x + rotation[0, 1] * y) + rotation[0, 2] * z) + translation[0],
            ((rotation[1, 0] * x + rotation[1, 1] * y) + rotation[1, 2] * z) + translation[1],
            ((rotation[2, 0] * x + rotation[2, 1] * y) + rotation[2, 2] * z) + translation[2])


@numba.njit(cache=True)
def intersect_posed(vertices_a, faces_a, rotation_a, translation_a,
                    vertices_b, faces_b, rotation_b, translation_b, pairs, first_only):
    """``intersect_batch`` for pairs of face indices into two posed meshes
    (the hierarchy's uncertain pairs): each triangle's vertices transformed
    as :func:`world_point`, so the same floats the traversal tested. With
    ``first_only`` it stops after the first pair decided to intersect (the
    rest stay undecided and False). Poses already checked."""
    k = pairs.shape[0]
    answer = np.zeros(k, dtype=np.bool_)
    decided = np.zeros(k, dtype=np.bool_)
    for n in range(k):
        i, j = pairs[n, 0], pairs[n, 1]
        a = (world_point(vertices_a, faces_a[i, 0], rotation_a, translation_a),
             world_point(vertices_a, faces_a[i, 1], rotation_a, translation_a),
             world_point(vertices_a, faces_a[i, 2], rotation_a, translation_a))
        b = (world_point(vertices_b, faces_b[j, 0], rotation_b, translation_b),
             world_point(vertices_b, faces_b[j, 1], rotation_b, translation_b),
             world_point(vertices_b, faces_b[j, 2], rotation_b, translation_b))
        answer[n], decided[n] = triangles_intersect_exact(a, b)
        if first_only and answer[n]:
            break
    return answer, decided


@numba.njit(cache=True)
def orient3d_batch(P, stage):
    """Signs of orient3d for the rows of a (k, 4, 3) array: ``stage`` 0 the
    filtered :func:`orient3d`, 1 :func:`orient3d_exact`, 2
    :func:`orient3d_expansion` (for the tests, which check each route)."""
    k = P.shape[0]
    out = np.empty(k, dtype=np.int64)
    for n in range(k):
        a = (P[n, 0, 0], P[n, 0, 1], P[n, 0, 2])
        b = (P[n, 1, 0], P[n, 1, 1], P[n, 1, 2])
        c = (P[n, 2, 0], P[n, 2, 1], P[n, 2, 2])
        d = (P[n, 3, 0], P[n, 3, 1], P[n, 3, 2])
        if stage == 0:
            out[n] = orient3d(a, b, c, d)
        elif stage == 1:
            out[n] = orient3d_exact(a, b, c, d)
        else:
            out[n] = orient3d_expansion(a, b, c, d)
    return out


@numba.njit(cache=True)
def orient2d_batch(P, stage):
    """Signs of orient2d for the rows of a (k, 3, 2) array, ``stage`` as in
    :func:`orient3d_batch`."""
    k = P.shape[0]
    out = np.empty(k, dtype=np.int64)
    for n in range(k):
        a = (P[n, 0, 0], P[n, 0, 1])
        b = (P[n, 1, 0], P[n, 1, 1])
        c = (P[n, 2, 0], P[n, 2, 1])
        if stage == 0:
            out[n] = orient2d(a, b, c)
        elif stage == 1:
            out[n] = orient2d_exact(a, b, c)
        else:
            out[n] = orient2d_expansion(a, b, c)
    return out
