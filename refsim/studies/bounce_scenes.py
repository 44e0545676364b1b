"""The bounce studies' scenes, and the reading of bounces from a trajectory:
what the studies (:mod:`refsim.studies.bounce`), the conformance kit's rigid
cases and the step benchmarks share.

- the drop (seed S5, S7): :func:`drop_scene`, one body released
  :data:`DROP_HEIGHT` above the floor of the world cube; :func:`touch_height`,
  where its origin is when it touches; :func:`duration_for`, long enough for
  a number of bounces;
- reading a trajectory: a bounce is a frame where the vertical velocity
  turns from downward to upward; an apex is the largest height between two
  bounces, refined by the parabola through it and its two neighbours (so
  that coarse steps do not read a low apex just because no frame fell on
  it): :func:`read_bounces`; the apex ratio over K bounces is the geometric
  mean ``(h_K / h_0)^(1/K)`` (:func:`apex_ratio`); :func:`settle_time` and
  :func:`energy_above_touch`;
- the step benchmarks' scenes: :func:`cubes_scene` (1 to 40 cubes on a
  grid, seeded velocities), :func:`sphere_scene`, :func:`bench_scene`.

Cost: building a scene loads its model once; reading bounces is O(frames).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from refsim.dynamics import analytic
from refsim.dynamics.energy import trajectory_energy

#: The sphere-like body and the cube of the studies (bundled models).
SPHERE = "sphere-2k.ac"
CUBE = "cube.ac"
#: The world of the drops: the cube's half size (m) and gravity (m/s^2).
HALF_SIZE = 5.0
GRAVITY = 9.81
#: Drop height above the touching height, metres.
DROP_HEIGHT = 4.0
#: Bounces whose apex ratios are averaged.
BOUNCES = 3
#: The reference step and solver (refsim's accuracy target, judged at this
#: step with this solver: refsim.claims.dynamics.APEX_RATIO_TARGET).
STEP = 1e-3
SOLVER = "rk4"
#: A bounce sequence has come to rest once every later apex is below this
#: fraction of the drop height (4 mm of 4 m): the measurable version of the
#: Zeno time, which needs infinitely many bounces.
REST_FRACTION = 1e-3


# -- the drop ------------------------------------------------------------------------


def _touch_depth(model: str, orientation=None, scale: float = 1.0) -> float:
    """How far the mesh reaches below its origin (rotated, scaled)."""
    from refsim.bundled import models_dir
    from refsim.models.loading import load_model

    mesh = load_model(models_dir() / model)
    r = np.eye(3) if orientation is None else np.asarray(orientation, dtype=np.float64)
    return float(-(mesh.vertices @ r.T)[:, 1].min() * scale)


def drop_scene(model: str, e: float, *, step: float = STEP, solver: str = SOLVER,
               duration: float = 3.0, rotation: str = "off", friction: float = 0.0,
               height: float = DROP_HEIGHT, velocity=(0.0, 0.0, 0.0)):
    """A scene with one body of ``model`` whose lowest point is ``height`` above
    the floor, moving with ``velocity``; ``duration`` is rounded up to a whole
    number of steps."""
    from refsim.scenes.loader import scene_from_dict
    from refsim.solvers.integrate import covering_duration

    y = -HALF_SIZE + _touch_depth(model) + height
    return scene_from_dict({
        "world": {"half_size": HALF_SIZE, "gravity": GRAVITY, "drag": 0.0,
                  "restitution": e, "friction": friction},
        "integration": {"solver": solver, "step": step,
                        "duration": covering_duration(duration, step)},
        "collision": {"level": "aabb"},
        "dynamics": {"rotation": rotation, "body_response": "off"},
        "body": [{"name": "body", "model": model, "position": [0.0, y, 0.0],
                  "velocity": [float(c) for c in velocity]}],
    })


def touch_height(scene, index: int = 0) -> float:
    """``y`` of the body's origin when its lowest point touches the floor."""
    body = scene.bodies[index]
    mesh = scene.mesh(body)
    r = np.asarray(body.orientation, dtype=np.float64)
    return -scene.world.half_size - float((mesh.vertices @ r.T)[:, 1].min() * body.scale)


def duration_for(e: float, bounces: int, height: float = DROP_HEIGHT) -> float:
    """Long enough for ``bounces`` bounces and the apex after the last one."""
    # The margin covers coarse steps whose bounces come late (Euler at 1/30 s
    # gains height, and so flight time, at every bounce).
    return float(analytic.apex_times(height, GRAVITY, e, bounces)[-1]
                 + 0.5 * analytic.fall_time(height, GRAVITY) + 0.1)


# -- reading a trajectory -----------------------------------------------------------


@dataclass(frozen=True)
class Bounces:
    """Bounces read from one body's trajectory: bounce times (B,), apex
    heights (A,) above the touching height with ``apex[0]`` the release
    height, apex times (A,)."""

    bounce_times: np.ndarray
    apex_heights: np.ndarray
    apex_times: np.ndarray


def _parabola_peak(t3, y3) -> tuple[float, float]:
    """Vertex of the parabola through three points (the middle one highest)."""
    (t0, t1, t2), (y0, y1, y2) = t3, y3
    denom = (t0 - t1) * (t0 - t2) * (t1 - t2)
    a = (t2 * (y1 - y0) + t1 * (y0 - y2) + t0 * (y2 - y1)) / denom
    b = (t2 * t2 * (y0 - y1) + t1 * t1 * (y2 - y0) + t0 * t0 * (y1 - y2)) / denom
    if a >= 0:
        return float(t1), float(y1)
    tp = -b / (2 * a)
    c = y1 - a * t1 * t1 - b * t1
    return float(tp), float(a * tp * tp + b * tp + c)


def read_bounces(t, y, vy, y_touch: float) -> Bounces:
    """Bounces and apexes of the height ``y - y_touch`` (frames ``t``)."""
    t = np.asarray(t, dtype=np.float64)
    h = np.asarray(y, dtype=np.float64) - y_touch
    vy = np.asarray(vy, dtype=np.float64)
    up = np.flatnonzero((vy[:-1] < 0.0) & (vy[1:] > 0.0)) + 1     # first frame moving up
    apex_h = [float(h[0])]
    apex_t = [float(t[0])]
    for i, start in enumerate(up):
        stop = up[i + 1] if i + 1 < len(up) else len(h)
        if stop - start < 3:
            continue
        m = start + int(np.argmax(h[start:stop]))
        if m <= start or m >= stop - 1:            # still rising at the end: no apex yet
            continue
        tp, hp = _parabola_peak(t[m - 1:m + 2], h[m - 1:m + 2])
        apex_h.append(hp)
        apex_t.append(tp)
    return Bounces(bounce_times=t[up], apex_heights=np.asarray(apex_h),
                   apex_times=np.asarray(apex_t))


def apex_ratio(apexes: np.ndarray, k: int = BOUNCES) -> float:
    """Geometric mean of the first ``k`` successive apex ratios, ``(h_k/h_0)^(1/k)``."""
    if len(apexes) <= k:
        return math.nan
    return float((apexes[k] / apexes[0]) ** (1.0 / k))


def energy_above_touch(scene, trajectory, y_touch: float) -> np.ndarray:
    """(F,) body 0's mechanical energy per unit weight (metres), the
    potential measured from the height ``y_touch`` at which it touches the
    floor: :func:`refsim.dynamics.energy.trajectory_energy` less the
    potential of that height, over ``m g``. Equal to the apex height above
    touching when the body is at rest at an apex (what the analytic series
    of :func:`refsim.dynamics.analytic.energy` gives per unit weight)."""
    weight = scene.bodies[0].mass * scene.world.gravity
    total = trajectory_energy(scene, trajectory).total[:, 0]
    return total / weight - (y_touch + scene.world.half_size)


def settle_time(bounces: Bounces, h0: float, fraction: float = REST_FRACTION) -> tuple[float, int]:
    """Time of the first bounce after which every apex is below ``fraction
    h0``, and the number of that bounce (nan, 0 if it never settles)."""
    h = bounces.apex_heights[1:]                  # apex after bounce 1, 2, ...
    above = np.flatnonzero(h >= fraction * h0)
    k = 0 if len(above) == 0 else int(above[-1]) + 1      # bounces before settling
    if k >= len(bounces.bounce_times) or k >= len(h):
        return math.nan, 0
    return float(bounces.bounce_times[k]), k + 1


# -- the step benchmarks' scenes ----------------------------------------------------

#: Body counts and rotation models of the step benchmarks (the seed's
#: "1 to 40 in this simulation"), of the report's and of ``make bench``.
BENCH_COUNTS = (1, 10, 40)
BENCH_ROTATIONS = ("off", "seed", "impulse")
#: Steps before timing the "late" phase: by then the cubes have settled on
#: the floor (restitution 0.8, friction 0.1) and Bullet has many contacts.
LATE_WARMUP = 3000
#: Seed of the benchmark scenes' random velocities.
BENCH_SEED = 20260522


def cubes_scene(count: int, rotation: str = "off", *, seed: int = BENCH_SEED,
                step: float = STEP, duration: float = 10.0, solver: str = SOLVER):
    """``count`` unit cubes on a grid in the world cube (spacing 2.2, at
    least 1.2 between faces), random velocities in [-3, 3]^3 m/s (seeded),
    collision level "aabb", the seed's body response."""
    rng = np.random.default_rng(seed)
    side = math.ceil(count ** (1.0 / 3.0) - 1e-9)
    spacing = 2.2
    offset = -spacing * (side - 1) / 2.0
    cells = [(i, j, k) for j in range(side) for i in range(side) for k in range(side)]
    bodies = []
    for n, (i, j, k) in enumerate(cells[:count]):
        bodies.append({"name": f"cube{n}", "model": CUBE,
                       "position": [offset + spacing * i, offset + spacing * j,
                                    offset + spacing * k],
                       "velocity": [float(x) for x in rng.uniform(-3.0, 3.0, 3)]})
    return _bench_world(bodies, rotation, step, duration, solver)


def _bench_world(bodies: list, rotation: str, step: float, duration: float, solver: str):
    """The step benchmarks' world (e = 0.8, friction 0.1, level "aabb", the
    seed's body response) holding the ``[[body]]`` tables ``bodies``."""
    from refsim.scenes.loader import scene_from_dict

    return scene_from_dict({
        "world": {"half_size": HALF_SIZE, "gravity": GRAVITY, "restitution": 0.8,
                  "friction": 0.1},
        "integration": {"solver": solver, "step": step, "duration": duration},
        "collision": {"level": "aabb"},
        "dynamics": {"rotation": rotation, "body_response": "seed"},
        "body": bodies,
    })


#: The step-cost benchmark's bodies (tests/benchmarks/test_bench_dynamics.py):
#: cubes on a grid (:func:`cubes_scene`) and one 2000-triangle sphere
#: (:func:`sphere_scene`); steps to a settled state.
BENCH_BODIES = ("1 cube", "10 cubes", "40 cubes", "sphere-2k")
SETTLE_STEPS = {"cubes": LATE_WARMUP, "sphere": 10_000}


def sphere_scene(rotation: str = "off", *, step: float = STEP, duration: float = 20.0,
                 solver: str = SOLVER):
    """One 2000-triangle sphere (:data:`SPHERE`) thrown from the centre of the
    world cube at (2, 1, -1.5) m/s, with :func:`cubes_scene`'s world (e = 0.8,
    friction 0.1), collision level "aabb"; it rests on the floor after about
    10 s."""
    return _bench_world([{"name": "ball", "model": SPHERE, "position": [0.0, 0.0, 0.0],
                          "velocity": [2.0, 1.0, -1.5]}], rotation, step, duration, solver)


def bench_scene(bodies: str, rotation: str):
    """The scene of one of :data:`BENCH_BODIES` and its settling steps."""
    if bodies == "sphere-2k":
        return sphere_scene(rotation), SETTLE_STEPS["sphere"]
    return cubes_scene(int(bodies.split()[0]), rotation), SETTLE_STEPS["cubes"]
