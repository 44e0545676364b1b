"""The certified triangle-pair filter of :mod:`refsim.collision.triangle_batch`,
compiled with numba: same steps, same formulas, one pair at a time in loops.

For each pair it returns ``(answer, certain)`` exactly as
``certified_batch`` does: the float determinants with Shewchuk's static error
bounds decide the pair when every sign it needs is certain; otherwise the pair
is left uncertain and :func:`triangles_intersect_numba` re-answers it with the
compiled exact stage (:mod:`refsim.collision._numba_exact`: the readable
test's steps over exact expansion predicates) and, for the pairs that stage
does not take (degenerate triangles, coordinates outside the filter's range),
with the readable exact kernel. The filter's steps (see triangle_batch's
docstring):

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


@functools.cache
def compiled_kernels():
    """``(certify_pair, certified, certified_indexed)`` compiled, or None
    without numba (see :mod:`refsim.collision._numba_kernels`).

    ``certify_pair(a, b) -> (answer, certain)`` for two (3, 3) triangles is
    what the hierarchy's boolean query calls at its leaves.
    """
    try:
        from refsim.collision import _numba_kernels as nk
    except ImportError:
        return None
    return nk.certify_pair, nk.certified, nk.certified_indexed


@functools.cache
def compiled_exact_kernels():
    """The compiled exact stage, :mod:`refsim.collision._numba_exact` (its
    ``intersect_batch``, ``intersect_indexed``, ``intersect_posed``), or None
    without numba."""
    try:
        from refsim.collision import _numba_exact
    except ImportError:
        return None
    return _numba_exact


def _resolve_open(answer, open_pairs, decided_answer, decided, readable) -> None:
    """Fill ``answer`` at the indices ``open_pairs``: the compiled exact
    stage's answer where it decided, ``readable(n)`` for the rest."""
    answer[open_pairs] = decided_answer
    for m in np.flatnonzero(~decided):
        answer[open_pairs[m]] = readable(open_pairs[m])


def _kernel():
    """The compiled ``certified(A, B) -> (answer, certain)``, or None."""
    kernels = compiled_kernels()
    return None if kernels is None else kernels[1]


def intersecting_indexed(world_a, faces_a, world_b, faces_b, pairs) -> np.ndarray:
    """Which face pairs ``(i, j)`` of two meshes in world space intersect,
    exactly: the compiled filter, then the compiled exact stage where it is
    unsure, then the readable kernel for what that stage does not take.
    ``world_*`` must be finite float64 (n, 3); returns a bool array (k,)."""
    from refsim.collision.triangle import triangles_intersect

    answer, certain = compiled_kernels()[2](world_a, faces_a, world_b, faces_b, pairs)
    open_pairs = np.flatnonzero(~certain)
    if len(open_pairs):
        world_a = np.ascontiguousarray(world_a, np.float64)
        world_b = np.ascontiguousarray(world_b, np.float64)
        decided_answer, decided = compiled_exact_kernels().intersect_indexed(
            world_a, faces_a, world_b, faces_b, np.ascontiguousarray(pairs[open_pairs]))

        def readable(n):
            i, j = pairs[n]
            return triangles_intersect(world_a[faces_a[i]], world_b[faces_b[j]])

        _resolve_open(answer, open_pairs, decided_answer, decided, readable)
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
    """Exact overlap of k triangle pairs: the compiled filter, then the
    compiled exact stage for the pairs it cannot certify, then the readable
    exact kernel for the pairs that stage does not take. Same answers as
    :func:`refsim.collision.triangle_batch.triangles_intersect_batch`."""
    from refsim.collision.triangle import triangles_intersect
    from refsim.collision.triangle_batch import _as_batch

    A, B = _as_batch(A, B)
    answer, certain = certified_numba(A, B)
    open_pairs = np.flatnonzero(~certain)
    if len(open_pairs):
        decided_answer, decided = compiled_exact_kernels().intersect_batch(
            np.ascontiguousarray(A[open_pairs]), np.ascontiguousarray(B[open_pairs]))
        _resolve_open(answer, open_pairs, decided_answer, decided,
                      lambda n: triangles_intersect(A[n], B[n]))
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
