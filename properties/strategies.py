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
    from refsim.collision.spheres import bounding_sphere
    from refsim.studies.levels import bundled_mesh, model_label

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


# as wild as a scene may be: every number within refsim.limits.MAX_MAGNITUDE
_WILD = _st.floats(min_value=-1e50, max_value=1e50, allow_nan=False, allow_infinity=False)


@_st.composite
def random_two_body_scenes(draw):
    """Two small bodies anywhere in a 3 m cube with wild velocities and spins
    (up to 1e50, the most a scene allows), any solver, models and step; for
    "no silent non-finite"."""
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
