"""Compiled kernels of the AABB updates (seed S2), for the optional extra ``fast``.

Line for line the same algorithms as the readable kernels in
:mod:`refsim.bounds.aabb_linear` and :mod:`refsim.bounds.aabb_incremental`,
written as plain loops over arrays so that numba can compile them. The
interpreter's overhead per vertex (a few hundred nanoseconds) would otherwise
hide the point of the incremental update, which is to examine a few dozen
vertices instead of all of them (docs/design.md, Speed).

Arithmetic: numba compiles without fast-math, so LLVM neither reassociates
the sums nor fuses a multiply and an add; each operation is rounded once, as in
Python and in elementwise numpy. tests/bounds/test_aabb_incremental.py checks
the two kernels bit for bit.

Cache: ``cache=True`` writes the compiled code next to this file (or to
``NUMBA_CACHE_DIR``), so only the first process on a machine pays the compile
(measured by :func:`refsim.studies.bounds.measure_numba_compile_cost`).

This module imports numba at import time; import it only when the numba kernel
is chosen.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True)
def aabb_linear_numba(vertices_t, rotation, translation):
    """Mirrors :func:`refsim.bounds.aabb_linear.aabb_linear_kernel`.

    Linear scan; ``vertices_t`` is (3, n) contiguous. Returns (lo, hi)."""
    x, y, z = vertices_t[0], vertices_t[1], vertices_t[2]
    lo = np.empty(3)
    hi = np.empty(3)
    for k in range(3):
        a, b, c = rotation[k, 0], rotation[k, 1], rotation[k, 2]
        r_min = (a * x[0] + b * y[0]) + c * z[0]
        r_max = r_min
        for i in range(1, x.shape[0]):
            r = (a * x[i] + b * y[i]) + c * z[i]
            if r < r_min:
                r_min = r
            if r > r_max:
                r_max = r
        lo[k] = r_min + translation[k]
        hi[k] = r_max + translation[k]
    return lo, hi


@numba.njit(cache=True, nogil=True)
def incremental_update_numba(vertices_t, offsets, indices, rotation, translation,
                             extremes, tie_window, value, stamp, touched, seen, queue,
                             generation, counts, lo, hi):
    """Mirrors :meth:`refsim.bounds.aabb_incremental.IncrementalAABB.update` (its readable kernel).

    One tracker update; ``extremes`` (2, 3) is read and written in place.

    ``extremes[0, k] < 0`` means "no previous frame": initialize by a full scan.
    Writes the box to ``lo``, ``hi`` and visits/evaluations to ``counts``.

    One flat function on purpose: numba passes arrays to a called function
    with reference counting, which cost more than the arithmetic here, as
    measured on the 2000-triangle sphere (docs/decisions/compiled-loop.md
    weighs the same counting in the simulation loop). So the memoized
    evaluation of ``r_k(v)`` is written out at its three sites (marked
    "evaluate"), identically.
    """
    x, y, z = vertices_t[0], vertices_t[1], vertices_t[2]
    n = x.shape[0]
    generation[0] += 1
    g_update = generation[0]
    visits = 0
    evaluations = 0
    if extremes[0, 0] < 0:
        for k in range(3):
            a, b, c = rotation[k, 0], rotation[k, 1], rotation[k, 2]
            i_min = 0
            i_max = 0
            r_min = (a * x[0] + b * y[0]) + c * z[0]
            r_max = r_min
            for i in range(1, n):
                r = (a * x[i] + b * y[i]) + c * z[i]
                if r < r_min:
                    r_min = r
                    i_min = i
                if r > r_max:
                    r_max = r
                    i_max = i
            extremes[0, k] = i_min
            extremes[1, k] = i_max
            lo[k] = r_min + translation[k]
            hi[k] = r_max + translation[k]
        counts[0] = n
        counts[1] = 3 * n
        return
    for k in range(3):
        a, b, c = rotation[k, 0], rotation[k, 1], rotation[k, 2]
        for side in range(2):
            sign = -1.0 if side == 0 else 1.0
            current = extremes[side, k]
            # evaluate r_k(current)
            if stamp[k, current] != g_update:
                stamp[k, current] = g_update
                value[k, current] = (a * x[current] + b * y[current]) + c * z[current]
                evaluations += 1
                if touched[current] != g_update:
                    touched[current] = g_update
                    visits += 1
            best = sign * value[k, current]
            while True:
                # Step 1: steepest ascent, strict improvement only.
                step_to = -1
                for p in range(offsets[current], offsets[current + 1]):
                    u = indices[p]
                    # evaluate r_k(u)
                    if stamp[k, u] != g_update:
                        stamp[k, u] = g_update
                        value[k, u] = (a * x[u] + b * y[u]) + c * z[u]
                        evaluations += 1
                        if touched[u] != g_update:
                            touched[u] = g_update
                            visits += 1
                    s = sign * value[k, u]
                    if s > best:
                        best = s
                        step_to = u
                if step_to >= 0:
                    current = step_to
                    continue
                # Step 2: certify over the near-plateau {s >= best - tie_window}.
                generation[1] += 1
                g_search = generation[1]
                floor = best - tie_window
                seen[current] = g_search
                queue[0] = current
                head = 0
                tail = 1
                found = -1
                found_best = best
                while head < tail:
                    v = queue[head]
                    head += 1
                    for p in range(offsets[v], offsets[v + 1]):
                        u = indices[p]
                        if seen[u] == g_search:
                            continue
                        # evaluate r_k(u)
                        if stamp[k, u] != g_update:
                            stamp[k, u] = g_update
                            value[k, u] = (a * x[u] + b * y[u]) + c * z[u]
                            evaluations += 1
                            if touched[u] != g_update:
                                touched[u] = g_update
                                visits += 1
                        s = sign * value[k, u]
                        if s >= floor:
                            seen[u] = g_search
                            queue[tail] = u
                            tail += 1
                            if s > found_best or (s == found_best and found >= 0
                                                  and u < found):
                                found_best = s
                                found = u
                if found < 0:
                    break  # certified: nothing better within reach
                current = found
                best = found_best
            extremes[side, k] = current
        lo[k] = value[k, extremes[0, k]] + translation[k]
        hi[k] = value[k, extremes[1, k]] + translation[k]
    counts[0] = visits
    counts[1] = evaluations
