"""refsim: a validated reference implementation of a 1997 rigid-body N-body
simulation (Kenny Hoff, COMP-205, UNC Chapel Hill), checked against python-fcl,
trimesh, scipy, pybullet and MuJoCo.

The public names below are a contract (docs/design.md, Public API). They are
imported lazily, on first use, so that ``import refsim`` and the command line
stay quick and an area's heavy imports are paid only by those who use it.
"""

from __future__ import annotations

import importlib
import importlib.util

__version__ = "0.1.0"

# public name -> module that defines it
_EXPORTS = {
    "RefsimError": "refsim.errors",
    "ModelError": "refsim.errors",
    "SceneError": "refsim.errors",
    "UnposableKey": "refsim.errors",
    "StateError": "refsim.errors",
    "DivergenceError": "refsim.errors",
    "OptionError": "refsim.errors",
    "ArgumentTypeError": "refsim.errors",
    "OutputError": "refsim.errors",
    "SweepError": "refsim.errors",
    "Mesh": "refsim.models.mesh",
    "Material": "refsim.models.mesh",
    "aabb_linear": "refsim.bounds.aabb_linear",
    "IncrementalAABB": "refsim.bounds.aabb_incremental",
    "make_aabb_tracker": "refsim.bounds.tracker",
    "world_cube_test": "refsim.bounds.world_cube",
    "WallCrossings": "refsim.bounds.world_cube",
    "triangles_intersect": "refsim.collision.triangle",
    "bodies_collide": "refsim.collision.bodies",
    "intersecting_pairs": "refsim.collision.bodies",
    "ModelWarning": "refsim.errors",
    "load_model": "refsim.models.loading",
    "read_ac3d": "refsim.models.ac3d",
    "write_ac3d": "refsim.models.ac3d",
    "load_scene": "refsim.scenes.loader",
    "Scene": "refsim.scenes.schema",
    "SOLVERS": "refsim.solvers.methods",
    "SEED_LITERAL_VARIANTS": "refsim.solvers.methods",
    "ExplicitRungeKutta": "refsim.solvers.explicit_rk",
    "integrate": "refsim.solvers.integrate",
    "solve_fixed_step": "refsim.solvers.integrate",
    "FixedStepResult": "refsim.solvers.integrate",
    "ParticleConfig": "refsim.particles.config",
    "ParticleSystem": "refsim.particles.system",
    "simulate": "refsim.dynamics.simulate",
    "Simulation": "refsim.dynamics.simulation",
    "Trajectory": "refsim.dynamics.trajectory",
    "view": "refsim.viewer.live",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        # a subpackage or module (refsim.types, refsim.collision, ...) on first use
        if not name.startswith("_") and importlib.util.find_spec(f"refsim.{name}"):
            return importlib.import_module(f"refsim.{name}")
        raise AttributeError(f"module 'refsim' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
