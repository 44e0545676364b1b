"""The one table of shipped engines (refsim.engines.registry) and what is
read from it."""

from __future__ import annotations

import tomllib
from pathlib import Path

from refsim.conformance.shipped import SHIPPED_ENGINES
from refsim.engines.registry import SHIPPED, install_hint, title
from refsim.report.sections.conformance import ENGINE_TITLES

ROOT = Path(__file__).resolve().parents[2]


def test_every_view_of_the_shipped_engines_is_the_registrys():
    assert list(SHIPPED_ENGINES) == [e.name for e in SHIPPED]
    assert all(ENGINE_TITLES[e.name] == e.title == title(e.name) for e in SHIPPED)
    assert title("my-engine") == "my-engine"


def test_each_extra_named_exists_and_the_hint_installs_those_engines():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    assert {e.extra for e in SHIPPED if e.extra} <= set(extras)
    assert install_hint(["mujoco", "drake"]) == "pip install 'refsim[oracles,drake]'"
    assert install_hint(["coal"]) == "pip install 'refsim[coal]'"
    # Drake's two contact models are one package, one extra
    assert install_hint(["drake", "drake-hydroelastic"]) == "pip install 'refsim[drake]'"
    assert install_hint(["my-engine"]) == "pip install 'refsim[oracles]'"
