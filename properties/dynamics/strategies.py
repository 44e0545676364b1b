"""Hypothesis strategies of the dynamics properties (refsim.dynamics, seeds S5-S9)."""

from __future__ import annotations

import numpy as _np
from hypothesis import strategies as _st

from properties.bounds.strategies import rotations

# ===========================================================================
# Dynamics: contacts, wall hits and random states (refsim.dynamics, S5-S9)
# ===========================================================================
# Contact pairs are two bodies with random masses, symmetric positive definite
# inertia tensors, velocities and spins, one contact point near the middle and
# a random unit normal. Wall hits put a regular polyhedron (isotropic inertia,
# so free rotation conserves energy exactly) just above the floor, approaching
# it at >= 0.5 m/s (a bounce, not resting contact). Random states cover
# velocities and spins over 300 orders of magnitude.

_DYN_FLOAT = _st.floats(min_value=-3.0, max_value=3.0, allow_nan=False, allow_infinity=False)
_DYN_VEC = _st.tuples(_DYN_FLOAT, _DYN_FLOAT, _DYN_FLOAT).map(
    lambda t: _np.array(t, dtype=_np.float64))


@_st.composite
def dynamic_bodies(draw):
    """``(m, I, x, v, w)``: mass, (3, 3) SPD inertia, position, velocity, spin."""
    m = draw(_st.floats(min_value=0.1, max_value=10.0))
    A = _np.array([draw(_DYN_VEC) for _ in range(3)])
    I = A @ A.T + draw(_st.floats(min_value=0.05, max_value=2.0)) * _np.eye(3)
    return m, I, draw(_DYN_VEC), draw(_DYN_VEC), draw(_DYN_VEC)


@_st.composite
def contact_pairs(draw):
    """``(body_a, body_b, p, n, e, mu)`` with bodies from :func:`dynamic_bodies`."""
    a, b = draw(dynamic_bodies()), draw(dynamic_bodies())
    p = 0.5 * (a[2] + b[2]) + 0.2 * draw(_DYN_VEC)
    n = draw(_DYN_VEC.filter(lambda d: _np.linalg.norm(d) > 0.1))
    e = draw(_st.floats(min_value=0.0, max_value=1.0))
    mu = draw(_st.floats(min_value=0.0, max_value=1.0))
    return a, b, p, n / _np.linalg.norm(n), e, mu


@_st.composite
def wall_hit_scenes(draw):
    """A one-body scene dict whose body will cross the floor within one step.

    The body (cube, tetrahedron or icosahedron; mass and rotation random) sits
    with its lowest vertex above the floor of a 4 m cube by at most 40 % of
    what one step covers, and moves down at 0.5 to 8 m/s, with lateral
    velocity and a spin; the rotation model is "impulse", gravity on or off,
    restitution and friction random.

    Why the floor is crossed: in one step h the lowest vertex moves down by
    at least ``|v_y| h`` (gravity only adds to it) less what the spin can lift
    it, at most ``|w| r h`` for a vertex at distance ``r`` from the centre of
    mass (a chord is no longer than its arc). The spin is scaled to
    ``|w| r_max <= |v_y| / 2``, so the vertex ends at least ``|v_y| h / 2 - gap
    >= 0.1 |v_y| h`` below the floor.
    """
    model = draw(_st.sampled_from(["cube.ac", "tetrahedron.ac", "icosahedron.ac"]))
    R = draw(rotations(kinds=("random", "identity", "signed-permutation")))
    import refsim
    from refsim.bundled import models_dir
    from refsim.types import transform_points

    mesh = refsim.load_model(models_dir() / model)
    vertices = mesh.vertices
    lowest = float(transform_points(vertices, (R, _np.zeros(3)))[:, 1].min())
    offsets = vertices - mesh.centroid_volume
    r_max = float(_np.sqrt((offsets * offsets).sum(axis=1)).max())
    half = 4.0
    h = 1e-3
    v = draw(_DYN_VEC)
    v[1] = -draw(_st.floats(min_value=0.5, max_value=8.0))
    w = draw(_DYN_VEC)
    w_norm = float(_np.sqrt((w * w).sum()))
    w_limit = 0.5 * -v[1] / r_max
    if w_norm > w_limit:
        w = w * (w_limit / w_norm)
    gap = draw(_st.floats(min_value=0.0, max_value=0.4)) * h * -v[1]
    return {
        "world": {"half_size": half, "gravity": draw(_st.sampled_from([0.0, 9.81])),
                  "restitution": draw(_st.floats(min_value=0.0, max_value=1.0)),
                  "friction": draw(_st.floats(min_value=0.0, max_value=1.0))},
        "integration": {"solver": "rk4", "step": h, "duration": h},
        "collision": {"level": "none"},
        "dynamics": {"rotation": "impulse", "body_response": "off"},
        "body": [{"name": "body", "model": model, "orientation": R.tolist(),
                  "position": [0.0, -half - lowest + gap, 0.0], "velocity": v.tolist(),
                  "angular_velocity": w.tolist(),
                  "mass": draw(_st.floats(min_value=0.1, max_value=10.0))}],
    }


# as wild as a scene may be: every number within refsim.limits.MAX_MAGNITUDE
_WILD = _st.floats(min_value=-1e50, max_value=1e50, allow_nan=False, allow_infinity=False)


@_st.composite
def random_two_body_scenes(draw):
    """Two small bodies anywhere in a 3 m cube with wild spins (up to 1e50,
    the most a scene allows), velocities up to the most a scene allows (a
    step covers at most half the cube), drags up to 1e50 (the most a scene
    allows: quadratic drag then overflows within a step), any solver,
    models and step; for "no silent non-finite"."""
    from refsim.scenes.schema import RESPONSE_MODELS, ROTATION_MODELS, SOLVER_NAMES

    half_size, step = 3.0, draw(_st.sampled_from([1e-3, 1e-2, 0.1]))
    fastest = half_size / step / 3.0 ** 0.5 * (1.0 - 1e-12)     # per component
    velocity = _st.floats(min_value=-fastest, max_value=fastest)

    def body(name):
        return {"name": name, "model": draw(_st.sampled_from(["cube.ac", "tetrahedron.ac"])),
                "position": [draw(_st.floats(min_value=-2.0, max_value=2.0))
                             for _ in range(3)],
                "velocity": [draw(velocity) for _ in range(3)],
                "angular_velocity": [draw(_WILD) for _ in range(3)]}

    return {
        "world": {"half_size": half_size,
                  "drag": draw(_st.sampled_from([0.0, 0.5, 1e3, 1e50])),
                  "drag_model": draw(_st.sampled_from(["linear", "quadratic"]))},
        "integration": {"solver": draw(_st.sampled_from(SOLVER_NAMES)), "step": step,
                        "duration": 1.0},
        "collision": {"level": draw(_st.sampled_from(["none", "aabb"]))},
        "dynamics": {"rotation": draw(_st.sampled_from(ROTATION_MODELS)),
                     "body_response": draw(_st.sampled_from(RESPONSE_MODELS))},
        "body": [body("a"), body("b")],
    }
