"""Hypothesis strategies of the bounds properties (refsim.bounds, seeds S2, S3)."""

from __future__ import annotations

import numpy as _np
from hypothesis import strategies as _st
from scipy.spatial import ConvexHull as _ConvexHull

from refsim.models.mesh import Mesh as _BoundsMesh
from refsim.types import random_rotation as _random_rotation
from refsim.types import rotation_about_axis as _rotation_about_axis

# ===========================================================================
# Bounds: convex meshes and pose sequences (refsim.bounds, seeds S2, S3)
# ===========================================================================
# Meshes are convex hulls of random points, wound outward, stretched by an
# anisotropic scale; a "grid" kind uses small integer points so that hull
# faces are coplanar and, at axis-aligned poses, whole faces tie exactly (the
# plateaus the incremental walk must cross). Poses come in sequences: coherent
# (a fixed turn per frame about one axis) or jumping (unrelated orientations),
# starting from random, identity or signed-permutation orientations (exact
# ties again).



SEEDS = _st.integers(min_value=0, max_value=2**32 - 1)
_AXIS_SCALE = _st.floats(min_value=0.05, max_value=20.0)


def hull_mesh(points) -> _BoundsMesh:
    """The convex hull of ``points`` (k, 3) as a Mesh wound outward.

    scipy's ConvexHull (qhull) lists each facet's triangle in no particular
    order; a triangle is flipped when its normal opposes the facet's outward
    normal (``hull.equations``). Points inside the hull are dropped by Mesh.
    """
    points = _np.asarray(points, dtype=_np.float64)
    hull = _ConvexHull(points)
    faces = hull.simplices.copy()
    v = points[faces]
    normal = _np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    flip = _np.einsum("ij,ij->i", normal, hull.equations[:, :3]) < 0.0
    faces[flip] = faces[flip][:, ::-1]
    return _BoundsMesh(points, faces, name="hull")


def midpoint_subdivision(mesh: _BoundsMesh) -> _BoundsMesh:
    """Each triangle split in four at its edge midpoints ``(a + b) / 2``.

    The new vertices lie on the old edges and faces: the mesh stays convex but
    gains vertices that are not corners of the solid (inside flat faces, on
    edges), where a strict hill climb can stall. Midpoints of dyadic
    coordinates are exact; otherwise ``a + b`` rounds and the surface is
    convex only to rounding, which the tracker must also survive.
    """
    v, f = mesh.vertices, mesh.faces
    a, b, c = f[:, 0], f[:, 1], f[:, 2]
    m = len(f)
    mid = _np.concatenate([(v[a] + v[b]) / 2.0, (v[b] + v[c]) / 2.0, (v[c] + v[a]) / 2.0])
    n = len(v)
    ab, bc, ca = n + _np.arange(m), n + m + _np.arange(m), n + 2 * m + _np.arange(m)
    faces = _np.concatenate([_np.stack([a, ab, ca], 1), _np.stack([ab, b, bc], 1),
                             _np.stack([ca, bc, c], 1), _np.stack([ab, bc, ca], 1)])
    return _BoundsMesh(_np.vstack([v, mid]), faces, name=f"{mesh.name}-subdivided")


@_st.composite
def convex_hull_meshes(draw, max_points: int = 80,
                       kinds=("gaussian", "sphere", "grid"), subdivisions=(0, 0, 1, 2)):
    """A convex Mesh: the hull of random points with an anisotropic scale.

    kinds: "gaussian" (generic points), "sphere" (every point on the hull:
    many vertices, small angles between neighbours), "grid" (integers in
    [-3, 3]: coplanar faces and, at axis-aligned poses, exact ties).
    Subdivision (0, 1 or 2 rounds of :func:`midpoint_subdivision`) adds
    vertices inside faces and edges. The vertices are then shuffled, so that
    the lowest index among tied vertices (the tracker's first choice) can be
    any of them, inside a face included.
    """
    rng = _np.random.default_rng(draw(SEEDS))
    kind = draw(_st.sampled_from(kinds))
    k = draw(_st.integers(min_value=4, max_value=max_points))
    if kind == "gaussian":
        points = rng.standard_normal((k, 3))
    elif kind == "sphere":
        points = rng.standard_normal((k, 3))
        points /= _np.linalg.norm(points, axis=1, keepdims=True)
    else:
        points = rng.integers(-3, 4, size=(k, 3)).astype(_np.float64)
        if _np.linalg.matrix_rank(points - points[0]) < 3:  # flat: make it solid
            points = _np.vstack([points, [[3, 0, 0], [0, 3, 0], [0, 0, 3], [-3, -3, -3]]])
    scale = _np.array([draw(_AXIS_SCALE) for _ in range(3)])
    mesh = hull_mesh(points * scale)
    for _ in range(draw(_st.sampled_from(subdivisions))):
        mesh = midpoint_subdivision(mesh)
    order = rng.permutation(mesh.n_vertices)  # new index -> old index
    new_index = _np.argsort(order)
    return _BoundsMesh(mesh.vertices[order], new_index[mesh.faces], name=mesh.name)


@_st.composite
def rotations(draw, kinds=("random", "random", "identity", "signed-permutation")):
    """A rotation: uniformly random, the identity, or a signed permutation
    (exactly orthonormal; maps the coordinate axes onto each other)."""
    kind = draw(_st.sampled_from(kinds))
    if kind == "random":
        return _random_rotation(_np.random.default_rng(draw(SEEDS)))
    if kind == "identity":
        return _np.eye(3)
    perm = draw(_st.permutations([0, 1, 2]))
    signs = _np.array([draw(_st.sampled_from([-1.0, 1.0])) for _ in range(3)])
    r = _np.eye(3)[:, list(perm)] * signs
    if _np.linalg.det(r) < 0.0:
        r[:, 0] = -r[:, 0]
    return r


@_st.composite
def pose_sequences(draw, min_frames: int = 2, max_frames: int = 40,
                   motions=("coherent", "jump"), rotation=None):
    """``(motion, poses)``: a list of ``(R, t)`` poses, "coherent" or "jump".

    Coherent: the start rotation turned by a fixed step (0.01 to 10 degrees)
    per frame about a random or a coordinate axis. Jump: an independent
    rotation every frame (drawn from ``rotation``, default :func:`rotations`).
    The translation is fixed, in [-10, 10]^3.
    """
    rotation = rotations() if rotation is None else rotation
    motion = draw(_st.sampled_from(motions))
    frames = draw(_st.integers(min_value=min_frames, max_value=max_frames))
    translation = _np.array([draw(_st.floats(min_value=-10.0, max_value=10.0))
                             for _ in range(3)])
    if motion == "jump":
        return motion, [(draw(rotation), translation) for _ in range(frames)]
    start = draw(rotation)
    axis_kind = draw(_st.sampled_from(["random", "coordinate"]))
    if axis_kind == "random":
        axis = _np.random.default_rng(draw(SEEDS)).standard_normal(3)
    else:
        axis = _np.eye(3)[draw(_st.integers(min_value=0, max_value=2))]
    step = _np.radians(draw(_st.floats(min_value=0.01, max_value=10.0)))
    return motion, [(_rotation_about_axis(axis, i * step) @ start, translation)
                    for i in range(frames)]
