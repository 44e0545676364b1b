"""refsim's own algorithms as engines: the seed model and the corrected model.

Both give the same exact answers to the geometric questions (refsim's triangle
test decides exactly, on any model); they differ where the seed's own
algorithm is one choice among several:

=====================  ===============================  ============================
capability             ``seed()``                       ``corrected()``
=====================  ===============================  ============================
triangles              exact edge-triangle test (S4)    the same
pairs, collide         the seed's levels: triangle      the deeper hierarchy
                       boxes, then exact (S4)           (``method="bvh"``)
aabb                   the linear scan (S2)             the same
ode                    the scene-file solver by name    the same
                       (default "rk4", order from the
                       tableau)
rigid                  rotation "seed" (S9), body       rotation and body response
                       response "seed" (S8), the        "impulse", the wall speed
                       seed's literal wall speed (S7)   at the wall (D1)
=====================  ===============================  ============================

The ``rigid`` capability runs the scene's world, bodies, solver and collision
level under the engine's model: the engine overrides the scene's
``[dynamics]`` table (and the wall law), nothing else.

A third engine runs a scene as it is posed, with no model of its own:
:func:`as_posed` (``refsim``: the scene's ``[dynamics]`` and wall speed, the
engine a study of the scene's own choices receives) and
:func:`as_posed_seed_wall_speed` (``refsim-seed-wall-speed``: the same with
the seed's literal wall speed, S7). Only its ``rigid`` capability exists;
the kit does not list it (:mod:`refsim.engines.registry`).

DEVIATION: the seed engine's RK4 is refsim's classical RK4, not the seed's
literal weights (which sum to 5/3; :data:`refsim.SEED_LITERAL_VARIANTS`): an
engine declares the order it has, and the literal reading has none.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from refsim.bounds.aabb_linear import aabb_linear_kernel
from refsim.collision.bodies import bodies_collide, intersecting_pairs
from refsim.collision.triangle import triangles_intersect
from refsim.dynamics.simulate import simulate
from refsim.dynamics.walls import SPEEDS
from refsim.engines.cache import MeshCache
from refsim.errors import StateError, check_option
from refsim.models.mesh import Mesh
from refsim.solvers.methods import SOLVERS
from refsim.types import as_pose

MODELS = ("seed", "corrected")


class RefsimEngine:
    """refsim as an engine (module docstring); build it with :func:`seed` or
    :func:`corrected`.

    Parameters
    ----------
    model : {"seed", "corrected"}
    solver : str
        A key of :data:`refsim.SOLVERS` for the ``ode`` capability.
    """

    def __init__(self, model: str = "corrected", solver: str = "rk4"):
        self.model = check_option("model", model, MODELS)
        self.solver = SOLVERS[check_option("solver", solver, tuple(SOLVERS))]
        self.name = f"refsim-{model}"
        self.ode_order = self.solver.order
        self._method = "seed" if model == "seed" else "bvh"
        self._meshes = MeshCache(lambda v, f: Mesh(v, f))

    def __repr__(self) -> str:
        return f"<RefsimEngine {self.name} ({self.solver.name})>"

    # -- geometry ------------------------------------------------------------------------

    def triangles_intersect(self, a, b) -> bool:
        return triangles_intersect(a, b)

    def intersecting_pairs(self, vertices_a, faces_a, pose_a, vertices_b, faces_b,
                           pose_b) -> np.ndarray:
        return intersecting_pairs(self._meshes.get(vertices_a, faces_a), pose_a,
                                  self._meshes.get(vertices_b, faces_b), pose_b,
                                  method=self._method)

    def bodies_collide(self, vertices_a, faces_a, pose_a, vertices_b, faces_b,
                       pose_b) -> bool:
        return bodies_collide(self._meshes.get(vertices_a, faces_a), pose_a,
                              self._meshes.get(vertices_b, faces_b), pose_b,
                              method=self._method)

    def aabb(self, vertices, pose) -> tuple[np.ndarray, np.ndarray]:
        """The linear scan (S2) of the vertices as given, every one counting."""
        vertices = np.asarray(vertices, dtype=np.float64)
        if vertices.ndim != 2 or vertices.shape[1] != 3 or not len(vertices):
            raise StateError(f"vertices must have shape (n, 3) with n >= 1, got "
                             f"{vertices.shape}")
        if not np.isfinite(vertices).all():
            raise StateError("vertices: non-finite value")
        rotation, translation = as_pose(pose)
        return aabb_linear_kernel(np.ascontiguousarray(vertices.T), rotation, translation)

    # -- solvers ---------------------------------------------------------------------------

    def ode_step(self, f, t: float, y, h: float) -> np.ndarray:
        return self.solver.step(f, t, np.asarray(y, dtype=np.float64), h)

    def ode_stability(self, z):
        """The stability function R(z) of the engine's solver (exact coefficients)."""
        from refsim.solvers.stability import amplification

        return amplification(self.solver, z)

    # -- rigid bodies ----------------------------------------------------------------------

    @property
    def honoured_keys(self) -> frozenset:
        """The scene keys beyond the seed's world this model poses
        (:data:`refsim.scenes.support.LOAD_KEYS`): every one for the
        corrected model; for the seed's, only the walls (its laws read no
        other; :func:`refsim.dynamics.loads.scene_loads` refuses the rest by
        name)."""
        from refsim.scenes.support import LOAD_KEYS

        return frozenset(LOAD_KEYS) if self.model == "corrected" else frozenset({"world.walls"})

    def simulate(self, scene, **kwargs):
        """``refsim.simulate`` of ``scene`` under this engine's model."""
        rotation = response = "seed" if self.model == "seed" else "impulse"
        scene = replace(scene, dynamics=replace(scene.dynamics, rotation=rotation,
                                                body_response=response))
        wall_speed = "seed" if self.model == "seed" else "wall"
        return simulate(scene, wall_speed=wall_speed, **kwargs)


def seed(solver: str = "rk4") -> RefsimEngine:
    """The seed-faithful model as an engine (``refsim.engines.refsim_engines:seed``)."""
    return RefsimEngine("seed", solver)


def corrected(solver: str = "rk4") -> RefsimEngine:
    """The corrected model as an engine (``refsim.engines.refsim_engines:corrected``)."""
    return RefsimEngine("corrected", solver)


class PosedRefsim:
    """refsim running a scene's own dynamics as the scene poses them (its
    rotation model, body response and wall law), with the wall speed
    ``wall_speed`` ("wall", "seed", or None for the scene's
    ``world.wall_speed``). The bounce studies receive it as "refsim": what
    they study is the scene's choices, not one model's.

    ``simulate`` records every step unless told otherwise (as the oracles'
    do), so that a bounce is read from every frame.

    ``poses_models`` is True: the engine runs the rotation model and body
    response the scene names, so a study that varies one of them
    (:mod:`refsim.studies.dynamics`) varies the scene it gives this engine.
    """

    poses_models = True

    def __init__(self, wall_speed: str | None = None):
        if wall_speed is not None:
            check_option("wall_speed", wall_speed, SPEEDS)
        self.wall_speed = wall_speed
        self.name = "refsim-seed-wall-speed" if wall_speed == "seed" else "refsim"

    def __repr__(self) -> str:
        return f"<PosedRefsim {self.name}>"

    @property
    def honoured_keys(self) -> frozenset:
        """Every scene key (:data:`refsim.scenes.support.LOAD_KEYS`): the
        scene is run as posed."""
        from refsim.scenes.support import LOAD_KEYS

        return frozenset(LOAD_KEYS)

    def simulate(self, scene, *, every: int = 1, **kwargs):
        """``refsim.simulate(scene, every=every)`` with this engine's wall speed."""
        return simulate(scene, every=every, wall_speed=self.wall_speed, **kwargs)


def as_posed() -> PosedRefsim:
    """refsim running the scene as posed (``refsim.engines.refsim_engines:as_posed``)."""
    return PosedRefsim()


def as_posed_seed_wall_speed() -> PosedRefsim:
    """The scene as posed with the seed's literal wall speed
    (``refsim.engines.refsim_engines:as_posed_seed_wall_speed``)."""
    return PosedRefsim("seed")
