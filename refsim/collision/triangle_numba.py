"""The certified triangle-pair filter of :mod:`refsim.collision.triangle_batch`,
compiled with numba: same steps, same formulas, one pair at a time in loops.

For each pair it returns ``(answer, certain)`` exactly as
``certified_batch`` does: the float determinants with Shewchuk's static error
bounds decide the pair when every sign it needs is certain; otherwise the pair
is left uncertain and :func:`triangles_intersect_numba` re-answers it with the
readable exact kernel. The steps (see triangle_batch's docstring):

1. both triangles certainly non-degenerate, coordinates in the filter's range;
2. plane rejection: one triangle certainly strictly on one side of the other's
   plane -> False;
3. the six edge-triangle tests: an edge with endpoints certainly on one side
   misses; endpoints certainly on opposite sides -> the three Plucker
   orientations: certainly mixed -> miss, all certain and equal -> hit;
4. any certain hit -> True, six certain misses -> False, else uncertain.

The expressions are written term for term as in the numpy kernel, so the
error bounds (which hold for that evaluation order) hold here too; the tests
check that both kernels certify the same pairs with the same answers.

Cost: O(k) for k pairs, ~1e7 pairs/s when compiled; compile once (cached).
"""

from __future__ import annotations

import functools

import numpy as np

from refsim.collision.predicates import (
    FILTER_MAX_ABS,
    FILTER_MIN_ABS,
    O2D_ERRBOUND_A,
    O3D_ERRBOUND_A,
)


@functools.cache
def _kernel():
    """The compiled ``certified(A, B) -> (answer, certain)``, or None."""
    kernels = compiled_kernels()
    return None if kernels is None else kernels[1]


@functools.cache
def compiled_kernels():
    """``(certify_pair, certified)`` compiled, or None without numba.

    ``certify_pair(a, b) -> (answer, certain)`` for two (3, 3) triangles is
    what the hierarchy's boolean query calls at its leaves.
    """
    try:
        import numba
    except ImportError:
        return None

    jit = numba.njit(cache=True)

    @jit
    def o3d(a, b, c, d):
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
        if abs(det) > O3D_ERRBOUND_A * permanent:
            return (1 if det > 0 else -1), True
        return 0, False

    @jit
    def o2d_certain(a0, a1, b0, b1, c0, c1):
        detleft = (a0 - c0) * (b1 - c1)
        detright = (a1 - c1) * (b0 - c0)
        det = detleft - detright
        return abs(det) > O2D_ERRBOUND_A * (abs(detleft) + abs(detright))

    @jit
    def in_range(t):
        for v in range(3):
            for k in range(3):
                m = abs(t[v, k])
                if m != 0.0 and not (FILTER_MIN_ABS <= m <= FILTER_MAX_ABS):
                    return False
        return True

    @jit
    def nondegenerate(t):
        p, q, r = t[0], t[1], t[2]
        for i, j in ((1, 2), (2, 0), (0, 1)):
            if o2d_certain(p[i], p[j], q[i], q[j], r[i], r[j]):
                return True
        return False

    @jit
    def edges_vs_triangle(e, t, s, c):
        """(any certain hit, all three edges certainly miss)."""
        all_miss = True
        for i in range(3):
            j = (i + 1) % 3
            if c[i] and c[j]:
                if s[i] == s[j]:
                    continue                                    # case 4a: miss
                g1, k1 = o3d(e[i], e[j], t[0], t[1])
                g2, k2 = o3d(e[i], e[j], t[1], t[2])
                g3, k3 = o3d(e[i], e[j], t[2], t[0])
                pos = g1 > 0 or g2 > 0 or g3 > 0
                neg = g1 < 0 or g2 < 0 or g3 < 0
                if pos and neg:
                    continue                                    # case 4c: miss
                if k1 and k2 and k3:
                    return True, False                          # case 4c: hit
            all_miss = False
        return False, all_miss

    @jit
    def certify_pair(a, b):
        """(answer, certain) for one pair of (3, 3) triangles."""
        # step 1
        if not (in_range(a) and in_range(b) and nondegenerate(a) and nondegenerate(b)):
            return False, False
        # step 2
        sa = np.empty(3, dtype=np.int64)
        ca = np.empty(3, dtype=np.bool_)
        sb = np.empty(3, dtype=np.int64)
        cb = np.empty(3, dtype=np.bool_)
        for v in range(3):
            sa[v], ca[v] = o3d(b[0], b[1], b[2], a[v])
            sb[v], cb[v] = o3d(a[0], a[1], a[2], b[v])
        one_side_a = ca[0] and ca[1] and ca[2] and sa[0] == sa[1] and sa[1] == sa[2]
        one_side_b = cb[0] and cb[1] and cb[2] and sb[0] == sb[1] and sb[1] == sb[2]
        if one_side_a or one_side_b:
            return False, True
        # steps 3 and 4
        hit, miss_a = edges_vs_triangle(a, b, sa, ca)
        if hit:
            return True, True
        hit, miss_b = edges_vs_triangle(b, a, sb, cb)
        if hit:
            return True, True
        return False, miss_a and miss_b

    @jit
    def certified(A, B):
        k = A.shape[0]
        answer = np.zeros(k, dtype=np.bool_)
        certain = np.zeros(k, dtype=np.bool_)
        for n in range(k):
            answer[n], certain[n] = certify_pair(A[n], B[n])
        return answer, certain

    @jit
    def certified_indexed(world_a, faces_a, world_b, faces_b, pairs):
        """``certified`` for pairs of face indices into two meshes."""
        k = pairs.shape[0]
        answer = np.zeros(k, dtype=np.bool_)
        certain = np.zeros(k, dtype=np.bool_)
        ta = np.empty((3, 3))
        tb = np.empty((3, 3))
        for n in range(k):
            for v in range(3):
                for c in range(3):
                    ta[v, c] = world_a[faces_a[pairs[n, 0], v], c]
                    tb[v, c] = world_b[faces_b[pairs[n, 1], v], c]
            answer[n], certain[n] = certify_pair(ta, tb)
        return answer, certain

    return certify_pair, certified, certified_indexed


def intersecting_indexed(world_a, faces_a, world_b, faces_b, pairs) -> np.ndarray:
    """Which face pairs ``(i, j)`` of two meshes in world space intersect,
    exactly: the compiled filter, then the readable kernel where it is unsure.
    ``world_*`` must be finite float64 (n, 3); returns a bool array (k,)."""
    from refsim.collision.triangle import triangles_intersect

    answer, certain = compiled_kernels()[2](world_a, faces_a, world_b, faces_b, pairs)
    for n in np.flatnonzero(~certain):
        i, j = pairs[n]
        answer[n] = triangles_intersect(world_a[faces_a[i]], world_b[faces_b[j]])
    return answer


def available() -> bool:
    return _kernel() is not None


def certified_numba(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(answer, certain)`` for finite float64 (k, 3, 3) arrays, compiled."""
    kernel = _kernel()
    if kernel is None:
        raise ImportError("certified_numba needs numba (pip install -e '.[fast]')")
    return kernel(np.ascontiguousarray(A, np.float64), np.ascontiguousarray(B, np.float64))


def triangles_intersect_numba(A, B) -> np.ndarray:
    """Exact overlap of k triangle pairs: the compiled filter, then the readable
    exact kernel for the pairs it cannot certify. Same answers as
    :func:`refsim.collision.triangle_batch.triangles_intersect_batch`."""
    from refsim.collision.triangle import triangles_intersect
    from refsim.collision.triangle_batch import _as_batch

    A, B = _as_batch(A, B)
    answer, certain = certified_numba(A, B)
    for i in np.flatnonzero(~certain):
        answer[i] = triangles_intersect(A[i], B[i])
    return answer


def measure_numba_compile_seconds() -> float:
    """Seconds to compile the kernel from nothing, in a fresh interpreter with
    an empty numba cache (so neither this process's nor the on-disk cache
    hides the cost); includes importing numba."""
    import os
    import subprocess
    import sys
    import tempfile

    code = ("import time, numpy as np; t = time.perf_counter(); "
            "from refsim.collision.triangle_numba import certified_numba; "
            "certified_numba(np.zeros((1, 3, 3)), np.ones((1, 3, 3))); "
            "print(time.perf_counter() - t)")
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                             text=True, check=True)
    return float(out.stdout.strip())
