"""Scene files: the bundled scenes load; every schema violation names its key."""

from __future__ import annotations

import os
import shutil

import pytest

from refsim.bundled import models_dir, scenes_dir
from refsim.errors import ModelError, SceneError
from refsim.limits import MAX_SCENE_BYTES, MAX_SCENE_NESTING
from refsim.models.ac3d import write_ac3d
from refsim.models.loading import load_model
from refsim.models.mesh import Mesh
from refsim.scenes.loader import first_line_nested_deeper, load_scene
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
    ("[integration]\nstep = 1e-9\nduration = 1000.0\n" + MINIMAL, "integration.duration",
     "exceeds the limit"),
    ("[integration]\nstep = 0.003\nduration = 1.0\n" + MINIMAL, "integration.duration",
     "not a whole number of steps (try duration = 0.999 or 1.002)"),
    ("[integration]\nstep = 0.01\nduration = 0.001\n" + MINIMAL, "integration.duration",
     "shorter than one step"),
    ("[world]\nhalf_size = 1e51\n" + MINIMAL, "world.half_size", "at most 1e+50"),
    ("[world]\ngravity = 1e400\n" + MINIMAL, "world.gravity", "must be finite"),
    ("[[body]]\nmodel = \"cube.ac\"\nmass = 1e-320\n", "body[0].mass", "at least 1e-50"),
    ("[[body]]\nmodel = \"cube.ac\"\nmass = 5e-324\n", "body[0].mass", "at least 1e-50"),
    ("[[body]]\nmodel = \"cube.ac\"\nvelocity = [0, 1e100, 0]\n", "body[0].velocity[1]",
     "at most 1e+50"),
    ("[[body]]\nmodel = \"cube.ac\"\nposition = [0, 99999999999999999999999999, 0]\n",
     "body[0].position", "starts outside the world cube"),
    ("[[body]]\nmodel = \"cube.ac\"\nposition = [0, -4.6, 0]\n", "body[0].position",
     "y = -5.1 to -4.1, the cube -5 to 5"),
    ("[[body]]\nmodel = \"cube.ac\"\nscale = 1e155\n", "body[0].scale", "at most 1e+50"),
    ("[[body]]\nmodel = \"cube.ac\"\nscale = 20.0\n", "body[0].scale",
     "larger than the world cube"),
    ("[[body]]\nmodel = \"cube.ac\"\nscale = 1e-65\n", "body[0].scale", "at least 1e-50"),
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
    # the keys that pose textbook problems (refsim.dynamics.loads)
    ("[world]\ngravity_direction = [0, 0, 0]\n" + MINIMAL, "world.gravity_direction",
     "zero vector"),
    ('[world]\nwalls = ["floor"]\n' + MINIMAL, "world.walls", "names 'floor': walls are"),
    ('[world]\nwalls = ["y-", "y-"]\n' + MINIMAL, "world.walls", "names a wall twice"),
    ("[world]\nwalls = \"y-\"\n" + MINIMAL, "world.walls", "list of strings"),
    ("[world]\nmu = -1\n" + MINIMAL, "world.mu", "must be >= 0"),
    ("[world]\nrestitution_threshold = -0.1\n" + MINIMAL, "world.restitution_threshold",
     ">= 0"),
    ('[[body]]\nshape = "cone"\n', "body[0].shape", "one of 'box', 'sphere'"),
    ('[[body]]\nshape = "box"\nmodel = "cube.ac"\n', "body[0].model", "not both"),
    ('[[body]]\nshape = "box"\nradius = 1.0\n', "body[0].radius", "shape = 'sphere'"),
    ('[[body]]\nmodel = "cube.ac"\nsize = [1, 1, 1]\n', "body[0].size", "shape = 'box'"),
    ('[[body]]\nshape = "box"\nsize = [1, 0, 1]\n', "body[0].size", "every component > 0"),
    ('[[body]]\nshape = "sphere"\nfrequency = 1.5\n', "body[0].frequency", "whole number"),
    ('[[body]]\nshape = "sphere"\nfrequency = 0\n', "body[0].frequency", "at least 1"),
    ('[[body]]\nshape = "box"\nfixed = 1\n', "body[0].fixed", "true or false"),
    ('[[body]]\nshape = "box"\nfixed = true\nvelocity = [1, 0, 0]\n', "body[0].velocity",
     "a fixed body never moves"),
    ('[[body]]\nshape = "box"\nmu = -0.5\n', "body[0].mu", ">= 0"),
    ('[[body]]\nshape = "box"\nrestitution = 2\n', "body[0].restitution", "[0, 1]"),
    ('[[body]]\nshape = "box"\nname = "a"\nposition = [2, 0, 0]\nrestitution = 0.5\n'
     '[[body]]\nshape = "box"\nname = "b"\nrestitution = 0.7\n', "body[1].restitution",
     "add a [[pair]] with bodies = ['a', 'b']"),
    ('[[body]]\nshape = "box"\nname = "a"\n[[pair]]\nbodies = ["a", "c"]\n', "pair[0].bodies",
     "no body is named 'c'"),
    ('[[body]]\nshape = "box"\nname = "a"\n[[pair]]\nbodies = ["a", "a"]\n', "pair[0].bodies",
     "twice"),
    ('[[body]]\nshape = "box"\nname = "a"\n[[pair]]\nmu = 0.5\n', "pair[0].bodies",
     "required"),
    ('[world]\nwalls = ["y-"]\n[particles]\ncount = 10\n', "world.walls",
     "rigid bodies only"),
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


def test_broken_model_reports_the_scene_key_and_the_model_file_and_line(tmp_path):
    (tmp_path / "cube.ac").write_text("AC3Db\nOBJECT poly\nnumvert 2\n0 0 0\n")
    scene = write(tmp_path, MINIMAL)
    with pytest.raises(SceneError) as info:
        load_scene(scene)
    assert info.value.key == "body[0].model" and info.value.path == str(scene)
    model = info.value.__cause__
    assert isinstance(model, ModelError)
    assert model.path.endswith("cube.ac") and model.line is not None
    assert f"{model.path}:{model.line}:" in str(info.value)


def test_models_are_loaded_once_per_file(tmp_path):
    text = '[[body]]\nmodel = "cube.ac"\n[[body]]\nmodel = "cube.ac"\n'
    scene = load_scene(write(tmp_path, text))
    a, b = scene.bodies
    assert scene.mesh(a) is scene.mesh(b)


def test_solver_names_match_the_solvers():
    import refsim

    assert set(SOLVER_NAMES) == set(refsim.SOLVERS)


# -- files that are not scenes, and bodies that cannot be simulated ---------------------


@pytest.mark.parametrize("kind", ["directory", "fifo"])
def test_special_files_are_refused_without_opening_them(tmp_path, kind):
    path = tmp_path / "scene.toml"
    if kind == "directory":
        path.mkdir()
    else:
        os.mkfifo(path)                     # reading it would block forever
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(info.value) == f"{path}: not a regular file (a {kind.replace('fifo', 'FIFO')})"


def test_bytes_that_are_not_utf8_are_reported_by_line_and_column(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_bytes(b'[world]\ngravity = 9.81\n# caf\xe9\n' + MINIMAL.encode())
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(info.value) == f"{path}:3: not UTF-8 text (byte 0xe9 at column 6)"
    assert info.value.line == 3


@pytest.mark.parametrize("depth", [MAX_SCENE_NESTING + 1, 500, 5000, 10**6])
def test_deep_nesting_is_refused_at_its_line_before_the_parser_recurses(tmp_path, depth):
    text = MINIMAL + "\n[world]\nx = " + "[" * depth + "]" * depth + "\n"
    path = write(tmp_path, text)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    line = MINIMAL.count("\n") + 3
    assert str(info.value) == (f"{path}:{line}: invalid TOML: arrays and inline tables "
                               f"nested more than {MAX_SCENE_NESTING} deep")


@pytest.mark.parametrize("text, line", [
    ("a = [[1], [2]]\nb = {c = [1, {d = [2]}]}\n", None),
    ("a = \"[[[[[[[[\"\nb = '{{{{{{'\n# [[[[[[[[[\n", None),
    ('a = """\n[[[[[[\n"""\nb = [[[[[[[1]]]]]]]\n', 4),
    ('a = "\\"[[[["\nb = [[[[[1]]]]]\n', 2),
    ("a = '''x\n'''\nb = [[[[[1]]]]]\n", 3),
])
def test_the_nesting_scan_skips_strings_and_comments(text, line):
    # limit 4: only the arrays outside strings and comments count
    assert first_line_nested_deeper(text, 4) == line


def test_a_scene_larger_than_its_limit_is_refused_unread(tmp_path):
    path = tmp_path / "big.toml"
    with open(path, "wb") as file:
        file.truncate(MAX_SCENE_BYTES + 1)          # sparse: no disk used
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert str(info.value) == (f"{path}: file too large: more than {MAX_SCENE_BYTES} bytes "
                               "(refsim.limits)")


def test_a_path_the_system_cannot_look_up_is_one_scene_error(tmp_path):
    long_name = "x" * 300 + ".toml"             # beyond NAME_MAX (255) on Linux file systems
    with pytest.raises(SceneError) as info:
        load_scene(tmp_path / long_name)
    assert str(info.value) == f"{tmp_path / long_name}: cannot read: File name too long"
    with pytest.raises(SceneError) as info:
        load_scene(long_name)                   # a bare name: looked up here, then bundled
    assert str(info.value) == f"{long_name}: cannot read: File name too long"


@pytest.mark.parametrize("model, why", [
    ("AC3Db\nOBJECT poly\nnumvert 3\n0 0 0\n1 0 0\n2 0 0\nnumsurf 1\nSURF 0x0\nmat 0\n"
     "refs 3\n0 0 0\n1 0 0\n2 0 0\nkids 0\n", "vertices lie on a line"),
    ("AC3Db\nOBJECT poly\nnumvert 1\n0 0 0\nnumsurf 1\nSURF 0x0\nmat 0\n"
     "refs 3\n0 0 0\n0 0 0\n0 0 0\nkids 0\n", "at one point"),
])
def test_a_body_whose_inertia_is_singular_is_refused(tmp_path, model, why):
    (tmp_path / "flat.ac").write_text(model)
    assert_scene_error(tmp_path, '[[body]]\nmodel = "flat.ac"\n', "body[0]", why)


def test_a_model_wound_inside_out_is_refused(tmp_path):
    cube = load_model(models_dir() / "cube.ac")
    write_ac3d(Mesh(cube.vertices, cube.faces[:, ::-1]), tmp_path / "inverted.ac")
    assert_scene_error(tmp_path, '[[body]]\nmodel = "inverted.ac"\n', "body[0].model",
                       "wound inside out (enclosed volume -1)")


def test_a_body_resting_on_the_floor_is_inside(tmp_path):
    # position y = -H + 1/2 puts the unit cube's bottom exactly on the floor
    scene = load_scene(write(tmp_path, MINIMAL.replace("\n", "\nposition = [0, -4.5, 0]\n",
                                                        1)))
    assert scene.bodies[0].position == (0.0, -4.5, 0.0)


def test_the_wall_law_keys_and_their_defaults(tmp_path):
    from refsim.dynamics.plan import resolve_wall_response
    from refsim.dynamics.simulation import Simulation

    scene = load_scene(write(tmp_path, MINIMAL))
    assert scene.world.wall_speed == "wall" and scene.dynamics.wall_response == "auto"
    assert resolve_wall_response(scene.dynamics) == "seed"        # rotation "seed"
    impulse = load_scene(write(tmp_path, '[dynamics]\nrotation = "impulse"\n' + MINIMAL))
    assert resolve_wall_response(impulse.dynamics) == "impulse"
    chosen = load_scene(write(tmp_path, '[world]\nwall_speed = "seed"\n[dynamics]\n'
                              'rotation = "impulse"\nwall_response = "seed"\n' + MINIMAL))
    sim = Simulation(chosen)
    assert (sim.plan.wall_speed, sim.plan.wall_response) == ("seed", "seed")
    assert sim.trajectory().settings["wall_response"] == "seed"
    assert_scene_error(tmp_path, '[world]\nwall_speed = "fast"\n' + MINIMAL,
                       "world.wall_speed", "must be one of 'wall', 'seed'")
    assert_scene_error(tmp_path, '[dynamics]\nwall_response = "soft"\n' + MINIMAL,
                       "dynamics.wall_response", "must be one of")


def test_particles_take_the_worlds_wall_speed(tmp_path):
    text = '[world]\nwall_speed = "seed"\n[particles]\ncount = 5\n'
    assert load_scene(write(tmp_path, text)).particles.wall_speed == "seed"
    assert load_scene(write(tmp_path, "[particles]\ncount = 5\n")).particles.wall_speed == "wall"


def test_a_body_or_particles_crossing_half_the_cube_in_one_step_are_refused(tmp_path):
    # H = 5 m, h = 1e-3 s: 5000 m/s covers exactly half the cube and is kept;
    # faster would be put back at walls it never reached
    fast = '[integration]\nstep = 0.001\n[[body]]\nmodel = "cube.ac"\nvelocity = [{}, 0, 0]\n'
    assert load_scene(write(tmp_path, fast.format(5000.0))).bodies[0].velocity[0] == 5000.0
    assert_scene_error(tmp_path, fast.format(3.0e4), "body[0].velocity",
                       "speed 30000 m/s covers 30 m in one step of 0.001 s, more than half "
                       "the world cube (5 m)")
    particles = "[integration]\nstep = 0.01\n[particles]\ncount = 10\nspeed_max = {}\n"
    assert load_scene(write(tmp_path, particles.format(500.0))).particles.speed_max == 500.0
    assert_scene_error(tmp_path, particles.format(501.0), "particles.speed_max",
                       "covers 5.01 m in one step of 0.01 s")


def test_a_dangling_symlink_beside_the_scene_is_not_replaced_by_the_bundled_model(tmp_path):
    # cube.ac here points nowhere: refused as missing, not read from models/
    (tmp_path / "cube.ac").symlink_to(tmp_path / "gone.ac")
    with pytest.raises(SceneError, match="no such file") as info:
        load_scene(write(tmp_path, MINIMAL))
    assert info.value.key == "body[0].model"
    assert f"{tmp_path / 'cube.ac'}: no such file" in str(info.value)


def test_a_model_name_with_a_nul_byte_is_refused_at_its_key(tmp_path):
    assert_scene_error(tmp_path, '[[body]]\nmodel = "cu\\u0000be.ac"\n', "body[0].model",
                       "cannot be looked up: it contains a NUL byte")


def test_a_scene_beyond_the_default_step_limit_needs_max_steps(tmp_path):
    from refsim.errors import StateError
    from refsim.limits import DEFAULT_MAX_STEPS, MAX_STEPS

    path = tmp_path / "long.toml"
    path.write_text("[integration]\nstep = 0.001\nduration = 20000.0\n" + MINIMAL)
    with pytest.raises(SceneError) as info:
        load_scene(path)
    assert info.value.key == "integration.duration"
    assert info.value.message.startswith(f"duration / step = 20000 / 0.001 = 2e+07 steps "
                                         f"exceeds the limit of {DEFAULT_MAX_STEPS:.0e}; "
                                         "to run it, raise the limit to 20000000 (")
    assert load_scene(path, max_steps=20_000_000).integration.n_steps == 20_000_000
    with pytest.raises(SceneError, match="exceeds the limit of 19999999;"):
        load_scene(path, max_steps=19_999_999)
    with pytest.raises(StateError, match=f"max_steps must be at least 1 and at most {MAX_STEPS}"):
        load_scene(path, max_steps=MAX_STEPS + 1)


#: A scene with every key beyond the seed's world (refsim.dynamics.loads).
EVERY_KEY = """
[world]
gravity_direction = [1, -2, 0]
walls = ["y-", "x+"]
mu = 1.5
restitution_threshold = 0.1
[[body]]
name = "table"
shape = "box"
size = [4, 0.5, 3]
position = [0, -4.75, 0]
fixed = true
restitution = 0.3
[[body]]
name = "ball"
shape = "sphere"
radius = 0.25
frequency = 3
position = [0, -3, 0]
force = [1, 0, 0]
torque = [0, 0, 0.5]
[[pair]]
bodies = ["ball", "table"]
mu = 0.2
[[body]]
name = "cube"
model = "cube.ac"
position = [3, -4.5, 0]
"""


def test_the_textbook_keys_load_into_the_scene(tmp_path):
    """Every key of refsim.dynamics.loads, read and resolved: shapes become
    meshes of the given size, coefficients resolve pair first, then body,
    then world."""
    scene = load_scene(write(tmp_path, EVERY_KEY))
    table, ball, _ = scene.bodies
    assert scene.world.walls == ("y-", "x+") and scene.world.coulomb_mu == 1.5
    assert scene.world.restitution_threshold == 0.1
    g = scene.world.gravity_vector
    assert g[0] == pytest.approx(9.81 / 5 ** 0.5) and g[1] == pytest.approx(-2 * 9.81 / 5 ** 0.5)
    box = scene.mesh(table)
    assert box.n_faces == 12 and tuple(box.vertices.max(axis=0)) == (2.0, 0.25, 1.5)
    sphere = scene.mesh(ball)
    assert sphere.n_faces == 20 * 3 ** 2
    assert abs(sum(c * c for c in sphere.vertices.T) ** 0.5 - 0.25).max() < 1e-15
    assert table.fixed and ball.force == (1.0, 0.0, 0.0) and ball.torque == (0.0, 0.0, 0.5)
    assert scene.coefficients(table, ball) == (0.3, 0.2)      # e: the table's; mu: the pair's
    assert scene.coefficients(ball) == (0.8, 1.5)             # with a wall: the world's
    assert scene.coefficients(table) == (0.3, 1.5)



def test_a_scene_with_every_key_survives_its_plain_data(tmp_path):
    """The advisor ships a scene to its workers as plain data
    (refsim.advisor.runs.scene_data): shapes, fixed bodies, forces,
    coefficients and pairs come back equal, and unset keys stay unset."""
    from refsim.advisor.runs import scene_data
    from refsim.scenes.loader import scene_from_dict

    scene = load_scene(write(tmp_path, EVERY_KEY))
    data = scene_data(scene)
    assert "mu" not in data["body"][0] and "model" not in data["body"][0]
    assert data["body"][2]["model"] == "cube.ac" and "shape" not in data["body"][2]
    back = scene_from_dict(data)
    assert (back.world, back.bodies, back.pairs) == (scene.world, scene.bodies, scene.pairs)
