"""Load and validate a scene file (seed S11).

``load_scene(path)`` parses TOML with the standard library's ``tomllib``,
checks every key against :mod:`refsim.scenes.schema`, resolves each body's
model (relative to the scene file first, then the bundled ``models/``), loads
each distinct model once, and returns a frozen :class:`Scene`.

Every mistake is a :class:`~refsim.errors.SceneError` whose message names the
file and the key path (``world.restitution``, ``body[1].position``); a broken
model file is the reader's :class:`~refsim.errors.ModelError`, which names the
model file and line.

Cost: O(size of the file) plus loading the models.
"""

from __future__ import annotations

import math
import tomllib
from pathlib import Path

from refsim.errors import SceneError
from refsim.paths import models_dir
from refsim.scenes.schema import (
    BODY_FIELDS,
    MAX_STEPS,
    TABLES,
    BodyConfig,
    Field,
    Scene,
)


def load_scene(path) -> Scene:
    """Read, validate and resolve the scene file at ``path``."""
    path = Path(path)
    try:
        text = path.read_bytes().decode("utf-8")
    except FileNotFoundError:
        raise SceneError("no such file", path) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"cannot read: {exc}", path) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise SceneError(f"invalid TOML: {exc}", path) from None
    return scene_from_dict(data, path)


def scene_from_dict(data: dict, path: Path | None = None) -> Scene:
    """Validate an already parsed scene (``path`` is for messages and for
    resolving relative model paths; None resolves against the bundled models)."""
    known = set(TABLES) | {"body"}
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
    if integration.duration / integration.step > MAX_STEPS:
        raise SceneError(f"duration / step exceeds {MAX_STEPS:.0e} steps",
                         path, "integration.step")

    raw_bodies = data.get("body", [])
    if not isinstance(raw_bodies, list):
        raise SceneError("must be an array of tables ([[body]])", path, "body")
    bodies = []
    for i, raw in enumerate(raw_bodies):
        where = f"body[{i}]"
        if not isinstance(raw, dict):
            raise SceneError("must be a table", path, where)
        values = _read_fields(raw, BODY_FIELDS, where, path)
        values["name"] = values["name"] or f"body{i}"
        values["model"] = _resolve_model(values["model"], path, f"{where}.model")
        bodies.append(BodyConfig(**values))
    names = [b.name for b in bodies]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise SceneError(f"duplicate body name {name!r}", path, f"body[{i}].name")
    if not bodies:
        raise SceneError("a scene needs at least one [[body]]", path, "body")

    meshes = _load_meshes(bodies)
    return Scene(path=path, bodies=tuple(bodies), meshes=meshes, **configs)


def _read_fields(raw: dict, fields: tuple[Field, ...], where: str, path) -> dict:
    by_name = {f.name: f for f in fields}
    for key in raw:
        if key not in by_name:
            raise SceneError(f"unknown key (expected one of {', '.join(by_name)})",
                             path, f"{where}.{key}")
    values = {}
    for f in fields:
        key = f"{where}.{f.name}"
        if f.name not in raw:
            if f.required:
                raise SceneError("required key is missing", path, key)
            values[f.name] = f.default
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
    value = float(value)
    if not math.isfinite(value):
        raise SceneError(f"must be finite, got {value!r}", path, key)
    return value


def _convert(value, kind: str, path, key):
    if kind == "float":
        return _number(value, path, key)
    if kind == "str":
        if not isinstance(value, str):
            raise SceneError(f"must be a string, got {type(value).__name__} {value!r}",
                             path, key)
        return value
    if kind == "vec3":
        if not isinstance(value, list) or len(value) != 3:
            raise SceneError(f"must be a list of 3 numbers, got {value!r}", path, key)
        return tuple(_number(x, path, f"{key}[{i}]") for i, x in enumerate(value))
    if kind == "mat3":
        if not isinstance(value, list) or len(value) != 3:
            raise SceneError("must be a 3x3 matrix (a list of 3 rows)", path, key)
        return tuple(_convert(row, "vec3", path, f"{key}[{i}]") for i, row in enumerate(value))
    raise AssertionError(f"unknown field kind {kind!r}")


def _resolve_model(name: str, scene_path: Path | None, key: str) -> Path:
    """The model file: relative to the scene's directory, then the bundled models."""
    candidates = []
    if scene_path is not None:
        candidates.append(Path(scene_path).parent / name)
    candidates.append(models_dir() / name)
    for candidate in candidates:
        if candidate.is_file():
            return candidate.resolve()
    looked = ", ".join(str(c) for c in candidates)
    raise SceneError(f"model {name!r} not found (looked in {looked})", scene_path, key)


def _load_meshes(bodies) -> dict:
    from refsim.models.loading import load_model

    meshes = {}
    for body in bodies:
        if body.model not in meshes:
            meshes[body.model] = load_model(body.model)
    return meshes
