"""The two former classifiers of a body-level disagreement (the kit's
classify_collide and the level study's classify_body_disagreement, as of
commit 8f28170) on the constructed cases of one-classifier.md's table.

Run it against that commit's code (one-classifier.md, "Reproducing the
before": a copy of 8f28170 and a sitecustomize that points the editable
install at it):

    cd /tmp/classify-base && PYTHONPATH=/tmp/classify-shim \
        .venv/bin/python docs/decisions/one_classifier_former_rules.py

On this branch
the same cases are tests/collision/test_body_disagreement.py's.
"""
from dataclasses import dataclass

import numpy as np

from refsim.collision.bodies import intersecting_pairs
from refsim.conformance.checks_geometry import classify_collide
from refsim.models.mesh import Mesh
from refsim.models.shapes import box
from refsim.studies.levels import bundled_mesh, classify_body_disagreement

IDENTITY = (np.eye(3), np.zeros(3))

#: Four bars around the origin, inner faces at x, y = +-0.75.
RING = (((2.0, 0.5, 1.0), (0.0, 1.0, 0.0)), ((2.0, 0.5, 1.0), (0.0, -1.0, 0.0)),
        ((0.5, 1.0, 1.0), (1.0, 0.0, 0.0)), ((0.5, 1.0, 1.0), (-1.0, 0.0, 0.0)))


def boxes(*parts) -> Mesh:
    """One mesh of several closed boxes: ``(extents, centre)`` per part."""
    vertices, faces, n = [], [], 0
    for extents, centre in parts:
        part = box(extents)
        vertices.append(part.vertices + np.asarray(centre, float))
        faces.append(np.asarray(part.faces) + n)
        n += len(part.vertices)
    return Mesh(np.vstack(vertices), np.vstack(faces))


@dataclass
class Case:
    mesh_a: Mesh
    pose_a: tuple
    mesh_b: Mesh
    pose_b: tuple
    truth: np.ndarray


class Engine:
    def __init__(self, answer, **declared):
        self.name, self.answer = "e", answer
        self.__dict__.update(declared)

    def bodies_collide(self, *arrays):
        return self.answer


def run(label, a, pa, b, pb, answer, tol=0.0, solid=False, engine=None):
    truth = intersecting_pairs(a, pa, b, pb)
    kit = classify_collide(Case(a, pa, b, pb, truth), answer, tol, solid)
    study = classify_body_disagreement(a, pa, b, pb, not answer, Engine(answer, **(engine or {})))
    print(label, "| kit:", kit.get("class"), kit.get("gap_metres"), "| study:", study)


def main():
    solid_all = {"is_solid": lambda v, f: True}
    unit = box((1.0, 1.0, 1.0))
    run("ring", boxes(*RING), IDENTITY, unit, IDENTITY, True, solid=True, engine=solid_all)
    parts = boxes(((0.25,) * 3, (3.0, 0.0, 0.0)), ((0.25,) * 3, (0.25, 0.0, 0.0)))
    run("two parts", unit, IDENTITY, parts, IDENTITY, True, solid=True, engine=solid_all)
    cube = bundled_mesh("cube")
    shallow = (np.eye(3), np.array([0.25, 0.125, 1.0 - 2.0 ** -24]))
    run("shallow", cube, IDENTITY, cube, shallow, False)
    run("nested", box((1.0 + 2.0 ** -20,) * 3), IDENTITY, unit, IDENTITY, True, tol=1e-6)
    beam = bundled_mesh("l-beam")
    apart = (np.eye(3), np.array([0.0, 0.0, 0.5 + 2.0 ** -30]))
    run("l-beams 2**-30 (trimesh's declarations)", beam, IDENTITY, beam, apart, True, tol=1e-6,
        solid=True)


if __name__ == "__main__":
    main()
