"""What the viewer draws besides the bodies, from a recorded run (S12).

Everything here is computed from a :class:`~refsim.dynamics.trajectory.Trajectory`
(the recorded poses, velocities and events) by refsim's own functions; none
of it feeds back into a simulation or a verdict:

- :func:`body_boxes`: each body's world box at each frame, by
  :func:`refsim.aabb_linear` on the recorded pose (the seed's linear scan,
  S2), and :func:`box_edges` to draw one;
- :func:`contacting_triangles`: the triangle pairs that intersect at one
  frame, by :func:`refsim.intersecting_pairs` (level "exact") between the
  bodies whose boxes overlap (S4), computed only for the frame shown;
- :func:`wall_hits`: the normal and the impulse of each wall hit, from the
  recorded events and the velocity jump across them (S7);
- :func:`energy_per_frame`: kinetic, potential and rotational energy per
  frame, by :meth:`refsim.Simulation.energy` itself.

Shapes: F frames, B bodies. A body's pose at frame f is
``(orientation[f, b], position[f, b])``: its (scaled) mesh's vertex ``p``
is at ``R p + x``.

Cost: boxes O(F B n) for meshes of n vertices; energy O(F B); wall hits
O(E n) for E events; contacting triangles one hierarchy traversal per
overlapping pair at the frame asked for.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from refsim.bounds.aabb_linear import aabb_linear
from refsim.collision.bodies import intersecting_pairs
from refsim.dynamics.energy import trajectory_energy
from refsim.dynamics.trajectory import Trajectory

#: The 12 edges of a box as pairs of corner indices; corner ``c`` has bit k
#: set where its coordinate k is the box's upper one.
BOX_EDGES = np.array([(a, a | 1 << k) for k in range(3) for a in range(8)
                      if not a & 1 << k], dtype=np.int64)

#: Vertices within this fraction of the body's extent of its outermost
#: vertex on a wall's axis are taken as the contact (a face resting flat on
#: the floor gives its centre, a corner gives the corner). A display choice.
CONTACT_BAND = 0.02


def body_meshes(scene) -> tuple:
    """Each body's mesh at its scale, in the scene's order (as the
    simulation uses them: ``scene.mesh(body).scaled(body.scale)``)."""
    return tuple(scene.mesh(b).scaled(b.scale) for b in scene.bodies)


def box_corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """(..., 8, 3) corners of boxes ``lo``, ``hi`` (..., 3), ordered as in BOX_EDGES."""
    lo, hi = np.asarray(lo, dtype=np.float64), np.asarray(hi, dtype=np.float64)
    bits = (np.arange(8)[:, None] >> np.arange(3)) & 1          # (8, 3)
    return np.where(bits.astype(bool), hi[..., None, :], lo[..., None, :])


def box_edges(lo, hi) -> np.ndarray:
    """(..., 12, 2, 3) edge segments of boxes ``lo``, ``hi`` (..., 3)."""
    return box_corners(lo, hi)[..., BOX_EDGES, :]


def cube_edges(half_size: float, offset=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(12, 2, 3) edges of the world cube ``[-H, H]^3`` moved by ``offset``."""
    offset = np.asarray(offset, dtype=np.float64)
    return box_edges(offset - half_size, offset + half_size)


def body_boxes(meshes, traj: Trajectory) -> np.ndarray:
    """(F, B, 2, 3) world boxes ``[lo, hi]`` of every body at every frame,
    by the linear scan on the recorded poses."""
    F, B = traj.position.shape[:2]
    boxes = np.empty((F, B, 2, 3))
    for f in range(F):
        for b in range(B):
            boxes[f, b] = aabb_linear(meshes[b], (traj.orientation[f, b], traj.position[f, b]))
    return boxes


def world_vertices(mesh, rotation: np.ndarray, position: np.ndarray) -> np.ndarray:
    """(n, 3) the mesh's vertices placed at a pose: ``R p + x`` for each ``p``."""
    return mesh.vertices @ np.asarray(rotation).T + np.asarray(position)


# -- contacting triangles --------------------------------------------------------------


@dataclass(frozen=True)
class TrianglePairs:
    """The intersecting triangles of bodies ``a`` and ``b`` at one frame:
    ``pairs`` (k, 2) face indices (of a, of b), as refsim.intersecting_pairs."""

    a: int
    b: int
    pairs: np.ndarray


def overlapping_bodies(boxes: np.ndarray) -> list[tuple[int, int]]:
    """Pairs ``(a, b)``, a < b, whose boxes (B, 2, 3) overlap (touching counts)."""
    lo, hi = boxes[:, 0], boxes[:, 1]
    B = len(boxes)
    return [(a, b) for a in range(B) for b in range(a + 1, B)
            if bool(np.all(lo[a] <= hi[b]) and np.all(lo[b] <= hi[a]))]


def contacting_triangles(meshes, traj: Trajectory, frame: int,
                         boxes: np.ndarray | None = None) -> list[TrianglePairs]:
    """The intersecting triangle pairs at ``frame`` of every two bodies whose
    boxes overlap there (``boxes``: that frame's (B, 2, 3), computed if not
    given); pairs without an intersection are left out."""
    if boxes is None:
        boxes = np.array([aabb_linear(m, (traj.orientation[frame, b], traj.position[frame, b]))
                          for b, m in enumerate(meshes)])
    found = []
    for a, b in overlapping_bodies(boxes):
        pairs = intersecting_pairs(meshes[a], (traj.orientation[frame, a], traj.position[frame, a]),
                                   meshes[b], (traj.orientation[frame, b], traj.position[frame, b]),
                                   level="exact")
        if len(pairs):
            found.append(TrianglePairs(a, b, pairs))
    return found


def triangle_soup(mesh, rotation, position, faces: np.ndarray) -> np.ndarray:
    """(k, 3, 3) world corners of the given faces of ``mesh`` at a pose."""
    W = world_vertices(mesh, rotation, position)
    return W[mesh.faces[np.asarray(faces, dtype=np.int64)]]


# -- wall hits ---------------------------------------------------------------------------


@dataclass(frozen=True)
class WallHit:
    """One wall hit as the viewer draws it.

    ``frame`` is the first recorded frame at or after the hit (``time``);
    ``point`` where the body touches the wall (on the wall plane);
    ``normal`` the wall's unit normal into the cube; ``impulse`` (N s) the
    momentum the wall gave: ``m (v_after - v_before) - m g dt`` between the
    frames around the hit (gravity's share over those frames removed; drag
    is not). Frames kept every ``k`` steps merge hits closer than that.
    """

    frame: int
    time: float
    body: int
    wall: str
    point: np.ndarray
    normal: np.ndarray
    impulse: np.ndarray


def wall_normal(wall: str) -> np.ndarray:
    """Unit normal into the cube of wall ``"x-"``, ``"y+"``, ...: +axis for
    a low wall, -axis for a high one."""
    n = np.zeros(3)
    n["xyz".index(wall[0])] = 1.0 if wall[1] == "-" else -1.0
    return n


def wall_hits(meshes, traj: Trajectory, masses, gravity: float,
              half_size: float) -> list[WallHit]:
    """Every wall event of ``traj`` with its contact point, normal and impulse.

    Parameters
    ----------
    meshes : the bodies' meshes (scaled), in ``traj.names`` order
    masses : (B,) kg
    gravity, half_size : the scene's ``world.gravity`` (m/s^2, along -y) and
        ``world.half_size`` (m)
    """
    index = {name: b for b, name in enumerate(traj.names)}
    g = np.array([0.0, -gravity, 0.0])
    hits = []
    for event in traj.events:
        if event.kind != "wall" or event.body not in index or not len(traj.t):
            continue
        b = index[event.body]
        after = min(int(np.searchsorted(traj.t, event.time - 1e-12 * max(1.0, event.time))),
                    len(traj.t) - 1)
        before = max(after - 1, 0)
        dt = traj.t[after] - traj.t[before]
        impulse = masses[b] * (traj.velocity[after, b] - traj.velocity[before, b] - g * dt)
        k = "xyz".index(event.other[0])
        low = event.other[1] == "-"
        W = world_vertices(meshes[b], traj.orientation[after, b], traj.position[after, b])
        extent = max(float(W[:, k].max() - W[:, k].min()), 1e-12)
        edge = W[:, k].min() if low else W[:, k].max()
        near = np.abs(W[:, k] - edge) <= CONTACT_BAND * extent
        point = W[near].mean(axis=0)
        point[k] = -half_size if low else half_size
        hits.append(WallHit(frame=after, time=event.time, body=b, wall=event.other,
                            point=point, normal=wall_normal(event.other), impulse=impulse))
    return hits


# -- energy -----------------------------------------------------------------------------


@dataclass(frozen=True)
class Energy:
    """Per frame (F,) and summed over bodies, in J: ``kinetic`` (m |v|^2 / 2),
    ``potential`` (m g (y + H), from the floor), ``rotational`` (w . I w / 2);
    ``total`` is :meth:`refsim.Simulation.energy` summed."""

    t: np.ndarray
    kinetic: np.ndarray
    potential: np.ndarray
    rotational: np.ndarray
    total: np.ndarray


def energy_per_frame(scene, traj: Trajectory) -> Energy:
    """The mechanical energy of every frame of ``traj``, a run of ``scene``,
    summed over bodies: :func:`refsim.dynamics.energy.trajectory_energy`, the
    formula of :meth:`refsim.Simulation.energy`, so the viewer shows the
    loop's own energy."""
    parts = trajectory_energy(scene, traj)
    kinetic, rotational, potential = (p.sum(axis=1) for p in
                                      (parts.kinetic, parts.rotational, parts.potential))
    return Energy(t=np.asarray(traj.t, dtype=np.float64), kinetic=kinetic,
                  potential=potential, rotational=rotational,
                  total=parts.total.sum(axis=1))


def _options() -> dict:
    from refsim.scenes import schema

    return {"solver": schema.SOLVER_NAMES, "step": (), "level": schema.COLLISION_LEVELS,
            "aabb": schema.AABB_MODES, "rotation": schema.ROTATION_MODELS,
            "body_response": schema.RESPONSE_MODELS}


#: The options the viewer's controls change, and the choices of each (step: a number).
OPTIONS = _options()


def scene_with(scene, **options):
    """``scene`` with the viewer's options replaced: ``solver``, ``step``
    (``[integration]``), ``level``, ``aabb`` (``[collision]``), ``rotation``,
    ``body_response`` (``[dynamics]``). A particle scene's solver and step
    follow (they come from ``[integration]``)."""
    from refsim.errors import SceneError, StateError, check_option
    from refsim.scenes import schema
    from refsim.solvers.integrate import whole_steps

    unknown = set(options) - set(OPTIONS)
    if unknown:
        raise StateError(f"unknown option {sorted(unknown)[0]!r} (expected one of "
                         f"{', '.join(OPTIONS)})")
    for name, choices in OPTIONS.items():
        if name in options and choices:
            check_option(name, options[name], choices)
    if "step" in options:
        step = options["step"]
        problem = (f"must be a number, got {step!r}" if isinstance(step, bool)
                   or not isinstance(step, int | float) else schema.positive(step))
        if problem:
            raise SceneError(f"{problem}", scene.path, "integration.step")
        options["step"] = float(step)
    integration = replace(scene.integration, **{k: options[k] for k in ("solver", "step")
                                                if k in options})
    try:
        whole_steps(integration.duration, integration.step)
    except StateError as exc:
        raise SceneError(str(exc), scene.path, "integration.step") from None
    collision = replace(scene.collision, **{k: options[k] for k in ("level", "aabb")
                                            if k in options})
    dynamics = replace(scene.dynamics, **{k: options[k] for k in ("rotation", "body_response")
                                          if k in options})
    particles = scene.particles
    if particles is not None:
        particles = replace(particles, solver=integration.solver, step=integration.step)
    return replace(scene, integration=integration, collision=collision, dynamics=dynamics,
                   particles=particles)
