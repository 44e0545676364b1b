"""The one table of shipped engines (refsim.engines.registry) and what is
read from it."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
from refsim.oracles import OracleUnavailable

from refsim.conformance.shipped import SHIPPED_ENGINES
from refsim.engines import capabilities
from refsim.engines.registry import ENGINES, SHIPPED, build, install_hint, title
from refsim.errors import OptionError
from refsim.report.sections.conformance import ENGINE_TITLES
from refsim.report.tasks import DEMO_ENGINES

ROOT = Path(__file__).resolve().parents[2]


def test_every_view_of_the_shipped_engines_is_the_registrys():
    assert list(SHIPPED_ENGINES) == [e.name for e in SHIPPED]
    assert all(ENGINE_TITLES[e.name] == e.title == title(e.name) for e in SHIPPED)
    assert title("my-engine") == "my-engine"


def test_each_extra_named_exists_and_the_hint_installs_those_engines():
    extras = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]
    assert {e.extra for e in ENGINES if e.extra} <= set(extras)
    assert install_hint(["mujoco", "drake"]) == "pip install 'refsim[oracles,drake]'"
    assert install_hint(["coal"]) == "pip install 'refsim[coal]'"
    # Drake's two contact models are one package, one extra
    assert install_hint(["drake", "drake-hydroelastic"]) == "pip install 'refsim[drake]'"
    assert install_hint(["my-engine"]) == "pip install 'refsim[oracles]'"


def test_the_kit_shows_the_kit_rows_and_every_name_is_one_row():
    assert [e.name for e in SHIPPED] == [e.name for e in ENGINES if e.kit]
    assert len({e.name for e in ENGINES}) == len(ENGINES)
    assert {"trimesh-mesh", "trimesh-collision", "scipy", "refsim",
            "refsim-seed-wall-speed"} == {e.name for e in ENGINES if not e.kit}


def test_refsim_as_posed_runs_the_scene_with_its_own_or_the_seeds_wall_speed():
    """The bounce studies' refsim: the scene's own dynamics, every step
    recorded; the seed-wall-speed row differs only by the wall law."""
    import numpy as np

    from refsim.dynamics.simulate import simulate
    from refsim.studies.bounce_scenes import drop_scene

    scene = drop_scene("cube.ac", 0.8, duration=1.2, rotation="seed")
    posed, literal = build("refsim"), build("refsim-seed-wall-speed")
    ours = posed.simulate(scene)
    assert (posed.name, literal.name) == ("refsim", "refsim-seed-wall-speed")
    assert len(ours.t) == scene.integration.n_steps + 1
    np.testing.assert_array_equal(ours.position, simulate(scene, every=1).position)
    seed = literal.simulate(scene)
    np.testing.assert_array_equal(seed.position,
                                  simulate(scene, every=1, wall_speed="seed").position)
    assert not np.array_equal(seed.position, ours.position)   # the bounce differs
    from refsim.engines.refsim_engines import PosedRefsim

    with pytest.raises(OptionError, match="wall_speed must be one of 'wall', 'seed'"):
        PosedRefsim("fast")


@pytest.mark.parametrize("entry", ENGINES, ids=lambda e: e.name)
def test_each_row_builds_the_engine_it_names(entry):
    try:
        engine = build(entry.name)
    except OracleUnavailable as exc:            # its extra is not installed
        assert entry.extra is not None, exc
        return
    try:
        # the two trimesh adapters the report asks alone call themselves trimesh
        assert engine.name == entry.name or entry.name.startswith(engine.name + "-")
        if entry.kit:
            assert capabilities(engine)
    finally:
        close = getattr(engine, "close", None)
        if close is not None:
            close()


def test_build_takes_an_adapters_settings_and_refuses_an_unknown_name():
    with build("pybullet", use_split_impulse=0) as engine:
        assert engine.settings.use_split_impulse == 0
    with pytest.raises(OptionError, match="engine must be one of 'refsim-seed', .*got 'bullet'"):
        build("bullet")


def test_each_pybullet_variant_of_the_report_builds_with_its_settings_changed():
    from dataclasses import asdict

    from refsim.report.entries.dynamics import PYBULLET_VARIANTS

    with build("pybullet") as oracle:
        base = asdict(oracle.settings)
    assert PYBULLET_VARIANTS[0][1] == {}                   # the oracle's own settings first
    for label, changes in PYBULLET_VARIANTS:
        with build("pybullet", **changes) as engine:
            settings = asdict(engine.settings)
        assert {k: v for k, v in settings.items() if v != base[k]} == changes, label


def test_each_replay_demo_runs_beside_a_rigid_engine_of_the_registry():
    names = {e.name: e for e in ENGINES}
    assert {v for v in DEMO_ENGINES.values() if v} == {"pybullet", "mujoco"}
    assert all(v is None or names[v].kit for v in DEMO_ENGINES.values())
