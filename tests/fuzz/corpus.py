"""The files the mutators start from.

- every bundled AC3D model but ``sphere-20k.ac`` (1.6 MB: reading one mutant
  takes seconds, and its lines are those of the smaller spheres) and every
  bundled scene, as bytes;
- the icosahedron written by trimesh as OBJ, ASCII and binary STL, ASCII and
  binary PLY and OFF (``refsim.load_model`` reads these through trimesh);
- :func:`long_polygon_ac3d`, one AC3D polygon of k corners (the ear clipper's
  worst case is a long non-convex polygon).

Everything here is a pure function of the bundled files, so a case built
from it is reproducible from its id.
"""

from __future__ import annotations

import functools
import math

from refsim.bundled import bundled_models, bundled_scenes, models_dir

#: Bundled models left out of the corpus, and why (module docstring).
SKIPPED_MODELS = ("sphere-20k.ac",)

#: Format names of the corpus, as the mutators know them.
FORMAT_SUFFIX = {"ac": ".ac", "obj": ".obj", "stl-ascii": ".stl", "stl-binary": ".stl",
                 "ply-ascii": ".ply", "ply-binary": ".ply", "off": ".off", "toml": ".toml"}

#: The bundled model the trimesh exports are made of (small, closed, convex).
EXPORTED_MODEL = "icosahedron.ac"


@functools.cache
def models() -> dict[str, bytes]:
    """Bundled AC3D models by file name."""
    return {p.name: p.read_bytes() for p in bundled_models() if p.name not in SKIPPED_MODELS}


@functools.cache
def scenes() -> dict[str, bytes]:
    """Bundled scenes by file name."""
    return {p.name: p.read_bytes() for p in bundled_scenes()}


@functools.cache
def exports() -> dict[str, bytes]:
    """The icosahedron in each trimesh format, by format name."""
    import trimesh

    from refsim.models.loading import load_model

    mesh = load_model(models_dir() / EXPORTED_MODEL)
    solid = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
    return {
        "obj": solid.export(file_type="obj").encode(),
        "stl-ascii": solid.export(file_type="stl_ascii").encode(),
        "stl-binary": bytes(solid.export(file_type="stl")),
        "ply-ascii": bytes(solid.export(file_type="ply", encoding="ascii")),
        "ply-binary": bytes(solid.export(file_type="ply", encoding="binary")),
        "off": solid.export(file_type="off").encode(),
    }


@functools.cache
def model_facts(name: str) -> dict[str, str]:
    """``refsim info``'s convex and closed lines of a bundled model: a uniform
    scale of the model by a positive factor must print the same (a negative
    one, the same closed line)."""
    from refsim.models.facts import describe
    from refsim.models.loading import load_model

    facts = describe(load_model(models_dir() / name))
    return {"convex": "yes" if facts.convex else "no",
            "closed": "yes" if facts.closed else "no"}


def long_polygon_ac3d(k: int, star: bool) -> bytes:
    """An AC3D file holding one polygon of ``k`` corners in the plane z = 0:
    a circle, or with ``star`` a star whose corners alternate between radii
    1 and 0.5 (non-convex: every other corner is a reflex vertex)."""
    lines = ["AC3Db", "OBJECT poly", 'name "polygon"', f"numvert {k}"]
    for i in range(k):
        radius = 0.5 if star and i % 2 else 1.0
        angle = 2.0 * math.pi * i / k
        lines.append(f"{radius * math.cos(angle)!r} {radius * math.sin(angle)!r} 0")
    lines += ["numsurf 1", "SURF 0x0", "mat 0", f"refs {k}"]
    lines += [f"{i} 0 0" for i in range(k)]
    lines.append("kids 0")
    return ("\n".join(lines) + "\n").encode()
