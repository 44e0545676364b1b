"""Generated shapes: counts, closedness, convexity and volumes from formulas."""

from __future__ import annotations

import numpy as np
import pytest

from refsim.models import shapes

#: Volumes computed from float coordinates agree with the closed forms to a
#: few ulps times the number of triangles summed; 1e-12 relative is ample.
VOLUME_RTOL = 1e-12


@pytest.mark.parametrize("f", [1, 2, 3, 5, 10, 16])
def test_geodesic_sphere_counts_and_convexity(f):
    mesh = shapes.geodesic_sphere(f)
    assert mesh.n_faces == 20 * f * f
    assert mesh.n_vertices == 10 * f * f + 2
    assert mesh.is_closed and mesh.is_convex
    np.testing.assert_allclose(np.linalg.norm(mesh.vertices, axis=1), 1.0, rtol=1e-15)
    # Euler's formula for a sphere: V - E + F = 2
    assert mesh.n_vertices - len(mesh.edges) + mesh.n_faces == 2


def test_geodesic_sphere_volume_approaches_the_ball():
    volumes = [shapes.geodesic_sphere(f).volume for f in (4, 8, 16, 32)]
    ball = 4.0 / 3.0 * np.pi
    gaps = [ball - v for v in volumes]
    assert all(g > 0 for g in gaps)                    # inscribed: always below
    ratios = [a / b for a, b in zip(gaps, gaps[1:], strict=False)]
    np.testing.assert_allclose(ratios, 4.0, rtol=0.05)  # error ~ 1/f^2


def test_box_and_tetrahedron_volumes():
    assert shapes.box((4.0, 0.25, 0.25)).volume == pytest.approx(0.25, rel=VOLUME_RTOL)
    # regular tetrahedron on alternate corners of a cube of side s: V = s^3 / 3
    assert shapes.tetrahedron(2.0).volume == pytest.approx(8.0 / 3.0, rel=VOLUME_RTOL)


def test_icosahedron_volume_closed_form():
    # edge a for unit circumradius; V = 5 (3 + sqrt 5) a^3 / 12
    a = 1.0 / np.sin(2.0 * np.pi / 5.0)
    mesh = shapes.icosahedron()
    assert mesh.volume == pytest.approx(5.0 * (3.0 + 5.0 ** 0.5) * a ** 3 / 12.0,
                                        rel=VOLUME_RTOL)
    assert np.isclose(np.linalg.norm(mesh.vertices[mesh.edges[:, 0]]
                                     - mesh.vertices[mesh.edges[:, 1]], axis=1), a).all()


def test_torus_volume_closed_form_and_nonconvex():
    mesh = shapes.torus(1.0, 0.35, 40, 25)
    assert mesh.n_faces == 2000 and mesh.is_closed and not mesh.is_convex
    exact = 2.0 * np.pi ** 2 * 1.0 * 0.35 ** 2
    assert 0.97 * exact < mesh.volume < exact          # a polyhedral torus is smaller


def test_smallest_torus_is_closed():
    mesh = shapes.torus(1.0, 0.35, 3, 3)
    assert mesh.n_faces == 18 and mesh.is_closed and mesh.volume > 0.0


@pytest.mark.parametrize("n_major, n_minor", [(2, 3), (3, 2), (1, 1)])
def test_torus_with_fewer_than_three_segments_raises(n_major, n_minor):
    # Found by the type checker: the surface is open, its volume None, and
    # the winding check used to fail with "'<' not supported ... NoneType".
    with pytest.raises(ValueError, match="must be >= 3"):
        shapes.torus(1.0, 0.35, n_major, n_minor)


@pytest.mark.parametrize("build, volume", [
    (shapes.l_beam, 2 * 2.0 * 0.5 * 0.5 - 0.5 * 0.5 * 0.5),
    (shapes.star_prism, None),
])
def test_prisms_are_closed_and_nonconvex(build, volume):
    mesh = build()
    assert mesh.is_closed and not mesh.is_convex and mesh.volume > 0
    assert len(mesh.degenerate_faces) == 0
    if volume is not None:
        assert mesh.volume == pytest.approx(volume, rel=VOLUME_RTOL)
    np.testing.assert_allclose(mesh.centroid_vertex_average, 0.0, atol=1e-15)
