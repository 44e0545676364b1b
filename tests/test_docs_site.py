"""The documentation site (docs/site/, ``make docs``) builds with warnings
as errors, and its pages hold what they promise: every public name, the
engine contract, the kit's classes, the scene keys, the extras.

The scene-key tables are not generated: the site includes the "Scene files"
section of docs/design.md, so the second half of this file holds those
tables to :mod:`refsim.scenes.schema`, key for key and default for default.

The build here is the HTML builder alone, into a temporary directory; the
tutorials' code runs under ``make docs`` (its doctest builder, a step of
``.ci/run``).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from dataclasses import fields
from pathlib import Path

import pytest

import refsim
from refsim.conformance.results import CLASS_DEFINITIONS
from refsim.dynamics.world import IntegrationConfig, WorldConfig
from refsim.scenes import schema

ROOT = Path(__file__).resolve().parents[1]
SITE = ROOT / "docs" / "site"
PAGES = ("index", "install", "api", "scene-keys", "engines", "conformance", "design",
         "tutorials/check-your-engine", "tutorials/read-the-report",
         "tutorials/textbook-problems", "tutorials/sweeps")


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The site built as ``make docs`` builds its HTML: ``-W --keep-going``."""
    out = tmp_path_factory.mktemp("site")
    build = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         "-d", str(out / "doctrees"), str(SITE), str(out / "html")],
        cwd=ROOT, capture_output=True, text=True)
    assert build.returncode == 0, build.stderr
    return out / "html"


def page(site: Path, name: str) -> str:
    return (site / f"{name}.html").read_text(encoding="utf-8")


def test_every_page_is_built(site):
    missing = [name for name in PAGES if not (site / f"{name}.html").is_file()]
    assert missing == []


def test_the_api_page_documents_every_public_name(site):
    html = page(site, "api")
    ids = set(re.findall(r'<dt class="sig sig-object py" id="([\w.]+)"', html))
    undocumented = [name for name in refsim.__all__
                    if f"refsim.{name}" not in ids
                    and f"{refsim._EXPORTS[name]}.{name}" not in ids]
    assert undocumented == []
    assert {"refsim.simulate", "refsim.load_scene", "refsim.Mesh"} <= ids
    assert "(n, 3)" in html                     # shapes as the docstrings give them


def test_the_engine_and_kit_pages_hold_the_contract_and_the_classes(site):
    engines = page(site, "engines")
    for method in ("triangles_intersect", "intersecting_pairs", "bodies_collide", "aabb",
                   "ode_step", "simulate", "distance_tolerance", "box_slack", "contact_law"):
        assert method in engines, method
    kit = page(site, "conformance")
    for name in CLASS_DEFINITIONS:
        assert f'<span class="pre">{name}</span>' in kit, name
    assert "check_engine" in kit


def test_the_scene_keys_and_install_pages_include_their_sources(site):
    keys = page(site, "scene-keys")
    for key in ("gravity_direction", "restitution_threshold", "wall_response", "torque",
                "[[pair]]", "box_lo"):
        assert key in keys, key
    install = page(site, "install")
    text = re.sub(r"<[^>]+>", "", install)
    for line in ("pip install refsim", "pip install 'refsim[oracles,coal", "make test"):
        assert line in text.replace("&#39;", "'"), line           # the three kinds of user
    for extra in _pyproject_extras():
        assert f'<span class="pre">{extra}</span>' in install, extra


def _pyproject_extras() -> list[str]:
    import tomllib

    return list(tomllib.loads((ROOT / "pyproject.toml").read_text())[
        "project"]["optional-dependencies"])


# -- docs/design.md's scene-key tables against the schema ----------------------

def scene_files_section() -> dict[str, str]:
    """docs/design.md's "Scene files" section, split at its ### headings."""
    text = (ROOT / "docs" / "design.md").read_text()
    section = text.split("\n## Scene files\n", 1)[1].split("\n## ", 1)[0]
    parts = re.split(r"^### (.*)$", section, flags=re.M)
    return {heading.strip(): body for heading, body in zip(parts[1::2], parts[2::2],
                                                             strict=True)}


def table_rows(body: str) -> list[list[str]]:
    """The cells of a Markdown table's body rows (``\\|`` is a literal bar)."""
    lines = [line for line in body.splitlines() if line.startswith("|")][2:]
    return [[cell.strip() for cell in re.split(r"(?<!\\)\|", line)[1:-1]] for line in lines]


def code_spans(cell: str) -> list[str]:
    return re.findall(r"`([^`]+)`", cell)


#: Default cells that are words, not TOML values, and what they stand for.
WORDED_DEFAULTS = {"unset": None, "all six": WorldConfig.walls, "identity":
                   ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))}


def default_of(cell: str):
    """A default cell as a value: a worded default, or JSON (a TOML scalar or
    array) with a unit word after it dropped (``0.001 s``)."""
    cell = cell.strip("`")
    if cell in WORDED_DEFAULTS:
        return WORDED_DEFAULTS[cell]
    return json.loads(re.sub(r" [a-z]+$", "", cell))


def same(documented, actual) -> bool:
    if isinstance(actual, tuple):
        return (isinstance(documented, list | tuple) and len(documented) == len(actual)
                and all(same(d, a) for d, a in zip(documented, actual, strict=True)))
    return documented == actual


def test_the_world_table_is_the_schemas_world_key_for_key_and_default_for_default():
    rows = table_rows(scene_files_section()["`[world]`"])
    documented = {code_spans(row[0])[0]: row[2] for row in rows}
    keys = [f.name for f in schema.TABLES["world"][1]]
    assert sorted(documented) == sorted(keys)
    wrong = {key: cell for key, cell in documented.items()
             if not same(default_of(cell), getattr(WorldConfig, key))}
    assert wrong == {}


def test_the_settings_table_is_the_schemas_integration_collision_and_dynamics():
    rows = table_rows(scene_files_section()["`[integration]`, `[collision]`, `[dynamics]`"])
    documented = {code_spans(row[0])[0]: row[1] for row in rows}
    configs = {"integration": IntegrationConfig, "collision": schema.CollisionConfig,
               "dynamics": schema.DynamicsConfig}
    keys = [f"{table}.{f.name}" for table in configs for f in schema.TABLES[table][1]]
    assert sorted(documented) == sorted(keys)
    wrong = {key: cell for key, cell in documented.items()
             if not same(default_of(cell), getattr(configs[key.split(".")[0]],
                                                   key.split(".")[1]))}
    assert wrong == {}


def test_the_body_table_names_every_body_key_with_its_default():
    """A row per key, but ``size``, ``radius`` and ``frequency``, which the
    ``shape`` row explains; ``name``'s default is a pattern, ``model`` has
    none, and ``restitution``, ``mu`` default to the world's."""
    rows = table_rows(scene_files_section()["`[[body]]`"])
    by_key = {key: row for row in rows for key in code_spans(row[0])}
    shape_row = " ".join(by_key["shape"])
    explained_by_shape = {"size", "radius", "frequency"}
    assert sorted(by_key) == sorted(f.name for f in schema.BODY_FIELDS
                                    if f.name not in explained_by_shape)
    assert all(f"`{key}`" in shape_row for key in explained_by_shape)
    defaults = {f.name: f.default for f in fields(schema.BodyConfig)}
    literal = set(by_key) - {"name", "model", "shape", "restitution", "mu"}
    wrong = {key: by_key[key][2] for key in literal
             if not same(default_of(by_key[key][2]), defaults[key])}
    assert wrong == {}


def test_the_pair_and_particles_paragraphs_name_every_key():
    section = scene_files_section()
    pair = set(code_spans(section["`[[pair]]`"]))
    assert {f.name for f in schema.PAIR_FIELDS} - pair - {"bodies"} == set()
    assert "bodies = [\"a\", \"b\"]" in pair
    particles = set(code_spans(section["`[particles]`"]))
    assert set(schema.PARTICLE_KEYS) <= particles
