"""The engines refsim ships, as ``module:factory`` specs (a composition root:
the kit itself never chooses an engine).

==================  ================================================  ==================
engine              spec                                              capabilities
==================  ================================================  ==================
refsim-seed         refsim.engines.refsim_engines:seed                all six
refsim-corrected    refsim.engines.refsim_engines:corrected           all six
fcl                 refsim.oracles.fcl_adapter:engine                 triangles, pairs,
                                                                      collide
coal                refsim.oracles.coal_adapter:engine                triangles, pairs,
                                                                      collide
trimesh             refsim.oracles.trimesh_engine:engine              collide, aabb
pybullet            refsim.oracles.pybullet_adapter:engine            rigid
mujoco              refsim.oracles.mujoco_adapter:engine              rigid
drake               refsim.oracles.drake_adapter:engine               rigid
drake-hydroelastic  refsim.oracles.drake_adapter:engine_hydroelastic  rigid
==================  ================================================  ==================

trimesh has two adapters, one per question it answers;
:mod:`refsim.oracles.trimesh_engine` puts them behind one engine so that
the matrix has one trimesh column.

The table is :data:`refsim.engines.registry.SHIPPED` (titles and extras
too); ``SHIPPED_ENGINES`` is its name -> spec view. Each shipped engine's
declared divergences are in
``refsim/conformance/expected/<name>.txt`` (:mod:`refsim.conformance.expected`).

Cost: building an engine is its adapter's (imports, a client); O(1) here.
"""

from __future__ import annotations

from refsim.engines.registry import SHIPPED

SHIPPED_ENGINES: dict[str, str] = {e.name: e.spec for e in SHIPPED}
