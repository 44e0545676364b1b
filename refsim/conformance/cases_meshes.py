"""Two posed meshes whose intersecting triangle pairs are known exactly
(seed S4, capabilities ``pairs`` and ``collide``).

What: ``n`` cases, each two bundled models with a pose each, cycling
through four families; the answer is refsim's exact path,
``refsim.intersecting_pairs(..., level="exact")``: the world vertices by
refsim's one transform arithmetic (:func:`refsim.types.transform_points`),
then exact orientation predicates on every candidate pair. That test is
itself checked against the rational separating-axis test on the triangle
cases (``triangles.reference``), and its answers depend on no float engine.

============  ==============================================================
family        construction
============  ==============================================================
separated     random rotations; B's centre 1.02 .. 2 times the sum of the
              bounding radii from A's, in a random direction
deep          random rotations; B's centre within 0.4 of the smaller
              bounding radius from A's (overlapping, or one inside the other)
touching      exact rotations (axes permuted with signs) and translations on
              a 1/4 grid; B placed so that its lowest extent along an axis
              equals A's highest (exactly, for the models with coordinates
              +-0.5: cube, tetrahedron; up to rounding for the others)
grazing       a touching pose moved by 1e-15 .. 1e-6 along the contact axis,
              apart or into A, and tilted by 1e-12 .. 1e-6 rad
============  ==============================================================

The models are the bundled small ones (tetrahedron, cube, icosahedron,
l-beam, star: convex and non-convex, 4 to 36 faces), so a case costs
milliseconds in every engine.

Cost: building is O(1) per case; the exact answer is refsim's bounding
volume hierarchy plus exact predicates on the candidate pairs, about a
millisecond per case for these models.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from refsim.conformance.draw import (
    dot3,
    matmul3,
    seeded_range,
    signed_permutations,
    strategy,
    unit_quaternion_rotation,
)

MODELS = ("tetrahedron.ac", "cube.ac", "icosahedron.ac", "l-beam.ac", "star.ac", "sphere-2k.ac")
FAMILIES = ("separated", "deep", "touching", "grazing")


@functools.cache
def bundled_mesh(name: str):
    """A bundled model as a :class:`refsim.Mesh` (loaded once per process;
    its arrays are read-only, so engines may cache by identity)."""
    from refsim.bundled import models_dir
    from refsim.models.loading import load_model

    return load_model(models_dir() / name)


def _radius(mesh) -> float:
    v = mesh.vertices
    return float(np.sqrt((v * v).sum(axis=1)).max())


def _extent(mesh, rotation, axis: int) -> tuple[float, float]:
    """Lowest and highest coordinate ``axis`` of the rotated vertices (exact
    for a signed permutation: each is +-1 times a coordinate)."""
    c = (rotation[axis, 0] * mesh.vertices[:, 0] + rotation[axis, 1] * mesh.vertices[:, 1]
         + rotation[axis, 2] * mesh.vertices[:, 2])
    return float(c.min()), float(c.max())


def _touching(draw, mesh_a, mesh_b):
    perms = signed_permutations()
    r_a, r_b = draw.choice(perms), draw.choice(perms)
    t_a = np.array(draw.integers(-8, 8, 3), dtype=np.float64) / 4.0
    axis = draw.integers(0, 2)[0]
    side = draw.choice((1.0, -1.0))
    lo_a, hi_a = _extent(mesh_a, r_a, axis)
    lo_b, hi_b = _extent(mesh_b, r_b, axis)
    t_b = t_a + np.array(draw.integers(-4, 4, 3), dtype=np.float64) / 8.0
    # B's low face on A's high face (side +1), or B's high face on A's low one
    t_b[axis] = (t_a[axis] + hi_a - lo_b) if side > 0 else (t_a[axis] + lo_a - hi_b)
    return r_a, t_a, r_b, t_b, axis, side


def _pose_case(draw, family: str, model_a: str, model_b: str):
    from refsim.types import rotation_about_axis

    mesh_a, mesh_b = bundled_mesh(model_a), bundled_mesh(model_b)
    gap = None
    if family in ("separated", "deep"):
        r_a, r_b = unit_quaternion_rotation(draw), unit_quaternion_rotation(draw)
        t_a = np.array(draw.uniform(-2.0, 2.0, 3))
        if family == "separated":
            d = np.array(draw.uniform(-1.0, 1.0, 3))
            norm = math.sqrt(dot3(d, d))
            d = d / norm if norm > 1e-3 else np.array([1.0, 0.0, 0.0])
            reach = (_radius(mesh_a) + _radius(mesh_b)) * draw.uniform(1.02, 2.0)[0]
            t_b = t_a + reach * d
        else:
            near = 0.4 * min(_radius(mesh_a), _radius(mesh_b))
            t_b = t_a + np.array(draw.uniform(-near, near, 3))
    else:
        r_a, t_a, r_b, t_b, axis, side = _touching(draw, mesh_a, mesh_b)
        if family == "grazing":
            gap = draw.log_uniform(-15.0, -6.0) * draw.choice((1.0, -1.0))
            t_b[axis] += side * gap                     # > 0 apart, < 0 into A
            tilt_axis = np.array(draw.uniform(-1.0, 1.0, 3))
            if np.abs(tilt_axis).max() > 1e-3:
                tilt = rotation_about_axis(tilt_axis, draw.log_uniform(-12.0, -6.0))
                r_b = matmul3(tilt, r_b)
    return PoseCase(model_a=model_a, model_b=model_b, pose_a=(r_a, t_a), pose_b=(r_b, t_b),
                    family=family, gap=gap, truth=_exact_pairs(model_a, (r_a, t_a),
                                                               model_b, (r_b, t_b)))


def _exact_pairs(model_a, pose_a, model_b, pose_b) -> np.ndarray:
    from refsim.collision.bodies import intersecting_pairs

    return intersecting_pairs(bundled_mesh(model_a), pose_a, bundled_mesh(model_b), pose_b,
                              level="exact", method="bvh")


@dataclass(frozen=True)
class PoseCase:
    """Two bundled models, their poses ``(R, t)``, the family, the gap of a
    grazing pose (else None) and the exact face pairs (k, 2), sorted."""

    model_a: str
    model_b: str
    pose_a: tuple
    pose_b: tuple
    family: str
    gap: float | None
    truth: np.ndarray

    @property
    def mesh_a(self):
        return bundled_mesh(self.model_a)

    @property
    def mesh_b(self):
        return bundled_mesh(self.model_b)

    def to_dict(self) -> dict:
        return {"family": self.family, "model_a": self.model_a, "model_b": self.model_b,
                "pose_a": {"R": self.pose_a[0].tolist(), "t": self.pose_a[1].tolist()},
                "pose_b": {"R": self.pose_b[0].tolist(), "t": self.pose_b[1].tolist()},
                "gap": self.gap, "truth_pairs": int(len(self.truth))}


def _any_case(draw) -> PoseCase:
    family = draw.choice(FAMILIES)
    return _pose_case(draw, family, draw.choice(MODELS), draw.choice(MODELS))


def pose_strategy():
    """Hypothesis strategy of :class:`PoseCase` over every family and model."""
    return strategy(_any_case)


@dataclass(frozen=True)
class PoseCases:
    """``n`` seeded cases: family ``i % 4``, models drawn."""

    cases: tuple
    seed: int

    def __len__(self) -> int:
        return len(self.cases)

    def strategy(self):
        return pose_strategy()


def pose_cases(n: int, seed: int = 0, start: int = 0, stop: int | None = None) -> PoseCases:
    """The seeded set of ``n`` mesh-pair cases (module docstring), or its
    cases ``start`` to ``stop - 1`` (a shard)."""
    def build(draw, i):
        return _pose_case(draw, FAMILIES[i % len(FAMILIES)], draw.choice(MODELS),
                          draw.choice(MODELS))

    cases = seeded_range(build, seed, 0x9053, start, n if stop is None else stop)
    return PoseCases(cases=cases, seed=seed)
