"""Where refsim finds its bundled data: models, scenes and report templates.

refsim is used from a source checkout (``pip install -e .``): the bundled
``models/``, ``scenes/`` and ``reports/templates/`` directories sit beside the
``refsim`` package. The environment variable ``REFSIM_MODELS`` may name another
directory of models.
"""

from __future__ import annotations

import os
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parent.parent
SCENES_DIR = REPO_ROOT / "scenes"
TEMPLATES_DIR = REPO_ROOT / "reports" / "templates"


def models_dir() -> Path:
    """The directory of bundled models (``$REFSIM_MODELS`` overrides it)."""
    override = os.environ.get("REFSIM_MODELS")
    return Path(override) if override else REPO_ROOT / "models"


def bundled_models() -> list[Path]:
    """Every bundled ``.ac`` model, sorted by name."""
    return sorted(models_dir().glob("*.ac"))
