"""The triangle hierarchy against FCL (seed S4): all intersecting pairs and
the boolean query on the benchmark configurations
(:data:`SPEED_CONFIGURATIONS`), by the hierarchy, by the seed's pairwise
path and by FCL, as medians and ratios measured in the same run
(:func:`measure_hierarchy_speed`); and the one-off compile cost of the numba
kernels (:func:`measure_compile_cost`).

``refsim study collision-speed`` prints the records; the report draws
them. FCL is passed in, so this module imports no oracle. Every name is
importable from :mod:`refsim.studies.levels` too.

Cost: every timing is the median of ``repeats`` calls after one untimed
call (which builds the hierarchy and, for numba, loads the compiled code);
the compile cost runs fresh interpreters.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.kernels import choose_kernel
from refsim.studies import TIMED
from refsim.studies.collision_cases import (
    DIAGONAL,
    XZ_DIAGONAL,
    Configuration,
    _median_seconds,
)


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
