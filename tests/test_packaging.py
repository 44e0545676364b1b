"""The package as installed: every subpackage in the wheel, the bundled data
found by the import system, the oracle adapters under refsim's namespace."""

from __future__ import annotations

import tomllib
from importlib.resources import files
from pathlib import Path

import refsim.oracles

from refsim.bundled import bundled_models, bundled_scenes, models_dir, templates_dir

ROOT = Path(__file__).resolve().parents[1]


def _pyproject() -> dict:
    return tomllib.loads((ROOT / "pyproject.toml").read_text())


def test_every_refsim_subpackage_is_listed_for_the_wheel():
    listed = set(_pyproject()["tool"]["setuptools"]["packages"])
    on_disk = {".".join(p.parent.relative_to(ROOT).parts)
               for p in (ROOT / "refsim").rglob("__init__.py")}
    assert on_disk <= listed, sorted(on_disk - listed)


def test_mapped_folders_are_the_source_folders():
    mapping = _pyproject()["tool"]["setuptools"]["package-dir"]
    assert mapping == {"refsim.oracles": "oracles", "refsim.bundled.models": "models",
                       "refsim.bundled.scenes": "scenes",
                       "refsim.bundled.templates": "reports/templates"}
    assert Path(refsim.oracles.__file__).resolve() == ROOT / "oracles" / "__init__.py"


def test_bundled_data_is_found_through_the_import_system(monkeypatch):
    monkeypatch.delenv("REFSIM_MODELS", raising=False)
    assert models_dir().resolve() == ROOT / "models"
    names = {p.name for p in bundled_models()}
    assert {"cube.ac", "sphere-2k.ac", "torus.ac"} <= names
    assert {p.name for p in bundled_scenes()} == {p.name for p in (ROOT / "scenes").glob("*.toml")}
    assert (templates_dir() / "index.html.j2").is_file()


def test_package_data_patterns_cover_every_bundled_file():
    data = _pyproject()["tool"]["setuptools"]["package-data"]
    suffixes = {package: {pattern.removeprefix("*") for pattern in patterns}
                for package, patterns in data.items()}
    mapping = _pyproject()["tool"]["setuptools"]["package-dir"]
    for package, folder in mapping.items():
        if package == "refsim.oracles":
            continue
        files = [p for p in (ROOT / folder).iterdir() if p.is_file()
                 and p.suffix != ".py"]
        missed = [p.name for p in files if "".join(p.suffixes[-1:]) not in suffixes[package]]
        assert not missed, (package, missed)


def test_the_type_marker_ships_as_package_data():
    # PEP 561: type checkers use an installed package's annotations only when
    # the package holds a py.typed file (.ci/check-wheel looks in the wheel).
    assert (ROOT / "refsim" / "py.typed").is_file()
    assert "py.typed" in _pyproject()["tool"]["setuptools"]["package-data"]["refsim"]
    assert files("refsim").joinpath("py.typed").is_file()
