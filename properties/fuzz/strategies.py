"""Hypothesis strategies of the API fuzzer (tests/fuzz, docs/design.md Errors):
hostile arguments to refsim's public functions, one probe at a time."""

from __future__ import annotations

from dataclasses import dataclass as _dataclass

import numpy as _np  # noqa: F401 (the probes' spellings name numpy)
from hypothesis import strategies as _st
from hypothesis.strategies import SearchStrategy as _SearchStrategy

from tests.fuzz.api_worker import Probe as _Probe

# ===========================================================================
# Fuzz: hostile arguments to the public API (tests/fuzz, docs/design.md Errors)
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

_KERNEL_BAD = ("'bogus'", "3", "''", "'numba'")

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
    factor = args["vertices"][0][len(f"{base}.vertices"):].replace(" * ", "") or "1.0"
    checks = {".is_convex": (f"_result == {base}.is_convex",
                             "convexity changed by a uniform scale"),
              ".is_closed": (f"_result == {base}.is_closed",
                             "closedness changed by a uniform scale"),
              # k^3 V by float products: inf where the true volume is beyond
              # float64 (k = 1e150 on a unit model), as IEEE rounds it
              ".volume": (f"_result == {base}.volume if {base}.volume is None else "
                          f"math.isclose(_result, {base}.volume * {factor} * {factor} * "
                          f"{factor}, rel_tol=1e-12)",
                          "volume is not k^3 times the unscaled one (inf beyond float64)"),
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
             "kernel": _keyword("kernel", ("None", "'readable'", "'compiled'"), (), _KERNEL_BAD)}
    return _probe("aabb_linear", "aabb_linear({mesh}, {pose}{kernel})", _draw_args(draw, specs),
                  "bool(np.all(_result[0] <= _result[1]))", "lo <= hi fails")


@_st.composite
def _incremental_probe(draw):
    specs = {"mesh": _arg(_CONVEX, ("TORUS",) + _HOSTILE_MESHES, _NOT_MESHES), "pose": _POSE,
             "kernel": _keyword("kernel", ("None", "'readable'", "'compiled'"), (),
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
            "kernel": _keyword("kernel", ("None", "'readable'", "'compiled'"), (), _KERNEL_BAD)}


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
             "wall_speed": _keyword("wall_speed", ("'wall'", "'seed'", "None"), (),
                                   ("'bogus'", "''", "0")),
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
             "kernel": _keyword("kernel", ("'readable'",), ("'compiled'",), ("'bogus'", "3")),
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
