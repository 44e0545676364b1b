"""Bounding boxes and the world cube (seed S2, S3).

- :mod:`~refsim.bounds.aabb_linear`: the O(n) scan of the transformed vertices.
- :mod:`~refsim.bounds.aabb_incremental`: the incremental update that walks the
  vertex-neighbour graph from last frame's six extreme vertices.
- :mod:`~refsim.bounds.tracker`: the scene option ``aabb`` choosing between them.
- :mod:`~refsim.bounds.world_cube`: the per-axis interval test against the cube.
- :mod:`~refsim.studies.bounds`: claims C1 (cost) and C2 (convexity) measured.

The public names (``refsim.aabb_linear``, ``refsim.IncrementalAABB``, ...) are
exported by ``refsim`` itself; this package re-exports nothing, so that
``refsim.bounds.aabb_linear`` is always the module, never the function.
"""
