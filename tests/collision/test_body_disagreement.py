"""The one classifier of a body-level disagreement
(refsim.collision.disagreement.classify_bodies), which the conformance
kit's ``collide.agreement`` and the level study's comparison with oracles
both call, on constructed cases where the two former classifiers parted.

Every case is built from boxes with edges and offsets exact in binary, so
each gap is an exact difference of coordinates, asserted with ``==``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from refsim.collision.bodies import intersecting_pairs
from refsim.collision.containment import contains_part, contains_point
from refsim.collision.disagreement import BODY_REASONS, classify_bodies
from refsim.conformance.checks_geometry import classify_collide
from refsim.models.mesh import Mesh
from refsim.models.shapes import box
from refsim.studies.levels import bundled_mesh, classify_body_disagreement

IDENTITY = (np.eye(3), np.zeros(3))


def boxes(*parts) -> Mesh:
    """One mesh of several closed boxes: ``(extents, centre)`` per part."""
    vertices, faces, n = [], [], 0
    for extents, centre in parts:
        part = box(extents)
        vertices.append(part.vertices + np.asarray(centre, dtype=np.float64))
        faces.append(np.asarray(part.faces) + n)
        n += len(part.vertices)
    return Mesh(np.vstack(vertices), np.vstack(faces), name="boxes")


#: Four bars in the plane z = 0 around the origin, apart from each other:
#: the inner faces at x = +-0.75 and y = +-0.75. Their vertices' centroid is
#: the origin, in the ring's hole.
RING = (((2.0, 0.5, 1.0), (0.0, 1.0, 0.0)), ((2.0, 0.5, 1.0), (0.0, -1.0, 0.0)),
        ((0.5, 1.0, 1.0), (1.0, 0.0, 0.0)), ((0.5, 1.0, 1.0), (-1.0, 0.0, 0.0)))


class Engine:
    """A ``collide`` engine that gives one answer, with the declarations
    given (refsim.engines.declarations)."""

    def __init__(self, answer: bool, **declared):
        self.name, self.answer = "constant", answer
        self.__dict__.update(declared)

    def bodies_collide(self, *arrays) -> bool:
        return self.answer


@dataclass(frozen=True)
class Case:
    """What the kit's classify_collide reads of a case (a PoseCase's fields)."""

    mesh_a: Mesh
    pose_a: tuple
    mesh_b: Mesh
    pose_b: tuple
    truth: np.ndarray


def both(mesh_a, mesh_b, answer: bool, **declared):
    """The kit's fields and the study's verdict for the engine's ``answer``."""
    truth = intersecting_pairs(mesh_a, IDENTITY, mesh_b, IDENTITY)
    kit = classify_collide(Case(mesh_a, IDENTITY, mesh_b, IDENTITY, truth), answer,
                           declared.get("distance_tolerance", 0.0), declared.get("solid", False))
    study = classify_body_disagreement(mesh_a, IDENTITY, mesh_b, IDENTITY, not answer,
                                       Engine(answer, **declared))
    return kit, study


def test_a_cube_in_the_hole_of_a_ring_is_not_contained():
    # The kit used to test the vertices' centroid of each body for being
    # inside the other: the ring's centroid (the origin) lies inside the cube,
    # so a solid engine's "collide" was a known divergence. It is not: no
    # part of either body lies inside the other (solid ring and solid cube
    # are 0.25 apart), so a solid engine saying "collide" is as wrong as any.
    # The study's rule (vertex 0 of each body) was right here.
    ring, cube = boxes(*RING), box((1.0, 1.0, 1.0))
    assert contains_point(cube, IDENTITY, ring.vertices.mean(axis=0))     # the old rule
    assert not contains_part(ring, IDENTITY, cube, IDENTITY)
    assert not contains_part(cube, IDENTITY, ring, IDENTITY)
    kit, study = both(ring, cube, True, solid=True)
    assert (study.kind, study.reason) == ("bug", "gap beyond tolerance")
    assert study.gap == 0.25                    # the cube's face x = 0.5 to the bar's x = 0.75
    assert not study.contained and not study.gap_is_lower_bound
    assert (kit["class"], kit["reason"], kit["gap_metres"]) == (study.kind, study.reason,
                                                                study.gap)
    assert "contained" not in kit


def test_a_body_in_two_parts_is_contained_by_either_part():
    # B in two parts: a cube of side 0.25 inside the unit cube A (at x = 0.25,
    # faces 0.125 from A's face x = 0.5) and one far outside, listed first so
    # that B's vertex 0 is outside A. The study tested vertex 0 only and the
    # kit the vertices' centroid (x = 1.625, outside A; A's centroid, the
    # origin, is outside both parts): both missed that one part of B lies in
    # A. A part not meeting A's surface is inside or outside as a whole, so one
    # vertex per connected part decides; a solid engine's "collide" is then
    # the documented divergence.
    unit = box((1.0, 1.0, 1.0))
    parts = boxes(((0.25, 0.25, 0.25), (3.0, 0.0, 0.0)), ((0.25, 0.25, 0.25), (0.25, 0.0, 0.0)))
    assert not contains_point(unit, IDENTITY, parts.vertices[0])          # the study's rule
    assert not contains_point(unit, IDENTITY, parts.vertices.mean(axis=0))  # the kit's
    assert contains_part(unit, IDENTITY, parts, IDENTITY)
    kit, study = both(unit, parts, True, solid=True)
    assert (study.kind, study.reason) == ("known-divergence", "containment")
    assert study.gap == 0.125 and study.contained and study.solid
    assert (kit["class"], kit["reason"], kit["gap_metres"]) == (study.kind, study.reason,
                                                                study.gap)
    assert kit["contained"] is True and kit["solid_declared"] is True
    # undeclared, the same answer has no excuse
    kit, study = both(unit, parts, True)
    assert (study.kind, study.reason, study.gap) == ("bug", "containment without solid", 0.125)
    assert (kit["class"], kit["reason"], kit["solid_declared"]) == ("bug",
                                                                    "containment without solid",
                                                                    False)


def test_a_gap_within_the_declared_tolerance_excuses_a_contained_body():
    # The unit cube inside one of side 1 + 2**-20: surfaces 2**-21 apart. An
    # engine that tests surfaces (not solids) and declares 1e-6 m may call
    # them touching: within its tolerance, whatever lies inside what. The
    # kit's former rule tested containment first and called it a bug.
    outer, unit = box((1.0 + 2.0 ** -20,) * 3), box((1.0, 1.0, 1.0))
    kit, study = both(outer, unit, True, distance_tolerance=1e-6)
    assert (study.kind, study.reason, study.gap) == ("tolerance", "gap within tolerance",
                                                     2.0 ** -21)
    assert study.contained and not study.solid
    assert (kit["class"], kit["reason"], kit["gap_metres"]) == (study.kind, study.reason,
                                                                study.gap)


def test_a_pose_the_engine_rounds_explains_its_answer():
    # Two unit cubes 2**-30 apart along z: rounded to float32, the translation
    # 1 + 2**-30 is 1 and the cubes share a face. An engine declaring that it
    # rounds poses (pose_used) and answers "collide" is right on the poses it
    # used: "tolerance" (its input's rounding), with the exact gap.
    def pose_used(pose):
        return (np.asarray(pose[0], np.float32).astype(np.float64),
                np.asarray(pose[1], np.float32).astype(np.float64))

    cube = bundled_mesh("cube")
    pose_b = (np.eye(3), np.array([0.0, 0.0, 1.0 + 2.0 ** -30]))
    verdict = classify_bodies(cube, IDENTITY, cube, pose_b, True, pose_used=pose_used)
    assert (verdict.kind, verdict.reason, verdict.gap) == ("tolerance", "float32 transform",
                                                           2.0 ** -30)
    verdict = classify_bodies(cube, IDENTITY, cube, pose_b, True)
    assert (verdict.kind, verdict.reason, verdict.gap) == ("bug", "gap beyond tolerance",
                                                           2.0 ** -30)


def test_touching_bodies_are_touching_before_any_tolerance():
    # Unit cubes sharing the face x = 0.5 exactly: the contact rests on exact
    # zeros, whatever the engine declares; an engine saying "apart" is
    # "touching", gap 0.
    cube = bundled_mesh("cube")
    verdict = classify_bodies(cube, IDENTITY, cube, (np.eye(3), np.array([1.0, 0.0, 0.0])),
                              False, distance_tolerance=1e-6)
    assert (verdict.kind, verdict.reason, verdict.gap) == ("touching", "touching", 0.0)


def test_only_a_disagreement_is_classified():
    cube = bundled_mesh("cube")
    with pytest.raises(ValueError, match="refsim's exact answer"):
        classify_bodies(cube, IDENTITY, cube, (np.eye(3), np.array([1.5, 0.0, 0.0])), False)


def test_every_reason_names_a_class_and_a_meaning():
    assert {kind for kind, _ in BODY_REASONS.values()} == {
        "bug", "known-divergence", "tolerance", "touching", "coplanar"}
    assert all(meaning for _, meaning in BODY_REASONS.values())
