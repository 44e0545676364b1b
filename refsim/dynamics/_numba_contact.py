"""The corrected body response's contact normal, depth and point
(:func:`refsim.dynamics.body_response.contact_geometry`), compiled with
numba: one call per contact instead of a few dozen numpy calls.

:func:`contact_geometry_numba` is written in the readable function's
operations and order (the sums of :mod:`refsim.dynamics.products`, left to
right, each rounded once; the centroids summed vertex by vertex in index
order); numba compiles without fast-math, so it gives the same normal,
depth, point and extent bit for bit (tests/dynamics/test_contact_compiled.py).

Cost: O(7 (n_a + n_b)) for the seven candidate axes, as the readable one.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, nogil=True, error_model="numpy")
def contact_geometry_numba(world_a, world_b, c_a, c_b, axes_a, axes_b, out):
    """Mirrors refsim.dynamics.body_response.contact_geometry: writes
    ``(n_x, n_y, n_z, depth, p_x, p_y, p_z, extent)`` into ``out`` (8,);
    returns False when every candidate axis has zero length (the readable
    function raises ValueError then)."""
    d0, d1, d2 = c_a[0] - c_b[0], c_a[1] - c_b[1], c_a[2] - c_b[2]
    found = False
    best = 0.0
    n0 = n1 = n2 = 0.0
    for c in range(7):
        if c == 0:
            x0, x1, x2 = d0, d1, d2
        elif c < 4:
            x0, x1, x2 = axes_a[0, c - 1], axes_a[1, c - 1], axes_a[2, c - 1]
        else:
            x0, x1, x2 = axes_b[0, c - 4], axes_b[1, c - 4], axes_b[2, c - 4]
        length = math.sqrt((x0 * x0 + x1 * x1) + x2 * x2)
        if length == 0.0:
            continue
        m0, m1, m2 = x0 / length, x1 / length, x2 / length
        if (m0 * d0 + m1 * d1) + m2 * d2 < 0.0:
            m0, m1, m2 = -m0, -m1, -m2                 # from B into A
        low_a = np.inf
        for i in range(world_a.shape[0]):
            p = (world_a[i, 0] * m0 + world_a[i, 1] * m1) + world_a[i, 2] * m2
            if p < low_a:
                low_a = p
        high_b = -np.inf
        for i in range(world_b.shape[0]):
            p = (world_b[i, 0] * m0 + world_b[i, 1] * m1) + world_b[i, 2] * m2
            if p > high_b:
                high_b = p
        depth = high_b - low_a
        if not found or depth < best:
            found, best, n0, n1, n2 = True, depth, m0, m1, m2
    if not found:
        return False
    low_a, high_a, low_b, high_b = np.inf, -np.inf, np.inf, -np.inf
    arg_low_a = arg_high_b = 0
    for i in range(world_a.shape[0]):
        p = (world_a[i, 0] * n0 + world_a[i, 1] * n1) + world_a[i, 2] * n2
        if p < low_a:
            low_a, arg_low_a = p, i
        if p > high_a:
            high_a = p
    for i in range(world_b.shape[0]):
        p = (world_b[i, 0] * n0 + world_b[i, 1] * n1) + world_b[i, 2] * n2
        if p < low_b:
            low_b = p
        if p > high_b:
            high_b, arg_high_b = p, i
    out[0], out[1], out[2], out[3] = n0, n1, n2, best
    if best < 0.0:
        for k in range(3):
            out[4 + k] = 0.5 * (world_a[arg_low_a, k] + world_b[arg_high_b, k])
    else:
        # the centroids of the vertices in the overlap slab, summed in index order
        sa0 = sa1 = sa2 = sb0 = sb1 = sb2 = 0.0
        count_a = count_b = 0
        for i in range(world_a.shape[0]):
            if (world_a[i, 0] * n0 + world_a[i, 1] * n1) + world_a[i, 2] * n2 <= high_b:
                if count_a == 0:
                    sa0, sa1, sa2 = world_a[i, 0], world_a[i, 1], world_a[i, 2]
                else:
                    sa0, sa1, sa2 = sa0 + world_a[i, 0], sa1 + world_a[i, 1], sa2 + world_a[i, 2]
                count_a += 1
        for i in range(world_b.shape[0]):
            if (world_b[i, 0] * n0 + world_b[i, 1] * n1) + world_b[i, 2] * n2 >= low_a:
                if count_b == 0:
                    sb0, sb1, sb2 = world_b[i, 0], world_b[i, 1], world_b[i, 2]
                else:
                    sb0, sb1, sb2 = sb0 + world_b[i, 0], sb1 + world_b[i, 1], sb2 + world_b[i, 2]
                count_b += 1
        out[4] = 0.5 * (sa0 / count_a + sb0 / count_b)
        out[5] = 0.5 * (sa1 / count_a + sb1 / count_b)
        out[6] = 0.5 * (sa2 / count_a + sb2 / count_b)
    out[7] = (high_a - low_a) + (high_b - low_b)
    return True
