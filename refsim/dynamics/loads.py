"""What acts on each body beyond the seed's world, and where it is honoured:
gravity along any direction, constant applied forces and torques, fixed
bodies, restitution and friction per body and per pair, a world with only
some of its six walls, and the restitution threshold (the scene keys:
docs/design.md, Scene files).

These keys exist to pose textbook problems (an incline, a ball on a fixed
table, a torque spinning a body up) on the corrected model: the readable
step honours all of them, the seed model those its laws can mean, and the
compiled loop none but the threshold and ``world.mu`` (it hands such a
scene to the readable step: :func:`refsim.dynamics.compiled_loop.loop_support`).

- The field: each body's constant acceleration ``a_b = g d + F_b / m_b``
  (``d`` the unit ``gravity_direction``, ``F_b`` its ``force`` at the
  centre of mass), 0 for a fixed body. A uniform field is conservative;
  its potential energy is ``-m a . (x - x_0)`` with ``x_0`` the corner of
  the world cube the field points to (:func:`field_potential`): ``m g (y +
  H)`` for the default gravity, the seed's energy, and never negative in
  the cube.
- Torques: the body's angular momentum gains ``h tau`` per step after the
  torque-free rotation step (a first-order splitting, O(h) per unit time;
  E. Hairer, C. Lubich, G. Wanner, *Geometric Numerical Integration*, 2nd
  ed., Springer 2006, section II.5).
- A fixed body has no inverse mass or inertia in the impulse solve and no
  field, so no impulse, push or force ever moves it.
- Coefficients: :meth:`refsim.Scene.coefficients`, per body and wall, per
  body pair.

Cost: O(B) once per simulation, O(B^2 P) when bodies or P pairs give
their own coefficients; per step O(B) for the field and the torques.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from refsim.dynamics.impulse import RESTITUTION_THRESHOLD
from refsim.errors import UnposableKey

#: The world keys beyond the seed's, and what the default of each is.
WORLD_KEYS = ("gravity_direction", "walls", "mu", "restitution_threshold")
#: The body keys beyond the seed's.
BODY_KEYS = ("fixed", "force", "torque", "restitution", "mu")


@dataclass(frozen=True)
class Loads:
    """The loads of B bodies, as arrays the step reads.

    ``accel`` (B, 3): each body's constant acceleration (gravity and its
    force; 0 for a fixed body). ``torque`` (B, 3), world frame. ``fixed``
    (B,) bool. ``wall_e``, ``wall_mu`` (B,): each body's coefficients with
    a wall; ``pair_e``, ``pair_mu`` (B, B) with another body. ``low``,
    ``high`` (3,) bool: whether the wall at ``-H`` (``+H``) of each axis
    exists. ``threshold``: the restitution threshold, m/s. ``uniform``:
    gravity alone, along -y, on every body (the seed's field: the step
    takes its original, bit-identical path).
    """

    accel: np.ndarray
    torque: np.ndarray
    fixed: np.ndarray
    wall_e: np.ndarray
    wall_mu: np.ndarray
    pair_e: np.ndarray
    pair_mu: np.ndarray
    low: np.ndarray
    high: np.ndarray
    threshold: float
    uniform: bool

    @property
    def all_walls(self) -> bool:
        return bool(self.low.all() and self.high.all())


def scene_loads(scene, *, rotation: str, body_response: str, wall_response: str) -> Loads:
    """The :class:`Loads` of ``scene`` run with these choices of the model.

    Raises
    ------
    UnposableKey
        Naming the scene file and the key, for a key the chosen model cannot
        honour: a torque without the corrected rotation, a fixed body with
        the seed's body response, a tilted gravity or a force under the
        seed's wall law, a restitution threshold with no corrected response,
        coefficients per body or pair or ``world.mu`` with no corrected
        response to read them.
    """
    world, bodies = scene.world, scene.bodies
    path = scene.path
    corrected = "impulse" in (body_response, wall_response)
    if world.mu is not None and not corrected:
        raise UnposableKey("is the Coulomb coefficient of the corrected responses; the seed's "
                           "laws read world.friction (set dynamics.wall_response or "
                           "body_response = 'impulse')", path, "world.mu")
    if world.restitution_threshold != RESTITUTION_THRESHOLD and not corrected:
        raise UnposableKey("is read by the corrected responses only; the seed's laws have "
                           "no threshold (set dynamics.wall_response or body_response = "
                           "'impulse')", path, "world.restitution_threshold")
    if world.gravity_direction != (0.0, -1.0, 0.0) and wall_response == "seed":
        raise UnposableKey("the seed's wall law assumes gravity along -y; a tilted gravity "
                           "needs dynamics.wall_response = 'impulse'", path,
                           "world.gravity_direction")
    for i, b in enumerate(bodies):
        where = f"body[{i}]"
        if any(b.force) and wall_response == "seed":
            raise UnposableKey("the seed's wall law assumes gravity alone; a force needs "
                               "dynamics.wall_response = 'impulse'", path, f"{where}.force")
        if any(b.torque) and rotation != "impulse":
            raise UnposableKey("a torque needs the corrected rotation (dynamics.rotation = "
                               "'impulse')", path, f"{where}.torque")
        if b.fixed and body_response == "seed":
            raise UnposableKey("a fixed body needs dynamics.body_response = 'impulse' (the "
                               "seed's exchange of velocities has no infinite mass)", path,
                               f"{where}.fixed")
        for key in ("restitution", "mu"):
            if getattr(b, key) is not None and not corrected:
                raise UnposableKey("is read by the corrected responses only (dynamics."
                                   "wall_response or body_response = 'impulse')", path,
                                   f"{where}.{key}")
    if scene.pairs and body_response != "impulse":
        raise UnposableKey("coefficients per pair are read by the corrected body response "
                           "only (dynamics.body_response = 'impulse')", path, "pair[0]")

    B = len(bodies)
    g = np.array(world.gravity_vector, dtype=np.float64)
    mass = np.array([b.mass for b in bodies], dtype=np.float64)
    force = np.array([b.force for b in bodies], dtype=np.float64).reshape(B, 3)
    fixed = np.array([b.fixed for b in bodies], dtype=bool)
    accel = g + force / mass[:, None]
    accel[fixed] = 0.0
    uniform = (world.gravity_direction == (0.0, -1.0, 0.0) and not force.any()
               and not fixed.any())
    wall = [scene.coefficients(b) for b in bodies]
    pair_e = np.full((B, B), world.restitution)
    pair_mu = np.full((B, B), world.coulomb_mu)
    # every pair takes the world's values unless a body or a pair gives its own
    if scene.pairs or any(b.restitution is not None or b.mu is not None for b in bodies):
        for i in range(B):
            for j in range(B):
                if i != j:
                    pair_e[i, j], pair_mu[i, j] = scene.coefficients(bodies[i], bodies[j])
    return Loads(accel=accel,
                 torque=np.array([b.torque for b in bodies], dtype=np.float64).reshape(B, 3),
                 fixed=fixed,
                 wall_e=np.array([c[0] for c in wall], dtype=np.float64),
                 wall_mu=np.array([c[1] for c in wall], dtype=np.float64),
                 pair_e=pair_e, pair_mu=pair_mu,
                 low=np.array([f"{a}-" in world.walls for a in "xyz"]),
                 high=np.array([f"{a}+" in world.walls for a in "xyz"]),
                 threshold=world.restitution_threshold, uniform=uniform)


def field_potential(mass, accel, center_of_mass, half_size: float) -> np.ndarray:
    """(..., B) potential energy of bodies of ``mass`` (B,) in the uniform
    fields ``accel`` (B, 3) at centres ``center_of_mass`` (..., B, 3):
    ``-m a . (x - x_0)``, ``x_0`` the corner of the cube of side ``2
    half_size`` that ``a`` points to (module docstring)."""
    a = np.asarray(accel, dtype=np.float64)
    corner = np.where(a < 0.0, -half_size, half_size)
    x = np.asarray(center_of_mass, dtype=np.float64)
    return -np.asarray(mass) * np.einsum("...bi,bi->...b", x - corner, a)


def apply_torques(w: np.ndarray, R: np.ndarray, I_body_inv: np.ndarray, torque: np.ndarray,
                  h: float) -> None:
    """``w`` (B, 3) after a step's angular impulse ``h tau`` (world frame) on
    bodies of orientations ``R`` and body-frame inverse inertias
    ``I_body_inv``: ``w += R I^-1 R^T (h tau)``, in place."""
    kick = h * torque
    body = np.einsum("bji,bj->bi", R, kick)                    # R^T (h tau)
    w += np.einsum("bij,bj->bi", R, np.einsum("bij,bj->bi", I_body_inv, body))


def keep_walls(correction: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """The world-cube correction (3,) with the push of each missing wall
    removed: a positive component comes from the low wall of its axis, a
    negative one from the high wall."""
    kept = correction.copy()
    for k in range(3):
        if (kept[k] > 0.0 and not low[k]) or (kept[k] < 0.0 and not high[k]):
            kept[k] = 0.0
    return kept
