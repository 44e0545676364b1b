"""The case sets: seeded, sized, and their answers exact and independent of
any float engine."""

from __future__ import annotations

import math
from dataclasses import replace
from fractions import Fraction

import numpy as np
import pytest

from refsim.collision.bodies import intersecting_pairs
from refsim.collision.predicates import orient3d
from refsim.collision.sat_exact import triangles_intersect_sat
from refsim.conformance import cases_rigid as R
from refsim.conformance.cases_boxes import GAMMA_4, box_cases, exact_box, rounding_bound
from refsim.conformance.cases_meshes import FAMILIES as POSE_FAMILIES
from refsim.conformance.cases_meshes import pose_cases
from refsim.conformance.cases_ode import (
    ERROR_FLOOR,
    STABILITY_POINTS,
    fitted_order,
    logistic,
    order_problems,
    time_dependent,
)
from refsim.conformance.cases_triangles import FAMILIES, triangle_cases
from refsim.conformance.checks_bounces import apex_tolerance
from refsim.conformance.checks_contact import incline_tolerance, spin_rest_time
from refsim.conformance.draw import signed_permutations
from refsim.conformance.rigid_runs import energy_tolerance
from refsim.types import transform_points


@pytest.fixture(scope="module")
def triangles():
    return triangle_cases(120, seed=3)


def test_triangle_cases_are_seeded_and_sized(triangles):
    again = triangle_cases(120, seed=3)
    other = triangle_cases(120, seed=4)
    assert len(triangles) == 120
    assert all(np.array_equal(p.a, q.a) and np.array_equal(p.b, q.b)
               for p, q in zip(triangles.pairs, again.pairs, strict=True))
    assert not all(np.array_equal(p.a, q.a) for p, q in zip(triangles.pairs, other.pairs,
                                                             strict=True))
    assert [p.family for p in triangles.pairs[:6]] == list(FAMILIES)
    # every family has both answers somewhere in 120 pairs
    for family in FAMILIES:
        assert {p.truth for p in triangles.pairs if p.family == family} == {True, False}


def test_triangle_truth_is_the_rational_sat(triangles):
    for p in triangles.pairs:
        assert triangles_intersect_sat(p.a, p.b) is p.truth      # never None: no degenerate


def _t(points):
    return [tuple(map(float, row)) for row in points]


def test_exact_families_touch_and_lie_in_one_plane_exactly(triangles):
    for p in triangles.pairs:
        a, b = _t(p.a), _t(p.b)
        if p.family == "touching-exact":
            assert orient3d(*a, b[0]) == 0                       # on A's plane
            sides = {orient3d(*a, b[1]), orient3d(*a, b[2])}
            assert sides in ({1}, {-1})                          # the rest strictly off it
        elif p.family == "coplanar-exact":
            assert all(orient3d(*a, q) == 0 for q in b)


def test_pose_truth_is_refsims_exact_path_and_families_cycle():
    cases = pose_cases(24, seed=5)
    assert [c.family for c in cases.cases[:4]] == list(POSE_FAMILIES)
    for c in cases.cases:
        again = intersecting_pairs(c.mesh_a, c.pose_a, c.mesh_b, c.pose_b, level="exact",
                                   method="seed")
        assert again.tolist() == c.truth.tolist()                 # both of refsim's paths
        if c.family == "separated":
            assert len(c.truth) == 0
        if c.family == "touching" and {c.model_a, c.model_b} == {"cube.ac"}:
            assert len(c.truth) > 0                               # faces meet exactly


def test_exact_box_of_a_hand_example():
    vertices = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, -1.0]])
    rotation = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    lo, hi = exact_box(vertices, (rotation, np.array([0.5, 0.0, 0.1])))
    assert lo == (Fraction(-3, 2), Fraction(0), Fraction(-1) + Fraction(0.1))   # 0.1 as stored
    assert hi == (Fraction(1, 2), Fraction(1), Fraction(0.1))


def test_exact_box_equals_every_vertex_in_rational_arithmetic():
    """The candidate filter of exact_box (float values within four rounding
    bounds of the extreme) never drops the exact extreme: 300 cases of
    every family (subnormal-sized "tiny" points and near-identity poses
    among them) against all vertices in ``Fraction``s."""
    for c in box_cases(300, seed=5).cases:
        R = [[Fraction(float(x)) for x in row] for row in c.pose[0]]
        t = [Fraction(float(x)) for x in c.pose[1]]
        coords = [[sum((R[i][j] * Fraction(float(p[j])) for j in range(3)), t[i])
                   for i in range(3)] for p in c.vertices]
        assert c.exact == (tuple(min(q[i] for q in coords) for i in range(3)),
                           tuple(max(q[i] for q in coords) for i in range(3))), c.family


def test_box_truth_and_bound():
    cases = box_cases(60, seed=2)
    for c in cases.cases:
        world = transform_points(c.vertices, c.pose)
        lo = np.array([float(x) for x in c.exact[0]])
        hi = np.array([float(x) for x in c.exact[1]])
        # refsim's own float arithmetic is within the bound of the exact box
        assert (np.abs(world.min(axis=0) - lo) <= c.bound).all()
        assert (np.abs(world.max(axis=0) - hi) <= c.bound).all()
        if c.family == "exact":
            assert (world.min(axis=0) == lo).all() and (world.max(axis=0) == hi).all()
    one = np.array([[3.0, -4.0, 0.0]])
    bound = rounding_bound(one, (np.eye(3), np.array([1.0, 0.0, 0.0])))
    assert bound[0] == pytest.approx(GAMMA_4 * 4.0, rel=1e-14)
    assert bound[1] == pytest.approx(GAMMA_4 * 4.0, rel=1e-14)


def test_signed_permutations_are_the_24_exact_rotations():
    rotations = signed_permutations()
    assert len(rotations) == 24
    assert len({r.tobytes() for r in rotations}) == 24
    for r in rotations:
        assert np.array_equal(r.T @ r, np.eye(3)) and round(np.linalg.det(r)) == 1


def test_ode_problems_satisfy_their_equations():
    for problem in order_problems():
        for t in (0.3, 1.1):
            d = 1e-5
            slope = (problem.exact(t + d) - problem.exact(t - d)) / (2 * d)
            np.testing.assert_allclose(slope, problem.f(t, problem.exact(t)), rtol=1e-8,
                                       atol=1e-8)
        np.testing.assert_allclose(problem.exact(problem.t0), problem.y0, rtol=1e-15)
    assert logistic().exact(2.0)[0] == pytest.approx(1 / (1 + 9 * math.exp(-2)), rel=1e-15)
    assert time_dependent().exact(2.0)[0] == pytest.approx(math.exp(math.sin(2.0)), rel=1e-15)
    assert STABILITY_POINTS[0] == 0.0 and STABILITY_POINTS[-1] == -5.0


def test_fitted_order_recovers_a_power_law():
    steps = [0.1, 0.05, 0.025, 0.0125]
    assert fitted_order(steps, [3 * h ** 2 for h in steps]) == pytest.approx(2.0, abs=1e-12)
    # points at the rounding floor are left out; fewer than two: no order
    assert fitted_order(steps, [1e-3, 1e-13, 1e-14, 1e-15]) is None
    assert fitted_order(steps, [h ** 4 for h in steps]) == pytest.approx(4.0, abs=1e-12)
    assert 1e-4 ** 4 < ERROR_FLOOR
    assert math.isnan(fitted_order(steps, [1.0, math.inf, 1.0, 1.0]))


def test_rigid_scenes_and_their_tolerances():
    cases = R.rigid_cases()
    names = [s.name for s in cases.scenes]
    assert names == ["drop-sphere-e0.5", "drop-sphere-e0.8", "drop-cube-e0.5", "drop-cube-e0.8",
                     "drop-icosahedron-e0.8", "oblique-sphere", "oblique-rolling",
                     "oblique-spin-e1", "oblique-backspin", "oblique-e0", "spin-cube", "rest-cube",
                     "free-brick", "strike-e1", "strike-e0.5", "offset-stack", "cantilever",
                     "board", "incline-slide", "incline-stick", "incline-mu1.5", "cradle-e1",
                     "cradle-e0.5", "slide-ball", "slide-box", "tumble-brick"]
    for scene in cases.of_kind("drop"):
        body = scene.scene.bodies[0]
        vertices = R._body(body.model.name)[0]
        assert body.position[1] + vertices[:, 1].min() + R.HALF_SIZE == pytest.approx(2.0)
        assert scene.scene.integration.step == 1e-3
    drops = {s.name: s for s in cases.of_kind("drop")}
    # CONTACT_STEPS h sqrt(2 g / h_K) / K with h_K = e^6 h0
    assert apex_tolerance(drops["drop-sphere-e0.5"]) == pytest.approx(
        2e-3 * math.sqrt(2 * 9.81 / (2.0 / 64)) / 3)
    assert apex_tolerance(drops["drop-cube-e0.8"]) == pytest.approx(0.00408, abs=1e-5)
    spin = cases.of_kind("spin")[0]
    # 2 w0 I / (mu m g r): I = 1/6, r = 0.3826 for the unit cube
    assert spin_rest_time(spin) == pytest.approx(2 * 5.0 / 6 / (0.5 * 9.81 * 0.382597858),
                                                 rel=1e-6)
    rest = cases.of_kind("rest")[0]
    assert energy_tolerance(rest) == pytest.approx(2 * 9.81 * 9.81e-3 * 1e-3)


def test_the_inclines_and_their_answers():
    """g (sin a - mu cos a) t^2 / 2 sliding (30 degrees, mu 0.3: 1.178 m in
    1 s), 0 sticking; the tolerance (a / 2 + 2 g) h t, and the block rests
    on the floor under gravity tilted by the angle."""
    inclines = {s.name: s for s in R.rigid_cases().of_kind("incline")}
    slide = inclines["incline-slide"]
    a = 9.81 * (0.5 - 0.3 * math.sqrt(3) / 2)
    assert R.incline_answer(slide) == pytest.approx(a / 2)
    assert incline_tolerance(slide) == pytest.approx((a / 2 + 2 * 9.81) * 1e-3)
    assert R.incline_answer(inclines["incline-stick"]) == 0.0
    assert R.incline_answer(inclines["incline-mu1.5"]) == 0.0
    world = slide.scene.world
    assert world.gravity_vector == pytest.approx((9.81 / 2, -9.81 * math.sqrt(3) / 2, 0.0))
    assert world.mu == 0.3 and inclines["incline-mu1.5"].scene.world.mu == 1.5
    block = slide.scene.bodies[0]
    assert block.position[1] - 0.25 == -R.HALF_SIZE


def test_the_strike_and_its_impulse_solution():
    """J = (1 + e) v / (1/m + 1/M + d^2 / I), the rod's I = M (4^2 +
    0.25^2) / 12 about z, masses 1, d = 1.5, v = 2; the ball 1.07 cm above
    the face, its lowest vertex straight below its centre."""
    strike = {s.name: s for s in R.rigid_cases().of_kind("strike")}
    inertia = (16.0 + 0.0625) / 12.0
    for name, e in (("strike-e1", 1.0), ("strike-e0.5", 0.5)):
        J = (1.0 + e) * 2.0 / (2.0 + 2.25 / inertia)
        answer = R.strike_answer(strike[name])
        assert answer == pytest.approx({"rod_velocity": -J, "rod_spin": -1.5 * J / inertia,
                                        "ball_velocity": -2.0 + J}, rel=1e-12)
        rod, ball = strike[name].scene.bodies
        lowest = ball.position[1] + ball.scale * R._body(ball.model.name)[0][:, 1].min()
        assert lowest - 0.125 == pytest.approx(0.0107)
        assert strike[name].scene.world.gravity == 0.0
        assert strike[name].scene.world.friction == 0.0


def test_the_cradles_and_their_chain_of_binary_impacts():
    """Equal balls in a row along x, 2.7 mm apart, the first at 1 m/s, no
    gravity, no friction: at e = 1 three balls leave the last at 1 m/s; at
    e = 0.5 two leave at v (1 - e) / 2 and v (1 + e) / 2; a row of three at
    e < 1 strikes again and is refused."""
    cradles = {s.name: s for s in R.rigid_cases().of_kind("cradle")}
    assert R.cradle_answer(cradles["cradle-e1"]) == [0.0, 0.0, 1.0]
    assert R.cradle_answer(cradles["cradle-e0.5"]) == [0.25, 0.75]
    for cradle in cradles.values():
        scene = cradle.scene
        assert scene.world.gravity == 0.0 and scene.world.friction == 0.0
        assert scene.world.restitution == cradle.e
        balls = scene.bodies
        assert [b.velocity for b in balls] == [(1.0, 0.0, 0.0)] + [(0.0, 0.0, 0.0)] * (
            len(balls) - 1)
        assert all(b.mass == 1.0 and b.position[1:] == (0.0, 0.0) for b in balls)
        for a, b in zip(balls[:-1], balls[1:], strict=True):
            right = a.position[0] + a.scale * R._body(a.model.name)[0][:, 0].max()
            left = b.position[0] + b.scale * R._body(b.model.name)[0][:, 0].min()
            assert left - right == pytest.approx(0.0027)
    three = replace(cradles["cradle-e1"], e=0.5)
    with pytest.raises(ValueError, match="strikes again"):
        R.cradle_answer(three)


def test_the_stacks_rest_on_each_other_with_their_centres_over_the_support():
    for stack in R.rigid_cases().of_kind("stack"):
        base, top = stack.scene.bodies
        v_base = R._body(base.model.name)[0] + base.position
        v_top = R._body(top.model.name)[0] + top.position
        assert v_base[:, 1].min() == pytest.approx(-R.HALF_SIZE)          # on the floor
        assert v_top[:, 1].min() == pytest.approx(v_base[:, 1].max())     # on the base
        # the top's centre of mass (its mesh origin) over the base's top face
        assert v_base[:, 0].min() < top.position[0] < v_base[:, 0].max()
        assert stack.scene.integration.duration == pytest.approx(0.5)


def test_free_brick_and_its_closed_form():
    free = R.rigid_cases().of_kind("free")[0]
    assert free.scene.world.gravity == 0.0
    assert free.scene.bodies[0].model.name == "brick.ac"
    closed = R.free_body(free)
    # the uniform box's moments m (b^2 + c^2) / 12 of its 1 x 0.6 x 0.3 sides
    assert closed.moments == pytest.approx(((0.36 + 0.09) / 12, (1 + 0.09) / 12,
                                            (1 + 0.36) / 12), rel=1e-12)
    assert closed.omega0 == (0.1, 10.0, 0.1)
    assert closed.flips(12.0) == 5
    assert closed.flip_interval == pytest.approx(2.43573, rel=1e-5)


def test_free_rotation_check_passes_the_corrected_model_and_fails_a_still_body():
    from refsim.conformance.checks_rotation import check_rigid_free_rotation
    from refsim.engines.refsim_engines import corrected

    cases = R.RigidCases(scenes=tuple(R.rigid_cases().of_kind("free")))
    result = check_rigid_free_rotation(corrected(), cases)
    measured = result.measured["free-brick"]
    assert (result.failed, measured["flips"]) == (0, 5)
    assert measured["energy_drift"] < 1e-5 and measured["momentum_drift"] < 1e-10
    still = check_rigid_free_rotation(_Still(), cases)
    assert still.failed == 1 and still.examples[0]["class"] == "bug"
    assert still.measured["free-brick"]["flips"] == 0


class _Still:
    """An engine whose bodies never move (to test the trajectory readers)."""

    name = "still"

    def simulate(self, scene):
        from refsim.dynamics.trajectory import Trajectory

        body = scene.bodies[0]
        n = 5
        return Trajectory(t=np.arange(n) * 0.1,
                          position=np.tile(np.array(body.position), (n, 1, 1)),
                          velocity=np.zeros((n, 1, 3)), angular_velocity=np.zeros((n, 1, 3)),
                          orientation=np.tile(np.eye(3), (n, 1, 1, 1)), names=("body",))


def test_trajectory_readers_on_a_body_at_rest():
    cases = R.rigid_cases()
    rest = cases.of_kind("rest")[0]
    trajectory = cases.run(_Still(), rest)
    np.testing.assert_allclose(R.lowest_height(rest, trajectory), 0.0, atol=1e-15)
    # the cube's centre is 0.5 above the floor: E = m g 0.5
    np.testing.assert_allclose(R.energy(rest, trajectory), 9.81 * 0.5, rtol=1e-14)
    engine = _Still()
    assert cases.run(engine, rest) is cases.run(engine, rest)       # one run per engine
