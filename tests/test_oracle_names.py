"""Where refsim says what it is checked against (the package's description,
``refsim --help``, the report's introduction, the README's opening), every
external engine the conformance kit ships is named."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from refsim.bundled import templates_dir
from refsim.cli import build_parser
from refsim.conformance.shipped import SHIPPED_ENGINES

REPO_ROOT = Path(__file__).resolve().parents[1]

#: How each shipped external engine is named in prose (Drake's two contact
#: models, point and hydroelastic, are one package: "Drake" names both).
NAMES = {"fcl": r"FCL|python-fcl", "coal": r"coal", "trimesh": r"trimesh", "pybullet": r"pybullet",
         "mujoco": r"MuJoCo", "drake": r"Drake", "drake-hydroelastic": r"Drake"}


def _texts() -> dict[str, str]:
    pyproject = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text())
    readme = (REPO_ROOT / "README.md").read_text()
    template = (templates_dir() / "index.html.j2").read_text()
    return {
        "pyproject description": pyproject["project"]["description"],
        "refsim --help": build_parser().description,
        "report introduction": template.split("<h1>", 1)[1].split("</p>", 1)[0],
        "README opening": readme.split("\n## ", 1)[0],
    }


def test_every_external_shipped_engine_has_a_name():
    assert set(NAMES) == {e for e in SHIPPED_ENGINES if not e.startswith("refsim-")}


@pytest.mark.parametrize("where", list(_texts()))
@pytest.mark.parametrize("engine", list(NAMES))
def test_every_external_engine_is_named(where, engine):
    assert re.search(NAMES[engine], _texts()[where]), (where, engine)
