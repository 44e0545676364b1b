"""The batched boxes equal the linear scan's and the incremental tracker's,
bit for bit, on both paths."""

from __future__ import annotations

import numpy as np

import refsim
from refsim.bundled import models_dir
from refsim.dynamics.boxes import boxes_compiled, boxes_numpy
from refsim.types import random_rotation


def test_batched_boxes_are_the_trackers_boxes():
    rng = np.random.default_rng(4)
    for name in ("cube.ac", "icosahedron.ac", "star.ac"):
        mesh = refsim.load_model(models_dir() / name)
        R = np.array([random_rotation(rng) for _ in range(12)] + [np.eye(3)])
        origin = rng.normal(size=(13, 3)) * 3.0
        vertices_t = np.ascontiguousarray(mesh.vertices.T)
        lo, hi = boxes_numpy(vertices_t, R, origin)
        lo_c, hi_c = boxes_compiled(vertices_t, R, origin)
        assert np.array_equal(lo, lo_c) and np.array_equal(hi, hi_c)
        for b in range(13):
            expected = refsim.aabb_linear(mesh, (R[b], origin[b]))
            assert np.array_equal(lo[b], expected[0]) and np.array_equal(hi[b], expected[1])
            if mesh.is_convex:
                tracker = refsim.IncrementalAABB(mesh)
                got = tracker.update((R[b], origin[b]))
                assert np.array_equal(lo[b], got[0]) and np.array_equal(hi[b], got[1])
