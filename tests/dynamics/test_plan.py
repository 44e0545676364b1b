"""The stage plan (refsim.dynamics.plan): each question the stages ask of a
scene's choices, answered once, for every combination of the choices."""

from __future__ import annotations

import itertools

import pytest

from refsim.dynamics import loop_layout as slot
from refsim.dynamics.plan import STAGES, stage_plan
from refsim.errors import OptionError
from refsim.scenes.loader import scene_from_dict


def scene(bodies=2, rotation="seed", response="seed", level="aabb", wall_response="auto",
          wall_speed="wall"):
    return scene_from_dict({
        "world": {"wall_speed": wall_speed},
        "collision": {"level": level},
        "dynamics": {"rotation": rotation, "body_response": response,
                     "wall_response": wall_response},
        "body": [{"name": f"b{i}", "model": "cube.ac", "position": [2.5 * i - 2, 0.0, 0.0]}
                 for i in range(bodies)]})


ROTATIONS, RESPONSES = ("off", "seed", "impulse"), ("off", "seed", "impulse")
LEVELS = ("none", "sphere", "aabb", "triangle-aabb", "exact")


@pytest.mark.parametrize(("bodies", "rotation", "response", "level"),
                         list(itertools.product((1, 2), ROTATIONS, RESPONSES, LEVELS)))
def test_each_answer_follows_from_the_choices(bodies, rotation, response, level):
    plan = stage_plan(scene(bodies, rotation, response, level))
    meet = bodies == 2 and level != "none" and response != "off"
    assert (plan.rotation, plan.body_response, plan.level) == (rotation, response, level)
    assert plan.body_body is meet
    assert plan.rotates is (rotation != "off")
    assert (plan.seed_rotation, plan.exact_rotation) == (rotation == "seed",
                                                         rotation == "impulse")
    # "auto": the corrected walls go with the corrected rotation
    assert plan.wall_response == ("impulse" if rotation == "impulse" else "seed")
    assert plan.impulse_walls is (rotation == "impulse")
    assert plan.seed_exchange is (response == "seed")
    assert plan.narrow_phase is (meet and level != "aabb")
    assert plan.mass_centre is ("impulse" in (rotation, response))
    expected = [s for s in STAGES
                if not (s == "rotation" and rotation == "off")
                and not (s in ("broad-phase", "body-response") and not meet)
                and not (s == "narrow-phase" and not (meet and level != "aabb"))]
    assert list(plan.stages) == expected
    assert plan.loop_rotation == {"off": slot.ROTATION_OFF, "seed": slot.ROTATION_SEED,
                                  "impulse": slot.ROTATION_EXACT}[rotation]
    assert plan.loop_body == (slot.BODY_NONE if not meet else
                              slot.BODY_EXCHANGE if (level, response) == ("aabb", "seed")
                              else slot.BODY_HAND_BACK)


def test_the_wall_law_and_speed_as_chosen():
    plan = stage_plan(scene(rotation="impulse", wall_response="seed", wall_speed="seed"))
    assert (plan.wall_response, plan.impulse_walls) == ("seed", False)
    assert (plan.wall_speed, plan.speed_at_wall) == ("seed", False)
    # an argument's wall speed overrides the scene's
    assert stage_plan(scene(wall_speed="seed"), "wall").speed_at_wall is True
    with pytest.raises(OptionError, match="wall_speed must be one of 'wall', 'seed'"):
        stage_plan(scene(), "fast")


def test_the_simulation_and_its_loop_read_the_plan():
    from refsim.dynamics.simulation import Simulation

    sim = Simulation(scene(rotation="impulse", response="impulse", level="exact"),
                     kernel="compiled")
    assert sim.plan == stage_plan(sim.scene)
    assert sim.stages == sim.plan.stages
    settings = sim._loop.view(slot.SETTINGS)
    assert (settings[slot.G_ROTATION_MODE], settings[slot.G_BODY_MODE]) == \
        (slot.ROTATION_EXACT, slot.BODY_HAND_BACK)
    assert (settings[slot.G_WALL_IMPULSE], settings[slot.G_WALL_SPEED_AT_WALL]) == (1, 1)


def test_a_plan_derives_its_answers_from_its_choices_and_checks_them():
    from dataclasses import replace

    plan = stage_plan(scene(rotation="seed"))
    turned = replace(plan, rotation="impulse", wall_response="impulse")
    assert (turned.exact_rotation, turned.seed_rotation, turned.impulse_walls) == \
        (True, False, True)
    assert turned.loop_rotation == slot.ROTATION_EXACT and turned.mass_centre
    assert replace(plan, bodies=1).stages == ("integrate", "rotation", "check", "bounds",
                                              "walls")
    with pytest.raises(OptionError, match="rotation must be one of 'off', 'seed', 'impulse'"):
        replace(plan, rotation="spin")
    with pytest.raises(OptionError, match="wall_response must be one of 'seed', 'impulse'"):
        replace(plan, wall_response="auto")         # resolved by stage_plan, never kept


def test_the_simulation_keeps_its_plan_and_names_its_choices():
    from refsim.dynamics.simulation import Simulation

    sim = Simulation(scene(rotation="impulse", wall_speed="seed"))
    with pytest.raises(AttributeError):
        sim.plan = stage_plan(scene())             # the stages were set up from it
    assert (sim.rotation, sim.body_response, sim.wall_response, sim.wall_speed, sim.level,
            sim.body_body) == ("impulse", "seed", "impulse", "seed", "aabb", True)


def test_the_levels_are_none_and_the_collision_querys():
    from refsim.collision.bodies import LEVELS
    from refsim.dynamics.plan import COLLISION_LEVELS

    assert COLLISION_LEVELS == ("none", *LEVELS)


def test_the_loop_runs_the_scenes_type_without_importing_it():
    # refsim.scenes.schema registers Scene with the loop's check; a copy of
    # a scene's fields in another type is refused with the one-line message
    from types import SimpleNamespace

    from refsim.dynamics.plan import SCENE_TYPES
    from refsim.dynamics.simulation import Simulation, check_scene
    from refsim.errors import ArgumentTypeError
    from refsim.scenes.schema import Scene

    assert SCENE_TYPES == [Scene]
    posed = scene()
    check_scene(posed)
    lookalike = SimpleNamespace(**{name: getattr(posed, name)
                                   for name in posed.__dataclass_fields__})
    with pytest.raises(ArgumentTypeError, match="scene must be a refsim.Scene .* got "
                                                "SimpleNamespace"):
        Simulation(lookalike)
