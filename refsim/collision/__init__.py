"""Body-to-body collision detection (seed S4).

Modules: ``predicates`` (exact, filtered orientation tests), ``triangle``
(the readable exact triangle-triangle test, level 3), ``triangle_batch`` (its
vectorized numpy fast path), ``triangle_numba`` (the same, compiled; numba
optional), ``measure`` (filter fallback rates, oracle comparison with
classified disagreements, claim C4, speed). The body-level tests and the
bounding-volume hierarchy built on these kernels live beside them, and
``containment``, the one point-in-mesh test (float; for classifying
disagreements).
"""
