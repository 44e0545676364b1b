"""The report's collision entries (seed S4, claims C3 and C4).

The levels of the seed's collision test (C3), the body-level oracles, the
hierarchy's speed against FCL, the exact triangle test against FCL's on
random and near-degenerate pairs, near-parallel triangles (C4), and the
triangle test's fallback rates and speed (``refsim study`` only). Each runs
without python-fcl (``run.optional``), its FCL columns then empty.
:data:`COLLISION_SIZES` holds every quick and full size.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from refsim.report.run import Run

#: (quick, full) sizes of each collision measurement: quick keeps the
#: section to seconds (after numba's first compile), full to minutes.
COLLISION_SIZES = {
    "repeats": (3, 21),
    "random_per_pair": (5, 50),
    "speed_repeats": (5, 31),
    "triangle_pairs": (2000, 20_000),
    "near_degenerate_pairs": (1000, 5000),
    "c4_frames": (10, 100),
}


@dataclass(frozen=True)
class TrianglePairs:
    """The exact triangle test against FCL on one family of pairs."""

    pairs: str                  # what the pairs are
    agreement: Any              # refsim.studies.triangles.Agreement


@dataclass(frozen=True)
class C4Run:
    """Near-parallel triangles: the fixed frames and the random frames."""

    c4: Any                     # refsim.studies.triangles.C4Result
    sweep: Any                  # refsim.studies.triangles.C4Sweep


@dataclass(frozen=True)
class TriangleSpeed:
    fallback: Any               # refsim.studies.triangles.FallbackRates
    throughput: Any             # refsim.studies.triangles.Throughput
    float_errors: Any           # refsim.studies.triangles.FloatErrors


def _collision(run: Run, key: str) -> int:
    return run.size(*COLLISION_SIZES[key])


def _fcl_triangles(run: Run):
    """FCL's triangle test, or None without python-fcl."""
    fcl = run.optional("fcl")
    return None if fcl is None else fcl.triangles_intersect


def collision_levels(run: Run):
    from refsim.studies import levels

    return levels.measure_levels(repeats=_collision(run, "repeats"),
                                 random_per_pair=_collision(run, "random_per_pair"),
                                 seed=run.seed)


def collision_body_oracles(run: Run):
    from refsim.studies import levels

    body = tuple(e for e in (run.optional("fcl"), run.optional("trimesh-collision"))
                 if e is not None)
    return levels.measure_body_oracles(body, run.optional("fcl"),
                                       random_per_pair=_collision(run, "random_per_pair"),
                                       seed=run.seed)


def collision_speed(run: Run):
    from refsim.studies import levels

    return levels.measure_hierarchy_speed(run.optional("fcl"), _collision(run, "speed_repeats"),
                                          compile_cost=not run.quick)


def collision_triangles(run: Run):
    import numpy as np

    from refsim.studies import triangles

    oracle = _fcl_triangles(run)
    if oracle is None:
        return []
    rng = np.random.default_rng(run.seed)
    n = _collision(run, "triangle_pairs")
    A, B = rng.uniform(-1.0, 1.0, (2, n, 3, 3))
    rows = [TrianglePairs("uniform random triangle pairs",
                          triangles.compare_with_oracle(A, B, oracle))]
    A, B, _ = triangles.near_degenerate_pairs(_collision(run, "near_degenerate_pairs"), run.seed)
    rows.append(TrianglePairs("near-degenerate triangle pairs",
                              triangles.compare_with_oracle(A, B, oracle)))
    return rows


def collision_c4(run: Run):
    from refsim.studies import triangles

    oracle = _fcl_triangles(run)
    return C4Run(triangles.measure_c4(oracle, run.seed),
                 triangles.measure_c4_sweep(_collision(run, "c4_frames"), oracle, run.seed))


def triangles_speed(run: Run):
    from refsim.studies import triangles

    n = run.size(2000, 20_000)
    oracle = _fcl_triangles(run)
    return TriangleSpeed(triangles.measure_filter_fallback(n, run.seed),
                         triangles.measure_throughput(n, run.seed, oracle),
                         triangles.measure_float_errors(min(n, 5000), run.seed, oracle))
