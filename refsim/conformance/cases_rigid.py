"""Rigid-body scenes with analytic answers (seeds S5, S7, S9; capability ``rigid``).

What: a fixed set of scenes of one or two bodies in the world cube (half size 5 m,
g = 9.81, step 1e-3 s, RK4 where the engine uses the scene's solver, no
drag), each with the answer :mod:`refsim.dynamics.analytic` gives for it:

=====================  =====================================================
scene                  what happens, and the answer
=====================  =====================================================
drop-sphere-e0.5/0.8   the sphere-2k model dropped from rest, its lowest
drop-cube-e0.5/0.8     point 2 m above the floor (the cube face down, the
drop-icosahedron-e0.8  icosahedron on an edge): apex heights e^(2k) h0,
                       apex ratio e^2; each lands on a vertex, face or edge
                       straight below its centre of mass, so no impulse has
                       a moment about it and the body does not turn
oblique-*              the sphere striking the floor obliquely, in every
                       regime of Coulomb friction over the whole impact:
                       ``oblique-sphere`` (5 cm up, (5, -2, 0) m/s, mu 0.3,
                       e 0.8) slides throughout; ``oblique-rolling`` ((2,
                       -2, 0)) leaves rolling; ``oblique-spin-e1`` (spin
                       only, 3 rad/s, mu 0.1, e 1) slides throughout;
                       ``oblique-backspin`` ((0.2, -1, 0), 3 rad/s of
                       backspin, mu 0.4, e 0.5) slides throughout and its
                       lateral velocity reverses; ``oblique-e0`` ((3, -2,
                       0), e 0) slides, then stays on the floor. The answer
                       (lateral velocity and spin after the impact) is
                       :func:`refsim.dynamics.analytic.oblique_impact_ball`
                       with the mesh's own inertia and its lowest vertex's
                       depth below the centre
spin-cube              the cube resting face down, spinning at 5 rad/s about
                       the vertical, mu = 0.5: friction brings it to rest
rest-cube              the cube resting face down, mu = 0.5: it stays on
                       the floor
free-brick             the brick (1 x 0.6 x 0.3 m, three different moments)
                       in the middle of the cube without gravity, spun at
                       10 rad/s about its middle axis with 0.1 rad/s about
                       each of the others: torque-free, it flips over every
                       2.436 s (Euler's equations in closed form,
                       :class:`refsim.dynamics.free_body.FreeBody`), 5 times
                       in 12 s, with constant energy
strike-e1, strike-e0.5 a ball (the sphere-2k model scaled to radius 0.25)
                       falling at 2 m/s on a free rod (long-box, 4 x 0.25 x
                       0.25 m) 1.5 m from its centre, no gravity, no
                       friction: one impact at one point, whose impulse
                       ``J = (1 + e) v / (1/m + 1/M + d^2 / I)`` gives the
                       rod's velocity and spin and the ball's velocity
                       (:func:`strike_answer`); the ball does not spin, and
                       the angular momentum about any fixed point is kept
offset-stack           resting contact between bodies, e 0.5, mu 0.5, 0.5 s:
cantilever             a cube on a cube 0.3 m off its centre; a rod on a cube
board                  overhanging it by 1.9 m with its centre 0.4 m from the
                       cube's; a cube on a rod lying on the floor, 1.5 m from
                       the rod's centre. Each is statically stable (every
                       centre of mass over its support): nothing moves
incline-*              a 1 x 0.5 x 1 m block (``shape = "box"``) resting on
                       the floor under gravity tilted by the incline's
                       angle (``world.gravity_direction``), Coulomb's mu
                       from ``world.mu``, 1 s from rest: ``incline-slide``
                       (30 degrees, mu 0.3) slides ``g (sin a - mu cos a)
                       t^2 / 2`` = 1.178 m; ``incline-stick`` (10 degrees,
                       mu 0.3) and ``incline-mu1.5`` (50 degrees, mu 1.5,
                       above 1) stay (tan a < mu)
cradle-e1, cradle-e0.5 Newton's cradle: a row along x of equal balls (the
                       sphere-2k model scaled to radius 0.25, mass 1), no
                       gravity, no friction, 2.7 mm between neighbours, the
                       first moving at 1 m/s toward the others: three balls
                       at e = 1 leave the last at 1 m/s and the others at
                       rest; two at e = 0.5 leave at 0.25 and 0.75 m/s
                       (:func:`cradle_answer`)
slide-ball, slide-box   a body set sliding on the floor at 3 m/s without
                       spin, Coulomb's mu 0.3, e = 0 (it stays on the floor):
                       friction decelerates the centre at mu g while the
                       contact slips; the sphere rolls from ``t* = v0 / (mu g
                       (1 + d^2 / k^2))`` on at ``v0 / (1 + k^2 / d^2)`` (2 v0
                       / (7 mu g) and 5/7 v0 for a smooth solid ball), the
                       cube stops at ``v0 / (mu g)`` after ``v0^2 / (2 mu
                       g)`` (:func:`slide_answer`)
tumble-brick           the brick dropped spinning at (1, 3, 2) rad/s, its
                       lowest vertex 2.7 m above the floor, e = 1, no
                       friction, 5 s: every impact is elastic and no force
                       but gravity's does work, so the mechanical energy
                       stays
=====================  =====================================================

Two choices keep the answers exact for every reasonable engine:

- the drop height is 2 m, so that the first impact (6.3 m/s) moves the
  sphere-2k model at most 6.3 mm in a step of 1e-3 s, less than the 7.4 mm
  between its lowest vertex and the next ring of vertices: the first contact
  is one vertex straight below the centre (no torque); from 4 m a step can
  carry the ring into the floor too, and a contact solver that treats the
  ring's vertices one after another spins the sphere.

The state's meaning (:mod:`refsim.dynamics.trajectory`, for scenes and
trajectories alike): ``position`` is the mesh origin's, ``velocity`` the
centre of mass's, ``angular_velocity`` in the world frame.

Reading a trajectory (:func:`lowest_height`, :func:`energy`): the height of
the body's lowest vertex above the floor in every frame (from the frame's
orientation, so a turning body is read correctly); apexes as
:func:`refsim.studies.bounce_scenes.read_bounces` reads them (bounce where the
vertical velocity turns upward, apex refined by the parabola through its
frame and the neighbours); the energy from the centre of mass's height and
velocity and ``w . I w / 2`` with the uniform solid's inertia.

A run of each scene is kept per engine (:meth:`RigidCases.run`), so the
checks share it; ``rerun`` runs a scene again for the determinism check.

The incline scenes use keys beyond the seed's world: an engine (or refsim's
seed model) that cannot pose them refuses the scene
(:class:`refsim.errors.UnposableKey`) and the check reports it as not
posed, with the key.

Cost: about 37,540 steps per engine in all (the drops are 1.8 to 3.0 s of
simulated time, the free brick 12 s, the tumbling brick 5 s, the slides 0.4
and 1.2 s, the cradles 20 ms), and 1,700 more for the determinism check's
reruns.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field, replace
from types import SimpleNamespace
from typing import TYPE_CHECKING

import numpy as np

from refsim.dynamics import analytic

if TYPE_CHECKING:
    from refsim.scenes.schema import Scene

HALF_SIZE = 5.0
GRAVITY = 9.81
STEP = 1e-3
SOLVER = "rk4"
SPHERE = "sphere-2k.ac"
CUBE = "cube.ac"
ICOSAHEDRON = "icosahedron.ac"
#: Drop height of the lowest point above the floor, metres (module docstring).
DROP_HEIGHT = 2.0
#: Bounces whose apex ratio is read (geometric mean over them).
BOUNCES = 3
RESTITUTIONS = (0.5, 0.8)
#: The oblique bounce (refsim.studies.bounce's first case, from 5 cm).
OBLIQUE_VELOCITY = (5.0, -2.0, 0.0)
OBLIQUE_HEIGHT = 0.05
OBLIQUE_FRICTION = 0.3
OBLIQUE_E = 0.8
#: The oblique impacts: name, velocity (m/s), spin about z (rad/s; positive
#: moves the contact point along +x), height of the lowest point (m), mu, e.
#: The spinning ones start one step's fall up and spin slowly: the mesh
#: turns little before its lowest vertex lands, whose lever off the vertical
#: (and the spin's share of its normal speed, ``|w|`` times that lever) the
#: check allows for (:mod:`refsim.conformance.checks_bounces`).
OBLIQUE_IMPACTS = (
    ("oblique-sphere", OBLIQUE_VELOCITY, 0.0, OBLIQUE_HEIGHT, OBLIQUE_FRICTION, OBLIQUE_E),
    ("oblique-rolling", (2.0, -2.0, 0.0), 0.0, OBLIQUE_HEIGHT, 0.3, 0.8),
    ("oblique-spin-e1", (0.0, -2.0, 0.0), 3.0, 0.002, 0.1, 1.0),
    ("oblique-backspin", (0.2, -1.0, 0.0), 3.0, 0.001, 0.4, 0.5),
    ("oblique-e0", (3.0, -2.0, 0.0), 0.0, OBLIQUE_HEIGHT, 0.3, 0.0),
)
#: The spinning cube: angular speed about the vertical (rad/s), friction.
SPIN = 5.0
SPIN_FRICTION = 0.5
SPIN_E = 0.5
SPIN_DURATION = 1.5
REST_DURATION = 1.0
BRICK = "brick.ac"
#: The free brick: its angular velocity in its own axes (rad/s; y is the
#: middle axis), and how long it turns.
FREE_SPIN = (0.1, 10.0, 0.1)
FREE_DURATION = 12.0

#: The strike (module docstring): the rod, the ball's scale (radius, m), its
#: closing speed (m/s), its distance from the rod's centre (m), the gap it
#: falls first (m; not a whole number of steps' travel, so that an engine
#: finds the contact with the ball 1.3 mm into the rod, as it would any
#: impact), the run (s, the impact at about 5 ms) and its e.
ROD = "long-box.ac"
ROD_HALF_WIDTH = 0.125
BALL_SCALE = 0.25
STRIKE_SPEED = 2.0
STRIKE_OFFSET = 1.5
STRIKE_GAP = 0.0107
STRIKE_DURATION = 0.1
STRIKE_RESTITUTIONS = (1.0, 0.5)

#: The resting stacks (module docstring): restitution, friction, run (s),
#: and the bodies, each lowest face on the floor or on the body below.
STACK_E = 0.5
STACK_MU = 0.5
STACK_DURATION = 0.5
_FLOOR = -HALF_SIZE
STACKS = (
    ("offset-stack", ({"name": "base", "model": CUBE, "position": [0.0, _FLOOR + 0.5, 0.0]},
                      {"name": "top", "model": CUBE, "position": [0.3, _FLOOR + 1.5, 0.0]})),
    ("cantilever", ({"name": "base", "model": CUBE, "position": [0.0, _FLOOR + 0.5, 0.0]},
                    {"name": "top", "model": ROD, "position": [0.4, _FLOOR + 1.125, 0.0]})),
    ("board", ({"name": "base", "model": ROD, "position": [0.0, _FLOOR + 0.125, 0.0]},
               {"name": "top", "model": CUBE, "position": [1.5, _FLOOR + 0.75, 0.0]})),
)


#: The inclines (module docstring): name, angle (degrees), mu; and the run (s).
INCLINES = (("incline-slide", 30.0, 0.3), ("incline-stick", 10.0, 0.3),
            ("incline-mu1.5", 50.0, 1.5))
INCLINE_DURATION = 1.0
INCLINE_BLOCK = (1.0, 0.5, 1.0)
INCLINE_START_X = -3.0


#: Newton's cradle (module docstring, :func:`cradle_answer`): name, balls,
#: e; the balls' scale (radius, m), the gap between neighbours (m; not a
#: whole number of steps' travel, so that an engine finds each contact
#: 0.3 mm deep, as it would any impact), the first ball's speed (m/s) and
#: the run (s: the pulse crosses three balls in 5.4 ms; the rest lets a
#: contact an engine resolves over ten steps end before the run does).
CRADLES = (("cradle-e1", 3, 1.0), ("cradle-e0.5", 2, 0.5))
CRADLE_SCALE = 0.25
CRADLE_GAP = 0.0027
CRADLE_SPEED = 1.0
CRADLE_DURATION = 0.02

#: The slides (module docstring, :func:`slide_answer`): name, model, speed
#: (m/s, along +x), mu, e, run (s: the ball's slip ends at 0.29 s, the cube
#: stops at 1.02 s; each run goes on a little past that).
SLIDES = (("slide-ball", SPHERE, 3.0, 0.3, 0.0, 0.4),
          ("slide-box", CUBE, 3.0, 0.3, 0.0, 1.2))

#: The elastic tumble (module docstring): the brick's start (its lowest
#: vertex's height, m; its centre 3 m above the floor), its spin (rad/s, world
#: axes) and the run (s). Five seconds hold six to eight floor impacts in
#: refsim, Bullet and MuJoCo; ten double the run for every engine and change
#: one verdict only (docs/decisions/textbook-checks.md).
TUMBLE_HEIGHT = 2.7
TUMBLE_SPIN = (1.0, 3.0, 2.0)
TUMBLE_DURATION = 5.0


@dataclass(frozen=True)
class RigidScene:
    """One scene of the set: its name, kind ("drop", "oblique", "spin",
    "rest", "free", "strike", "stack", "incline", "cradle", "slide",
    "tumble"), the scene, and the
    parameters its answer needs (``angle``: an incline's, degrees)."""

    name: str
    kind: str
    scene: Scene
    e: float
    friction: float = 0.0
    height: float = 0.0
    angle: float = 0.0

    def to_dict(self) -> dict:
        if len(self.scene.bodies) > 1:
            return {"scene": self.name, "kind": self.kind, "restitution": self.e,
                    "friction": self.friction,
                    "bodies": [{"model": b.model.name, "scale": b.scale,
                                "position": list(b.position), "velocity": list(b.velocity),
                                "angular_velocity": list(b.angular_velocity)}
                               for b in self.scene.bodies],
                    "step": self.scene.integration.step,
                    "duration": self.scene.integration.duration}
        body = self.scene.bodies[0]
        extra = {}
        if self.kind == "incline":
            extra = {"incline_degrees": self.angle, "mu": self.friction,
                     "gravity_direction": list(self.scene.world.gravity_direction)}
        return {"scene": self.name, "kind": self.kind, "model": body.model.name, **extra,
                "restitution": self.e, "friction": self.friction,
                "position": list(body.position), "velocity": list(body.velocity),
                "angular_velocity": list(body.angular_velocity),
                "step": self.scene.integration.step,
                "duration": self.scene.integration.duration}


def _touch_y(model: str) -> float:
    """``y`` of the mesh origin when its lowest vertex is on the floor."""
    from refsim.conformance.cases_meshes import bundled_mesh

    return -HALF_SIZE - float(bundled_mesh(model).vertices[:, 1].min())


def _scene(model: str, e: float, friction: float, height: float, duration: float,
           velocity=(0.0, 0.0, 0.0), angular_velocity=(0.0, 0.0, 0.0)):
    """One body, its lowest vertex ``height`` above the floor, level "aabb"
    (one body: no body contact to find)."""
    return _bodies_scene([{"name": "body", "model": model,
                           "position": [0.0, _touch_y(model) + height, 0.0],
                           "velocity": [float(c) for c in velocity],
                           "angular_velocity": [float(c) for c in angular_velocity]}],
                         GRAVITY, e, friction, duration, level="aabb")


def oblique_impact_speed(v_y: float = OBLIQUE_VELOCITY[1],
                         height: float = OBLIQUE_HEIGHT) -> float:
    """Normal speed at an oblique scene's impact: ``v_y`` (< 0) after a fall
    of ``height``."""
    return math.sqrt(v_y * v_y + 2.0 * GRAVITY * height)


def oblique_answer(scene: RigidScene) -> tuple[float, float, float]:
    """``(v_n, v_t', w_z')`` of an oblique scene: the impact speed and
    :func:`refsim.dynamics.analytic.oblique_impact_ball` with the sphere
    mesh's own moment of inertia (about z, for the scene's mass) and the
    depth of its lowest vertex below the centre of mass."""
    vertices, center, inertia = _body(_model(scene))
    body = scene.scene.bodies[0]
    v_n = oblique_impact_speed(body.velocity[1], scene.height)
    radius = float(center[1] - vertices[:, 1].min())
    v_t, w = analytic.oblique_impact_ball(
        body.velocity[0], body.angular_velocity[2], v_n, scene.friction, scene.e, radius,
        body.mass, body.mass * float(inertia[2, 2]))
    return v_n, v_t, w


def rigid_scenes() -> tuple[RigidScene, ...]:
    """The scenes of the module docstring, in order."""
    scenes = []
    drops = [(SPHERE, "sphere", e) for e in RESTITUTIONS]
    drops += [(CUBE, "cube", e) for e in RESTITUTIONS] + [(ICOSAHEDRON, "icosahedron", 0.8)]
    for model, label, e in drops:
        duration = (analytic.apex_times(DROP_HEIGHT, GRAVITY, e, BOUNCES)[-1]
                    + 0.5 * analytic.fall_time(DROP_HEIGHT * e ** (2 * BOUNCES), GRAVITY)
                    + 0.05)
        scenes.append(RigidScene(f"drop-{label}-e{e}", "drop",
                                 _scene(model, e, 0.0, DROP_HEIGHT, duration), e,
                                 height=DROP_HEIGHT))
    for name, velocity, spin, height, mu, e in OBLIQUE_IMPACTS:
        v_imp = oblique_impact_speed(velocity[1], height)
        # to the middle of the flight after the first bounce (e = 0: as long
        # as the fall, sliding on the floor)
        duration = (v_imp + velocity[1]) / GRAVITY + max(e, 0.5) * v_imp / GRAVITY
        scenes.append(RigidScene(name, "oblique",
                                 _scene(SPHERE, e, mu, height, duration, velocity=velocity,
                                        angular_velocity=(0.0, 0.0, spin)),
                                 e, mu, height))
    scenes.append(RigidScene("spin-cube", "spin",
                             _scene(CUBE, SPIN_E, SPIN_FRICTION, 0.0, SPIN_DURATION,
                                    angular_velocity=(0.0, SPIN, 0.0)),
                             SPIN_E, SPIN_FRICTION))
    scenes.append(RigidScene("rest-cube", "rest",
                             _scene(CUBE, SPIN_E, SPIN_FRICTION, 0.0, REST_DURATION),
                             SPIN_E, SPIN_FRICTION))
    scenes.append(RigidScene("free-brick", "free", _free_scene(), 1.0))
    for e in STRIKE_RESTITUTIONS:
        scenes.append(RigidScene(f"strike-e{e:g}", "strike", _strike_scene(e), e))
    for name, bodies in STACKS:
        scenes.append(RigidScene(name, "stack", _bodies_scene(bodies, GRAVITY, STACK_E, STACK_MU,
                                                              STACK_DURATION),
                                 STACK_E, STACK_MU))
    for name, angle, mu in INCLINES:
        scenes.append(RigidScene(name, "incline", _incline_scene(angle, mu), 0.0, mu,
                                 angle=angle))
    for name, balls, e in CRADLES:
        scenes.append(RigidScene(name, "cradle", _cradle_scene(balls, e), e))
    for name, model, speed, mu, e, duration in SLIDES:
        scenes.append(RigidScene(name, "slide",
                                 _scene(model, e, mu, 0.0, duration, velocity=(speed, 0.0, 0.0)),
                                 e, mu))
    scenes.append(RigidScene("tumble-brick", "tumble",
                             _scene(BRICK, 1.0, 0.0, TUMBLE_HEIGHT, TUMBLE_DURATION,
                                    angular_velocity=TUMBLE_SPIN),
                             1.0, 0.0, TUMBLE_HEIGHT))
    return tuple(scenes)


def slide_answer(scene: RigidScene) -> dict[str, float]:
    """The slide's closed form: the body moves along x at ``v0`` without
    spin, its lowest point on the floor, under Coulomb's kinetic friction
    ``mu m g`` against the slip of its contact point (Kleppner & Kolenkow,
    *An Introduction to Mechanics*, the bowling ball that slides into
    rolling; Goldstein, *Classical Mechanics*, rigid-body motion).

    - The centre decelerates at ``mu g`` while the contact slips.
    - The sphere: the friction's moment ``mu m g d`` about the centre (``d``
      the depth of the contact below it) spins it up at ``mu g d / k^2``
      (``I = m k^2``), so the slip ``v + w d`` falls at ``mu g (1 + d^2 /
      k^2)``: it ends at ``t* = v0 / (mu g (1 + d^2 / k^2))``, and the ball
      rolls on at ``v0 / (1 + k^2 / d^2)``. With ``k^2 = 2/5 d^2`` (a smooth
      solid ball) that is ``2 v0 / (7 mu g)`` and ``5/7 v0``; here ``k`` is
      the sphere mesh's own (its uniform solid's moment about z) and ``d``
      its lowest vertex's depth below the centre of mass, as in
      :func:`oblique_answer`.
    - The cube slides on its face, which cannot roll: it stops at ``t* = v0
      / (mu g)`` after ``v0^2 / (2 mu g)`` and stays.

    Keys: ``deceleration``, ``slip_end_time``, ``speed_after`` (the
    centre's speed once the slip has ended), ``depth`` (``d``) and, for the
    cube, ``distance``."""
    vertices, center, inertia = _body(_model(scene))
    body = scene.scene.bodies[0]
    v0 = float(body.velocity[0])
    a = scene.friction * GRAVITY
    depth = float(center[1] - vertices[:, 1].min())
    if _model(scene) == SPHERE:
        ratio = depth * depth / float(inertia[2, 2])           # d^2 / k^2
        return {"deceleration": a, "slip_end_time": v0 / (a * (1.0 + ratio)),
                "speed_after": v0 / (1.0 + 1.0 / ratio), "depth": depth}
    return {"deceleration": a, "slip_end_time": v0 / a, "speed_after": 0.0, "depth": depth,
            "distance": v0 * v0 / (2.0 * a)}


def _cradle_scene(balls: int, e: float):
    """``balls`` equal balls in a row along x, centred on the origin,
    CRADLE_GAP apart, the first (the most negative x) moving at
    CRADLE_SPEED along +x; no gravity, no friction, restitution ``e``."""
    pitch = 2.0 * CRADLE_SCALE + CRADLE_GAP
    first = -0.5 * (balls - 1) * pitch
    return _bodies_scene([
        {"name": f"ball{i + 1}", "model": SPHERE, "scale": CRADLE_SCALE,
         "position": [first + i * pitch, 0.0, 0.0],
         "velocity": [CRADLE_SPEED if i == 0 else 0.0, 0.0, 0.0]}
        for i in range(balls)], 0.0, e, 0.0, CRADLE_DURATION)


def cradle_answer(scene: RigidScene) -> list[float]:
    """The balls' velocities along the row after Newton's cradle, in order.

    The balls start apart, so the impacts are a sequence of binary head-on
    impacts, each of two equal masses, of which one is at rest, at one point
    on their line of centres: Newton's law of restitution gives ``v1' = v (1
    - e) / 2``, ``v2' = v (1 + e) / 2`` (Kleppner & Kolenkow, *An
    Introduction to Mechanics*, collisions in one dimension; Stronge,
    *Impact Mechanics*, 2000, ch. 2). At e = 1 each
    impact hands the whole velocity on: the last ball leaves at v, the
    others rest, momentum and energy are kept. With e < 1 a struck ball
    leaves slower than its striker arrived, which still moves, and strikes
    again later: the final state is a longer sequence, so the e < 1 case
    has two balls, one impact.

    Touching balls would make the answer depend on the contact model: a row
    in contact transmits the pulse by its compliance (Hertzian contact
    disperses it and the last ball does not leave alone), and a
    simultaneous impact at several contacts has no answer from the
    coefficient of restitution alone: it depends on how the contact model
    orders or couples the contacts (R. M. Brach, *Mechanical Impact
    Dynamics*, 1991; Stronge, *Impact Mechanics*; F. Herrmann and P.
    Schmalzle, Am. J. Phys. 49, 761, 1981). The gaps make each impact one
    pair's, at its own time."""
    balls = len(scene.scene.bodies)
    v = [CRADLE_SPEED] + [0.0] * (balls - 1)
    if balls > 2 and scene.e != 1.0:
        raise ValueError(f"{scene.name}: a cradle of {balls} balls at e = {scene.e} strikes "
                         f"again after the first pass; its answer is not posed here")
    for i in range(balls - 1):
        u = v[i]
        v[i], v[i + 1] = u * (1.0 - scene.e) / 2.0, u * (1.0 + scene.e) / 2.0
    return v


def _incline_scene(angle: float, mu: float):
    """The block resting on the floor under gravity tilted by ``angle``
    degrees about z (down the slope is +x), e = 0, Coulomb's ``mu``."""
    from refsim.scenes.loader import scene_from_dict
    from refsim.solvers.integrate import covering_duration

    a = math.radians(angle)
    return scene_from_dict({
        "world": {"half_size": HALF_SIZE, "gravity": GRAVITY,
                  "gravity_direction": [math.sin(a), -math.cos(a), 0.0], "drag": 0.0,
                  "restitution": 0.0, "mu": mu},
        "integration": {"solver": SOLVER, "step": STEP,
                        "duration": covering_duration(INCLINE_DURATION, STEP)},
        "collision": {"level": "aabb"},
        "body": [{"name": "block", "shape": "box", "size": list(INCLINE_BLOCK),
                  "position": [INCLINE_START_X, _FLOOR + 0.5 * INCLINE_BLOCK[1], 0.0]}]})


def incline_answer(scene: RigidScene) -> float:
    """How far the incline's block travels down the slope in the scene's
    duration from rest: ``g (sin a - mu cos a) t^2 / 2`` when ``tan a > mu``
    (sliding, Coulomb's kinetic friction), else 0 (static friction holds
    it). Kleppner & Kolenkow, *An Introduction to Mechanics*, 2nd ed.,
    section 3.3."""
    a = math.radians(scene.angle)
    along = GRAVITY * (math.sin(a) - scene.friction * math.cos(a))
    t = scene.scene.integration.duration
    return max(along, 0.0) * t * t / 2.0


def _bodies_scene(bodies, gravity: float, e: float, mu: float, duration: float,
                  level: str = "exact"):
    """A scene of the given bodies (``[[body]]`` tables), by default at the
    exact level."""
    from refsim.scenes.loader import scene_from_dict
    from refsim.solvers.integrate import covering_duration

    return scene_from_dict({
        "world": {"half_size": HALF_SIZE, "gravity": gravity, "drag": 0.0,
                  "restitution": e, "friction": mu},
        "integration": {"solver": SOLVER, "step": STEP,
                        "duration": covering_duration(duration, STEP)},
        "collision": {"level": level},
        "body": [dict(b) for b in bodies]})


def _strike_scene(e: float):
    """The ball above the rod's top face, STRIKE_OFFSET from its centre,
    STRIKE_GAP apart, falling at STRIKE_SPEED; no gravity, no friction."""
    return _bodies_scene([
        {"name": "rod", "model": ROD},
        {"name": "ball", "model": SPHERE, "scale": BALL_SCALE,
         "position": [STRIKE_OFFSET, ROD_HALF_WIDTH + BALL_SCALE + STRIKE_GAP, 0.0],
         "velocity": [0.0, -STRIKE_SPEED, 0.0]}], 0.0, e, 0.0, STRIKE_DURATION)


def strike_answer(scene: RigidScene) -> dict[str, float]:
    """The strike's velocities after the impact: Newton's impact law at one
    frictionless point (Stronge, *Impact Mechanics*, 2000, ch. 2; Mirtich
    1996, 3.3), normal impulse ``J = (1 + e) v / (1/m + 1/M + d^2 / I)``
    with the closing speed v, the rod's mass M, its moment I about the
    axis across its length and the face normal, and the lever d; the
    ball's lever lies along the normal (its lowest vertex is straight below
    its centre), so it takes no spin. From the uniform solids' mass
    properties of the meshes (the ball's scaled)."""
    _, _, rod_inertia = _body(ROD)
    rod, ball = scene.scene.bodies
    inertia = rod.mass * float(rod_inertia[2, 2])
    J = ((1.0 + scene.e) * STRIKE_SPEED
         / (1.0 / ball.mass + 1.0 / rod.mass + STRIKE_OFFSET ** 2 / inertia))
    return {"rod_velocity": -J / rod.mass, "rod_spin": -J * STRIKE_OFFSET / inertia,
            "ball_velocity": -STRIKE_SPEED + J / ball.mass}


def angular_momentum(scene: RigidScene, trajectory) -> np.ndarray:
    """(F, 3) the total angular momentum about the world origin, ``sum m c x
    v + R I R^T w`` with the uniform solids' mass properties (scaled) and
    the recorded velocity (the centre of mass's)."""
    total = np.zeros((len(np.asarray(trajectory.t)), 3))
    for i, body in enumerate(scene.scene.bodies):
        _, center, inertia = _body(body.model.name)
        R = np.asarray(trajectory.orientation)[:, i]
        c = np.einsum("fij,j->fi", R, center * body.scale)
        x = np.asarray(trajectory.position)[:, i] + c
        w = np.asarray(trajectory.angular_velocity)[:, i]
        Iw = np.einsum("fij,jk,fkl,fl->fi", R, inertia * body.mass * body.scale ** 2,
                       np.transpose(R, (0, 2, 1)), w)
        total += body.mass * np.cross(x, np.asarray(trajectory.velocity)[:, i]) + Iw
    return total


def largest_vertex_travel(scene: RigidScene, trajectory) -> float:
    """The farthest any vertex of any body gets from where it started
    (metres): a body that turns in place moves its vertices too."""
    travel = 0.0
    for i, body in enumerate(scene.scene.bodies):
        vertices, _, _ = _body(body.model.name)
        vertices = vertices * body.scale
        R = np.asarray(trajectory.orientation)[:, i]
        x = np.asarray(trajectory.position)[:, i]
        world = np.einsum("fij,vj->fvi", R, vertices) + x[:, None, :]
        travel = max(travel, float(np.sqrt(((world - world[0]) ** 2).sum(axis=2)).max()))
    return travel


def _free_scene():
    """The brick at the middle of the cube, no gravity, spinning (FREE_SPIN)."""
    from refsim.scenes.loader import scene_from_dict
    from refsim.solvers.integrate import covering_duration

    return scene_from_dict({
        "world": {"half_size": HALF_SIZE, "gravity": 0.0, "drag": 0.0},
        "integration": {"solver": SOLVER, "step": STEP,
                        "duration": covering_duration(FREE_DURATION, STEP)},
        "collision": {"level": "aabb"},
        "body": [{"name": "body", "model": BRICK, "position": [0.0, 0.0, 0.0],
                  "angular_velocity": list(FREE_SPIN)}],
    })


def free_body(scene: RigidScene):
    """The closed-form torque-free motion of a free scene: the uniform
    solid's principal moments (the brick's axes are its mesh axes, moments
    increasing along x, y, z) and the start's body-frame angular velocity."""
    from refsim.dynamics.free_body import FreeBody

    _, _, inertia = _body(_model(scene))
    mass = scene.scene.bodies[0].mass
    w = scene.scene.bodies[0].angular_velocity
    return FreeBody((float(mass * inertia[0, 0]), float(mass * inertia[1, 1]),
                     float(mass * inertia[2, 2])), (float(w[0]), float(w[1]), float(w[2])))


def body_angular_velocity(trajectory) -> np.ndarray:
    """(F, 3) the angular velocity in the body's own axes, ``R^T w``."""
    R = np.asarray(trajectory.orientation)[:, 0]
    w = np.asarray(trajectory.angular_velocity)[:, 0]
    return np.einsum("fji,fj->fi", R, w)


def sign_changes(t: np.ndarray, values: np.ndarray) -> np.ndarray:
    """Times at which ``values`` (F,) changes sign, each by linear
    interpolation between the frames on either side."""
    s = np.sign(values)
    k = np.flatnonzero(s[1:] * s[:-1] < 0)
    return t[k] - values[k] * (t[k + 1] - t[k]) / (values[k + 1] - values[k])


@dataclass(frozen=True)
class RigidCases:
    """The scene set and, per engine, one run of each scene (kept so that the
    checks share it; keyed by the engine object's identity, the engine kept
    alive alongside so the identity is not reused)."""

    scenes: tuple
    seed: int = 0
    _runs: dict = field(default_factory=dict, compare=False, repr=False)

    def __len__(self) -> int:
        return len(self.scenes)

    def of_kind(self, *kinds: str) -> list[RigidScene]:
        return [s for s in self.scenes if s.kind in kinds]

    def run(self, engine, scene: RigidScene):
        """``engine.simulate(scene.scene)`` read by :func:`read_trajectory`,
        once per engine and scene; an exception it raised is kept too, and
        raised again for every check that asks."""
        key = (id(engine), scene.name)
        if key not in self._runs:
            try:
                self._runs[key] = (engine, read_trajectory(engine.simulate(scene.scene), scene))
            except Exception as exc:  # noqa: BLE001 - each check records it as a crash
                self._runs[key] = (engine, exc)
        answer = self._runs[key][1]
        if isinstance(answer, Exception):
            raise answer
        return answer

    def rerun(self, engine, scene: RigidScene):
        """A fresh run (not kept)."""
        return read_trajectory(engine.simulate(scene.scene), scene)


#: The arrays a trajectory holds, each's shape after the frame count F and
#: the body count B.
TRAJECTORY_SHAPES = {"position": (3,), "velocity": (3,), "angular_velocity": (3,),
                     "orientation": (3, 3)}


def read_trajectory(trajectory, scene: RigidScene) -> SimpleNamespace:
    """The engine's answer as float64 arrays ``t`` (F,) and those of
    :data:`TRAJECTORY_SHAPES` (F, B, ...) for the scene's B bodies;
    ValueError naming the field and its shape for an answer that has not
    the contract's (:mod:`refsim.engines`), so that the check records what
    is wrong with it."""
    read = {}
    for name in ("t", *TRAJECTORY_SHAPES):
        if not hasattr(trajectory, name):
            raise ValueError(f"{scene.name}: the trajectory has no {name!r}")
        read[name] = np.asarray(getattr(trajectory, name), dtype=np.float64)
    frames = read["t"].shape
    if len(frames) != 1 or frames[0] < 2:
        raise ValueError(f"{scene.name}: trajectory.t has shape {frames}, expected (F,), F >= 2")
    bodies = (len(scene.scene.bodies),)
    for name, shape in TRAJECTORY_SHAPES.items():
        if read[name].shape != frames + bodies + shape:
            raise ValueError(f"{scene.name}: trajectory.{name} has shape {read[name].shape}, "
                             f"expected {frames + bodies + shape}")
    return SimpleNamespace(**read)


def with_step(scene: RigidScene, step: float) -> RigidScene:
    """``scene`` at time step ``step`` (s), its duration covered by whole steps."""
    from refsim.solvers.integrate import covering_duration

    integration = scene.scene.integration
    integration = replace(integration, step=step,
                          duration=covering_duration(integration.duration, step))
    return replace(scene, scene=replace(scene.scene, integration=integration))


def rigid_cases(seed: int = 0) -> RigidCases:
    return RigidCases(scenes=rigid_scenes(), seed=seed)


# -- reading a trajectory ----------------------------------------------------------------


@functools.cache
def _body(model: str):
    """(vertices, centre of mass, body-frame inertia) of a bundled model of mass 1."""
    from refsim.conformance.cases_meshes import bundled_mesh
    from refsim.dynamics.mass_properties import body_mass_properties

    mesh = bundled_mesh(model)
    props = body_mass_properties(mesh, 1.0)
    return np.array(mesh.vertices), np.array(props.center), np.array(props.inertia)


def _model(scene: RigidScene) -> str:
    return scene.scene.bodies[0].model.name


def lowest_height(scene: RigidScene, trajectory) -> np.ndarray:
    """(F,) height of the body's lowest vertex above the floor, per frame."""
    vertices, _, _ = _body(_model(scene))
    R = np.asarray(trajectory.orientation)[:, 0]
    y = (R[:, 1, 0:1] * vertices[:, 0] + R[:, 1, 1:2] * vertices[:, 1]
         + R[:, 1, 2:3] * vertices[:, 2])
    return np.asarray(trajectory.position)[:, 0, 1] + y.min(axis=1) + HALF_SIZE


def energy(scene: RigidScene, trajectory) -> np.ndarray:
    """(F,) mechanical energy by :func:`refsim.dynamics.energy.mechanical_energy`
    with the uniform solid's mass properties, whatever the engine's own: the
    centre of mass at ``x + R c`` for the mesh origin ``x``, moving at the
    recorded velocity (the centre of mass's), potential from the floor
    (joules, for the scene's mass)."""
    from refsim.dynamics.energy import mechanical_energy

    _, center, inertia = _body(_model(scene))
    mass = scene.scene.bodies[0].mass
    R = np.asarray(trajectory.orientation)[:, 0]
    x = np.asarray(trajectory.position)[:, 0]
    v = np.asarray(trajectory.velocity)[:, 0]
    w = np.asarray(trajectory.angular_velocity)[:, 0]
    rc = np.einsum("fij,j->fi", R, center)
    parts = mechanical_energy([mass], [inertia * mass], GRAVITY, -HALF_SIZE,
                              (x + rc)[:, None], R[:, None], v[:, None], w[:, None])
    return parts.total[:, 0]


def apex_ratio(scene: RigidScene, trajectory) -> tuple[float, list[float]]:
    """Geometric-mean apex ratio over :data:`BOUNCES` bounces and the apex
    heights read (release first); nan when fewer bounces are found."""
    from refsim.studies.bounce_scenes import apex_ratio as mean_ratio
    from refsim.studies.bounce_scenes import read_bounces

    heights = lowest_height(scene, trajectory)
    bounces = read_bounces(trajectory.t, heights,
                           np.asarray(trajectory.velocity)[:, 0, 1], 0.0)
    return mean_ratio(bounces.apex_heights, BOUNCES), [float(h) for h in
                                                      bounces.apex_heights[:BOUNCES + 1]]


def with_body(scene: RigidScene, **changes) -> RigidScene:
    """``scene`` with fields of its body changed (for tests)."""
    s = scene.scene
    return replace(scene, scene=replace(s, bodies=(replace(s.bodies[0], **changes),)))
