"""Generated case sets kept on disk (refsim.conformance.case_cache)."""

from __future__ import annotations

import pytest

from refsim.conformance import case_cache
from refsim.conformance.registry import build_cases


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("REFSIM_CACHE_DIR", str(tmp_path / "cache"))
    return tmp_path / "cache"


def _dicts(case_set):
    return [c.to_dict() for c in case_set.pairs]


def test_a_set_built_once_is_read_back_the_same(cache, monkeypatch):
    first = build_cases(["triangles"], 30, 4)["triangles"]
    files = list(cache.iterdir())
    assert len(files) == 1 and files[0].name.startswith("triangles-n30-seed4-")

    def no_building(*args):
        raise AssertionError("built again although it was kept")

    monkeypatch.setattr("refsim.conformance.cases_triangles.triangle_cases", no_building)
    again = build_cases(["triangles"], 30, 4)["triangles"]
    assert str(_dicts(again)) == str(_dicts(first))


def test_another_seed_or_size_is_another_file(cache):
    paths = {case_cache.cache_path("boxes", n, seed) for n, seed in ((10, 0), (10, 1), (11, 0))}
    assert len(paths) == 3
    assert case_cache.cache_path("ode", 10, 0) is None             # fixed sets are not kept


def test_an_unreadable_file_is_built_again_and_replaced(cache):
    path = case_cache.cache_path("triangles", 12, 0)
    path.parent.mkdir(parents=True)
    path.write_bytes(b"not a pickle")
    built = build_cases(["triangles"], 12, 0)["triangles"]
    assert len(built) == 12
    assert path.read_bytes() != b"not a pickle"


def test_an_empty_directory_name_turns_the_cache_off(tmp_path, monkeypatch):
    monkeypatch.setenv("REFSIM_CACHE_DIR", "")
    assert case_cache.cache_directory() is None
    assert case_cache.cache_path("triangles", 12, 0) is None


def test_the_default_directory_follows_xdg(tmp_path, monkeypatch):
    monkeypatch.delenv("REFSIM_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert case_cache.cache_directory() == tmp_path / "refsim" / "cases"


def test_a_directory_that_cannot_be_written_only_costs_the_saving(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("in the way")
    monkeypatch.setenv("REFSIM_CACHE_DIR", str(blocker / "cache"))
    assert len(build_cases(["boxes"], 6, 0)["boxes"]) == 6


def test_other_models_or_other_sources_name_another_file(cache, tmp_path, monkeypatch):
    """The mesh cases' truths depend on the models and on code the builders
    import inside functions: another models directory, a model whose bytes
    changed, or another set of source files gives another file."""
    import shutil

    from refsim.bundled import models_dir

    default = case_cache.cache_path("poses", 10, 0)
    copy = tmp_path / "models"
    shutil.copytree(models_dir(), copy)
    monkeypatch.setenv("REFSIM_MODELS", str(copy))
    copied = case_cache.cache_path("poses", 10, 0)
    assert copied != default
    cube = copy / "cube.ac"
    cube.write_text(cube.read_text() + "\n")
    edited = case_cache.cache_path("poses", 10, 0)
    assert edited != copied
    extra = tmp_path / "extra.py"
    extra.write_text("x = 1\n")
    stamp = case_cache._source_stamp()
    monkeypatch.setattr(case_cache, "_source_stamp",
                        lambda: (*stamp, (str(extra), extra.stat().st_size,
                                          extra.stat().st_mtime_ns)))
    assert case_cache.cache_path("poses", 10, 0) != edited
