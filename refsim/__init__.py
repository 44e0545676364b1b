"""refsim: a validated reference implementation of a 1997 rigid-body N-body
simulation (Kenny Hoff, COMP-205, UNC Chapel Hill), checked against python-fcl,
trimesh, scipy and pybullet.

The public names below are a contract (DESIGN.md, Public API). They are
imported lazily, on first use, so that ``import refsim`` and the command line
stay quick and an area's heavy imports are paid only by those who use it.
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

# public name -> module that defines it
_EXPORTS = {
    "RefsimError": "refsim.errors",
    "ModelError": "refsim.errors",
    "SceneError": "refsim.errors",
    "StateError": "refsim.errors",
    "DivergenceError": "refsim.errors",
    "Mesh": "refsim.models.mesh",
    "Material": "refsim.models.mesh",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'refsim' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
