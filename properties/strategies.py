"""Hypothesis strategies shared by the property tests, one section per area."""


# ===========================================================================
# Collision: triangles and triangle pairs (refsim.collision, seed S4)
# ===========================================================================
# Generic pairs come from bounded floats; constructed pairs use small dyadic
# coordinates (k / 8, |k| <= 32), so that midpoints, quarter points and the
# exact rigid motions below are computed without rounding and their touching
# or coplanar contacts are exact.

import numpy as _np  # noqa: E402
from hypothesis import strategies as _st  # noqa: E402

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
# Models: random meshes for the AC3D reader and writer (refsim.models, seed S1)
# ===========================================================================
# Coordinates mix awkward doubles (signed zeros, the extremes of the exponent
# range, subnormals, values with no short decimal form) with arbitrary finite
# floats. Names avoid only what AC3D cannot quote: '"', line breaks and lone
# surrogates (not encodable). face_object is sorted, as in any mesh read from
# a file (AC3D groups a file's faces by object).

from refsim.models.mesh import Material as _Material  # noqa: E402
from refsim.models.mesh import Mesh as _Mesh  # noqa: E402

AWKWARD_FLOATS = (0.0, -0.0, 1e-300, -1e-300, 1e300, -1e300, 5e-324, -5e-324,
                  2.2250738585072014e-308, 1.7976931348623157e308, 0.1, 1.0 / 3.0,
                  2.0 ** 53 + 2.0, 3.141592653589793, -1.0, 1.0)

#: A coordinate: awkward half the time, any finite double otherwise.
MODEL_COORDINATE = _st.one_of(_st.sampled_from(AWKWARD_FLOATS),
                              _st.floats(allow_nan=False, allow_infinity=False))

#: A name AC3D can carry in quotes (spaces, tabs, any other Unicode allowed).
AC3D_NAME = _st.text(_st.characters(blacklist_categories=("Cs",),
                                    blacklist_characters='"\n\r'), max_size=12)

#: Valid text after a MATERIAL line's rgb triple (the reader keeps it verbatim).
MATERIAL_REST = _st.sampled_from([
    "", "amb 0.2 0.2 0.2  emis 0 0 0  spec 0.5 0.5 0.5  shi 10  trans 0", "shi 5",
    "trans 0.5  amb 1 1 1", "spec 1e-300 -0.0 5\tshi 128", "emis 1 2 3",
])

materials = _st.builds(
    _Material, name=AC3D_NAME,
    rgb=_st.tuples(MODEL_COORDINATE, MODEL_COORDINATE, MODEL_COORDINATE),
    rest=MATERIAL_REST)


@_st.composite
def meshes(draw, max_vertices=12, max_faces=10):
    """A random :class:`Mesh` with per-face materials, flags and objects.

    Faces index random vertices (repeats and degenerate triangles included);
    ``face_flags`` are polygon surfaces (low 4 bits 0) with random shading bits.
    """
    n = draw(_st.integers(min_value=3, max_value=max_vertices))
    vertices = [[draw(MODEL_COORDINATE) for _ in range(3)] for _ in range(n)]
    m = draw(_st.integers(min_value=1, max_value=max_faces))
    index = _st.integers(min_value=0, max_value=n - 1)
    faces = [[draw(index) for _ in range(3)] for _ in range(m)]
    palette = draw(_st.lists(materials, min_size=1, max_size=3))
    objects = draw(_st.lists(AC3D_NAME, min_size=1, max_size=3))
    per_face = _st.lists
    face_material = draw(per_face(_st.integers(0, len(palette) - 1), min_size=m, max_size=m))
    face_flags = draw(per_face(_st.integers(0, 2 ** 20).map(lambda k: 16 * k),
                               min_size=m, max_size=m))
    face_object = sorted(draw(per_face(_st.integers(0, len(objects) - 1), min_size=m,
                                       max_size=m)))
    return _Mesh(_np.array(vertices, dtype=_np.float64), _np.array(faces, dtype=_np.int64),
                 face_material=face_material, face_flags=face_flags, face_object=face_object,
                 materials=palette, objects=objects)


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

import numpy as _np  # noqa: E402, F811  (this section stands on its own)
from hypothesis import strategies as _st  # noqa: E402, F811
from scipy.spatial import ConvexHull as _ConvexHull  # noqa: E402

from refsim.models.mesh import Mesh as _BoundsMesh  # noqa: E402
from refsim.types import random_rotation as _random_rotation  # noqa: E402
from refsim.types import rotation_about_axis as _rotation_about_axis  # noqa: E402

_SEEDS = _st.integers(min_value=0, max_value=2**32 - 1)
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
    rng = _np.random.default_rng(draw(_SEEDS))
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
        return _random_rotation(_np.random.default_rng(draw(_SEEDS)))
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
        axis = _np.random.default_rng(draw(_SEEDS)).standard_normal(3)
    else:
        axis = _np.eye(3)[draw(_st.integers(min_value=0, max_value=2))]
    step = _np.radians(draw(_st.floats(min_value=0.01, max_value=10.0)))
    return motion, [(_rotation_about_axis(axis, i * step) @ start, translation)
                    for i in range(frames)]


# ===========================================================================
# Solvers and particles (refsim.solvers, refsim.particles; seed S6, S10)
# ===========================================================================
# Linear test equations y' = lambda y with h lambda in a disc where every
# solver's R(z) is O(1), so a step's rounding is a few ulps of |y|; and small
# particle systems with configs drawn across every option.

SOLVER_NAMES = _st.sampled_from(["euler", "averaged-euler", "backwards-euler", "midpoint",
                                 "rk4"])

#: Components of h lambda: |z| <= 3 keeps |R(z)| <= ~20 for rk4.
_Z_COMPONENT = _st.floats(min_value=-2.0, max_value=2.0, allow_nan=False,
                          allow_subnormal=False)

STEP_SIZES = _st.floats(min_value=1e-3, max_value=0.5, allow_nan=False)


@_st.composite
def linear_test_equations(draw):
    """``(lam, h, y0)``: complex ``lam``, step ``h`` and a complex (d,) ``y0``,
    ``d`` in 1..4, with ``|Re(h lam)|, |Im(h lam)| <= 2``."""
    h = draw(STEP_SIZES)
    z = complex(draw(_Z_COMPONENT), draw(_Z_COMPONENT))
    d = draw(_st.integers(min_value=1, max_value=4))
    parts = _st.floats(min_value=-10.0, max_value=10.0, allow_subnormal=False)
    y0 = _np.array([complex(draw(parts), draw(parts)) for _ in range(d)])
    return z / h, h, y0


@_st.composite
def particle_configs(draw, max_count: int = 30):
    """A small :class:`refsim.particles.config.ParticleConfig` over every
    solver, drag model and wall setting; the cube is small enough that
    particles reach its walls within a few steps."""
    from refsim.particles.config import ParticleConfig

    half_size = draw(_st.floats(min_value=0.5, max_value=3.0))
    return ParticleConfig(
        count=draw(_st.integers(min_value=1, max_value=max_count)),
        seed=draw(_st.integers(min_value=0, max_value=2**31 - 1)),
        box_lo=(-half_size,) * 3, box_hi=(half_size,) * 3,
        speed_min=0.0, speed_max=draw(_st.floats(min_value=0.0, max_value=20.0)),
        gravity=draw(_st.floats(min_value=0.0, max_value=20.0)),
        drag=draw(_st.floats(min_value=0.0, max_value=2.0)),
        drag_model=draw(_st.sampled_from(["linear", "quadratic"])),
        mass=draw(_st.floats(min_value=0.1, max_value=10.0)),
        restitution=draw(_st.floats(min_value=0.0, max_value=1.0)),
        friction=draw(_st.floats(min_value=0.0, max_value=1.0)),
        half_size=half_size,
        walls=draw(_st.booleans()),
        solver=draw(SOLVER_NAMES),
        step=draw(_st.floats(min_value=1e-4, max_value=0.05)),
    )


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
    from refsim.collision.measure_levels import bundled_mesh, model_label
    from refsim.collision.spheres import bounding_sphere

    (name_a, scale_a), (name_b, scale_b) = draw(_st.sampled_from(models)), \
        draw(_st.sampled_from(models))
    mesh_a, mesh_b = bundled_mesh(name_a, scale_a), bundled_mesh(name_b, scale_b)
    rot_a, rot_b = draw(rotations()), draw(rotations())
    if draw(_st.sampled_from(["generic", "dyadic"])) == "generic":
        rng = _np.random.default_rng(draw(_SEEDS))
        direction = rng.standard_normal(3)
        direction /= _np.linalg.norm(direction)
        reach = bounding_sphere(mesh_a)[1] + bounding_sphere(mesh_b)[1]
        t_b = direction * draw(_st.floats(min_value=0.0, max_value=1.1 * reach))
    else:
        t_b = _np.array([draw(_st.integers(min_value=-16, max_value=16)) / 8.0
                         for _ in range(3)])
    label = f"{model_label(name_a, scale_a)} / {model_label(name_b, scale_b)}"
    return mesh_a, (rot_a, _np.zeros(3)), mesh_b, (rot_b, t_b), label


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


_WILD = _st.floats(min_value=-1e150, max_value=1e150, allow_nan=False, allow_infinity=False)


@_st.composite
def random_two_body_scenes(draw):
    """Two small bodies anywhere in a 3 m cube with wild velocities and spins
    (up to 1e150), any solver, models and step; for "no silent non-finite"."""
    from refsim.scenes.schema import RESPONSE_MODELS, ROTATION_MODELS, SOLVER_NAMES

    def body(name):
        return {"name": name, "model": draw(_st.sampled_from(["cube.ac", "tetrahedron.ac"])),
                "position": [draw(_st.floats(min_value=-2.0, max_value=2.0))
                             for _ in range(3)],
                "velocity": [draw(_WILD) for _ in range(3)],
                "angular_velocity": [draw(_WILD) for _ in range(3)]}

    return {
        "world": {"half_size": 3.0, "drag": draw(_st.sampled_from([0.0, 0.5, 1e3])),
                  "drag_model": draw(_st.sampled_from(["linear", "quadratic"]))},
        "integration": {"solver": draw(_st.sampled_from(SOLVER_NAMES)),
                        "step": draw(_st.sampled_from([1e-3, 1e-2, 0.1])),
                        "duration": 1.0},
        "collision": {"level": draw(_st.sampled_from(["none", "aabb"]))},
        "dynamics": {"rotation": draw(_st.sampled_from(ROTATION_MODELS)),
                     "body_response": draw(_st.sampled_from(RESPONSE_MODELS))},
        "body": [body("a"), body("b")],
    }


# ===========================================================================
# Fuzz: hostile arguments to the public API (tests/fuzz, DESIGN.md Errors)
# ===========================================================================
# A probe is one Python expression over the fixtures of
# tests.fuzz.api_worker.PRELUDE (CUBE, SPHERE, ID, BOUNCE, FIFO_TOML, ...), so
# that it runs in a worker process under a memory limit and is its own
# reproducer. Each argument is drawn from three lists of spellings: "good"
# (the contract allows it), "edge" (allowed, but at the limits of float64 or
# of the machine: 1e308, 5e-324, 1e155 whose square overflows, 1e9 steps) and
# "bad" (the contract forbids it: None, a wrong shape, NaN, an unknown option,
# a FIFO). A call with a bad argument must refuse (must_refuse); a call with
# only good ones must succeed (must_accept). Good spellings come first, so
# that Hypothesis shrinks towards them.

from dataclasses import dataclass as _dataclass  # noqa: E402

from hypothesis.strategies import SearchStrategy as _SearchStrategy  # noqa: E402

from tests.fuzz.api_worker import Probe as _Probe  # noqa: E402

#: The public functions the API fuzzer probes, in a fixed order.
API_FUNCTIONS = ("Mesh", "load_model", "aabb_linear", "IncrementalAABB.update",
                 "triangles_intersect", "bodies_collide", "intersecting_pairs",
                 "SOLVERS[name].step", "integrate", "load_scene", "scene_from_dict",
                 "simulate", "Simulation", "ParticleConfig", "ParticleSystem.run",
                 "Trajectory.load")

_GOOD, _EDGE, _BAD = "good", "edge", "bad"


@_dataclass(frozen=True)
class _Spec:
    """The spellings of one argument: good ones (or a strategy of good
    ``(spelling, "good")`` pairs), edge ones and bad ones."""

    good: object
    edge: tuple = ()
    bad: tuple = ()


def _arg(good=(), edge=(), bad=()):
    return _Spec(tuple(good), tuple(edge), tuple(bad))


def _keyword(name, good=(), edge=(), bad=()):
    """An optional keyword argument: left out (good), or ``, name=spelling``."""
    return _Spec(("",) + tuple(f", {name}={e}" for e in good),
                 tuple(f", {name}={e}" for e in edge), tuple(f", {name}={e}" for e in bad))


def _draw_args(draw, specs: dict) -> dict:
    """name -> (spelling, class) for every argument: at most two of them
    hostile (edge or bad), the others good, so that a refusal has one cause."""
    hostile_count = draw(_st.sampled_from((1, 1, 1, 0, 2)))
    order = draw(_st.permutations(sorted(specs)))
    hostile = set(order[:hostile_count])
    args = {}
    for name, spec in specs.items():
        if name in hostile and (spec.edge or spec.bad):
            args[name] = draw(_st.sampled_from([(e, _EDGE) for e in spec.edge]
                                               + [(e, _BAD) for e in spec.bad]))
        elif isinstance(spec.good, _SearchStrategy):
            args[name] = draw(spec.good)
        else:
            args[name] = (draw(_st.sampled_from(spec.good)), _GOOD)
    return args


def _probe(function, template, args, check=None, law=""):
    """The probe of ``template`` (a format string) filled with ``args``
    (name -> (spelling, class)); ``check`` is filled the same way."""
    spellings = {name: spelling for name, (spelling, _) in args.items()}
    bad = [f"{name}={spelling.lstrip(', ').removeprefix(name + '=')}"
           for name, (spelling, kind) in args.items() if kind == _BAD]
    return _Probe(function, template.format(**spellings), must_refuse=bool(bad),
                  why=", ".join(bad),
                  check=None if check is None or bad else check.format(**spellings), law=law,
                  must_accept=all(kind == _GOOD for _, kind in args.values()),
                  bad=tuple(sorted(name for name, (_, kind) in args.items() if kind == _BAD)))


_MODELS = ("CUBE", "SPHERE", "TETRA", "TORUS")
_CONVEX = ("CUBE", "SPHERE", "TETRA")
_HOSTILE_MESHES = ("Mesh(SPHERE.vertices * 1e155, SPHERE.faces)",
                   "Mesh(CUBE.vertices * 1e154, CUBE.faces)",
                   "Mesh(CUBE.vertices * 1e308, CUBE.faces)",
                   "Mesh(CUBE.vertices * 1e-300, CUBE.faces)",
                   "Mesh(CUBE.vertices * 5e-324, CUBE.faces)",
                   "Mesh([[0, 0, 0], [1, 0, 0], [2, 0, 0]], [[0, 1, 2]])",
                   "Mesh([[0, 0, 0], [0, 0, 0], [0, 0, 0]], [[0, 1, 2]])")
_NOT_MESHES = ("None", "'cube.ac'", "42", "np.zeros((3, 3))", "(CUBE.vertices, CUBE.faces)")
_MESH = _arg(_MODELS, _HOSTILE_MESHES, _NOT_MESHES)

_POSE = _arg(
    ("ID", "(ROT, np.array([0.5, 0.25, 0.0]))", "(np.eye(3), np.array([0.5, 0.0, 0.0]))"),
    ("(np.eye(3), np.full(3, 1e308))", "(np.eye(3), np.full(3, 5e307))",
     "(np.eye(3), np.full(3, -5e307))", "(np.eye(3), np.full(3, 1e154))",
     "(np.eye(3), np.full(3, 5e-324))", "(-np.eye(3), np.zeros(3))",
     "(np.eye(3).tolist(), [0, 0, 0])"),
    ("None", "(np.eye(3),)", "(np.eye(3), np.zeros(2))", "(2 * np.eye(3), np.zeros(3))",
     "(np.full((3, 3), np.nan), np.zeros(3))", "(np.eye(3), np.array([np.inf, 0.0, 0.0]))",
     "(np.eye(3), np.array([np.nan, 0.0, 0.0]))", "'identity'", "(np.eye(4), np.zeros(3))",
     "(np.eye(3), np.zeros(3), 1)", "(np.eye(3), ['0', 0, 0])"))

_KERNEL_BAD = ("'bogus'", "3", "''")

#: Uniform scales of a model that keep its shape (no underflow to zero, no
#: reflection): convexity and closedness must not change.
_SHAPE_KEEPING = ("", " * 1e155", " * 1e154", " * 1e150", " * 1e62")


@_st.composite
def _mesh_probe(draw):
    base = draw(_st.sampled_from(_MODELS))
    scales = ("1e155", "1e154", "-1e155", "1e150", "1e62", "1e308", "1e300", "1e-300",
              "5e-324", "0.0")
    specs = {
        "vertices": _arg((f"{base}.vertices",), tuple(f"{base}.vertices * {k}" for k in scales)
                  + (f"{base}.vertices.astype(complex)",),
                  ("None", "'abc'", f"np.full_like({base}.vertices, np.nan)",
                   f"{base}.vertices[:, :2]", "np.zeros((0, 3))", "[[0, 0], [1]]")),
        "faces": _arg((f"{base}.faces",), (f"{base}.faces[::-1]", "np.array([[0, 0, 0]])"),
                  ("None", "np.array([[0, 1, 99999]])", "np.array([[0, 1, -1]])",
                   "np.array([[0.0, 1.0, 2.0]])", "np.zeros((0, 3), int)",
                   f"{base}.faces[:, :2]", "[[0, 1, 2], [3]]", "np.array([[0, 1, 2**62]])",
                   "'faces'")),
        "weld_tolerance": _keyword("weld_tolerance", ("0.0", "1e-9"), ("1e308", "5e-324"),
                      ("-1.0", "float('nan')", "float('inf')", "'0'", "None"))}
    args = _draw_args(draw, specs)
    if draw(_st.booleans()):          # a uniform scale that keeps the shape, and its laws
        args["vertices"] = (f"{base}.vertices" + draw(_st.sampled_from(_SHAPE_KEEPING)), _GOOD)
        args["faces"], args["weld_tolerance"] = (f"{base}.faces", _GOOD), ("", _GOOD)
    attribute = draw(_st.sampled_from(("", ".is_convex", ".volume", ".is_closed",
                                       ".centroid_volume", ".neighbors", ".degenerate_faces",
                                       ".bounds", ".face_areas")))
    checks = {".is_convex": (f"_result == {base}.is_convex",
                             "convexity changed by a uniform scale"),
              ".is_closed": (f"_result == {base}.is_closed",
                             "closedness changed by a uniform scale"),
              ".volume": ("_result is None or math.isfinite(_result)", "volume is not finite"),
              ".centroid_volume": ("_result is None or bool(np.isfinite(_result).all())",
                                   "volume centroid is not finite")}
    keeps_shape = (args["faces"][0] == f"{base}.faces" and args["weld_tolerance"][0] == ""
                   and args["vertices"][0] in tuple(f"{base}.vertices" + k for k in _SHAPE_KEEPING))
    check, law = checks.get(attribute, (None, "")) if keeps_shape else (None, "")
    return _probe("Mesh", "Mesh({vertices}, {faces}{weld_tolerance})" + attribute, args, check,
                  law)


@_st.composite
def _load_model_probe(draw):
    specs = {
        "path": _arg(("'cube.ac'", "pathlib.Path('cube.ac')", "CUBE_AC", "'tetrahedron.ac'",
                   "LATIN1_OBJ"),
                  ("COLLINEAR_AC", "'CUBE.AC'"),
                  ("None", "42", "b'cube.ac'", "''", "'/'", "DIR_AC", "FIFO_AC", "LOOP_AC",
                   "'/dev/null'", "'missing.ac'", "NOTES", "JUNK_AC", "EMPTY_AC",
                   "'x' * 5000 + '.ac'", "'cube.ac\\x00'", "['cube.ac']")),
        "weld_tolerance": _keyword("weld_tolerance", ("1e-9",), ("1e308",),
                                   ("-1.0", "float('nan')"))}
    return _probe("load_model", "load_model({path}{weld_tolerance})", _draw_args(draw, specs))


@_st.composite
def _aabb_linear_probe(draw):
    specs = {"mesh": _MESH, "pose": _POSE,
             "kernel": _keyword("kernel", ("'numpy'", "'numba'"), (), _KERNEL_BAD + ("None",))}
    return _probe("aabb_linear", "aabb_linear({mesh}, {pose}{kernel})", _draw_args(draw, specs),
                  "bool(np.all(_result[0] <= _result[1]))", "lo <= hi fails")


@_st.composite
def _incremental_probe(draw):
    specs = {"mesh": _arg(_CONVEX, ("TORUS",) + _HOSTILE_MESHES, _NOT_MESHES), "pose": _POSE,
             "kernel": _keyword("kernel", ("None", "'numba'", "'python'"), (),
                                _KERNEL_BAD + ("'numpy'",)),
             "allow_nonconvex": _keyword("allow_nonconvex", ("False",), ("True", "'yes'"), ())}
    args = _draw_args(draw, specs)
    check = None
    if args["mesh"][0] in _CONVEX and args["allow_nonconvex"][0] in (
            "", ", allow_nonconvex=False"):
        check = ("bool(np.array_equal(_result[0], aabb_linear({mesh}, {pose})[0]) and "
                 "np.array_equal(_result[1], aabb_linear({mesh}, {pose})[1]))")
    return _probe("IncrementalAABB.update",
                  "IncrementalAABB({mesh}{kernel}{allow_nonconvex}).update({pose})", args,
                  check, "the incremental box differs from the linear scan")


_COORDINATE = _st.floats(min_value=-2.0, max_value=2.0, allow_nan=False, allow_infinity=False)


@_st.composite
def _random_triangle(draw):
    rows = [[draw(_COORDINATE) for _ in range(3)] for _ in range(3)]
    return f"np.array({rows!r})", _GOOD


_TRIANGLE = _Spec(
    _st.one_of(_random_triangle(), _st.just(("[[0, 0, 0], [1, 0, 0], [0, 1, 0]]", _GOOD))),
    ("np.full((3, 3), 1e308)", "np.array([[1e308, 0, 0], [0, 1e308, 0], [0, 0, 1e308]])",
     "np.array([[5e-324, 0, 0], [0, 5e-324, 0], [0, 0, 0]])", "np.zeros((3, 3))",
     "np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2]])",
     "np.array([[1e155, 0, 0], [0, 1e155, 0], [0, 0, 1e155]])",
     "np.array([[-1e308, 0, 0], [1e308, 0, 0], [0, 1e308, 0]])"),
    ("None", "np.zeros((2, 3))", "np.zeros((3, 2))", "np.full((3, 3), np.nan)", "'abc'",
     "[[0, 0, 0], [1, 0], [0, 1, 0]]", "np.zeros((3, 3, 1))",
     "np.array([[0, 0, np.inf], [1, 0, 0], [0, 1, 0]])"))


@_st.composite
def _triangles_probe(draw):
    args = _draw_args(draw, {"a": _TRIANGLE, "b": _TRIANGLE})
    return _probe("triangles_intersect", "triangles_intersect({a}, {b})", args,
                  "_result == triangles_intersect({b}, {a})", "not symmetric in its arguments")


def _options(levels, bad_levels=("'bogus'", "'EXACT'", "None", "3", "'none'")):
    return {"level": _keyword("level", levels, (), bad_levels),
            "method": _keyword("method", ("'bvh'", "'seed'"), (), ("'bogus'", "None", "'BVH'")),
            "kernel": _keyword("kernel", ("None", "'numba'", "'python'"), (), _KERNEL_BAD)}


_BODY_PAIR = {"mesh_a": _MESH, "pose_a": _POSE, "mesh_b": _MESH, "pose_b": _POSE}

#: Offsets of two copies of one mesh placed at +t and -t on every axis: the
#: copies overlap when the mesh is larger than t, at coordinates up to 1e308.
_MIRROR_OFFSETS = ("0.25", "2.5e307", "5e307", "1e154", "2.5e153", "1e-300")


@_st.composite
def _bodies_collide_probe(draw):
    if draw(_st.booleans()):
        # every level at once, by the seed's method: a coarser level is conservative
        # (module docstring of refsim.collision.bodies), it never says apart where
        # "exact" says touching; half the time two copies of one mesh mirrored
        # about the origin, which overlap at any scale
        levels = ("{{l: bodies_collide({mesh_a}, {pose_a}, {mesh_b}, {pose_b}, level=l, "
                  "method='seed') for l in LEVELS}}")
        if draw(_st.booleans()):
            mesh = draw(_st.sampled_from(_MODELS + _HOSTILE_MESHES))
            t = draw(_st.sampled_from(_MIRROR_OFFSETS))
            kind, offset = (_GOOD if mesh in _MODELS else _EDGE), (_GOOD if t == "0.25"
                                                                   else _EDGE)
            args = {"mesh_a": (mesh, kind), "mesh_b": (mesh, kind),
                    "pose_a": (f"(np.eye(3), np.full(3, {t}))", offset),
                    "pose_b": (f"(np.eye(3), np.full(3, -{t}))", offset)}
        else:
            args = _draw_args(draw, _BODY_PAIR)
        return _probe("bodies_collide", levels, args,
                      "not _result['exact'] or all(_result.values())",
                      "a coarser level says apart where exact says touching")
    specs = _BODY_PAIR | _options(("'sphere'", "'aabb'", "'triangle-aabb'", "'exact'"))
    return _probe("bodies_collide",
                  "bodies_collide({mesh_a}, {pose_a}, {mesh_b}, {pose_b}{level}{method}{kernel})",
                  _draw_args(draw, specs),
                  "_result == bodies_collide({mesh_b}, {pose_b}, {mesh_a}, {pose_a}"
                  "{level}{method}{kernel})", "not symmetric in its bodies")


@_st.composite
def _intersecting_pairs_probe(draw):
    specs = _BODY_PAIR | _options(("'exact'", "'triangle-aabb'"),
                                  ("'sphere'", "'aabb'", "'bogus'", "None"))
    pair = "{mesh_a}, {pose_a}, {mesh_b}, {pose_b}"
    return _probe("intersecting_pairs", "intersecting_pairs(" + pair + "{level}{method}{kernel})",
                  _draw_args(draw, specs),
                  "bool(np.array_equal(intersecting_pairs(" + pair + "{level}, method='seed'), "
                  "intersecting_pairs(" + pair + "{level}, method='bvh')))",
                  "methods 'seed' and 'bvh' disagree")


@_st.composite
def _step_probe(draw):
    specs = {
        "solver": _arg(("'euler'", "'averaged-euler'", "'backwards-euler'", "'midpoint'",
                        "'rk4'")),
        "f": _arg(("decay",), ("lambda t, y: np.full_like(y, np.nan)", "lambda t, y: y * 1e308"),
                  ("None", "42", "lambda t, y: None", "lambda t, y: 'x'",
                   "lambda t, y: np.zeros(7)")),
        "t": _arg(("0.0",), ("float('nan')", "1e308"), ("None", "'0'")),
        "y": _arg(("np.array([1.0])", "np.array([1.0, 2.0])"),
                  ("np.array([1e308])", "np.array([5e-324])", "np.zeros(0)", "[1.0]",
                   "np.array([np.nan])"),
                  ("None", "'abc'", "np.zeros((2, 2))")),
        "h": _arg(("0.1",), ("5e-324", "1e308", "0.0", "-0.1", "float('nan')", "float('inf')"),
                  ("None", "'0.1'"))}
    return _probe("SOLVERS[name].step", "SOLVERS[{solver}].step({f}, {t}, {y}, {h})",
                  _draw_args(draw, specs), "np.shape(_result) == np.shape({y})",
                  "the state changes shape")


@_st.composite
def _integrate_probe(draw):
    specs = {
        "f": _arg(("decay",), (), ("None", "lambda t, y: None", "lambda t, y: np.zeros(7)")),
        "y0": _arg(("[1.0]", "np.array([1.0, 0.5])"), ("np.array([1e308])", "1.0", "[]"),
                   ("None", "np.array([np.nan])", "np.zeros((2, 2))", "'abc'")),
        "t0": _arg(("0.0",), ("-1e308",), ("float('nan')", "None")),
        "t1": _arg(("1.0", "0.5"), ("1e9", "1e308"), ("float('inf')", "-1.0", "None")),
        "h": _arg(("0.1", "0.25"), ("5e-324", "1e-9", "1.0", "0.3", "1e308"),
                  ("0.0", "-0.1", "float('nan')", "None", "'0.1'")),
        "method": _keyword("method", ("'rk4'", "'euler'", "'midpoint'"), (),
                           ("'bogus'", "None", "3")),
        "last_step": _keyword("last_step", ("'error'", "'short'"), (), ("'bogus'", "None"))}
    return _probe("integrate", "integrate({f}, {y0}, {t0}, {t1}, {h}{method}{last_step})",
                  _draw_args(draw, specs),
                  "_result[1].shape == (len(_result[0]), np.atleast_1d({y0}).size)",
                  "y does not have shape (steps + 1, d)")


@_st.composite
def _load_scene_probe(draw):
    specs = {"path": _arg(
        ("'bounce.toml'", "SCENE_FILE", "pathlib.Path(SCENE_FILE)", "'particles.toml'"), (),
        ("None", "42", "DIR_TOML", "FIFO_TOML", "ZERO_TOML", "LOOP_TOML", "DEEP_TOML",
         "LATIN1_TOML", "'missing.toml'", "''", "'x' * 5000 + '.toml'", "b'bounce.toml'",
         "'bounce.toml\\x00'", "'/dev/null'"))}
    return _probe("load_scene", "load_scene({path})", _draw_args(draw, specs),
                  "scene_absurdity(_result) is None", "accepts a physically absurd scene")


_HOSTILE_VALUES = (float("nan"), float("inf"), -float("inf"), -0.0, 1e308, 5e-324, 1e155,
                   1e-320, 1e62, 1e-65, -1.0, 0.0, 10**30, 10**10, 2**63, "", "bogus", True,
                   None, [], [1.0, 2.0], [float("nan"), 0.0, 0.0], {})
_SCENE_VALUE = _st.one_of(_st.sampled_from(_HOSTILE_VALUES),
                          _st.floats(min_value=-10.0, max_value=10.0),
                          _st.lists(_st.sampled_from((0.0, 1.0, 1e308, -1e308, 0.5)),
                                    min_size=3, max_size=3))


def _py(value) -> str:
    """Python source for a TOML-like value (``repr`` but for NaN and infinities)."""
    if isinstance(value, float) and not _np.isfinite(value):
        return f"float('{value}')"
    if isinstance(value, list):
        return "[" + ", ".join(_py(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k!r}: {_py(v)}" for k, v in value.items()) + "}"
    return repr(value)


def _table(keys):
    return _st.dictionaries(_st.sampled_from(keys + ("bogus",)), _SCENE_VALUE, max_size=3)


#: A valid scene as a dict: one cube dropped in the default world.
_BASE_SCENE = {"integration": {"step": 0.001, "duration": 0.01},
               "body": [{"model": "cube.ac", "position": [0.0, 2.0, 0.0]}]}


@_st.composite
def _scene_from_dict_probe(draw):
    """A valid scene with zero to two hostile changes: a key of any table
    (or ``[[body]]``, or an unknown table) set to a hostile value, or a
    table replaced whole; mostly refused, sometimes accepted, and then the
    scene must not be physically absurd."""
    from refsim.scenes.schema import BODY_FIELDS, PARTICLE_KEYS, TABLES

    keys = {name: tuple(f.name for f in fields) + ("bogus",)
            for name, (_, fields) in TABLES.items()}
    keys["body"] = tuple(f.name for f in BODY_FIELDS) + ("bogus",)
    keys["particles"] = PARTICLE_KEYS + ("bogus",)
    data = {"integration": dict(_BASE_SCENE["integration"]),
            "body": [dict(_BASE_SCENE["body"][0])]}
    for _ in range(draw(_st.sampled_from((1, 1, 2, 0)))):
        table = draw(_st.sampled_from(sorted(keys) + ["bogus"]))
        if table == "bogus" or draw(_st.integers(0, 9)) == 0:       # a whole table
            data[table] = draw(_SCENE_VALUE)
            continue
        key = draw(_st.sampled_from(keys[table]))
        value = draw(_st.one_of(_SCENE_VALUE, _st.sampled_from(
            ("cube.ac", "missing.ac", "sphere-2k.ac", "rk5", "exact", "impulse"))))
        if table == "body":
            if isinstance(data["body"], list) and data["body"] and isinstance(
                    data["body"][0], dict):
                data["body"][0][key] = value
        elif isinstance(data.setdefault(table, {}), dict):
            data[table][key] = value
    return _Probe("scene_from_dict", f"scene_from_dict({_py(data)})",
                  check="scene_absurdity(_result) is None",
                  law="accepts a physically absurd scene")


_SCENE = _arg(("BOUNCE", "HEADON", "SPIN"),
              ("body_scene(scale=1e154)", "body_scene(scale=1e155)", "body_scene(scale=1e-65)",
               "body_scene(scale=1e62)", "body_scene(mass=5e-324)", "body_scene(mass=1e-320)",
               "body_scene(model=COLLINEAR_AC)", "body_scene(velocity=[1e100, 0.0, 0.0])",
               "body_scene(model='torus.ac', scale=1e155)",
               "body_scene(orientation=[[-1, 0, 0], [0, 1, 0], [0, 0, 1]])"),
              ("None", "'bounce.toml'", "42", "PARTICLES"))


@_st.composite
def _simulate_probe(draw):
    specs = {"scene": _SCENE,
             "duration": _arg((", duration=0.01", ", duration=0.004"), (),
                              (", duration=-1.0", ", duration=0.0", ", duration=float('nan')",
                               ", duration=float('inf')", ", duration='0.1'", ", duration=1e9",
                               ", duration=5e-324", ", duration=1e-9")),
             "every": _keyword("every", ("1", "3"), ("10**30",),
                               ("0", "-1", "2.5", "'2'", "float('nan')"))}
    return _probe("simulate", "simulate({scene}{duration}{every})", _draw_args(draw, specs),
                  "_result.n_frames >= 2 and bool(np.isfinite(_result.position).all())",
                  "returns fewer than two frames or non-finite positions")


@_st.composite
def _simulation_probe(draw):
    specs = {"scene": _SCENE,
             "wall_speed": _keyword("wall_speed", ("'wall'", "'seed'"), (), ("'bogus'", "None")),
             "boxes": _keyword("boxes", ("'auto'", "'trackers'", "'batched'"), (),
                               ("'bogus'", "3")),
             "n_steps": _arg(("1", "3"), ("0",), ("-1", "2.5", "None", "'3'", "10**9"))}
    return _probe("Simulation", "Simulation({scene}{wall_speed}{boxes}).run({n_steps})",
                  _draw_args(draw, specs))


_PARTICLE_FIELDS = {
    "count": _arg(("10", "1"), ("10**10",), ("0", "-5", "2.5", "None", "'10'", "True",
                                             "float('nan')")),
    "seed": _arg(("0", "7"), ("2**64",), ("-1", "None", "2.5")),
    "box_lo": _arg(("(-1, -1, -1)",), (), ("(np.nan, 0, 0)", "(1, 2)", "None", "'abc'",
                                          "(-10, 0, 0)")),
    "box_hi": _arg(("(1, 1, 1)",), (), ("(np.inf, 0, 0)", "(10, 0, 0)", "(-2, -2, -2)")),
    "speed_min": _arg(("0.0",), (), ("-1.0", "float('nan')", "'x'")),
    "speed_max": _arg(("5.0",), ("1e308",), ("float('inf')", "-1.0")),
    "gravity": _arg(("9.81",), ("1e308",), ("-1.0", "float('nan')")),
    "drag": _arg(("0.1",), ("1e308",), ("-1.0",)),
    "drag_model": _arg(("'linear'", "'quadratic'"), (), ("'bogus'", "None")),
    "mass": _arg(("1.0",), ("5e-324", "1e-320"), ("0.0", "-1.0", "float('nan')")),
    "restitution": _arg(("0.5",), (), ("-0.1", "1.5", "float('nan')")),
    "friction": _arg(("0.5",), (), ("-0.1", "1.5")),
    "half_size": _arg(("5.0",), ("1e308", "5e-324"), ("0.0", "-1.0", "float('inf')")),
    "walls": _arg(("True", "False"), (), ("'yes'", "1", "None")),
    "solver": _arg(("'rk4'", "'euler'"), (), ("'bogus'", "None", "3")),
    "step": _arg(("0.001",), ("5e-324", "1e308"), ("0.0", "-1.0", "float('nan')")),
}


@_st.composite
def _particle_fields(draw, count=None):
    """``ParticleConfig`` keyword arguments as probe arguments (name ->
    (``name=spelling``, class)): up to four fields, at most two hostile;
    with ``count``, that count."""
    names = draw(_st.lists(_st.sampled_from(sorted(_PARTICLE_FIELDS)), max_size=4,
                           unique=True))
    specs = {name: _PARTICLE_FIELDS[name] for name in names if name != "count" or count is None}
    args = _draw_args(draw, specs) if specs else {}
    if count is not None:
        args["count"] = count
    return {name: (f"{name}={spelling}", kind) for name, (spelling, kind) in args.items()}


def _call(name: str, args: dict) -> str:
    """``name({a}, {b}, ...)``: a template calling ``name`` with every argument."""
    return name + "(" + ", ".join("{" + key + "}" for key in args) + ")"


@_st.composite
def _particle_config_probe(draw):
    args = draw(_particle_fields())
    return _probe("ParticleConfig", _call("ParticleConfig", args), args)


@_st.composite
def _particle_system_probe(draw):
    specs = {"state": _arg(("",), (), (", positions=np.zeros((10, 3))",
                                       ", positions=np.zeros((10, 2)), "
                                       "velocities=np.zeros((10, 2))",
                                       ", positions=np.full((10, 3), np.nan), "
                                       "velocities=np.zeros((10, 3))",
                                       ", positions='abc', velocities='abc'")),
             "kernel": _keyword("kernel", ("'numpy'",), ("'fused'",), ("'bogus'", "3")),
             "steps": _arg(("1", "5"), ("0",), ("-5", "2.5", "None", "'3'", "10**9")),
             "count": _arg(("10",), ("10**8",), ("10**10",))}
    args = _draw_args(draw, specs)
    fields = draw(_particle_fields(count=args.pop("count")))
    args |= fields
    return _probe("ParticleSystem.run", "ParticleSystem(" + _call("ParticleConfig", fields)
                  + "{state}{kernel}).run({steps})", args)


@_st.composite
def _trajectory_probe(draw):
    specs = {"path": _arg(("GOOD_NPZ", "pathlib.Path(GOOD_NPZ)"), (),
                          ("None", "'missing.npz'", "DIR_AC", "JUNK_NPZ", "PARTIAL_NPZ",
                           "PICKLE_NPZ", "FIFO_NPZ", "'/dev/null'", "42", "SCENE_FILE"))}
    return _probe("Trajectory.load", "Trajectory.load({path})", _draw_args(draw, specs),
                  "_result.n_frames >= 1", "loads no frames")


_API_PROBES = {
    "Mesh": _mesh_probe, "load_model": _load_model_probe, "aabb_linear": _aabb_linear_probe,
    "IncrementalAABB.update": _incremental_probe, "triangles_intersect": _triangles_probe,
    "bodies_collide": _bodies_collide_probe, "intersecting_pairs": _intersecting_pairs_probe,
    "SOLVERS[name].step": _step_probe, "integrate": _integrate_probe,
    "load_scene": _load_scene_probe, "scene_from_dict": _scene_from_dict_probe,
    "simulate": _simulate_probe, "Simulation": _simulation_probe,
    "ParticleConfig": _particle_config_probe, "ParticleSystem.run": _particle_system_probe,
    "Trajectory.load": _trajectory_probe,
}


def api_probes(function: str):
    """Probes (tests.fuzz.api_worker.Probe) of one public function of API_FUNCTIONS."""
    return _API_PROBES[function]()
