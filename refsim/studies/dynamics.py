"""Measurements of the dynamics for the report: claims C11 and C12, and the
energy of a bouncing body, the seed's model against the corrected one.

- :func:`measure_spin` (C12, "the angular velocity does not properly dampen
  and come to a rest"): |w| and the rotational energy over time of a cube
  dropped with spin (``scenes/spinning-cube.toml``), ``rotation = "seed"``
  against ``"impulse"``; another engine (pybullet) runs the same scene
  with its own model and is measured the same way.
- :func:`measure_interpenetration` (C11, "sometimes objects will
  interpenetrate when they are moving slowly or in the same direction"):
  the number of frames in which two bodies intersect (the exact triangle
  test, :func:`refsim.bodies_collide` at level "exact") for a chase (same
  direction), a slow approach and a body falling onto another, with
  ``body_response = "seed"`` against ``"impulse"``.
- :func:`measure_energy`: the mechanical energy over time of a bouncing,
  spinning cube, seed against corrected.

Each study receives its engines: what it varies is one choice of the scene
(its rotation model, its body response), so refsim runs as an engine that
poses the scene's own choices (:func:`refsim.engines.refsim_engines.as_posed`,
the default; an engine with ``poses_models``), once per value of that choice,
with everything else as the scene gives it. An engine with a model of its own
runs the scene once. Every record names its engine.

Every function returns frozen dataclasses of numbers; the report draws them
and computes nothing itself. ``refsim study dynamics-spin``,
``dynamics-interpenetration`` and ``dynamics-rotation-energy`` print them.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from refsim.dynamics.energy import trajectory_energy
from refsim.dynamics.simulate import default_every, with_duration
from refsim.dynamics.simulation import Simulation
from refsim.dynamics.trajectory import Trajectory
from refsim.engines import engine_name
from refsim.errors import StateError

#: Below these, a body counts as at rest (the corrected model's resting
#: cube jitters at ~1e-5 m/s and rad/s: gravity's g h per step undone by the
#: contact impulses; a visible motion is > 1e-2).
REST_SPEED = 1e-3          # m/s
REST_SPIN = 1e-3           # rad/s


def _scene(name: str):
    from refsim.bundled import scenes_dir
    from refsim.scenes.loader import load_scene

    return load_scene(scenes_dir() / name)


def _scene_from(data: dict):
    from refsim.scenes.loader import scene_from_dict

    return scene_from_dict(data)


def _default_engines(engines) -> tuple:
    """``engines``, or refsim running the scene as posed."""
    if engines is not None:
        return tuple(engines)
    from refsim.engines.refsim_engines import as_posed

    return (as_posed(),)


def poses_models(engine) -> bool:
    """Whether ``engine`` runs the rotation model and body response the scene
    names (refsim as posed), rather than a model of its own."""
    return bool(getattr(engine, "poses_models", False))


def _posing_engine(engine):
    """``engine`` (default: refsim as posed), refused unless it poses the
    scene's own models: the study varies one of them."""
    if engine is None:
        from refsim.engines.refsim_engines import as_posed

        engine = as_posed()
    if not poses_models(engine):
        raise StateError(f"engine {engine_name(engine)!r} runs a model of its own; this "
                         f"study varies the scene's model and needs an engine that poses "
                         f"it (refsim.engines.refsim_engines.as_posed)")
    return engine


# -- C12 -------------------------------------------------------------------------------


@dataclass(frozen=True)
class SpinSeries:
    """One model's spin over time (body 0)."""

    engine: str                 # the engine that ran it
    model: str                  # the scene's rotation model ("seed", "impulse"), or
                                # the engine's name for an engine with its own model
    t: np.ndarray               # (F,) s
    spin: np.ndarray            # (F,) |w|, rad/s
    spin_normal: np.ndarray     # (F,) w_y, the component along the floor's normal
    rotational_energy: np.ndarray   # (F,) J
    speed: np.ndarray           # (F,) |v|, m/s
    final_spin: float           # mean |w| over the last second
    final_speed: float          # mean |v| over the last second
    at_rest: bool               # final_spin < REST_SPIN and final_speed < REST_SPEED


def _spin_series(engine: str, label: str, scene, traj: Trajectory) -> SpinSeries:
    rotational = trajectory_energy(scene, traj).rotational.sum(axis=1)
    w = traj.angular_velocity[:, 0]
    v = traj.velocity[:, 0]
    spin = np.linalg.norm(w, axis=1)
    speed = np.linalg.norm(v, axis=1)
    last = traj.t >= traj.t[-1] - 1.0
    final_spin, final_speed = float(spin[last].mean()), float(speed[last].mean())
    return SpinSeries(engine=engine, model=label, t=traj.t, spin=spin, spin_normal=w[:, 1].copy(),
                      rotational_energy=rotational, speed=speed, final_spin=final_spin,
                      final_speed=final_speed,
                      at_rest=final_spin < REST_SPIN and final_speed < REST_SPEED)


def measure_spin(scene=None, *, engines=None, duration: float | None = None,
                 rotations=("seed", "impulse")) -> list[SpinSeries]:
    """C12: a cube dropped with spin, seed rotation against the corrected one.

    ``scene`` defaults to ``scenes/spinning-cube.toml``. Each engine that
    poses the scene's models (default: refsim as posed) runs it with its
    ``rotation`` replaced by each of ``rotations``; any other engine runs it
    once, as its own model, under its own name. Frames are kept every
    :func:`refsim.dynamics.simulate.default_every` steps for every engine.
    """
    scene = with_duration(scene or _scene("spinning-cube.toml"), duration)
    every = default_every(scene.integration.n_steps)
    # each series by (engine, its model), refused before any run when two
    # engines would give a series of one name (the report draws them by name)
    runs = [(engine, engine_name(engine), model)
            for engine in _default_engines(engines)
            for model in (rotations if poses_models(engine) else (engine_name(engine),))]
    names: dict[str, str] = {}
    for _, name, model in runs:
        if model in names:
            raise StateError(f"engines {names[model]!r} and {name!r} both give a spin "
                             f"series named {model!r}; give one of them")
        names[model] = name
    rows: list[SpinSeries] = []
    for engine, name, model in runs:
        posed = (replace(scene, dynamics=replace(scene.dynamics, rotation=model))
                 if poses_models(engine) else scene)
        rows.append(_spin_series(name, model, posed, engine.simulate(posed, every=every)))
    return rows


# -- C11 -------------------------------------------------------------------------------


@dataclass(frozen=True)
class InterpenetrationRow:
    engine: str                 # the engine that ran it (it poses the scene's response)
    case: str                   # one of C11_CASES
    response: str               # body_response: "seed" or "impulse"
    frames: int                 # frames examined (one per step)
    interpenetrating: int       # frames in which the exact test finds an intersection
    longest_run: int            # the longest run of consecutive such frames
    contacts: int               # body-contact onsets (events)


def c11_scene(case: str, response: str, *, duration: float = 2.0, step: float = 1e-3):
    """The scene of one C11 case.

    - "chase": two unit cubes on the x axis without gravity, the back one at
      2 m/s chasing the front one at 0.5 m/s (same direction);
    - "slow": two icosahedra approaching head-on at 0.05 m/s each, without
      gravity (slower than one step's overlap can resolve);
    - "stack": an icosahedron dropped from 0.8 m onto another resting on the
      floor (slow contact under gravity, e = 0.5);
    - "glancing": a unit cube at 1 m/s passing a resting one offset by 0.8 m
      sideways (their corners overlap; the centroid line is oblique).
    """
    base = {"integration": {"solver": "rk4", "step": step, "duration": duration},
            "collision": {"level": "exact", "aabb": "auto"},
            "dynamics": {"rotation": "off", "body_response": response}}
    if case == "chase":
        base["world"] = {"gravity": 0.0, "restitution": 1.0, "half_size": 5.0}
        base["body"] = [
            {"name": "chaser", "model": "cube.ac", "position": [-2.0, 0.0, 0.0],
             "velocity": [2.0, 0.0, 0.0]},
            {"name": "leader", "model": "cube.ac", "position": [-0.5, 0.0, 0.0],
             "velocity": [0.5, 0.0, 0.0]}]
    elif case == "slow":
        base["world"] = {"gravity": 0.0, "restitution": 1.0, "half_size": 5.0}
        base["body"] = [
            {"name": "left", "model": "icosahedron.ac", "position": [-0.9, 0.0, 0.0],
             "velocity": [0.05, 0.0, 0.0]},
            {"name": "right", "model": "icosahedron.ac", "position": [0.9, 0.0, 0.0],
             "velocity": [-0.05, 0.0, 0.0]}]
    elif case == "stack":
        base["world"] = {"gravity": 9.81, "restitution": 0.5, "half_size": 3.0}
        base["body"] = [
            {"name": "bottom", "model": "icosahedron.ac", "position": [0.0, -2.149, 0.0]},
            {"name": "top", "model": "icosahedron.ac", "position": [0.0, 0.5, 0.0]}]
    elif case == "glancing":
        base["world"] = {"gravity": 0.0, "restitution": 1.0, "half_size": 5.0}
        base["body"] = [
            {"name": "mover", "model": "cube.ac", "position": [-2.0, 0.0, 0.0],
             "velocity": [1.0, 0.0, 0.0]},
            {"name": "rester", "model": "cube.ac", "position": [0.0, 0.8, 0.0]}]
    else:
        raise ValueError(f"unknown C11 case {case!r}")
    return _scene_from(base)


C11_CASES = ("chase", "slow", "stack", "glancing")


def count_interpenetrating(scene, traj: Trajectory) -> tuple[int, int]:
    """``(frames with an exact intersection of bodies 0 and 1, longest run)``."""
    from refsim.collision.bodies import bodies_collide

    sim = Simulation(scene)
    mesh_a, mesh_b = sim.bodies[0].mesh, sim.bodies[1].mesh
    count = run = longest = 0
    for f in range(traj.n_frames):
        pose_a = (traj.orientation[f, 0], traj.position[f, 0])
        pose_b = (traj.orientation[f, 1], traj.position[f, 1])
        if bodies_collide(mesh_a, pose_a, mesh_b, pose_b, level="exact"):
            count += 1
            run += 1
            longest = max(longest, run)
        else:
            run = 0
    return count, longest


def measure_interpenetration(cases=C11_CASES, responses=("seed", "impulse"), *,
                             engine=None, duration: float = 2.0, step: float = 1e-3
                             ) -> list[InterpenetrationRow]:
    """C11: interpenetrating frames per case and body response, every step
    recorded, run by ``engine`` (default: refsim as posed; it must pose the
    scene's body response)."""
    engine = _posing_engine(engine)
    rows = []
    for case in cases:
        for response in responses:
            scene = c11_scene(case, response, duration=duration, step=step)
            traj = engine.simulate(scene, every=1)
            count, longest = count_interpenetrating(scene, traj)
            contacts = sum(1 for e in traj.events if e.kind == "body")
            rows.append(InterpenetrationRow(engine=engine_name(engine), case=case,
                                            response=response,
                                            frames=traj.n_frames, interpenetrating=count,
                                            longest_run=longest, contacts=contacts))
    return rows


# -- energy of a bouncing body -------------------------------------------------------------


@dataclass(frozen=True)
class EnergySeries:
    engine: str                 # the engine that ran it (it poses the scene's rotation)
    model: str                  # rotation model
    t: np.ndarray               # (F,) s
    energy: np.ndarray          # (F,) kinetic + rotational + potential, J
    rotational: np.ndarray      # (F,) J
    increases: int              # frames where the energy rose by more than ENERGY_SLACK
    max_rise: float             # largest rise between consecutive frames, J


#: A rise of the energy between frames smaller than this (J, for a 1 kg
#: body) is the resting jitter of the wall push-back (m g h^2 / 2 ~ 5e-6 J
#: per step at h = 1e-3), not a gain.
ENERGY_SLACK = 1e-4


def measure_energy(scene=None, *, engine=None, duration: float | None = None,
                   models=("seed", "impulse")) -> list[EnergySeries]:
    """Energy over time of the bouncing, spinning cube (default
    ``scenes/spinning-cube.toml``), one series per rotation model, run by
    ``engine`` (default: refsim as posed; it must pose the scene's
    rotation), a frame every 10 steps."""
    scene = with_duration(scene or _scene("spinning-cube.toml"), duration)
    engine = _posing_engine(engine)
    rows = []
    for model in models:
        s = replace(scene, dynamics=replace(scene.dynamics, rotation=model))
        traj = engine.simulate(s, every=10)
        parts = trajectory_energy(s, traj)
        energy, rotational = parts.total.sum(axis=1), parts.rotational.sum(axis=1)
        rise = np.diff(energy)
        rows.append(EnergySeries(engine=engine_name(engine), model=model, t=traj.t,
                                 energy=energy, rotational=rotational,
                                 increases=int((rise > ENERGY_SLACK).sum()),
                                 max_rise=float(rise.max(initial=0.0))))
    return rows
