"""A scene's dynamics choices, resolved once into the plan that the readable
step and the compiled loop both read.

A scene names its choices as strings: ``[dynamics]`` rotation, body response
and wall response, ``[collision]`` level, ``[world]`` wall speed. The stages
ask questions of them ("does the body turn?", "is this the seed's wall
response?", "does the narrow phase run?"). :func:`stage_plan` answers every
such question once, in one place, as a :class:`StagePlan`: the readable
stages (:class:`refsim.dynamics.simulation.Simulation` and its stage
modules) read its flags, and the compiled loop
(:class:`refsim.dynamics.compiled_loop.CompiledLoop`) reads the same plan's
integer codes (:mod:`refsim.dynamics.loop_layout`). A new choice, or a
changed rule for an old one, is then one edit here rather than one per
path.

What stays outside the plan: which narrow phase a level runs (the body
stage passes the level on to the collision query, and looks at "sphere"
and "exact" only to choose that query's form), which scenes the compiled
loop covers (:func:`refsim.dynamics.compiled_loop.loop_support`), and the
loads a choice refuses (:mod:`refsim.dynamics.loads`, which takes the
choices by name).

Cost: O(1) per scene.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from refsim.dynamics import loop_layout as slot
from refsim.dynamics.walls import SPEEDS
from refsim.errors import check_option

#: The values of each choice (the scene file's keys take these:
#: :mod:`refsim.scenes.schema`); a plan holds the wall response with "auto"
#: resolved. The levels are "none" and the collision query's
#: (:data:`refsim.collision.bodies.LEVELS`), in increasing cost.
ROTATION_MODELS = ("off", "seed", "impulse")
RESPONSE_MODELS = ("off", "seed", "impulse")
WALL_RESPONSES = ("auto", "seed", "impulse")
COLLISION_LEVELS = ("none", "sphere", "aabb", "triangle-aabb", "exact")

#: The stages of a step, in order (the outline of
#: :mod:`refsim.dynamics.simulation`); a plan keeps those that run.
STAGES = ("integrate", "rotation", "check", "bounds", "walls", "broad-phase", "narrow-phase",
          "body-response")


#: The types a simulation runs (:func:`refsim.dynamics.simulation.check_scene`).
#: The scenes lie above the dynamics, which cannot import them, so
#: :mod:`refsim.scenes.schema` adds its Scene here as it is imported
#: (:func:`register_scene_type`): any Scene that exists was made after that.
SCENE_TYPES: list[type] = []


def register_scene_type(kind: type) -> None:
    """Add ``kind`` to :data:`SCENE_TYPES` (once)."""
    if kind not in SCENE_TYPES:
        SCENE_TYPES.append(kind)


def resolve_wall_response(dynamics) -> str:
    """``dynamics.wall_response`` with "auto" resolved: the corrected wall
    impulses when the rotation model is the corrected one, else the seed's
    per-axis response (the scene key, :mod:`refsim.scenes.schema`)."""
    if dynamics.wall_response != "auto":
        return dynamics.wall_response
    return "impulse" if dynamics.rotation == "impulse" else "seed"


@dataclass(frozen=True)
class StagePlan:
    """The choices of one scene and every question the stages ask of them.

    The choices (given): ``rotation`` ("off", "seed", "impulse"),
    ``wall_response`` ("seed", "impulse"; "auto" resolved by
    :func:`stage_plan`), ``body_response`` ("off", "seed", "impulse"),
    ``level`` (the collision level), ``wall_speed`` ("wall", "seed") and
    ``bodies`` (how many).

    The answers (derived from the choices when the plan is made, so that a
    plan cannot hold answers of other choices; each a bool unless said):

    - ``body_body``: two or more bodies that can meet and respond (a level
      other than "none", a body response other than "off");
    - ``rotates``: the rotation stage runs (DEVIATION D7: rotation "off"
      also zeroes the initial angular velocity);
    - ``seed_rotation``: the seed's Euler step of the axes (S9), and its
      change of w at a wall's contact vertex;
    - ``exact_rotation``: the corrected rotation (principal frame, angular
      momentum kept), and a body response that keeps angular momentum when
      it moves a body;
    - ``impulse_walls``: the corrected wall impulses, with Coulomb's mu
      (else the seed's per-axis response with its friction fraction, S7);
    - ``speed_at_wall``: the wall flips the speed at the wall (D1), not the
      seed's speed at the penetrated position;
    - ``seed_exchange``: the seed's velocity exchange between bodies (S8);
    - ``narrow_phase``: the narrow-phase stage runs (bodies meet, at a level
      beyond the boxes; which narrow phase is the level's own dispatch);
    - ``mass_centre``: bodies turn about the solid's centre of mass, else
      about the vertex average (AMBIGUITY, seed S9);
    - ``stages``: the stages that run, in order (:data:`STAGES`);
    - ``loop_rotation``, ``loop_body``: the compiled loop's rotation and
      body-body modes (:mod:`refsim.dynamics.loop_layout`: the seed's
      exchange at level "aabb" is the loop's own, any other body stage is
      handed back to Python).
    """

    rotation: str
    wall_response: str
    body_response: str
    level: str
    wall_speed: str
    bodies: int
    body_body: bool = field(init=False)
    rotates: bool = field(init=False)
    seed_rotation: bool = field(init=False)
    exact_rotation: bool = field(init=False)
    impulse_walls: bool = field(init=False)
    speed_at_wall: bool = field(init=False)
    seed_exchange: bool = field(init=False)
    narrow_phase: bool = field(init=False)
    mass_centre: bool = field(init=False)
    stages: tuple[str, ...] = field(init=False)
    loop_rotation: int = field(init=False)
    loop_body: int = field(init=False)

    def __post_init__(self) -> None:
        rotation = check_option("rotation", self.rotation, ROTATION_MODELS)
        walls = check_option("wall_response", self.wall_response, WALL_RESPONSES[1:])
        response = check_option("body_response", self.body_response, RESPONSE_MODELS)
        speed = check_option("wall_speed", self.wall_speed, SPEEDS)
        level = check_option("level", self.level, COLLISION_LEVELS)
        meet = self.bodies >= 2 and level != "none" and response != "off"
        narrow = meet and level != "aabb"
        runs = {"rotation": rotation != "off", "broad-phase": meet, "body-response": meet,
                "narrow-phase": narrow}
        if not meet:
            loop_body = slot.BODY_NONE
        elif level == "aabb" and response == "seed":
            loop_body = slot.BODY_EXCHANGE
        else:
            loop_body = slot.BODY_HAND_BACK
        answers = {
            "body_body": meet, "rotates": rotation != "off",
            "seed_rotation": rotation == "seed", "exact_rotation": rotation == "impulse",
            "impulse_walls": walls == "impulse", "speed_at_wall": speed == "wall",
            "seed_exchange": response == "seed", "narrow_phase": narrow,
            "mass_centre": "impulse" in (rotation, response),
            "stages": tuple(s for s in STAGES if runs.get(s, True)),
            "loop_rotation": {"off": slot.ROTATION_OFF, "seed": slot.ROTATION_SEED,
                              "impulse": slot.ROTATION_EXACT}[rotation],
            "loop_body": loop_body}
        for name, value in answers.items():
            object.__setattr__(self, name, value)    # frozen: set once, here


def stage_plan(scene, wall_speed: str | None = None) -> StagePlan:
    """The plan of ``scene`` (a :class:`refsim.Scene`), with ``wall_speed``
    in place of the scene's ``world.wall_speed`` when given.

    Raises
    ------
    OptionError
        ``wall_speed`` is not one of "wall", "seed".
    """
    dyn = scene.dynamics
    return StagePlan(
        rotation=dyn.rotation, wall_response=resolve_wall_response(dyn),
        body_response=dyn.body_response, level=scene.collision.level,
        wall_speed=scene.world.wall_speed if wall_speed is None else wall_speed,
        bodies=len(scene.bodies))
