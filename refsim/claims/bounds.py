"""Claims C1 and C2: the incremental bounding box against the linear scan (S2).

C1 (cost): "incremental and linear AABB update cost about the same until
models are large; incremental clearly faster at 2000 triangles", judged on
the cost study of :func:`refsim.studies.bounds.measure_update_cost`.
C2 (correctness): "the incremental update needs a convex model", judged on
:func:`refsim.studies.bounds.measure_incremental_error`.
"""

from __future__ import annotations

from collections.abc import Sequence

from refsim.claims.result import ClaimResult, by_timed_parts, comparison, spread
from refsim.studies.bounds import BoundsAgreement, IncrementalError, UpdateCostStudy

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


#: The scan/incremental time ratio at which the incremental update is faster.
PARITY = 1.0


def _band_side(ratio: float, repeats) -> str:
    """Where a ratio lies against the :data:`ABOUT_EQUAL` band, with its
    run-to-run spread: "inside", "outside" or "within spread" of an edge."""
    low, high = (comparison(ratio, edge, repeats)["side"] for edge in ABOUT_EQUAL)
    if low in ("above", "at") and high in ("below", "at"):     # the band is closed
        return "inside"
    if low == "below" or high == "above":
        return "outside"
    return "within spread"


def c1(study: UpdateCostStudy) -> ClaimResult:
    """C1 from the measured speed-ups, each against its run-to-run spread
    (the interquartile range of the per-repeat ratios,
    :func:`refsim.claims.result.comparison`). Its two parts: the incremental
    update is faster (scan/incremental ratio above :data:`PARITY`) at every
    size from :data:`SEED_LARGE_MODEL` triangles on, and below the compiled
    crossover the two cost about the same (every ratio inside
    :data:`ABOUT_EQUAL`). A part is open when a ratio it rests on lies within
    its spread of the threshold and none clearly breaks it; the verdict is
    "undecided" when the open parts could turn it
    (:func:`refsim.claims.result.by_timed_parts`)."""
    compiled = study.crossovers.get(COMPILED)
    ratios = dict(study.speedups.get(COMPILED, []))   # size -> scan time / incremental time
    repeats = dict(study.speedup_repeats.get(COMPILED, []))   # size -> per-repeat ratios
    below = [r for n, r in ratios.items() if compiled is None or n < compiled]
    large = {n: comparison(r, PARITY, repeats.get(n, ())) for n, r in ratios.items()
             if n >= SEED_LARGE_MODEL}
    band = {n: _band_side(r, repeats.get(n, ())) for n, r in ratios.items()
            if compiled is None or n < compiled}
    sides = [c["side"] for c in large.values()]
    faster = ("failed" if not sides or "below" in sides or "at" in sides  # a tie is not faster
              else "open" if "within spread" in sides else "held")
    equal = ("failed" if not band or "outside" in band.values()
             else "open" if "within spread" in band.values() else "held")
    parts = (faster, equal)
    return ClaimResult("C1", by_timed_parts(parts.count("held"), parts.count("open"), 2), {
        "compiled_crossover": compiled,
        "interpreted_crossover": study.crossovers.get(INTERPRETED),
        "large_model": SEED_LARGE_MODEL,
        "ratio_at_large_model": ratios.get(SEED_LARGE_MODEL),
        "ratios_below_crossover": below,
        "about_equal": ABOUT_EQUAL,
        "equal_below_crossover": equal == "held",
        "faster_at_large_model": faster == "held",
        "faster_part": faster,
        "equal_part": equal,
        "against_parity": {n: large[n] for n in sorted(large)},
        "against_band": {n: band[n] for n in sorted(band)},
        "spreads": {n: spread(repeats.get(n, ())) for n in sorted(ratios)},
        "open": sorted({n for n, c in large.items() if c["side"] == "within spread"}
                       | {n for n, side in band.items() if side == "within spread"}),
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


#: The class of trimesh's boxes differing from refsim's scan in the last bits
#: (within the bound of the arithmetic: its BLAS 4x4 product rounds
#: differently), in the divergence catalogue.
TRIMESH_BITS_CLASS = "oracle disagreement: tolerance"


def box_agreement(rows: Sequence[BoundsAgreement]) -> dict:
    """The box agreement's findings over the meshes: trimesh's boxes against
    the scan (poses within the arithmetic bound, bitwise equal, differing,
    and, when some differ, the largest difference over the bound with its
    divergence class :data:`TRIMESH_BITS_CLASS`); the incremental box
    against the scan on the convex meshes (bitwise equal poses)."""
    poses = sum(a.poses for a in rows)
    bitwise = sum(a.trimesh_bitwise for a in rows)
    convex = [a for a in rows if a.incremental_exact is not None]
    found: dict = {"poses": poses, "trimesh_within": sum(a.trimesh_within for a in rows),
                   "trimesh_bitwise": bitwise, "trimesh_differ": poses - bitwise,
                   "convex_poses": sum(a.poses for a in convex),
                   "incremental_exact": sum(a.incremental_exact or 0 for a in convex)}
    if found["trimesh_differ"]:
        found |= {"largest_over_bound": max(a.max_difference_over_tolerance for a in rows),
                  "class": TRIMESH_BITS_CLASS}
    return found
