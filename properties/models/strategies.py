"""Hypothesis strategies of the models properties (refsim.models, seed S1)."""

from __future__ import annotations

import math as _math

import numpy as _np
from hypothesis import strategies as _st

from refsim.models.mesh import Material as _Material
from refsim.models.mesh import Mesh as _Mesh

# ===========================================================================
# Models: random meshes for the AC3D reader and writer (refsim.models, seed S1)
# ===========================================================================
# Coordinates mix awkward doubles (signed zeros, the extremes of the exponent
# range, subnormals, values with no short decimal form) with arbitrary finite
# floats. Names avoid only what AC3D cannot quote: '"', line breaks and lone
# surrogates (not encodable). face_object is sorted, as in any mesh read from
# a file (AC3D groups a file's faces by object).


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
# Models: polygons to ear-clip (refsim.models.triangulate, ear_index; seed S1)
# ===========================================================================
# Float stars (angles on a 1/96-turn grid, radii on a 1/16 grid) are the
# polygons the triangulation's laws were first checked on. Lattice polygons
# have small integer (or quarter-integer) corners, so every orientation is
# computed exactly and ear_index's lemma applies as proved; collinear runs,
# repeated points, spikes that overlap and bridges to holes occur on purpose.


#: Float stars: angles on a 1/96-turn grid and radii on a 1/16 grid, so exact
#: collinear and repeated-direction cases occur, yet every polygon is simple.
POLYGON_ANGLE_STEPS, POLYGON_RADIUS_STEPS = 96, 16


@_st.composite
def star_polygons(draw):
    """A simple polygon (k, 3), 3 <= k <= 24 (plus gap fillers), star-shaped
    about the origin: corners sorted by angle about a point that sees the
    whole boundary, in the plane z = 0, counter-clockwise."""
    steps = draw(_st.lists(_st.integers(0, POLYGON_ANGLE_STEPS - 1), min_size=3, max_size=24,
                           unique=True))
    steps.sort()
    # the centre must see every edge: no angular gap of half a turn or more
    while True:
        gaps = _np.diff(steps + [steps[0] + POLYGON_ANGLE_STEPS])
        if gaps.max() < POLYGON_ANGLE_STEPS // 2:
            break
        steps = sorted(steps + [(steps[int(_np.argmax(gaps))] + POLYGON_ANGLE_STEPS // 4)
                                % POLYGON_ANGLE_STEPS])
    t = 2.0 * _np.pi * _np.array(steps) / POLYGON_ANGLE_STEPS
    r = _np.array([draw(_st.integers(1, POLYGON_RADIUS_STEPS)) for _ in steps])
    r = r / POLYGON_RADIUS_STEPS
    return _np.c_[r * _np.cos(t), r * _np.sin(t), _np.zeros(len(t))]


#: Lattice stars have corners in [-LATTICE_RADIUS, LATTICE_RADIUS]^2: distinct
#: directions differ by more than 1 / (2 R^2) rad, far above atan2's rounding.
LATTICE_RADIUS = 24


def _plane(xy):
    return _np.array([(x, y, 0.0) for x, y in xy], dtype=_np.float64)


@_st.composite
def lattice_star_polygons(draw, max_corners=40, radius=LATTICE_RADIUS):
    """A simple polygon (k, 3), 4 <= k <= ``max_corners``, with integer
    corners, star-shaped about the origin: one corner on each half axis (so
    no angular gap reaches half a turn) and random lattice points, one per
    direction (the first drawn wins), sorted by angle. Collinear neighbours
    occur (lattice points on a line); the corner on the positive x axis is
    ``(x, 0)`` with ``x > 0``."""
    length = _st.integers(1, radius)
    axes = [(draw(length), 0), (0, draw(length)), (-draw(length), 0), (0, -draw(length))]
    coordinate = _st.integers(-radius, radius)
    more = draw(_st.lists(_st.tuples(coordinate, coordinate), max_size=max_corners - 4))
    kept = []
    for p in axes + [q for q in more if q != (0, 0)]:
        if not any(p[0] * q[1] - p[1] * q[0] == 0 and p[0] * q[0] + p[1] * q[1] > 0
                   for q in kept):
            kept.append(p)
    kept.sort(key=lambda p: _math.atan2(p[1], p[0]))
    return _plane(kept)


@_st.composite
def decorated_polygons(draw, max_operations=12):
    """A lattice star, scaled by 4, with collinear runs, repeated points and
    spikes: each operation at a random corner ``p`` (edge ``p -> q``) adds one
    to three corners at quarter points of the edge, or repeats ``p`` (a
    zero-length edge), or adds a spike towards the origin, to ``p / 2`` or
    ``p / 4`` and back to ``p``. Spikes may start on other spikes or on
    collinear corners, so spikes overlap and corners lie on other edges: the
    polygon touches itself but never crosses. Corners are multiples of 1/16,
    so orientations stay exact."""
    xy = [(4.0 * x, 4.0 * y) for x, y, _ in draw(lattice_star_polygons(max_corners=24))]
    for _ in range(draw(_st.integers(1, max_operations))):
        j = draw(_st.integers(0, len(xy) - 1))
        (px, py), (qx, qy) = xy[j], xy[(j + 1) % len(xy)]
        kind = draw(_st.sampled_from(["run", "repeat", "spike"]))
        if kind == "run":
            count = draw(_st.integers(1, 3))
            xy[j + 1:j + 1] = [(px + (qx - px) * t / 4.0, py + (qy - py) * t / 4.0)
                               for t in range(1, count + 1)]
        elif kind == "repeat":
            xy.insert(j, (px, py))
        else:
            f = draw(_st.sampled_from([0.5, 0.25]))
            xy[j + 1:j + 1] = [(f * px, f * py), (px, py)]
    return _plane(xy)


@_st.composite
def bridged_polygons(draw):
    """A lattice star with a lattice-star hole, joined as modellers export a
    face with a hole: the outline to its corner ``(X, 0)``, across the
    positive x axis to the hole's ``(h, 0)``, round the hole clockwise, back
    to ``(h, 0)`` and across to ``(X, 0)``. The outline is scaled (by an
    integer) until its inradius about the origin exceeds the hole's radius,
    so the bridge and the hole cross nothing. Returns ``(points, area)``
    with the exact area (outline minus hole)."""
    outer = draw(lattice_star_polygons(max_corners=24))[:, :2]
    hole = draw(lattice_star_polygons(max_corners=12, radius=4))[:, :2]
    nxt = _np.roll(outer, -1, axis=0)
    inradius = float(((outer[:, 0] * nxt[:, 1] - outer[:, 1] * nxt[:, 0])
                      / _np.hypot(*(nxt - outer).T)).min())
    outer = outer * (_math.ceil(6.0 / inradius) + 1)  # hole radius <= 4 sqrt 2 < 6
    o = int(_np.flatnonzero((outer[:, 1] == 0) & (outer[:, 0] > 0))[0])
    h = int(_np.flatnonzero((hole[:, 1] == 0) & (hole[:, 0] > 0))[0])
    hole_cw = _np.vstack([hole[h::-1], hole[:h:-1]])
    ring = _np.vstack([outer[:o + 1], hole_cw, hole_cw[:1], outer[o:]])

    def shoelace(q):
        r = _np.roll(q, -1, axis=0)
        return 0.5 * float((q[:, 0] * r[:, 1] - r[:, 0] * q[:, 1]).sum())

    return _np.c_[ring, _np.zeros(len(ring))], shoelace(outer) - shoelace(hole)
