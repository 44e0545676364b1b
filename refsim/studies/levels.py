"""Measurements of body-body collision: the four levels of accuracy (claim
C3), agreement of the exact level with body-level oracles, and the speed of
the triangle hierarchy against FCL (seed S4).

What: ``measure_*`` functions return frozen dataclasses of numbers that the
tests gate on and the report draws; nothing here prints or plots
(``refsim study collision-levels``, ``collision-body-oracles`` and
``collision-speed`` print them).

- :func:`measure_levels` (C3, "3 levels of accuracy [...] to trade accuracy
  for speed"): every level of :func:`refsim.collision.bodies.bodies_collide`
  on constructed configurations of the bundled models (:data:`CONFIGURATIONS`)
  and on seeded random poses: false positives against the exact level (body
  level: the level says "collide" where the exact level says no; pair level:
  triangle-aabb pairs that are not exact pairs), false negatives (none may
  exist: every level is conservative), and the median time per query; the
  seed's pairwise path against the hierarchy.
- :func:`measure_body_oracles`: refsim's exact answers against FCL's
  intersecting face pairs, FCL's boolean query and trimesh's
  ``CollisionManager``, every disagreement classified
  (:func:`classify_body_disagreement`, the conformance kit's classifier:
  a class and a reason; pairs by
  :func:`refsim.studies.triangles.classify_disagreement`).
- :func:`measure_hierarchy_speed`: the 2k-triangle sphere and torus pairs in
  three configurations, and two touching pairs (cubes face to face, a cube
  on the sphere) (:data:`SPEED_CONFIGURATIONS`): all intersecting pairs
  by the hierarchy, by the seed's path and by FCL, and the boolean query
  against FCL's, as medians and ratios measured in the same run; and the
  one-off compile cost of the numba kernels.

The study of the levels is here; the others have their own modules, whose
names this one re-exports (so ``refsim.studies.levels.X`` keeps working):
:mod:`refsim.studies.collision_cases` (the models, configurations and
random poses), :mod:`refsim.studies.body_oracles` and
:mod:`refsim.studies.hierarchy_speed`. Oracles are passed in (callables or
adapter objects), so refsim does not import ``oracles``; the composition
root (:mod:`refsim.report.plan`) builds them.

Cost: a query is what :mod:`refsim.collision.bodies` costs (O(n + m) per
body plus the traversal); every timing is the median of ``repeats`` calls
after one untimed call (which builds the hierarchy and, for numba, loads the
compiled code).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from refsim.collision.bodies import LEVELS, bodies_collide, intersecting_pairs
from refsim.kernels import choose_kernel
from refsim.studies import TIMED
from refsim.studies.body_oracles import (  # noqa: F401  (re-exported)
    BODY_DISAGREEMENT_KINDS,
    BodyAgreement,
    BodyDisagreement,
    OracleAgreement,
    PairAgreement,
    PairDisagreement,
    classify_body_disagreement,
    measure_body_oracles,
)
from refsim.studies.collision_cases import (  # noqa: F401  (re-exported)
    CONFIGURATIONS,
    DIAGONAL,
    FIXED_ANGLE,
    FIXED_AXIS,
    HALF_TURN_Z,
    KINDS,
    RANDOM_MODEL_PAIRS,
    XZ_DIAGONAL,
    Configuration,
    _median_seconds,
    _repeat_seconds,
    bundled_mesh,
    fixed_rotation,
    model_label,
    random_poses,
)
from refsim.studies.hierarchy_speed import (  # noqa: F401  (re-exported)
    SPEED_CONFIGURATIONS,
    CompileCost,
    HierarchySpeed,
    SpeedCase,
    SpeedConfiguration,
    measure_compile_cost,
    measure_hierarchy_compile_seconds,
    measure_hierarchy_speed,
)


@dataclass(frozen=True)
class ConfigurationLevels:
    """Every level on one constructed configuration."""

    name: str
    kind: str
    description: str
    intended: bool                  # the exact answer by construction
    answers: dict                   # level -> bool (bodies_collide, method "bvh")
    seconds: dict = field(metadata=TIMED)  # level -> median seconds per boolean query ("bvh")
    # "triangle-aabb", "exact" -> median seconds, method "seed"
    seed_seconds: dict = field(metadata=TIMED)
    candidate_pairs: int            # triangle-aabb pairs
    exact_pairs: int
    # "bvh", "seed" -> median seconds of intersecting_pairs at the exact level
    pairs_seconds: dict = field(metadata=TIMED)
    seed_answers_equal: bool        # method "seed" gave the same answers and pairs
    # level -> each repeat's seconds per boolean query ("bvh"), whose median is ``seconds``
    seconds_by_repeat: dict = field(default_factory=dict, metadata=TIMED)

    @property
    def pair_false_positives(self) -> int:
        return self.candidate_pairs - self.exact_pairs

    def false_positive(self, level: str) -> bool:
        return self.answers[level] and not self.answers["exact"]

    def false_negative(self, level: str) -> bool:
        return self.answers["exact"] and not self.answers[level]


@dataclass(frozen=True)
class RandomLevels:
    """Every level on seeded random poses of one model pair."""

    model_a: str
    model_b: str
    n: int
    exact_true: int
    false_positives: dict           # level -> count (level True, exact False)
    false_negatives: dict           # level -> count (level False, exact True)
    candidate_pairs: int            # summed over the poses
    exact_pairs: int
    seed_mismatches: int            # poses where method "seed" gave other pairs


@dataclass(frozen=True)
class LevelSummary:
    level: str
    median_seconds: float = field(metadata=TIMED)  # median over the configurations of their medians
    false_positives: int            # configurations + random poses
    negatives: int                  # queries where exact says no (the most FPs possible)
    false_negatives: int
    # for each repeat k, the median over the configurations of their k-th time:
    # the run-to-run spread of median_seconds
    seconds_by_repeat: tuple[float, ...] = field(default=(), metadata=TIMED)

    @property
    def false_positive_rate(self) -> float:
        return self.false_positives / self.negatives if self.negatives else 0.0


@dataclass(frozen=True)
class LevelsResult:
    levels: tuple
    kernel: str
    repeats: int
    seed: int
    configurations: tuple           # ConfigurationLevels
    random: tuple                   # RandomLevels
    summary: tuple                  # LevelSummary, one per level

    @property
    def false_negatives(self) -> int:
        return sum(s.false_negatives for s in self.summary)

    def level(self, name: str) -> LevelSummary:
        return next(s for s in self.summary if s.level == name)

    def configuration(self, name: str) -> ConfigurationLevels:
        return next(c for c in self.configurations if c.name == name)


def measure_levels(configurations: tuple[Configuration, ...] = CONFIGURATIONS,
                   repeats: int = 21, *, random_pairs=RANDOM_MODEL_PAIRS,
                   random_per_pair: int = 50, seed: int = 0,
                   kernel: str | None = None) -> LevelsResult:
    """Claim C3: answers, false positives and negatives, and time per level.

    The boolean queries use ``method="bvh"`` (``kernel``: default numba when
    installed); the seed's pairwise path (``method="seed"``) is timed beside
    it at the two triangle levels, and its answers and pairs are checked to
    be the same. The random poses (:func:`random_poses`, ``random_per_pair``
    per model pair, seeded) give the rates; they are not timed.
    """
    kernel = choose_kernel(kernel)
    done = []
    for c in configurations:
        mesh_a, mesh_b = c.meshes()
        pose_a, pose_b = c.poses()

        def ask(level, method="bvh", a=mesh_a, b=mesh_b, pa=pose_a, pb=pose_b):
            return bodies_collide(a, pa, b, pb, level=level, method=method, kernel=kernel)

        def pairs(level, method="bvh", a=mesh_a, b=mesh_b, pa=pose_a, pb=pose_b):
            return intersecting_pairs(a, pa, b, pb, level=level, method=method, kernel=kernel)

        # bool(): the sphere level returns a numpy bool (see the report)
        answers = {level: bool(ask(level)) for level in LEVELS}
        by_repeat = {level: _repeat_seconds(functools.partial(ask, level), repeats)
                     for level in LEVELS}
        seconds = {level: float(np.median(times)) for level, times in by_repeat.items()}
        seed_seconds = {level: _median_seconds(functools.partial(ask, level, "seed"),
                                               max(3, repeats // 4))
                        for level in ("triangle-aabb", "exact")}
        candidates, exact = pairs("triangle-aabb"), pairs("exact")
        same = (all(ask(level, "seed") == answers[level] for level in ("triangle-aabb", "exact"))
                and np.array_equal(pairs("triangle-aabb", "seed"), candidates)
                and np.array_equal(pairs("exact", "seed"), exact))
        done.append(ConfigurationLevels(
            name=c.name, kind=c.kind, description=c.description, intended=c.intended,
            answers=answers, seconds=seconds, seed_seconds=seed_seconds,
            candidate_pairs=len(candidates), exact_pairs=len(exact),
            pairs_seconds={"bvh": _median_seconds(functools.partial(pairs, "exact"), repeats),
                           "seed": _median_seconds(functools.partial(pairs, "exact", "seed"),
                                                   max(3, repeats // 4))},
            seed_answers_equal=bool(same), seconds_by_repeat=by_repeat))

    rng = np.random.default_rng(seed)
    randoms = []
    for (name_a, scale_a), (name_b, scale_b) in random_pairs:
        mesh_a, mesh_b = bundled_mesh(name_a, scale_a), bundled_mesh(name_b, scale_b)
        fp = dict.fromkeys(LEVELS, 0)
        fn = dict.fromkeys(LEVELS, 0)
        exact_true = n_candidates = n_exact = mismatches = 0
        for pose_a, pose_b in random_poses(mesh_a, mesh_b, random_per_pair, rng):
            answers = {level: bool(bodies_collide(mesh_a, pose_a, mesh_b, pose_b, level=level,
                                                  kernel=kernel)) for level in LEVELS}
            exact_true += answers["exact"]
            for level in LEVELS:
                fp[level] += answers[level] and not answers["exact"]
                fn[level] += answers["exact"] and not answers[level]
            candidates = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b,
                                            level="triangle-aabb", kernel=kernel)
            exact = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, kernel=kernel)
            n_candidates += len(candidates)
            n_exact += len(exact)
            mismatches += not np.array_equal(
                exact, intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, method="seed",
                                          kernel=kernel))
        randoms.append(RandomLevels(
            model_a=model_label(name_a, scale_a), model_b=model_label(name_b, scale_b),
            n=random_per_pair, exact_true=exact_true, false_positives=fp, false_negatives=fn,
            candidate_pairs=n_candidates, exact_pairs=n_exact, seed_mismatches=mismatches))

    summary = []
    for level in LEVELS:
        negatives = (sum(not c.answers["exact"] for c in done)
                     + sum(r.n - r.exact_true for r in randoms))
        summary.append(LevelSummary(
            level=level,
            median_seconds=float(np.median([c.seconds[level] for c in done])) if done else 0.0,
            false_positives=(sum(c.false_positive(level) for c in done)
                             + sum(r.false_positives[level] for r in randoms)),
            negatives=negatives,
            false_negatives=(sum(c.false_negative(level) for c in done)
                             + sum(r.false_negatives[level] for r in randoms)),
            seconds_by_repeat=tuple(float(np.median(times)) for times in zip(
                *(c.seconds_by_repeat[level] for c in done), strict=True)) if done else ()))
    return LevelsResult(levels=LEVELS, kernel=kernel, repeats=repeats, seed=seed,
                        configurations=tuple(done), random=tuple(randoms),
                        summary=tuple(summary))
