"""Mass properties from signed tetrahedra, against closed forms and trimesh."""

from __future__ import annotations

import numpy as np
import pytest
from refsim.oracles.trimesh_adapter import TrimeshOracle

import refsim
from refsim.bundled import models_dir
from refsim.dynamics.mass_properties import mass_properties, point_mass_properties
from refsim.errors import ModelError

#: Sums of m signed terms of order 1: a few hundred ulps for the 2000-face meshes.
RTOL = 1e-12

MODELS = ("cube.ac", "tetrahedron.ac", "icosahedron.ac", "l-beam.ac", "star.ac",
          "torus.ac", "long-box.ac")


def test_unit_cube_is_m_over_6():
    mesh = refsim.load_model(models_dir() / "cube.ac")
    p = mass_properties(mesh.vertices, mesh.faces, 3.0)
    assert p.volume == pytest.approx(1.0, rel=RTOL)
    assert np.allclose(p.center, 0.0, atol=1e-15)
    assert np.allclose(p.inertia, 0.5 * np.eye(3), rtol=RTOL, atol=1e-15)


def test_box_closed_form_after_scaling_and_shift():
    mesh = refsim.load_model(models_dir() / "cube.ac")
    size = np.array([2.0, 0.5, 1.0])
    p = mass_properties(mesh.vertices * size + [3.0, -1.0, 2.0], mesh.faces, 6.0)
    a, b, c = size
    expected = 6.0 / 12.0 * np.diag([b * b + c * c, a * a + c * c, a * a + b * b])
    assert np.allclose(p.center, [3.0, -1.0, 2.0], rtol=RTOL)
    assert np.allclose(p.inertia, expected, rtol=RTOL, atol=1e-14)


@pytest.mark.oracle
@pytest.mark.parametrize("name", MODELS)
def test_against_trimesh(oracle, name):
    engine = oracle(TrimeshOracle)
    mesh = refsim.load_model(models_dir() / name)
    mass = 2.5
    p = mass_properties(mesh.vertices, mesh.faces, mass)
    assert p.volume == pytest.approx(engine.volume(mesh.vertices, mesh.faces), rel=RTOL)
    scale = np.abs(mesh.vertices).max()
    assert np.allclose(p.center, engine.center_mass(mesh.vertices, mesh.faces),
                       atol=RTOL * scale)
    assert np.allclose(p.inertia, engine.moment_inertia(mesh.vertices, mesh.faces, mass),
                       atol=RTOL * mass * scale * scale)


def test_open_or_inside_out_mesh_raises():
    mesh = refsim.load_model(models_dir() / "cube.ac")
    with pytest.raises(ModelError, match="closed"):
        mass_properties(mesh.vertices, mesh.faces[:, ::-1], 1.0)


def test_point_masses_at_vertices():
    v = np.array([[1.0, 0, 0], [-1.0, 0, 0]])
    p = point_mass_properties(v, 2.0)
    assert np.allclose(p.inertia, np.diag([0.0, 2.0, 2.0]))
