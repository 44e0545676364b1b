"""Particle scenes (S10 in S11): a ``[particles]`` table, with the forces and
cube from ``[world]`` and the solver and step from ``[integration]``."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.bundled import scenes_dir
from refsim.particles.config import ParticleConfig
from refsim.scenes.loader import load_scene
from refsim.scenes.schema import PARTICLE_FIELDS_FROM, PARTICLE_KEYS
from tests.helpers import assert_scene_error

PARTICLES = "[particles]\ncount = 10\nseed = 4\n"


def write(tmp_path, text, name="scene.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_every_particle_field_comes_from_exactly_one_table():
    assert set(PARTICLE_KEYS) | set(PARTICLE_FIELDS_FROM) == set(ParticleConfig.field_names())
    assert not set(PARTICLE_KEYS) & set(PARTICLE_FIELDS_FROM)


def test_bundled_particle_scene():
    scene = load_scene(scenes_dir() / "particles.toml")
    assert scene.bodies == ()
    p = scene.particles
    assert p.count == 10_000 and p.seed == 1997 and p.walls is True
    # the world's forces and cube, the integration's solver and step
    assert (p.gravity, p.drag, p.drag_model) == (scene.world.gravity, scene.world.drag,
                                                 scene.world.drag_model)
    assert (p.restitution, p.friction, p.half_size) == (
        scene.world.restitution, scene.world.friction, scene.world.half_size)
    assert (p.solver, p.step) == (scene.integration.solver, scene.integration.step)


def test_a_particle_scene_takes_world_and_integration(tmp_path):
    text = ('[world]\ngravity = 3.0\ndrag = 0.2\ndrag_model = "quadratic"\nrestitution = 0.5\n'
            'friction = 0.25\nhalf_size = 2\n[integration]\nsolver = "midpoint"\n'
            'step = 0.01\nduration = 1.0\n[particles]\ncount = 7\nseed = 3\n'
            'box_lo = [-1, -1, -1]\nbox_hi = [1, 1.5, 1]\nspeed_min = 1\nspeed_max = 2.5\n'
            'mass = 2.0\nwalls = false\n')
    scene = load_scene(write(tmp_path, text))
    assert scene.particles == ParticleConfig(
        count=7, seed=3, box_lo=(-1.0, -1.0, -1.0), box_hi=(1.0, 1.5, 1.0), speed_min=1.0,
        speed_max=2.5, gravity=3.0, drag=0.2, drag_model="quadratic", mass=2.0,
        restitution=0.5, friction=0.25, half_size=2.0, walls=False, solver="midpoint",
        step=0.01)


def test_defaults_and_seeded_initial_state(tmp_path):
    a = load_scene(write(tmp_path, PARTICLES, "a.toml")).particles
    b = load_scene(write(tmp_path, PARTICLES, "b.toml")).particles
    assert a == b and a.mass == 1.0 and a.walls is True and a.solver == "rk4"
    xa, va = a.initial_state()
    xb, vb = b.initial_state()
    assert xa.shape == (10, 3) and np.array_equal(xa, xb) and np.array_equal(va, vb)


def test_an_empty_particles_table_means_the_defaults(tmp_path):
    scene = load_scene(write(tmp_path, "[particles]\n"))
    assert scene.particles == ParticleConfig()


def test_bodies_and_particles_together(tmp_path):
    scene = load_scene(write(tmp_path, PARTICLES + '[[body]]\nmodel = "cube.ac"\n'))
    assert len(scene.bodies) == 1 and scene.particles.count == 10


def test_a_scene_without_particles_has_none(tmp_path):
    scene = load_scene(write(tmp_path, '[[body]]\nmodel = "cube.ac"\n'))
    assert scene.particles is None


BAD = [
    # (scene text, the key path the error must name, a phrase it must contain)
    ("[particles]\ncount = 0\n", "particles.count", "must be in [1, 20000000]"),
    ("[particles]\ncount = 1000000000\n", "particles.count", "at most 2e+07 particles"),
    ("[particles]\ncount = 4611686018427387904\n", "particles.count", "must be in [1, "),
    ("[particles]\nmass = 1e-320\n", "particles.mass", "at least 1e-50"),
    ("[particles]\nspeed_max = 1e60\n", "particles.speed_max", "at most 1e+50"),
    ("[particles]\ncount = 2.5\n", "particles.count", "integer"),
    ("[particles]\ncount = true\n", "particles.count", "integer"),
    ("[particles]\nseed = -1\n", "particles.seed", "non-negative"),
    ('[particles]\nspeed_min = "fast"\n', "particles.speed_min", "number"),
    ("[particles]\nspeed_min = 3.0\nspeed_max = 2.0\n", "particles.speed_max", "must be in"),
    ("[particles]\nmass = 0.0\n", "particles.mass", "must be in"),
    ('[particles]\nwalls = "yes"\n', "particles.walls", "true or false"),
    ("[particles]\nbox_lo = [0, 0]\n", "particles.box_lo", "list of 3 numbers"),
    ('[particles]\nbox_hi = [1, "x", 1]\n', "particles.box_hi[1]", "must be a number"),
    ("[particles]\nbox_lo = [1, 1, 1]\nbox_hi = [0, 0, 0]\n", "particles.box_hi", "below"),
    ("[world]\nhalf_size = 0.5\n[particles]\n", "particles.box_lo", "outside the world cube"),
    ("[particles]\ncolour = 1\n", "particles.colour", "unknown key"),
    ("[particles]\ngravity = 1.0\n", "particles.gravity", "set in [world]"),
    ('[particles]\nsolver = "rk4"\n', "particles.solver", "set in [integration]"),
    ("particles = 3\n", "particles", "must be a table"),
    ("[world]\ndrag = -1.0\n[particles]\n", "world.drag", "must be >= 0"),
]


@pytest.mark.parametrize("text, key, phrase", BAD, ids=[b[1] + ":" + b[2] for b in BAD])
def test_bad_particle_keys_name_file_and_key(tmp_path, text, key, phrase):
    assert_scene_error(tmp_path, text, key, phrase)
