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

Oracles are passed in (callables or adapter objects), so refsim does not
import ``oracles``; the composition root (:mod:`refsim.report.plan`) builds
them.

Cost: a query is what :mod:`refsim.collision.bodies` costs (O(n + m) per
body plus the traversal); every timing is the median of ``repeats`` calls
after one untimed call (which builds the hierarchy and, for numba, loads the
compiled code).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from refsim.collision.bodies import LEVELS, bodies_collide, intersecting_pairs
from refsim.collision.boxes import world_vertices
from refsim.collision.disagreement import (
    BODY_CLASSES,
    BODY_REASONS,
    BodyVerdict,
    classify_bodies,
)
from refsim.collision.spheres import bounding_sphere
from refsim.engines import body_conventions
from refsim.kernels import choose_kernel
from refsim.studies import TIMED
from refsim.studies.triangles import DISAGREEMENT_KINDS, classify_disagreement
from refsim.types import Pose, random_rotation, rotation_about_axis

# --------------------------------------------------------------------------
# models and configurations
# --------------------------------------------------------------------------

#: The fixed rotation of the second body in the speed benchmark and in the
#: constructed configurations (about a generic axis, so no face of the second
#: body is parallel to one of the first).
FIXED_AXIS = (1.0, 2.0, 3.0)
FIXED_ANGLE = 0.7

#: Half a turn about z, written exactly (no rounding of cos(pi), sin(pi)).
HALF_TURN_Z = ((-1.0, 0.0, 0.0), (0.0, -1.0, 0.0), (0.0, 0.0, 1.0))

DIAGONAL = (1.0, 1.0, 1.0)          # sphere pairs move apart along this
XZ_DIAGONAL = (1.0, 0.0, 1.0)       # torus pairs (the torus lies in the xz plane)


@functools.cache
def bundled_mesh(name: str, scale: float = 1.0):
    """A bundled model (``models/<name>.ac``), its vertices scaled by ``scale``
    about the origin (the scene files' ``scale`` key). Cached: the same mesh
    object, hence the same hierarchy and oracle models, for every query."""
    from refsim.bundled import models_dir
    from refsim.models.loading import load_model
    from refsim.models.mesh import Mesh

    mesh = load_model(models_dir() / f"{name}.ac")
    if scale == 1.0:
        return mesh
    return Mesh(mesh.vertices * scale, mesh.faces, name=f"{name}@{scale:g}")


def model_label(name: str, scale: float = 1.0) -> str:
    return name if scale == 1.0 else f"{name} x{scale:g}"


def fixed_rotation() -> np.ndarray:
    return rotation_about_axis(FIXED_AXIS, FIXED_ANGLE)


@dataclass(frozen=True)
class Configuration:
    """Two bundled bodies placed by construction: A at the identity pose,
    B at ``(rotation_b, translation_b)``.

    ``rotation_b`` is "fixed" (:func:`fixed_rotation`), "identity",
    "half-turn-z" or ``("y", angle)`` (about the y axis).
    ``translation_b`` is ``distance`` along the unit vector of ``direction``.
    """

    name: str
    kind: str            # see KINDS
    description: str
    model_a: str
    model_b: str
    scale_a: float = 1.0
    scale_b: float = 1.0
    rotation_b: str | tuple[str, float] = "fixed"
    direction: tuple = (1.0, 0.0, 0.0)
    distance: float = 0.0
    intended: bool = False          # the exact answer by construction

    def meshes(self):
        return bundled_mesh(self.model_a, self.scale_a), bundled_mesh(self.model_b, self.scale_b)

    def poses(self) -> tuple[Pose, Pose]:
        if self.rotation_b == "fixed":
            rotation = fixed_rotation()
        elif self.rotation_b == "identity":
            rotation = np.eye(3)
        elif self.rotation_b == "half-turn-z":
            rotation = np.array(HALF_TURN_Z)
        elif isinstance(self.rotation_b, tuple):
            axis, angle = self.rotation_b
            rotation = rotation_about_axis(np.eye(3)["xyz".index(axis)], angle)
        else:
            raise ValueError(f"rotation_b {self.rotation_b!r}: not 'fixed', 'identity', "
                             "'half-turn-z' or (axis, angle)")
        direction = np.asarray(self.direction, dtype=np.float64)
        if np.count_nonzero(direction) == 1:
            translation = direction * self.distance          # exact for axis directions
        else:
            translation = direction / np.linalg.norm(direction) * self.distance
        return (np.eye(3), np.zeros(3)), (rotation, translation)


KINDS = ("separated-far", "separated-boxes-overlap", "touching", "grazing",
         "interpenetrating", "inside")

#: The constructed configurations of :func:`measure_levels`. Sizes: sphere-2k
#: has radius 1; the torus lies in the xz plane, major radius 1, tube radius
#: 0.35 (its hole has radius 0.65, half-height 0.35); the cube is [-0.5, 0.5]^3.
CONFIGURATIONS: tuple[Configuration, ...] = (
    Configuration("far", "separated-far",
                  "sphere-2k and torus, centres 4 apart along x: boxes apart",
                  "sphere-2k", "torus", direction=(1.0, 0.0, 0.0), distance=4.0),
    Configuration("spheres-2.1", "separated-boxes-overlap",
                  "two sphere-2k, centres 2.1 apart along (1,1,1): gap 0.1, boxes overlap, "
                  "bounding spheres apart",
                  "sphere-2k", "sphere-2k", direction=DIAGONAL, distance=2.1),
    Configuration("tori-2.72", "separated-boxes-overlap",
                  "two tori, centres 2.72 apart along (1,0,1), second turned: boxes and "
                  "triangle boxes overlap, surfaces apart",
                  "torus", "torus", direction=XZ_DIAGONAL, distance=2.72),
    Configuration("l-beams-nested", "separated-boxes-overlap",
                  "two L-beams, the second turned half a turn about z and moved by "
                  "(0.9, 0.9, 0): it sits in the first one's empty quadrant, gap 1/15",
                  "l-beam", "l-beam", rotation_b="half-turn-z", direction=(1.0, 1.0, 0.0),
                  distance=0.9 * math.sqrt(2.0)),
    Configuration("cubes-face", "touching",
                  "two unit cubes, centres 1 apart along x: they share the face x = 0.5 "
                  "(exact coordinates)",
                  "cube", "cube", rotation_b="identity", direction=(1.0, 0.0, 0.0),
                  distance=1.0, intended=True),
    Configuration("cubes-corner", "touching",
                  "two unit cubes, centres (1, 1, 1) apart: they share one corner only",
                  "cube", "cube", rotation_b="identity", direction=DIAGONAL,
                  distance=math.sqrt(3.0), intended=True),
    Configuration("spheres-1.99", "grazing",
                  "two sphere-2k, centres 1.99 apart along (1,1,1): overlap depth 0.01, a "
                  "handful of triangle pairs",
                  "sphere-2k", "sphere-2k", direction=DIAGONAL, distance=1.99, intended=True),
    Configuration("tori-2.66", "grazing",
                  "two tori, centres 2.66 apart along (1,0,1): a handful of triangle pairs",
                  "torus", "torus", direction=XZ_DIAGONAL, distance=2.66, intended=True),
    Configuration("spheres-1.0", "interpenetrating",
                  "two sphere-2k, centres 1 apart along (1,1,1): hundreds of triangle pairs",
                  "sphere-2k", "sphere-2k", direction=DIAGONAL, distance=1.0, intended=True),
    Configuration("tori-1.0", "interpenetrating",
                  "two tori, centres 1 apart along (1,0,1): hundreds of triangle pairs",
                  "torus", "torus", direction=XZ_DIAGONAL, distance=1.0, intended=True),
    Configuration("icosahedron-in-sphere", "inside",
                  "an icosahedron scaled by 0.5 (radius 0.5) at the centre of sphere-2k "
                  "(radius 1), turned",
                  "sphere-2k", "icosahedron", scale_b=0.5),
    Configuration("cube-in-torus-hole", "inside",
                  "a cube scaled by 0.8 in the torus's hole, turned 0.3 rad about y: its "
                  "corners stay 0.566 from the axis (hole radius 0.65); it pokes out of "
                  "the torus's slab (|y| <= 0.35)",
                  "torus", "cube", scale_b=0.8, rotation_b=("y", 0.3)),
    Configuration("cube-in-cube", "inside",
                  "a cube scaled by 0.5 at the centre of the unit cube, turned",
                  "cube", "cube", scale_b=0.5),
)

#: Model pairs posed at random by :func:`measure_levels` and
#: :func:`measure_body_oracles`: ((name, scale), (name, scale)). Small models
#: (fast), convex and non-convex, and small bodies that fit inside larger
#: ones (so containment occurs).
RANDOM_MODEL_PAIRS: tuple[tuple[tuple[str, float], tuple[str, float]], ...] = (
    (("cube", 1.0), ("cube", 1.0)),
    (("icosahedron", 1.0), ("cube", 1.0)),
    (("long-box", 1.0), ("long-box", 1.0)),
    (("star", 1.0), ("l-beam", 1.0)),
    (("l-beam", 1.0), ("l-beam", 1.0)),
    (("torus", 1.0), ("icosahedron", 0.5)),
    (("sphere-2k", 1.0), ("icosahedron", 0.5)),
    (("cube", 1.0), ("cube", 0.3)),
)


def random_poses(mesh_a, mesh_b, n: int, rng: np.random.Generator, reach: float = 1.1):
    """n pose pairs: both bodies turned at random, A's bounding-sphere centre at
    the origin, B's at a uniform random distance in [0, reach (r_a + r_b)]
    along a uniform random direction (so from deep inside to just apart)."""
    ca, ra = bounding_sphere(mesh_a)
    cb, rb = bounding_sphere(mesh_b)
    poses = []
    for _ in range(n):
        rot_a, rot_b = random_rotation(rng), random_rotation(rng)
        direction = rng.standard_normal(3)
        direction /= np.linalg.norm(direction)
        centre_b = direction * rng.uniform(0.0, reach * (ra + rb))
        poses.append(((rot_a, -rot_a @ ca), (rot_b, centre_b - rot_b @ cb)))
    return poses


def _repeat_seconds(call: Callable[[], object], repeats: int) -> tuple[float, ...]:
    """Wall time of each of ``repeats`` calls (time.perf_counter), after one
    untimed call."""
    call()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return tuple(times)


def _median_seconds(call: Callable[[], object], repeats: int) -> float:
    """Median wall time of ``repeats`` calls, after one untimed call."""
    return float(np.median(_repeat_seconds(call, repeats)))


# --------------------------------------------------------------------------
# claim C3: the levels
# --------------------------------------------------------------------------

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


# --------------------------------------------------------------------------
# agreement with body-level oracles
# --------------------------------------------------------------------------

#: The classes of a body-level disagreement, in the order the study
#: tabulates them: the conformance kit's classes
#: (:data:`refsim.collision.disagreement.BODY_CLASSES`), each disagreement's
#: finer reason kept beside its class.
BODY_DISAGREEMENT_KINDS = BODY_CLASSES


def classify_body_disagreement(mesh_a, pose_a, mesh_b, pose_b, ours: bool,
                               engine, kernel: str | None = None) -> BodyVerdict:
    """Why a ``collide`` engine's answer differs from refsim's exact ``ours``:
    :func:`refsim.collision.disagreement.classify_bodies` (the conformance
    kit's ``collide.agreement`` classifier) with the engine's declared
    conventions (:func:`refsim.engines.body_conventions`: its distance
    tolerance, unit roundoff, ``solid`` or ``is_solid``, ``pose_used``).
    The verdict's ``kind`` is the class, ``reason`` the finer reason and
    ``gap`` the gap in metres."""
    return classify_bodies(mesh_a, pose_a, mesh_b, pose_b, not ours, kernel=kernel,
                           **body_conventions(engine))


@dataclass(frozen=True)
class BodyDisagreement:
    source: str             # "random" or "constructed"
    case: str               # the configuration name or "model_a / model_b #k"
    refsim: bool
    oracle: bool
    kind: str               # the class (BODY_DISAGREEMENT_KINDS)
    reason: str = ""        # a key of refsim.collision.disagreement.BODY_REASONS
    gap: float = 0.0        # metres: distance apart, or minus the deepest pair's depth


@dataclass(frozen=True)
class BodyAgreement:
    """refsim's exact bodies_collide against one body-level oracle."""

    oracle: str
    source: str             # "random" or "constructed"
    n: int
    agree: int
    refsim_true: int
    oracle_true: int
    counts: dict = field(default_factory=dict)      # kind -> disagreements
    disagreements: tuple = ()
    reasons: dict = field(default_factory=dict)     # reason -> disagreements (those met)


@dataclass(frozen=True)
class PairDisagreement:
    case: str
    face_a: int
    face_b: int
    refsim: bool
    oracle: bool
    kind: str


@dataclass(frozen=True)
class PairAgreement:
    """refsim's exact intersecting_pairs against FCL's face pairs."""

    source: str
    queries: int
    queries_equal: int      # queries where the two sets of pairs are identical
    refsim_pairs: int       # summed over the queries
    oracle_pairs: int
    common_pairs: int
    counts: dict = field(default_factory=dict)      # kind -> pairs in one set only
    disagreements: tuple = ()


@dataclass(frozen=True)
class OracleAgreement:
    seed: int
    random_per_pair: int
    model_pairs: tuple              # labels "a / b"
    bodies: tuple                   # BodyAgreement per oracle and source
    pairs: tuple                    # PairAgreement per source (empty without FCL)

    @property
    def bugs(self) -> int:
        return (sum(b.counts.get("bug", 0) for b in self.bodies)
                + sum(p.counts.get("bug", 0) for p in self.pairs))

    def body(self, oracle: str, source: str) -> BodyAgreement:
        return next(b for b in self.bodies if b.oracle == oracle and b.source == source)

    def pair(self, source: str) -> PairAgreement:
        return next(p for p in self.pairs if p.source == source)


def _cases(configurations, random_pairs, random_per_pair, seed):
    """(source, case label, mesh_a, pose_a, mesh_b, pose_b) for every query."""
    for c in configurations:
        (mesh_a, mesh_b), (pose_a, pose_b) = c.meshes(), c.poses()
        yield ("constructed", c.name, mesh_a, pose_a, mesh_b, pose_b)
    rng = np.random.default_rng(seed)
    for (name_a, scale_a), (name_b, scale_b) in random_pairs:
        mesh_a, mesh_b = bundled_mesh(name_a, scale_a), bundled_mesh(name_b, scale_b)
        label = f"{model_label(name_a, scale_a)} / {model_label(name_b, scale_b)}"
        for k, (pose_a, pose_b) in enumerate(random_poses(mesh_a, mesh_b, random_per_pair,
                                                          rng)):
            yield ("random", f"{label} #{k}", mesh_a, pose_a, mesh_b, pose_b)


def measure_body_oracles(collide_engines: tuple = (), pairs_engine=None, *,
                         configurations: tuple[Configuration, ...] = CONFIGURATIONS,
                         random_pairs=RANDOM_MODEL_PAIRS, random_per_pair: int = 50,
                         seed: int = 0, kernel: str | None = None) -> OracleAgreement:
    """refsim's exact answers against the oracles, on the constructed
    configurations and on seeded random poses (:func:`random_poses`) of
    ``random_pairs``; every disagreement classified, none dropped.

    ``collide_engines``: engines with the ``collide`` capability
    (:mod:`refsim.engines`), compared with ``bodies_collide(level="exact")``.
    ``pairs_engine``: an engine with the ``pairs`` capability, compared with
    ``intersecting_pairs``; each pair in one set only is classified by
    :func:`refsim.studies.triangles.classify_disagreement` on refsim's world
    triangles.
    """
    kernel = choose_kernel(kernel)
    body_rows: dict[tuple[str, str], list] = {}
    pair_rows: dict[str, list] = {}
    for source, case, mesh_a, pose_a, mesh_b, pose_b in _cases(
            configurations, random_pairs, random_per_pair, seed):
        ours = bool(bodies_collide(mesh_a, pose_a, mesh_b, pose_b, kernel=kernel))
        arrays = (mesh_a.vertices, mesh_a.faces, pose_a, mesh_b.vertices, mesh_b.faces, pose_b)
        for engine in collide_engines:
            theirs = bool(engine.bodies_collide(*arrays))
            verdict = None if theirs == ours else classify_body_disagreement(
                mesh_a, pose_a, mesh_b, pose_b, ours, engine, kernel)
            body_rows.setdefault((engine.name, source), []).append(
                (case, ours, theirs, verdict))
        if pairs_engine is not None:
            mine = intersecting_pairs(mesh_a, pose_a, mesh_b, pose_b, kernel=kernel)
            other = np.asarray(pairs_engine.intersecting_pairs(*arrays), dtype=np.int64)
            ours_set = set(map(tuple, mine.tolist()))
            theirs_set = set(map(tuple, other.reshape(-1, 2).tolist()))
            found = []
            if ours_set != theirs_set:
                world_a = world_vertices(mesh_a, pose_a)
                world_b = world_vertices(mesh_b, pose_b)
                for i, j in sorted(ours_set ^ theirs_set):
                    kind = classify_disagreement(world_a[mesh_a.faces[i]],
                                                 world_b[mesh_b.faces[j]])
                    found.append(PairDisagreement(case, i, j, (i, j) in ours_set,
                                                  (i, j) in theirs_set, kind))
            pair_rows.setdefault(source, []).append(
                (len(ours_set), len(theirs_set), len(ours_set & theirs_set), found))

    bodies = []
    for (name, source), rows in body_rows.items():
        body_found = tuple(BodyDisagreement(source, case, ours, theirs, v.kind, v.reason, v.gap)
                           for case, ours, theirs, v in rows if v is not None)
        bodies.append(BodyAgreement(
            oracle=name, source=source, n=len(rows), agree=len(rows) - len(body_found),
            refsim_true=sum(r[1] for r in rows), oracle_true=sum(r[2] for r in rows),
            counts={k: sum(d.kind == k for d in body_found) for k in BODY_DISAGREEMENT_KINDS},
            disagreements=body_found,
            reasons={r: n for r in BODY_REASONS
                     if (n := sum(d.reason == r for d in body_found))}))
    pairs = []
    for source, rows in pair_rows.items():
        pair_found = tuple(d for r in rows for d in r[3])
        pairs.append(PairAgreement(
            source=source, queries=len(rows), queries_equal=sum(not r[3] for r in rows),
            refsim_pairs=sum(r[0] for r in rows), oracle_pairs=sum(r[1] for r in rows),
            common_pairs=sum(r[2] for r in rows),
            counts={k: sum(d.kind == k for d in pair_found) for k in DISAGREEMENT_KINDS},
            disagreements=pair_found))
    labels = tuple(f"{model_label(*a)} / {model_label(*b)}" for a, b in random_pairs)
    return OracleAgreement(seed=seed, random_per_pair=random_per_pair, model_pairs=labels,
                           bodies=tuple(bodies), pairs=tuple(pairs))


# --------------------------------------------------------------------------
# the hierarchy against FCL
# --------------------------------------------------------------------------

@dataclass(frozen=True)
class SpeedConfiguration:
    """One body of ``model`` at the identity, a body of ``model_b`` (None: a
    copy of ``model``) at (``rotation_b``, ``distance`` along ``direction``)."""

    model: str
    kind: str               # "separated-boxes-overlap", "grazing", "deep", "touching"
    direction: tuple
    distance: float
    description: str
    model_b: str | None = None
    rotation_b: str = "fixed"     # as Configuration.rotation_b

    @property
    def label(self) -> str:
        """The model, or both models of a mixed pair (``"sphere-2k+cube"``)."""
        return self.model if self.model_b is None else f"{self.model}+{self.model_b}"

    def as_configuration(self) -> Configuration:
        return Configuration(f"{self.label}-{self.kind}", self.kind, self.description,
                             self.model, self.model_b or self.model,
                             rotation_b=self.rotation_b, direction=self.direction,
                             distance=self.distance)


#: The benchmark configurations: two sphere-2k (radius 1) and two torus
#: (2000 triangles each; outer radius 1.35 in the xz plane, tube 0.35), the
#: second body turned by the fixed rotation (FIXED_AXIS, FIXED_ANGLE); then
#: the touching pairs, unturned.
SPEED_CONFIGURATIONS: tuple[SpeedConfiguration, ...] = (
    SpeedConfiguration("sphere-2k", "separated-boxes-overlap", DIAGONAL, 2.1,
                       "centres 2.1 apart along (1,1,1): gap 0.1, boxes overlap"),
    SpeedConfiguration("sphere-2k", "grazing", DIAGONAL, 1.99,
                       "centres 1.99 apart along (1,1,1): depth 0.01"),
    SpeedConfiguration("sphere-2k", "deep", DIAGONAL, 1.0,
                       "centres 1 apart along (1,1,1): depth 1"),
    SpeedConfiguration("torus", "separated-boxes-overlap", XZ_DIAGONAL, 2.72,
                       "centres 2.72 apart along (1,0,1): surfaces apart, boxes overlap"),
    SpeedConfiguration("torus", "grazing", XZ_DIAGONAL, 2.66,
                       "centres 2.66 apart along (1,0,1)"),
    SpeedConfiguration("torus", "deep", XZ_DIAGONAL, 1.0,
                       "centres 1 apart along (1,0,1)"),
    # touching configurations: nearly every candidate pair touches exactly,
    # the float filter certifies none, the exact stage answers them all
    SpeedConfiguration("cube", "touching", (0.0, 1.0, 0.0), 1.0,
                       "unit cubes sharing the face y = 0.5 (84 triangle-box pairs, 62 touch)",
                       rotation_b="identity"),
    SpeedConfiguration("sphere-2k", "touching", (0.0, 1.0, 0.0), 1.5,
                       "a unit cube resting on the sphere's top vertex (12 of 12 pairs touch)",
                       model_b="cube", rotation_b="identity"),
)


@dataclass(frozen=True)
class SpeedCase:
    model: str
    kind: str
    description: str
    candidate_pairs: int            # triangle-box pairs (test 2)
    exact_pairs: int
    fcl_pairs: int | None
    bvh_seconds: float = field(metadata=TIMED)  # intersecting_pairs, method "bvh"
    seed_seconds: float = field(metadata=TIMED)  # intersecting_pairs, method "seed"
    fcl_seconds: float | None = field(metadata=TIMED)  # FCL's all intersecting pairs
    bvh_boolean_seconds: float = field(metadata=TIMED)  # bodies_collide exact, method "bvh"
    fcl_boolean_seconds: float | None = field(metadata=TIMED)

    @property
    def pairs_ratio(self) -> float | None:
        """bvh time / FCL time (below 1: refsim faster)."""
        return None if self.fcl_seconds is None else self.bvh_seconds / self.fcl_seconds

    @property
    def boolean_ratio(self) -> float | None:
        if self.fcl_boolean_seconds is None:
            return None
        return self.bvh_boolean_seconds / self.fcl_boolean_seconds

    @property
    def seed_over_bvh(self) -> float:
        return self.seed_seconds / self.bvh_seconds


@dataclass(frozen=True)
class CompileCost:
    """Seconds from a fresh interpreter: cold (empty NUMBA_CACHE_DIR: numba
    import plus compilation) and warm (the same, with the cache just written:
    loading the machine code)."""

    # triangle_numba.measure_numba_compile_seconds
    triangle_kernel_cold_seconds: float = field(metadata=TIMED)
    # every compiled kernel the hierarchy uses
    hierarchy_cold_seconds: float = field(metadata=TIMED)
    hierarchy_warm_seconds: float = field(metadata=TIMED)


@dataclass(frozen=True)
class HierarchySpeed:
    kernel: str
    repeats: int
    cases: tuple                     # SpeedCase
    compile: CompileCost | None      # None when not measured

    def case(self, model: str, kind: str) -> SpeedCase:
        return next(c for c in self.cases if c.model == model and c.kind == kind)


#: The code timed by :func:`measure_hierarchy_compile_seconds`: every numba
#: kernel of the hierarchy (level triangle-aabb's refit and traversal, level
#: exact's query in the first body's frame in both modes, with the exact
#: filter it calls), on two cubes.
_HIERARCHY_COMPILE_CODE = """
import time
import numpy as np
from refsim.models.mesh import Mesh
vertices = np.array([[x, y, z] for x in (-.5, .5) for y in (-.5, .5) for z in (-.5, .5)])
faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
cube = Mesh(vertices, faces)
near = (np.eye(3), np.array([0.5, 0.25, 0.0]))
start = time.perf_counter()
from refsim.collision.bodies import bodies_collide, intersecting_pairs
identity = (np.eye(3), np.zeros(3))
for level in ("triangle-aabb", "exact"):
    bodies_collide(cube, identity, cube, near, level=level, kernel="compiled")
    intersecting_pairs(cube, identity, cube, near, level=level, kernel="compiled")
print(time.perf_counter() - start)
"""


def measure_hierarchy_compile_seconds() -> tuple[float, float]:
    """``(cold, warm)`` seconds to import the collision package and make
    every numba kernel of the hierarchy ready, in a fresh interpreter: first
    with an empty ``NUMBA_CACHE_DIR`` (compilation from nothing), then again
    with the cache that run wrote (loading the cached machine code)."""
    import os
    import subprocess
    import sys
    import tempfile

    seconds = []
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for _ in range(2):
            out = subprocess.run([sys.executable, "-c", _HIERARCHY_COMPILE_CODE], env=env,
                                 capture_output=True, text=True, check=True)
            seconds.append(float(out.stdout.strip().splitlines()[-1]))
    return seconds[0], seconds[1]


def measure_compile_cost() -> CompileCost:
    from refsim.collision.triangle_numba import measure_numba_compile_seconds

    cold, warm = measure_hierarchy_compile_seconds()
    return CompileCost(triangle_kernel_cold_seconds=measure_numba_compile_seconds(),
                       hierarchy_cold_seconds=cold, hierarchy_warm_seconds=warm)


def measure_hierarchy_speed(fcl=None, repeats: int = 21, *,
                            configurations: tuple[SpeedConfiguration, ...] = SPEED_CONFIGURATIONS,
                            kernel: str | None = None,
                            compile_cost: bool = True) -> HierarchySpeed:
    """The hierarchy against FCL on the benchmark configurations.

    ``fcl``: an engine with the ``pairs`` and ``collide`` capabilities
    (``refsim.oracles.fcl_adapter.FCLOracle``), or None to time refsim
    alone. Its models are built once per mesh before timing, as refsim's
    trees are. The seed's path is timed with
    ``max(3, repeats // 4)`` repeats (it is the slowest path, by far).
    ``compile_cost``: also measure the numba compile cost (two fresh
    interpreters for the hierarchy, one for the triangle kernel).
    """
    kernel = choose_kernel(kernel)
    cases = []
    for sc in configurations:
        c = sc.as_configuration()
        mesh_a, mesh_b = c.meshes()
        pose_a, pose_b = c.poses()
        args = (mesh_a, pose_a, mesh_b, pose_b)
        arrays = (mesh_a.vertices, mesh_a.faces, pose_a, mesh_b.vertices, mesh_b.faces, pose_b)

        def pairs(method, level="exact", args=args):
            return intersecting_pairs(*args, level=level, method=method, kernel=kernel)

        exact = pairs("bvh")
        fcl_pairs = fcl_seconds = fcl_bool = None
        if fcl is not None:
            fcl_pairs = len(fcl.intersecting_pairs(*arrays))
            fcl_seconds = _median_seconds(functools.partial(fcl.intersecting_pairs, *arrays),
                                          repeats)
            fcl_bool = _median_seconds(functools.partial(fcl.bodies_collide, *arrays), repeats)
        cases.append(SpeedCase(
            model=sc.label, kind=sc.kind, description=sc.description,
            candidate_pairs=len(pairs("bvh", "triangle-aabb")), exact_pairs=len(exact),
            fcl_pairs=fcl_pairs,
            bvh_seconds=_median_seconds(functools.partial(pairs, "bvh"), repeats),
            seed_seconds=_median_seconds(functools.partial(pairs, "seed"),
                                         max(3, repeats // 4)),
            fcl_seconds=fcl_seconds,
            bvh_boolean_seconds=_median_seconds(
                functools.partial(bodies_collide, *args, kernel=kernel), repeats),
            fcl_boolean_seconds=fcl_bool))
    compile_result = measure_compile_cost() if compile_cost and kernel == "compiled" else None
    return HierarchySpeed(kernel=kernel, repeats=repeats, cases=tuple(cases),
                          compile=compile_result)
