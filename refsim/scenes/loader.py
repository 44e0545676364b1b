"""Load and validate a scene file (seed S11).

``load_scene(path)`` parses TOML with the standard library's ``tomllib``,
checks every key against :mod:`refsim.scenes.schema`, resolves each body's
model (relative to the scene file first, then the bundled ``models/``), loads
each distinct model once, builds the particle configuration of a
``[particles]`` table, and returns a frozen :class:`Scene`.

Every mistake is a :class:`~refsim.errors.SceneError` whose message names the
file and the key path (``world.restitution``, ``body[1].position``); a broken
model file is the reader's :class:`~refsim.errors.ModelError`, which names the
model file and line.

Cost: O(size of the file) plus loading the models.
"""

from __future__ import annotations

import math
import os
import tomllib
from pathlib import Path

import numpy as np

from refsim.bundled import models_dir, scenes_dir
from refsim.dynamics.mass_properties import body_mass_properties, inertia_problem
from refsim.dynamics.world import DOWN, WALL_NAMES
from refsim.errors import ModelError, SceneError, StateError, check_count
from refsim.limits import (
    DEFAULT_MAX_STEPS,
    MAX_MAGNITUDE,
    MAX_SCENE_BYTES,
    MAX_SCENE_NESTING,
    MAX_STEPS,
)
from refsim.models.loading import load_model
from refsim.scenes.schema import (
    BODY_FIELDS,
    PAIR_FIELDS,
    PARTICLE_FIELDS_FROM,
    PARTICLE_KEYS,
    START_INSIDE_RTOL,
    TABLES,
    BodyConfig,
    Field,
    PairConfig,
    ParticleConfig,
    Scene,
)
from refsim.solvers.integrate import STEP_COUNT_RTOL, whole_steps
from refsim.storage.reading import (
    as_path,
    bundled_if_bare,
    decode_utf8,
    read_regular_file,
    refuse_missing_bundled,
    similar_bundled,
    similar_hint,
)
from refsim.types import transform_points


def load_scene(path, *, max_steps: int = DEFAULT_MAX_STEPS) -> Scene:
    """Read, validate and resolve the scene file at ``path`` (seed S11).

    Parameters
    ----------
    path : str or PathLike
        A TOML scene file (keys: docs/design.md, Scene files; every key but
        ``[[body]] model`` has a default). A bare file name that is not in
        the current directory names a bundled scene
        (``refsim.bundled.scenes_dir()``), e.g. ``"bounce.toml"``.
    max_steps : int
        The most steps (duration over step) the scene may take: by default
        ``refsim.limits.DEFAULT_MAX_STEPS``, at most ``refsim.limits.MAX_STEPS``.

    Returns
    -------
    Scene
        Frozen: the world, integration, collision and dynamics settings, the
        bodies with their models loaded (``scene.mesh(body)``) and the
        particle configuration of a ``[particles]`` table, or None.

    Raises
    ------
    SceneError
        Naming the file and the key (or line) of the first problem found.
    ModelError
        Never: a body's broken model is reported as a SceneError naming the
        scene, the body's key and the model file's own line.
    """
    return load_scene_text(path, max_steps=max_steps)[0]


def load_scene_text(path, *, max_steps: int = DEFAULT_MAX_STEPS) -> tuple[Scene, str]:
    """:func:`load_scene`, and the text of the file as it was read (what
    ``refsim run`` records, so that a replay can rebuild the scene)."""
    path = bundled_if_bare(as_path(path), scenes_dir())
    refuse_missing_bundled(path, scenes_dir(), "scene", SceneError)
    data = read_regular_file(path, SceneError, max_bytes=MAX_SCENE_BYTES)
    text = decode_utf8(data, path, SceneError)
    return scene_from_text(text, path, max_steps=max_steps), text


def scene_from_text(text: str, path: Path | None = None, *,
                    max_steps: int = DEFAULT_MAX_STEPS) -> Scene:
    """The scene of TOML ``text``, validated as :func:`load_scene` does;
    ``path`` is where the text came from, for messages and for resolving
    model paths relative to it (None: against the bundled models only)."""
    too_deep = first_line_nested_deeper(text, MAX_SCENE_NESTING)
    if too_deep is not None:
        raise SceneError(f"invalid TOML: arrays and inline tables nested more than "
                         f"{MAX_SCENE_NESTING} deep", path, line=too_deep)
    try:
        table = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"invalid TOML: {exc}", path) from None
    return scene_from_dict(table, path, max_steps=max_steps)


def steps_limit_hint(duration: float, step: float, max_steps: int) -> str:
    """What to do about a run of ``duration / step`` steps beyond
    ``max_steps`` (to append to the refusal), or "" when it is within: raise
    the limit, or, beyond ``MAX_STEPS``, change the scene."""
    ratio = duration / step if duration > 0.0 and step > 0.0 else 0.0
    if not ratio > max_steps:
        return ""
    # a whole number of steps to the loop's tolerance is that number
    needed = round(ratio) if abs(ratio - round(ratio)) <= STEP_COUNT_RTOL * ratio else \
        math.ceil(ratio)
    if needed <= MAX_STEPS:
        return (f"; to run it, raise the limit to {needed} (--max-steps of refsim "
                f"run and view, max_steps= of refsim.load_scene)")
    return (f"; no run may take more than {MAX_STEPS} steps (refsim.limits.MAX_STEPS): "
            f"lengthen the step or shorten the duration")


def first_line_nested_deeper(text: str, limit: int) -> int | None:
    """The 1-based line where TOML ``text`` first opens more than ``limit``
    arrays and inline tables inside one another, or None.

    Brackets inside strings and comments do not count; a table header
    (``[world]``, ``[[body]]``) opens and closes on its line. The scan only
    counts, so a malformed file passes it and ``tomllib`` reports the syntax
    error; its purpose is to refuse the nesting ``tomllib`` would recurse into
    until the stack overflows. Cost: O(len(text)).
    """
    depth, line, i, n = 0, 1, 0, len(text)
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
        elif c == "#":
            end = text.find("\n", i)
            i = n if end < 0 else end
            continue
        elif c in "\"'":
            i, line = _skip_string(text, i, line)
            continue
        elif c in "[{":
            depth += 1
            if depth > limit:
                return line
        elif c in "]}":
            depth = max(depth - 1, 0)
        i += 1
    return None


def _skip_string(text: str, i: int, line: int) -> tuple[int, int]:
    """The index after the TOML string that opens at ``text[i]`` and the line
    number there. A one-line string ends at its line's end if unterminated
    (``tomllib`` then reports it); a basic string's backslash escapes the
    next character, a line break included."""
    quote = text[i] * 3 if text.startswith(text[i] * 3, i) else text[i]
    i += len(quote)
    while i < len(text):
        if text.startswith(quote, i):
            return i + len(quote), line
        if text[i] == "\\" and quote[0] == '"':
            i += 1
        if i < len(text) and text[i] == "\n":
            if len(quote) == 1:
                return i, line
            line += 1
        i += 1
    return i, line


def scene_from_dict(data: dict, path: Path | None = None, *,
                    max_steps: int = DEFAULT_MAX_STEPS) -> Scene:
    """Validate an already parsed scene (``path`` is for messages and for
    resolving relative model paths; None resolves against the bundled
    models; ``max_steps`` as for :func:`load_scene`)."""
    max_steps = check_count("max_steps", max_steps, 1, MAX_STEPS)
    known = set(TABLES) | {"body", "pair", "particles"}
    for key in data:
        if key not in known:
            raise SceneError(f"unknown key (expected one of {', '.join(sorted(known))})",
                             path, key)
    configs = {}
    for table, (cls, fields) in TABLES.items():
        raw = data.get(table, {})
        if not isinstance(raw, dict):
            raise SceneError("must be a table", path, table)
        configs[table] = cls(**_read_fields(raw, fields, table, path))

    integration = configs["integration"]
    try:
        whole_steps(integration.duration, integration.step, max_steps)
    except StateError as exc:
        hint = steps_limit_hint(integration.duration, integration.step, max_steps)
        raise SceneError(f"{exc}{hint}", path, "integration.duration") from None

    raw_bodies = data.get("body", [])
    if not isinstance(raw_bodies, list):
        raise SceneError("must be an array of tables ([[body]])", path, "body")
    bodies = []
    for i, raw in enumerate(raw_bodies):
        where = f"body[{i}]"
        if not isinstance(raw, dict):
            raise SceneError("must be a table", path, where)
        values = _read_fields(raw, BODY_FIELDS, where, path)
        values["name"] = values.get("name") or f"body{i}"
        _check_shape_keys(values, path, where)
        if "shape" in values:
            values["model"] = shape_name(values)
        else:
            values["model"] = _resolve_model(values["model"], path, f"{where}.model")
        _check_fixed(values, path, where)
        bodies.append(BodyConfig(**values))
    names = [b.name for b in bodies]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise SceneError(f"duplicate body name {name!r}", path, f"body[{i}].name")
    pairs = _pairs(data.get("pair", []), names, path)
    _check_coefficients(bodies, pairs, path)
    particles = None
    if "particles" in data:
        particles = _particle_config(data["particles"], configs, path)
        world = configs["world"]
        for key, default in (("gravity_direction", DOWN), ("walls", WALL_NAMES)):
            if getattr(world, key) != default:
                raise SceneError("is read by the rigid bodies only: a scene with [particles] "
                                 "keeps the default", path, f"world.{key}")
    if not bodies and particles is None:
        raise SceneError("a scene needs at least one [[body]] or a [particles] table",
                         path, "body")

    _check_speeds(bodies, particles, configs["world"].half_size, integration.step, path)
    meshes = _load_meshes(bodies, path)
    for i, body in enumerate(bodies):
        _check_body(body, meshes[body.model], configs["world"], path, f"body[{i}]")
    return Scene(path=path, bodies=tuple(bodies), meshes=meshes, particles=particles,
                 pairs=pairs, **configs)


def shape_name(values: dict) -> Path:
    """The name a ``[[body]] shape`` is known by, its key in ``Scene.meshes``
    (a relative path that no resolved model file, always absolute, can be)."""
    if values["shape"] == "box":
        size = values.get("size", BodyConfig.size)
        return Path("<box " + " x ".join(f"{x:g}" for x in size) + ">")
    radius = values.get("radius", BodyConfig.radius)
    frequency = values.get("frequency", BodyConfig.frequency)
    return Path(f"<sphere r {radius:g} f {frequency}>")


#: The keys only one shape reads.
SHAPE_KEYS = {"size": "box", "radius": "sphere", "frequency": "sphere"}


def _check_shape_keys(values: dict, path, where: str) -> None:
    """A body has a model file or a shape, not both, and only its shape's keys."""
    shape = values.get("shape")
    if shape is None and "model" not in values:
        raise SceneError("required key is missing (or give a shape: shape = \"box\" "
                         "with size, or \"sphere\" with radius)", path, f"{where}.model")
    if shape is not None and "model" in values:
        raise SceneError(f"a body has a model file or a shape, not both (shape = {shape!r})",
                         path, f"{where}.model")
    for key, owner in SHAPE_KEYS.items():
        if key in values and shape != owner:
            raise SceneError(f"is read only with shape = {owner!r}", path, f"{where}.{key}")


def _check_fixed(values: dict, path, where: str) -> None:
    """A fixed body starts and stays at rest, with nothing to push it."""
    if not values.get("fixed"):
        return
    for key in ("velocity", "angular_velocity", "force", "torque"):
        if any(values.get(key, (0.0, 0.0, 0.0))):
            raise SceneError("a fixed body never moves: leave it out or make it 0", path,
                             f"{where}.{key}")


def _pairs(raw_pairs, names: list[str], path) -> tuple[PairConfig, ...]:
    """The ``[[pair]]`` entries: two distinct bodies of the scene each, every
    pair once."""
    if not isinstance(raw_pairs, list):
        raise SceneError("must be an array of tables ([[pair]])", path, "pair")
    pairs: list[PairConfig] = []
    for i, raw in enumerate(raw_pairs):
        where = f"pair[{i}]"
        if not isinstance(raw, dict):
            raise SceneError("must be a table", path, where)
        values = _read_fields(raw, PAIR_FIELDS, where, path)
        a, b = values["bodies"]
        for name in (a, b):
            if name not in names:
                raise SceneError(f"no body is named {name!r} (bodies: "
                                 f"{', '.join(names) or 'none'})", path, f"{where}.bodies")
        if a == b:
            raise SceneError(f"names {a!r} twice: a pair is two bodies", path,
                             f"{where}.bodies")
        if any({a, b} == set(p.bodies) for p in pairs):
            raise SceneError(f"the pair {a!r}, {b!r} is given twice", path, f"{where}.bodies")
        pairs.append(PairConfig(**values))
    return tuple(pairs)


def _check_coefficients(bodies, pairs, path) -> None:
    """Two bodies that give different values of a coefficient need a
    ``[[pair]]`` that gives their contacts' value (Scene.coefficients)."""
    for key in ("restitution", "mu"):
        given = [(i, b) for i, b in enumerate(bodies) if getattr(b, key) is not None]
        for n, (_, a) in enumerate(given):
            for j, b in given[n + 1:]:
                if getattr(a, key) == getattr(b, key):
                    continue
                pair = next((p for p in pairs if set(p.bodies) == {a.name, b.name}), None)
                if pair is None or getattr(pair, key) is None:
                    raise SceneError(
                        f"bodies {a.name!r} and {b.name!r} give different {key} "
                        f"({getattr(a, key):g}, {getattr(b, key):g}): add a [[pair]] with "
                        f"bodies = [{a.name!r}, {b.name!r}] and the {key} of their contacts",
                        path, f"body[{j}].{key}")


def _particle_config(raw, configs: dict, path) -> ParticleConfig:
    """The ParticleConfig of a ``[particles]`` table, with the world's forces
    and cube and the integration's solver and step (schema.PARTICLE_FIELDS_FROM).

    Values are validated by ParticleConfig itself; its errors name
    ``particles.<field>`` (or the ``world.``/``integration.`` key the field
    came from) and get the file added here.
    """
    if not isinstance(raw, dict):
        raise SceneError("must be a table", path, "particles")
    for key in raw:
        if key in PARTICLE_FIELDS_FROM:
            raise SceneError(f"set in [{PARTICLE_FIELDS_FROM[key].split('.')[0]}] "
                             f"({PARTICLE_FIELDS_FROM[key]}), not in [particles]",
                             path, f"particles.{key}")
        if key not in PARTICLE_KEYS:
            raise SceneError(f"unknown key (expected one of {', '.join(PARTICLE_KEYS)})",
                             path, f"particles.{key}")
    values = dict(raw)
    for key in ("box_lo", "box_hi"):
        if key in values:   # element-wise messages: particles.box_lo[1]
            values[key] = _convert(values[key], "vec3", path, f"particles.{key}")
    for name, scene_key in PARTICLE_FIELDS_FROM.items():
        table, table_key = scene_key.split(".")
        values[name] = getattr(configs[table], table_key)
    try:
        return ParticleConfig(**values)
    except SceneError as exc:
        field = (exc.key or "").removeprefix("particles.")
        raise SceneError(exc.message, path,
                         PARTICLE_FIELDS_FROM.get(field, exc.key)) from None


def _read_fields(raw: dict, fields: tuple[Field, ...], where: str, path) -> dict:
    by_name = {f.name: f for f in fields}
    for key in raw:
        if key not in by_name:
            raise SceneError(f"unknown key (expected one of {', '.join(by_name)})",
                             path, f"{where}.{key}")
    values = {}
    for f in fields:
        key = f"{where}.{f.name}"
        if f.name not in raw:                 # the config dataclass's default
            if f.required:
                raise SceneError("required key is missing", path, key)
            continue
        value = _convert(raw[f.name], f.kind, path, key)
        if f.check is not None:
            problem = f.check(value)
            if problem:
                raise SceneError(f"{problem}, got {raw[f.name]!r}", path, key)
        values[f.name] = value
    return values


def _number(value, path, key) -> float:
    # bool is an int in Python; "true" is never a number in a scene.
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise SceneError(f"must be a number, got {type(value).__name__} {value!r}", path, key)
    try:
        value = float(value)
    except OverflowError:                 # an integer beyond float64
        raise SceneError(f"must be at most {MAX_MAGNITUDE:g} in magnitude, got {value!r}",
                         path, key) from None
    if not math.isfinite(value):
        raise SceneError(f"must be finite, got {value!r}", path, key)
    if abs(value) > MAX_MAGNITUDE:
        raise SceneError(f"must be at most {MAX_MAGNITUDE:g} in magnitude, got {value!r}",
                         path, key)
    return value


def _convert(value, kind: str, path, key):
    if kind == "float":
        return _number(value, path, key)
    if kind == "int":
        if isinstance(value, bool) or not isinstance(value, int):
            raise SceneError(f"must be a whole number, got {type(value).__name__} {value!r}",
                             path, key)
        if abs(value) > 1_000_000:
            raise SceneError(f"must be at most 1000000 in magnitude, got {value!r}", path, key)
        return value
    if kind == "bool":
        if not isinstance(value, bool):
            raise SceneError(f"must be true or false, got {type(value).__name__} {value!r}",
                             path, key)
        return value
    if kind in ("walls", "names2"):
        count = "2 " if kind == "names2" else ""
        if (not isinstance(value, list | tuple) or not all(isinstance(x, str) for x in value)
                or (kind == "names2" and len(value) != 2)):
            raise SceneError(f"must be a list of {count}strings, got {value!r}", path, key)
        return tuple(value)
    if kind == "str":
        if not isinstance(value, str):
            raise SceneError(f"must be a string, got {type(value).__name__} {value!r}",
                             path, key)
        return value
    if kind == "vec3":
        # a tuple too: a scene written back from its dataclasses (asdict)
        if not isinstance(value, list | tuple) or len(value) != 3:
            raise SceneError(f"must be a list of 3 numbers, got {value!r}", path, key)
        return tuple(_number(x, path, f"{key}[{i}]") for i, x in enumerate(value))
    if kind == "mat3":
        if not isinstance(value, list | tuple) or len(value) != 3:
            raise SceneError("must be a 3x3 matrix (a list of 3 rows)", path, key)
        return tuple(_convert(row, "vec3", path, f"{key}[{i}]") for i, row in enumerate(value))
    raise AssertionError(f"unknown field kind {kind!r}")


def _resolve_model(name: str, scene_path: Path | None, key: str) -> Path:
    """The model file: relative to the scene's directory, then the bundled
    models. The first name that exists is taken whatever it is (a directory
    or a FIFO is then refused by the model reader as not a regular file,
    rather than reported missing); a name the system cannot look up (too
    long, behind an unsearchable directory) is refused here."""
    shown = f"model {name[:60]!r}{'...' if len(name) > 60 else ''}"
    if "\0" in name:
        raise SceneError(f"{shown} cannot be looked up: it contains a NUL byte",
                         scene_path, key)
    candidates = []
    if scene_path is not None:
        candidates.append(Path(scene_path).parent / name)
    candidates.append(models_dir() / name)
    for candidate in candidates:
        # lexists: a dangling or looping symlink is there too (and refused
        # by the reader), not a reason to take the bundled model instead
        try:
            os.lstat(candidate)
        except (FileNotFoundError, NotADirectoryError):
            continue
        except OSError as exc:
            raise SceneError(f"{shown} cannot be looked up: {exc.strerror}", scene_path,
                             key) from None
        return candidate.absolute()           # a symlink keeps the name (and suffix) given
    looked = ", ".join(str(c) for c in candidates)
    bare = Path(name).name
    hint = ""
    if bare != name and (models_dir() / bare).is_file():
        hint = f"; a bundled model of that name exists: use {bare!r}"
    elif similar := similar_bundled(bare, models_dir(), ".ac"):
        hint = f"; {similar_hint(similar, 'model')}"
    raise SceneError(f"model {name!r} not found (looked in {looked}){hint}", scene_path, key)


def _load_meshes(bodies, scene_path) -> dict:
    """Each distinct model once; a model's error names the scene and the
    first body that uses it, then the model file and its line. A shape's
    mesh is built from its keys (refsim.models.shapes)."""
    from refsim.models import shapes

    meshes = {}
    for i, body in enumerate(bodies):
        if body.shape and body.model not in meshes:
            meshes[body.model] = (shapes.box(body.size) if body.shape == "box" else
                                  shapes.geodesic_sphere(body.frequency, body.radius))
        if body.model not in meshes:
            try:
                meshes[body.model] = load_model(body.model)
            except ModelError as exc:           # the model's own error stays the cause
                raise SceneError(str(exc), scene_path, f"body[{i}].model") from exc
    return meshes


def _check_speeds(bodies, particles, half_size: float, step: float, path) -> None:
    """No body or particle starts fast enough to cross half the world cube in
    one step: the wall stage would then put it back at a wall it never
    reached (a step would skip the walls between), which is no simulation of
    the scene. Refused at the key, with the distance a step covers."""
    for i, body in enumerate(bodies):
        speed = math.hypot(*body.velocity)
        if speed * step > half_size:
            raise SceneError(f"speed {speed:.6g} m/s covers {speed * step:.6g} m in one step "
                             f"of {step:g} s, more than half the world cube ({half_size:g} "
                             "m); lower the speed or the step", path, f"body[{i}].velocity")
    if particles is None or not particles.walls:
        return
    speed, step, half_size = particles.speed_max, particles.step, particles.half_size
    if speed * step > half_size:
        raise SceneError(f"speed {speed:.6g} m/s covers {speed * step:.6g} m in one step of "
                         f"{step:g} s, more than half the world cube ({half_size:g} m); lower "
                         "the speed or the step", path, "particles.speed_max")


def _check_body(body: BodyConfig, mesh, world, path, where: str) -> None:
    """A body the loop can simulate: a model wound outward, a starting box
    inside the world cube, and a positive-definite inertia."""
    name = body.model.name
    if mesh.is_closed and mesh.volume is not None and mesh.volume < 0.0:
        raise SceneError(f"model {name} is wound inside out (enclosed volume "
                         f"{mesh.volume:.6g}); reverse its faces' corner order",
                         path, f"{where}.model")
    try:
        scaled = mesh.scaled(body.scale)
    except ModelError:
        raise SceneError(f"model {name} at scale {body.scale:g} has coordinates beyond "
                         "float64's range", path, f"{where}.scale") from None
    H = world.half_size
    rotation = np.array(body.orientation, dtype=np.float64)
    with np.errstate(over="ignore"):          # a box beyond float64 is refused below
        world_vertices = transform_points(scaled.vertices,
                                          (rotation, np.array(body.position)))
        lo, hi = world_vertices.min(axis=0), world_vertices.max(axis=0)
        span = hi - lo                        # inf for a box wider than float64's range
    slack = START_INSIDE_RTOL * H
    low = [f"{'xyz'[k]}-" in world.walls for k in range(3)]
    high = [f"{'xyz'[k]}+" in world.walls for k in range(3)]
    if any(span[k] > 2.0 * H + slack and low[k] and high[k] for k in range(3)):
        raise SceneError(f"model {name} at scale {body.scale:g} is larger than the world "
                         f"cube: its box spans {_spans(span)}, the cube {2.0 * H:g}",
                         path, f"{where}.scale" if body.scale != 1.0 else f"{where}.model")
    for k in range(3):
        if (low[k] and lo[k] < -H - slack) or (high[k] and hi[k] > H + slack):
            raise SceneError(
                f"the body starts outside the world cube: its box spans {'xyz'[k]} = "
                f"{lo[k]:.6g} to {hi[k]:.6g}, the cube -{H:g} to {H:g}", path,
                f"{where}.position")

    problem = inertia_problem(body_mass_properties(scaled, body.mass))
    if problem:
        raise SceneError(f"model {name} at scale {body.scale:g}: {problem}", path, where)


def _spans(extent) -> str:
    return " x ".join(f"{x:.6g}" for x in extent)
