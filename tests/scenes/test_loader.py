"""Scene files: the bundled scenes load; every schema violation names its key."""

from __future__ import annotations

import shutil

import pytest

from refsim.bundled import models_dir, scenes_dir
from refsim.errors import ModelError, SceneError
from refsim.scenes.loader import load_scene
from refsim.scenes.schema import SOLVER_NAMES, IntegrationConfig, WorldConfig
from tests.helpers import assert_scene_error

MINIMAL = '[[body]]\nmodel = "cube.ac"\n'


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("scene", sorted(scenes_dir().glob("*.toml")), ids=lambda p: p.name)
def test_bundled_scenes_load(scene):
    loaded = load_scene(scene)
    assert loaded.bodies or loaded.particles is not None
    for body in loaded.bodies:
        assert loaded.mesh(body).n_faces > 0


def test_defaults_are_the_documented_ones(tmp_path):
    scene = load_scene(write(tmp_path, MINIMAL))
    assert scene.world == WorldConfig()
    assert scene.world.half_size == 5.0 and scene.world.gravity == 9.81
    assert scene.world.restitution == 0.8 and scene.world.friction == 0.0
    assert scene.integration == IntegrationConfig(solver="rk4", step=0.001, duration=5.0)
    assert scene.collision.level == "exact" and scene.collision.aabb == "auto"
    assert scene.dynamics.rotation == "seed" and scene.dynamics.body_response == "seed"
    (body,) = scene.bodies
    assert body.name == "body0"
    assert body.position == (0.0, 0.0, 0.0) and body.mass == 1.0 and body.scale == 1.0
    assert body.model == (models_dir() / "cube.ac").resolve()


def test_integers_are_accepted_where_floats_are_expected(tmp_path):
    scene = load_scene(write(tmp_path, "[world]\nhalf_size = 3\n" + MINIMAL))
    assert scene.world.half_size == 3.0 and isinstance(scene.world.half_size, float)


BAD = [
    # (scene text, the key path the error must name, a phrase it must contain)
    ("[wrld]\n" + MINIMAL, "wrld", "unknown key"),
    ("[world]\nhalfsize = 5.0\n" + MINIMAL, "world.halfsize", "unknown key"),
    ('[world]\nhalf_size = "5"\n' + MINIMAL, "world.half_size", "must be a number"),
    ("[world]\ngravity = true\n" + MINIMAL, "world.gravity", "must be a number"),
    ("[world]\nhalf_size = nan\n" + MINIMAL, "world.half_size", "must be finite"),
    ("[world]\nhalf_size = -1.0\n" + MINIMAL, "world.half_size", "must be > 0"),
    ("[world]\nrestitution = 1.5\n" + MINIMAL, "world.restitution", "[0, 1]"),
    ("[world]\nfriction = -0.1\n" + MINIMAL, "world.friction", "[0, 1]"),
    ('[world]\ndrag_model = "cubic"\n' + MINIMAL, "world.drag_model", "one of"),
    ("[integration]\nstep = 0.0\n" + MINIMAL, "integration.step", "must be > 0"),
    ('[integration]\nsolver = "rk5"\n' + MINIMAL, "integration.solver", "one of"),
    ("[integration]\nstep = 1e-9\nduration = 1000.0\n" + MINIMAL, "integration.step",
     "steps"),
    ('[collision]\nlevel = "obb"\n' + MINIMAL, "collision.level", "one of"),
    ('[collision]\naabb = "fast"\n' + MINIMAL, "collision.aabb", "one of"),
    ('[dynamics]\nrotation = "full"\n' + MINIMAL, "dynamics.rotation", "one of"),
    ("world = 5\n" + MINIMAL, "world", "must be a table"),
    ("[[body]]\nname = \"a\"\n", "body[0].model", "required"),
    ('[[body]]\nmodel = "cube.ac"\nposition = [1.0, 2.0]\n', "body[0].position",
     "list of 3 numbers"),
    ('[[body]]\nmodel = "cube.ac"\nposition = [1.0, "x", 2.0]\n', "body[0].position[1]",
     "must be a number"),
    ('[[body]]\nmodel = "cube.ac"\norientation = [[2, 0, 0], [0, 1, 0], [0, 0, 1]]\n',
     "body[0].orientation", "orthonormal"),
    ('[[body]]\nmodel = "cube.ac"\norientation = [[-1, 0, 0], [0, 1, 0], [0, 0, 1]]\n',
     "body[0].orientation", "reflection"),
    ('[[body]]\nmodel = "cube.ac"\nmass = 0.0\n', "body[0].mass", "must be > 0"),
    ('[[body]]\nmodel = "cube.ac"\nspin = 1.0\n', "body[0].spin", "unknown key"),
    ('[[body]]\nmodel = "no-such-model.ac"\n', "body[0].model", "not found"),
    ('[[body]]\nmodel = "cube.ac"\nname = "a"\n[[body]]\nmodel = "cube.ac"\nname = "a"\n',
     "body[1].name", "duplicate"),
    ("[world]\nhalf_size = 5.0\n", "body", "at least one [[body]] or a [particles] table"),
]


@pytest.mark.parametrize("text, key, phrase", BAD, ids=[b[1] + ":" + b[2] for b in BAD])
def test_schema_violations_name_file_and_key(tmp_path, text, key, phrase):
    assert_scene_error(tmp_path, text, key, phrase)


def test_invalid_toml_names_the_line(tmp_path):
    path = write(tmp_path, "[world]\nhalf_size = = 5\n")
    with pytest.raises(SceneError, match=r"invalid TOML.*line 2") as info:
        load_scene(path)
    assert str(path) in str(info.value)


def test_missing_scene_file(tmp_path):
    with pytest.raises(SceneError, match="no such file"):
        load_scene(tmp_path / "absent.toml")


def test_model_resolves_next_to_the_scene_first(tmp_path):
    local = tmp_path / "cube.ac"
    shutil.copy(models_dir() / "tetrahedron.ac", local)
    scene = load_scene(write(tmp_path, MINIMAL))
    assert scene.bodies[0].model == local.resolve()
    assert scene.mesh(scene.bodies[0]).n_faces == 4


def test_broken_model_reports_the_model_file_and_line(tmp_path):
    (tmp_path / "cube.ac").write_text("AC3Db\nOBJECT poly\nnumvert 2\n0 0 0\n")
    with pytest.raises(ModelError) as info:
        load_scene(write(tmp_path, MINIMAL))
    assert info.value.path.endswith("cube.ac") and info.value.line is not None


def test_models_are_loaded_once_per_file(tmp_path):
    text = '[[body]]\nmodel = "cube.ac"\n[[body]]\nmodel = "cube.ac"\n'
    scene = load_scene(write(tmp_path, text))
    a, b = scene.bodies
    assert scene.mesh(a) is scene.mesh(b)


def test_solver_names_match_the_solvers():
    import refsim

    assert set(SOLVER_NAMES) == set(refsim.SOLVERS)
