"""The compiled contact points (refsim.collision._numba_contact) against the
readable ones (refsim.collision.contact), bit for bit: seeded poses of two
cubes overlapping deeply, two cubes face to face (touching and grazing), and
a faceted sphere on a cube; the winding numbers and the contact polygon on
their own."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from refsim.collision.contact import contact_points, contact_polygon, winding_numbers

pytest.importorskip("numba")

from refsim.collision._numba_contact import (  # noqa: E402  (after the numba check)
    contact_polygon_numba,
    winding_number_numba,
)

CUBE = refsim.load_model("cube.ac")               # side 1, centred
SPHERE = refsim.load_model("sphere-2k.ac")


def _rotation(rng) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.random(random_state=int(rng.integers(2**31))).as_matrix()


def _turn_about_y(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _deep(rng):
    """Two cubes turned at random, centres up to 0.9 apart on each axis."""
    pose_b = (_rotation(rng), rng.uniform(-0.2, 0.2, 3))
    pose_a = (_rotation(rng), pose_b[1] + rng.uniform(-0.9, 0.9, 3))
    return CUBE, pose_a, CUBE, pose_b


def _face_to_face(rng):
    """A cube on another's top face, turned about the normal and offset
    sideways: touching exactly (gap 0) or grazing (overlap or gap 1e-9)."""
    gap = rng.choice([0.0, -1e-9, 1e-9, -1e-4])
    pose_b = (np.eye(3), np.zeros(3))
    side = rng.uniform(-0.8, 0.8, 2)
    pose_a = (_turn_about_y(rng.uniform(0.0, np.pi / 2)),
              np.array([side[0], 1.0 + gap, side[1]]))
    return CUBE, pose_a, CUBE, pose_b


def _sphere_on_cube(rng):
    """The 2000-triangle sphere (radius 1) a little into a turned cube."""
    pose_b = (_rotation(rng), np.zeros(3))
    direction = rng.normal(size=3)
    direction /= np.linalg.norm(direction)
    pose_a = (_rotation(rng), direction * rng.uniform(1.2, 1.5))
    return SPHERE, pose_a, CUBE, pose_b


@pytest.mark.parametrize(("make", "cases", "seed"), [
    (_deep, 60, 1), (_face_to_face, 60, 2), (_sphere_on_cube, 8, 3)])
def test_compiled_contact_points_are_the_readable_ones(make, cases, seed):
    rng = np.random.default_rng(seed)
    found = 0
    for _ in range(cases):
        mesh_a, pose_a, mesh_b, pose_b = make(rng)
        n = pose_a[1] - pose_b[1]
        n = n / np.linalg.norm(n)
        readable = contact_points(mesh_a, pose_a, mesh_b, pose_b, n, kernel="readable")
        compiled = contact_points(mesh_a, pose_a, mesh_b, pose_b, n, kernel="compiled")
        assert readable.shape == compiled.shape
        assert readable.tobytes() == compiled.tobytes()      # bit for bit, signs of zero too
        found += len(readable) > 0
    # most of the poses touch: the comparison is not between empty sets
    assert found >= cases // 2


def test_compiled_winding_numbers_are_the_readable_ones():
    rng = np.random.default_rng(4)
    for mesh in (CUBE, SPHERE):
        world = mesh.vertices @ _rotation(rng).T + rng.uniform(-1.0, 1.0, 3)
        # inside, outside, on the surface (the vertices), near an edge's line
        points = np.concatenate([
            rng.uniform(world.min(axis=0) - 0.5, world.max(axis=0) + 0.5, (40, 3)),
            world[:20], 0.5 * (world[mesh.faces[:10, 0]] + world[mesh.faces[:10, 1]])
            + rng.normal(scale=1e-9, size=(10, 3))])
        readable = winding_numbers(points, world[mesh.faces])
        compiled = np.array([winding_number_numba(p[0], p[1], p[2], world, mesh.faces)
                             for p in points])
        assert readable.tobytes() == compiled.tobytes()
        assert (readable > 0.9).any() and (np.abs(readable) < 1e-9).any()


def test_compiled_contact_polygon_is_the_readable_one():
    rng = np.random.default_rng(5)
    clouds = [rng.normal(size=(k, 3)) for k in (1, 2, 3, 7, 50)]
    square = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    clouds += [np.concatenate([square, square + [0.0, 1e-3, 0.0], square[:2]]),  # repeats
               np.linspace([0.0, 0.0, 0.0], [1.0, 0.0, 1.0], 6),              # collinear
               np.repeat(square[:1], 4, axis=0)]                              # one point
    for points in clouds:
        for n in (np.array([0.0, 1.0, 0.0]), rng.normal(size=3)):
            n = n / np.linalg.norm(n)
            readable = contact_polygon(points, n)
            compiled = contact_polygon_numba(points, n[0], n[1], n[2])
            assert readable.shape == compiled.shape
            assert readable.tobytes() == compiled.tobytes()
