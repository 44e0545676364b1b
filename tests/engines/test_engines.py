"""The engine contract (refsim.engines): capabilities found by protocol,
engines loaded by 'module:factory', refsim's own engines and the oracle
adapters implementing it, and the per-mesh cache behind them."""

from __future__ import annotations

import numpy as np
import pytest

import refsim
from refsim.engines import capabilities, engine_name, load_engine
from refsim.engines.cache import MeshCache
from refsim.engines.refsim_engines import corrected, seed
from refsim.errors import ArgumentTypeError, OptionError

CUBE = refsim.load_model("cube.ac")
IDENTITY = (np.eye(3), np.zeros(3))
NEAR = (refsim.types.rotation_about_axis([1.0, 2.0, 3.0], 0.3), np.array([0.9, 0.1, 0.0]))


class OnlyTriangles:
    name = "only-triangles"

    def triangles_intersect(self, a, b):
        return True


def test_capabilities_are_the_methods_an_engine_has():
    assert capabilities(OnlyTriangles()) == ("triangles",)
    assert capabilities(corrected()) == ("triangles", "pairs", "collide", "aabb", "ode",
                                         "rigid")
    assert capabilities(object()) == ()


@pytest.mark.parametrize("spec, phrase", [
    ("refsim.engines.refsim_engines", "expected 'module:factory'"),
    ("a:b:c", "expected 'module:factory'"),
    ("no_such_module_xyz:engine", "cannot import 'no_such_module_xyz'"),
    ("refsim.engines.refsim_engines:nothing", "has no callable 'nothing'"),
    ("collections:OrderedDict", "an engine needs a non-empty string attribute 'name'"),
])
def test_bad_engine_specs_are_one_option_error(spec, phrase):
    with pytest.raises(OptionError, match=phrase):
        load_engine(spec)


def test_load_engine_passes_keyword_arguments():
    engine = load_engine("refsim.engines.refsim_engines:seed", solver="midpoint")
    assert (engine.name, engine.solver.name, engine.ode_order) == ("refsim-seed", "midpoint", 2)
    with pytest.raises(ArgumentTypeError):
        engine_name(object())


def test_seed_and_corrected_agree_on_geometry_and_differ_in_dynamics():
    a, b = seed(), corrected()
    args = (CUBE.vertices, CUBE.faces, IDENTITY, CUBE.vertices, CUBE.faces, NEAR)
    expected = refsim.intersecting_pairs(CUBE, IDENTITY, CUBE, NEAR)
    assert np.array_equal(a.intersecting_pairs(*args), expected)
    assert np.array_equal(b.intersecting_pairs(*args), expected)
    assert a.bodies_collide(*args) and b.bodies_collide(*args)
    lo, hi = a.aabb(CUBE.vertices, NEAR)
    assert np.array_equal(lo, refsim.aabb_linear(CUBE, NEAR)[0])
    assert np.array_equal(hi, refsim.aabb_linear(CUBE, NEAR)[1])
    scene = refsim.load_scene("spinning-cube.toml")
    sa, sb = a.simulate(scene, duration=0.05), b.simulate(scene, duration=0.05)
    assert (sa.settings["rotation"], sa.settings["wall_speed"]) == ("seed", "seed")
    assert (sb.settings["rotation"], sb.settings["wall_speed"]) == ("impulse", "wall")


def test_ode_capability_is_the_named_solver():
    engine = corrected("rk4")
    y = engine.ode_step(lambda t, y: -y, 0.0, np.array([1.0]), 0.1)
    assert y[0] == refsim.SOLVERS["rk4"].step(lambda t, y: -y, 0.0, np.array([1.0]), 0.1)[0]
    assert engine.ode_stability(-0.1) == pytest.approx(y[0], rel=1e-15)


def test_the_cache_keys_read_only_arrays_by_identity_and_others_by_content():
    built = []
    cache = MeshCache(lambda v, f: built.append(1) or len(built))
    assert cache.get(CUBE.vertices, CUBE.faces) == cache.get(CUBE.vertices, CUBE.faces) == 1
    v, f = CUBE.vertices.copy(), CUBE.faces.copy()               # writeable: by content
    assert cache.get(v, f) == 2 and cache.get(v.copy(), f.copy()) == 2
    v[0, 0] += 1.0                                                # changed in place: rebuilt
    assert cache.get(v, f) == 3 and len(cache) == 3


@pytest.mark.oracle
@pytest.mark.parametrize("spec, expected", [
    ("refsim.oracles.fcl_adapter:engine", ("triangles", "pairs", "collide")),
    ("refsim.oracles.coal_adapter:engine", ("triangles", "pairs", "collide")),
    ("refsim.oracles.trimesh_collision:engine", ("collide",)),
    ("refsim.oracles.trimesh_adapter:engine", ("aabb",)),
    ("refsim.oracles.pybullet_adapter:engine", ("rigid",)),
])
def test_the_oracle_adapters_are_engines(spec, expected):
    assert capabilities(load_engine(spec)) == expected


#: How far each rigid engine's centre of mass may stray from the straight
#: line in 0.2 s of free flight, metres: refsim's state is the centre's
#: (exact but for rounding); pybullet's base state is the centre's and its
#: step is exact without forces; MuJoCo integrates the frame origin's
#: velocity with semi-implicit Euler (the centre lags by O(h |w|^2 |c| t):
#: measured 5e-4 m here); Drake's free body too holds its origin's velocity
#: and steps it first order (measured 3.9e-4 m, as MuJoCo in the same run).
COM_DRIFT = {"refsim.engines.refsim_engines:corrected": 1e-12,
             "refsim.engines.refsim_engines:seed": 1e-12,
             "refsim.oracles.pybullet_adapter:engine": 1e-9,
             "refsim.oracles.mujoco_adapter:engine": 2e-3,
             "refsim.oracles.drake_adapter:engine": 2e-3}


@pytest.mark.parametrize("spec", [
    pytest.param(spec, marks=[pytest.mark.oracle] if spec.startswith("refsim.oracles") else [])
    for spec in sorted(COM_DRIFT)])
def test_every_rigid_engine_reads_velocity_as_the_centre_of_mass_s(spec):
    """One physics: the l-beam (centre of mass off its origin) spinning at
    5 rad/s about z with ``velocity`` (0.3, 0, 0) and no gravity; the centre
    of mass moves 0.06 m along x in 0.2 s in every engine (read as the mesh
    origin's velocity, it would swing on a circle of the centre's offset,
    more than 5 cm here),
    and the recorded velocity is the centre's, (0.3, 0, 0)."""
    from refsim.conformance.cases_rigid import _body
    from refsim.scenes.loader import scene_from_dict

    scene = scene_from_dict({
        "world": {"half_size": 5.0, "gravity": 0.0},
        "integration": {"solver": "rk4", "step": 1e-3, "duration": 0.2},
        "dynamics": {"rotation": "impulse", "body_response": "impulse"},
        "body": [{"model": "l-beam.ac", "velocity": [0.3, 0.0, 0.0],
                  "angular_velocity": [0.0, 0.0, 5.0]}]})
    _, solid_center, _ = _body("l-beam.ac")
    center = solid_center
    if spec.endswith(":seed"):       # the seed's centre: the vertex average, here the origin
        center = scene.meshes[scene.bodies[0].model].centroid_vertex_average
    trajectory = load_engine(spec).simulate(scene)
    R = np.asarray(trajectory.orientation)[:, 0]
    com = np.asarray(trajectory.position)[:, 0] + R @ center
    t = np.asarray(trajectory.t)
    line = com[0] + np.outer(t, [0.3, 0.0, 0.0])
    assert np.abs(com - line).max() < COM_DRIFT[spec]
    assert t[-1] == pytest.approx(0.2)
    # ...and the swing of the solid's centre about the origin is far larger
    assert np.abs(R[-1] @ solid_center - R[0] @ solid_center).max() > 0.05
    np.testing.assert_allclose(np.asarray(trajectory.velocity)[-1, 0], [0.3, 0.0, 0.0],
                               atol=max(COM_DRIFT[spec] / 0.2, 1e-12))
