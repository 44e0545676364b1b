"""The bodies the collision studies pose: the bundled models, the constructed
configurations of the level study (:data:`CONFIGURATIONS`), the model pairs
posed at random (:data:`RANDOM_MODEL_PAIRS`, :func:`random_poses`) and the
timing helpers the studies share.

Shared by :mod:`refsim.studies.levels` (claim C3),
:mod:`refsim.studies.body_oracles` (agreement with body-level oracles) and
:mod:`refsim.studies.hierarchy_speed` (the hierarchy against FCL); every
name is importable from :mod:`refsim.studies.levels` too.

Cost: loading a model once (cached per name and scale); a random pose is
O(1) after the bounding spheres (O(n) once per mesh).
"""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from refsim.collision.spheres import bounding_sphere
from refsim.types import Pose, random_rotation, rotation_about_axis

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
