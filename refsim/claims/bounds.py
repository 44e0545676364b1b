"""Claims C1 and C2: the incremental bounding box against the linear scan (S2).

C1 (cost): "incremental and linear AABB update cost about the same until
models are large; incremental clearly faster at 2000 triangles", judged on
the cost study of :func:`refsim.studies.bounds.measure_update_cost`.
C2 (correctness): "the incremental update needs a convex model", judged on
:func:`refsim.studies.bounds.measure_incremental_error`.
"""

from __future__ import annotations

from collections.abc import Sequence

from refsim.claims.result import ClaimResult, by_parts
from refsim.studies.bounds import IncrementalError, UpdateCostStudy

#: "Nearly equal" in the seed's C1: a scan / incremental time ratio within a
#: factor of two either way. At a few microseconds per update a factor below
#: two is invisible in a simulation step; the seed compared whole-simulation
#: frame rates.
ABOUT_EQUAL = (0.5, 2.0)

#: The model size at which the seed found the incremental update "clearly
#: faster" (triangles).
SEED_LARGE_MODEL = 2000

#: The seed measured compiled C; the like-for-like comparison is the compiled
#: incremental walk against the compiled scan, at 1 degree per frame (the
#: coherent motion the incremental update is for). The interpreted pair is
#: reported beside it, not used for the verdict.
COMPILED = ("coherent", "incremental-numba", "scan-numba")
INTERPRETED = ("coherent", "incremental-python", "scan-numpy")


def c1(study: UpdateCostStudy) -> ClaimResult:
    """C1 from the measured crossovers and speed-ups. Its two parts: the
    incremental update is faster from :data:`SEED_LARGE_MODEL` triangles on
    (the compiled crossover is at or below it), and below the crossover the
    two cost about the same (every ratio within :data:`ABOUT_EQUAL`)."""
    compiled = study.crossovers.get(COMPILED)
    ratios = dict(study.speedups.get(COMPILED, []))   # size -> scan time / incremental time
    below = [r for n, r in ratios.items() if compiled is None or n < compiled]
    equal_below = bool(below) and all(ABOUT_EQUAL[0] <= r <= ABOUT_EQUAL[1] for r in below)
    faster_at_large = compiled is not None and compiled <= SEED_LARGE_MODEL
    return ClaimResult("C1", by_parts(faster_at_large + equal_below, 2), {
        "compiled_crossover": compiled,
        "interpreted_crossover": study.crossovers.get(INTERPRETED),
        "large_model": SEED_LARGE_MODEL,
        "ratio_at_large_model": ratios.get(SEED_LARGE_MODEL),
        "ratios_below_crossover": below,
        "about_equal": ABOUT_EQUAL,
        "equal_below_crossover": equal_below,
        "faster_at_large_model": faster_at_large,
    }, timing=True)


def c2(errors: Sequence[IncrementalError]) -> ClaimResult:
    """C2 from the incremental box's errors. Confirmed when it is never wrong
    on a convex mesh and wrong on some non-convex one; partly when, besides,
    some non-convex mesh never makes it wrong (convexity is sufficient, not
    necessary); refuted when it is wrong on a convex mesh or never wrong."""
    convex_wrong = sum(e.wrong_frames for e in errors if e.convex)
    wrong = sorted({e.mesh for e in errors if not e.convex and e.wrong_frames})
    never = sorted({e.mesh for e in errors if not e.convex and not e.wrong_frames})
    needed = convex_wrong == 0 and bool(wrong)
    sufficient_not_necessary = needed and bool(never)
    verdict = ("partly" if sufficient_not_necessary else "confirmed" if needed else "refuted")
    return ClaimResult("C2", verdict, {
        "convex_wrong_frames": convex_wrong,
        "nonconvex_wrong": wrong,
        "nonconvex_never_wrong": never,
        "sufficient_not_necessary": sufficient_not_necessary,
    })
