"""Where refsim finds its bundled data: models, scenes and report templates.

The folders ``models/``, ``scenes/`` and ``reports/templates/`` sit at the top
of the source tree and are installed as the packages ``refsim.bundled.models``,
``refsim.bundled.scenes`` and ``refsim.bundled.templates`` (pyproject.toml,
``[tool.setuptools.package-dir]``). They are found through
``importlib.resources``, so the same code works in a source checkout (an
editable install) and from an installed wheel. The environment variable
``REFSIM_MODELS`` may name another directory of models.
"""

from __future__ import annotations

import os
from importlib.resources import files
from pathlib import Path


def _folder(package: str) -> Path:
    # A package on the file system (a wheel unpacked into site-packages, or
    # the source tree behind an editable install) is a real directory.
    return Path(str(files(package)))


def models_dir() -> Path:
    """The directory of bundled models (``$REFSIM_MODELS`` overrides it)."""
    override = os.environ.get("REFSIM_MODELS")
    return Path(override) if override else _folder("refsim.bundled.models")


def scenes_dir() -> Path:
    """The directory of bundled scene files."""
    return _folder("refsim.bundled.scenes")


def templates_dir() -> Path:
    """The directory of the report's templates."""
    return _folder("refsim.bundled.templates")


def bundled_models() -> list[Path]:
    """Every bundled ``.ac`` model, sorted by name."""
    return sorted(models_dir().glob("*.ac"))


def bundled_scenes() -> list[Path]:
    """Every bundled ``.toml`` scene, sorted by name."""
    return sorted(scenes_dir().glob("*.toml"))


def model_path(name: str) -> Path:
    """The bundled model ``name`` (e.g. ``"tetrahedron.ac"``, as the
    conformance kit's cases and scenes name them) as a file path.

    Raises :class:`refsim.errors.ModelError` naming the bundled models when
    there is none of that name."""
    from refsim.errors import ModelError

    path = models_dir() / name
    if Path(name).name != name or not path.is_file():
        available = ", ".join(sorted(p.name for p in models_dir().glob("*.ac")))
        raise ModelError(f"not a bundled model (bundled: {available})", path=name)
    return path
