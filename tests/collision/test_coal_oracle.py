"""coal's adapter (refsim.oracles.coal_adapter) on answers known exactly: a
touching pair, pairs apart by more than its declared tolerance, a crossing
pose's face pairs against refsim's exact ones, and the reason it offers no
``aabb``. The kit's verdict on it (declared divergences only) is asserted
with the other shipped engines in tests/conformance/test_matrix.py.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest
from refsim.oracles import OracleUnavailable
from refsim.oracles.coal_adapter import CoalEngine

from refsim import intersecting_pairs
from refsim.bundled import models_dir
from refsim.engines import capabilities, declarations
from refsim.models.loading import load_model
from refsim.types import random_rotation, transform_points

pytestmark = pytest.mark.oracle

#: A unit right triangle in the plane z = 0.
A = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


@pytest.fixture
def coal(oracle):
    return oracle(CoalEngine)


def _above(gap: float) -> np.ndarray:
    """A triangle with one vertex ``gap`` above A's face point (0.25, 0.25, 0)
    and the others higher: touching A for ``gap`` 0, apart by ``gap`` else."""
    return np.array([[0.25, 0.25, gap], [0.5, 0.25, 1.0], [0.25, 0.5, 1.0]])


def test_it_is_an_engine_with_the_tolerance_of_its_gjk(coal):
    assert capabilities(coal) == ("triangles", "pairs", "collide")
    assert declarations(coal).distance_tolerance == 1e-6     # coal's gjk_tolerance
    assert declarations(coal).box_slack == 0.0


def test_a_vertex_on_the_face_touches(coal):
    assert coal.triangles_intersect(A, _above(0.0))
    assert coal.triangles_intersect(A, A[[1, 2, 0]] + [1.0, 0.0, 0.0])   # a shared vertex


@pytest.mark.parametrize("gap", [2e-6, 1e-5, 1e-3, 0.5])
def test_pairs_apart_beyond_the_tolerance_are_apart(coal, gap):
    """Beyond ``distance_tolerance`` coal must answer exactly: apart."""
    assert not coal.triangles_intersect(A, _above(gap))
    assert not coal.triangles_intersect(_above(gap), A)


def test_a_crossing_pair_intersects(coal):
    through = np.array([[0.2, 0.2, -0.5], [0.3, 0.2, 0.5], [0.2, 0.3, 0.5]])
    assert coal.triangles_intersect(A, through)


def _model(name: str):
    return load_model(models_dir() / name)


def test_crossing_bodies_list_refsims_exact_face_pairs(coal):
    """Random crossing poses, none grazing (no face pair within coal's
    tolerance of touching): exactly refsim's exact pairs, and "collide"."""
    rng = np.random.default_rng(7)
    star, beam = _model("star.ac"), _model("l-beam.ac")
    compared = 0
    for _ in range(6):
        pose_a = (random_rotation(rng), rng.uniform(-0.1, 0.1, 3))
        pose_b = (random_rotation(rng), rng.uniform(-0.3, 0.3, 3))
        exact = intersecting_pairs(star, pose_a, beam, pose_b, level="exact")
        got = coal.intersecting_pairs(star.vertices, star.faces, pose_a,
                                      beam.vertices, beam.faces, pose_b)
        assert got.dtype == np.int64 and got.shape == exact.shape
        np.testing.assert_array_equal(got, exact)
        assert coal.bodies_collide(star.vertices, star.faces, pose_a,
                                   beam.vertices, beam.faces, pose_b) == (len(exact) > 0)
        compared += len(exact)
    assert compared > 100                       # the poses do cross (measured: 220 pairs)


def test_bodies_apart_do_not_collide(coal):
    cube = _model("cube.ac")
    identity = (np.eye(3), np.zeros(3))
    for gap in (2e-6, 1e-3):
        apart = (np.eye(3), np.array([1.0 + gap, 0.0, 0.0]))       # the cube is 1 m wide
        assert len(coal.intersecting_pairs(cube.vertices, cube.faces, identity,
                                           cube.vertices, cube.faces, apart)) == 0
        assert not coal.bodies_collide(cube.vertices, cube.faces, identity,
                                       cube.vertices, cube.faces, apart)
    touching = (np.eye(3), np.array([1.0, 0.0, 0.0]))
    assert coal.bodies_collide(cube.vertices, cube.faces, identity,
                               cube.vertices, cube.faces, touching)


def test_coals_world_box_is_too_loose_to_offer_as_aabb(coal):
    """Why the adapter has no ``aabb``: ``CollisionObject.computeAABB`` is
    the box of the rotated local box, wider than the box of the rotated
    vertices by a fraction of the size (at most 4/sqrt(3) times the largest
    half-extent per side, the bound derived in docs/decisions/coal.md), not
    by a length a ``box_slack`` could declare."""
    sphere = _model("sphere-2k.ac")
    rng = np.random.default_rng(3)
    half = (sphere.vertices.max(axis=0) - sphere.vertices.min(axis=0)).max() / 2
    lib = coal.coal
    model = lib.BVHModelOBBRSS()
    model.beginModel(0, len(sphere.vertices))
    model.addVertices(np.ascontiguousarray(sphere.vertices))
    model.endModel()
    widest = 0.0
    for _ in range(8):
        pose = (random_rotation(rng), rng.uniform(-1.0, 1.0, 3))
        posed = lib.CollisionObject(model, lib.Transform3s(*pose))
        posed.computeAABB()
        box = posed.getAABB()
        world = transform_points(sphere.vertices, pose)
        lo, hi = world.min(axis=0), world.max(axis=0)
        wider = np.maximum(lo - np.array(box.min_), np.array(box.max_) - hi)
        assert (wider >= -1e-12).all()                                  # it encloses
        assert wider.max() <= 4 / np.sqrt(3) * half
        widest = max(widest, wider.max() / half)
    # measured 0.73 of the radius: a sphere's box under a diagonal axis can
    # be wider by sqrt(3) - 1 of it
    assert widest > 0.5


def test_without_coal_the_error_names_its_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "coal", None)              # import coal -> ImportError
    with pytest.raises(OracleUnavailable) as info:
        CoalEngine()
    assert str(info.value).startswith("oracle engine 'coal' is not installed "
                                      "(pip install 'refsim[coal]'): ")
