"""The facts `refsim info` prints and the report lists, and their agreement
with trimesh."""

from __future__ import annotations

import math

import pytest
from refsim.oracles.trimesh_adapter import TrimeshOracle

from refsim.bundled import bundled_models, models_dir
from refsim.models.facts import describe, format_facts
from refsim.models.loading import load_model
from refsim.models.mesh import Mesh
from refsim.studies.models import measure_mesh_facts_agreement

#: Volumes and centroids from two summation orders agree to a few ulps times
#: the number of triangles; 1e-12 relative leaves room and still catches a
#: wrong formula (which would be off by percent).
ROUNDING = 1e-12


def test_facts_of_the_cube():
    facts = describe(load_model(models_dir() / "cube.ac"), name="cube.ac")
    assert (facts.triangles, facts.vertices, facts.objects) == (12, 8, 1)
    assert facts.convex and facts.closed and facts.degenerate_triangles == 0
    assert facts.bounds_lo == (-0.5, -0.5, -0.5) and facts.bounds_hi == (0.5, 0.5, 0.5)
    assert facts.volume == 1.0 and facts.centroid_offset == 0.0
    assert facts.max_neighbors == 6
    text = format_facts(facts)
    assert "triangles" in text and "centroid (volume)" in text


def test_l_beam_centroids_differ():
    facts = describe(load_model(models_dir() / "l-beam.ac"))
    # vertex average at the origin by construction; the solid's centre of mass
    # lies toward the corner: for arms of length 2 and width 0.5 it is at
    # (x, y) = (-1/6 + ..., ...) -- computed from two rectangles below
    arm_a = (2.0 * 0.5, (1.0, 0.25))       # area, centre of the horizontal arm
    arm_b = (1.5 * 0.5, (0.25, 1.25))      # the vertical arm above it
    area = arm_a[0] + arm_b[0]
    cx = (arm_a[0] * arm_a[1][0] + arm_b[0] * arm_b[1][0]) / area
    vertex_mean_x = (0 + 2 + 2 + 0.5 + 0.5 + 0) / 6
    assert facts.centroid_volume[0] == pytest.approx(cx - vertex_mean_x, abs=ROUNDING)
    assert facts.centroid_offset > 0.05


def test_every_bundled_model_agrees_with_trimesh():
    rows = measure_mesh_facts_agreement(TrimeshOracle(), bundled_models())
    assert len(rows) == len(bundled_models())
    for row in rows:
        assert row.convex_agrees and row.closed_agrees, row.name
        assert row.volume_relative_difference < ROUNDING, row.name
        assert row.centroid_difference_over_diagonal < ROUNDING, row.name


def test_a_volume_beyond_float64_is_printed_from_its_logarithm():
    # The unit cube scaled by 1e154 bounds 1e462: float64 rounds it to inf,
    # but the coordinates are finite and so is the volume's logarithm.
    cube = load_model(models_dir() / "cube.ac")
    facts = describe(Mesh(cube.vertices * 1e154, cube.faces))
    assert facts.volume == math.inf
    assert facts.volume_log10 == pytest.approx(462.0, abs=1e-9)
    line = next(row for row in format_facts(facts).splitlines() if row.startswith("volume"))
    assert line.split()[1:] == ["1e+462", "(beyond", "float64's", "range)"]
