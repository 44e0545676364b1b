"""refsim's exact body-body answers against body-level oracles: FCL's
intersecting face pairs and boolean query, trimesh's ``CollisionManager``
(:func:`measure_body_oracles`), on the constructed configurations and on
seeded random poses of :mod:`refsim.studies.collision_cases`.

Every disagreement is classified, none dropped: a body-level one by the
conformance kit's classifier (:func:`classify_body_disagreement`,
:func:`refsim.collision.disagreement.classify_bodies`: a class, a reason and
a gap in metres), a face pair by
:func:`refsim.studies.triangles.classify_disagreement`. The records are
plain frozen dataclasses; ``refsim study collision-body-oracles`` prints
them and the report draws them. Oracles are passed in, so this module
imports none. Every name is importable from :mod:`refsim.studies.levels`
too.

Cost: per query, refsim's exact query and each oracle's, plus a
classification per disagreement (:mod:`refsim.collision.disagreement`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.collision.boxes import world_vertices
from refsim.collision.disagreement import (
    BODY_CLASSES,
    BODY_REASONS,
    BodyVerdict,
    classify_bodies,
)
from refsim.engines import body_conventions
from refsim.kernels import choose_kernel
from refsim.studies.collision_cases import (
    CONFIGURATIONS,
    RANDOM_MODEL_PAIRS,
    Configuration,
    bundled_mesh,
    model_label,
    random_poses,
)
from refsim.studies.triangles import DISAGREEMENT_KINDS, classify_disagreement

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
