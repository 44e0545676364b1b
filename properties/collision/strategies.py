"""Hypothesis strategies of the collision properties (refsim.collision, seed S4)."""

from __future__ import annotations

import numpy as _np
from hypothesis import strategies as _st

from properties.bounds.strategies import SEEDS, rotations

# ===========================================================================
# Collision: triangles and triangle pairs (refsim.collision, seed S4)
# ===========================================================================
# Generic pairs come from bounded floats; constructed pairs use small dyadic
# coordinates (k / 8, |k| <= 32), so that midpoints, quarter points and the
# exact rigid motions below are computed without rounding and their touching
# or coplanar contacts are exact.


#: Generic coordinates: bounded so that pairs overlap often enough.
TRIANGLE_COORDINATE = _st.floats(min_value=-2.0, max_value=2.0, allow_nan=False,
                                 allow_infinity=False, allow_subnormal=False)

#: Dyadic coordinates k / 8: every sum, midpoint and quarter point is exact.
DYADIC_COORDINATE = _st.integers(min_value=-32, max_value=32).map(lambda k: k / 8.0)


@_st.composite
def triangles(draw, coordinate=TRIANGLE_COORDINATE):
    """A (3, 3) float64 vertex array (possibly degenerate)."""
    return _np.array([[draw(coordinate) for _ in range(3)] for _ in range(3)], dtype=_np.float64)


@_st.composite
def triangle_pairs(draw):
    """Two generic triangles in the same small box."""
    return draw(triangles()), draw(triangles())


@_st.composite
def constructed_contact_pairs(draw):
    """``(a, b, kind)``: a dyadic triangle a and a triangle b built to touch
    it or lie in its plane, exactly.

    kinds: "shared-vertex", "vertex-on-edge", "vertex-on-face" (b touches a;
    the answer is True), "coplanar" (b's vertices are dyadic affine
    combinations of a's: all six points on one plane; either answer).
    """
    a = draw(triangles(DYADIC_COORDINATE))
    kind = draw(_st.sampled_from(["shared-vertex", "vertex-on-edge", "vertex-on-face",
                                  "coplanar"]))
    b = draw(triangles(DYADIC_COORDINATE))
    quarter = _st.integers(min_value=0, max_value=4).map(lambda k: k / 4.0)
    i = draw(_st.integers(min_value=0, max_value=2))
    if kind == "shared-vertex":
        b[0] = a[i]
    elif kind == "vertex-on-edge":
        s = draw(quarter)
        b[0] = a[i] + s * (a[(i + 1) % 3] - a[i])
    elif kind == "vertex-on-face":
        s = draw(quarter)
        t = draw(quarter.filter(lambda t: t + s <= 1.0))
        b[0] = a[0] + s * (a[1] - a[0]) + t * (a[2] - a[0])
    else:
        weight = _st.integers(min_value=-4, max_value=8).map(lambda k: k / 4.0)
        for j in range(3):
            s, t = draw(weight), draw(weight)
            b[j] = a[0] + s * (a[1] - a[0]) + t * (a[2] - a[0])
    return a, b, kind


@_st.composite
def exact_rigid_motions(draw):
    """A map of (n, 3) arrays that float arithmetic applies exactly to points
    with few significant bits (such as the dyadic ones above): an axis
    permutation, sign flips, a power-of-two scale (2**-3 .. 2**3) and a
    translation by multiples of 1/8 (|t| <= 16)."""
    perm = draw(_st.permutations([0, 1, 2]))
    signs = _np.array([draw(_st.sampled_from([-1.0, 1.0])) for _ in range(3)])
    scale = 2.0 ** draw(_st.integers(min_value=-3, max_value=3))
    shift = _np.array([draw(_st.integers(min_value=-128, max_value=128)) / 8.0
                       for _ in range(3)])

    def motion(points):
        return _np.asarray(points, dtype=_np.float64)[:, list(perm)] * signs * scale + shift

    return motion


# ===========================================================================
# Collision: posed pairs of bundled models (refsim.collision.bodies, seed S4)
# ===========================================================================
# Two small bundled models (scaled copies included, so that one can sit
# inside the other), each at a pose. Rotations come from ``rotations`` above
# (random, identity or signed permutations: the last two keep the models'
# faces axis-aligned). Translations are either generic (a random direction
# and a distance from 0 to 1.1 times the sum of the bounding radii) or
# dyadic (multiples of 1/8, exact): with axis-aligned rotations the dyadic
# ones make faces, edges and corners touch exactly, the case every level must
# still report.

POSED_MODELS = (("cube", 1.0), ("icosahedron", 1.0), ("star", 1.0), ("l-beam", 1.0),
                ("long-box", 1.0), ("tetrahedron", 1.0), ("cube", 0.5), ("icosahedron", 0.5))


@_st.composite
def posed_model_pairs(draw, models=POSED_MODELS):
    """``(mesh_a, pose_a, mesh_b, pose_b, label)`` for two bundled models."""
    from refsim.collision.spheres import bounding_sphere
    from refsim.studies.levels import bundled_mesh, model_label

    (name_a, scale_a), (name_b, scale_b) = draw(_st.sampled_from(models)), \
        draw(_st.sampled_from(models))
    mesh_a, mesh_b = bundled_mesh(name_a, scale_a), bundled_mesh(name_b, scale_b)
    rot_a, rot_b = draw(rotations()), draw(rotations())
    if draw(_st.sampled_from(["generic", "dyadic"])) == "generic":
        rng = _np.random.default_rng(draw(SEEDS))
        direction = rng.standard_normal(3)
        direction /= _np.linalg.norm(direction)
        reach = bounding_sphere(mesh_a)[1] + bounding_sphere(mesh_b)[1]
        t_b = direction * draw(_st.floats(min_value=0.0, max_value=1.1 * reach))
    else:
        t_b = _np.array([draw(_st.integers(min_value=-16, max_value=16)) / 8.0
                         for _ in range(3)])
    label = f"{model_label(name_a, scale_a)} / {model_label(name_b, scale_b)}"
    return mesh_a, (rot_a, _np.zeros(3)), mesh_b, (rot_b, t_b), label
