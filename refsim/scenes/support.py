"""Which of a scene's keys an engine must honour, and the one-line refusal
of an engine that cannot (so that no engine silently runs another problem
than the scene poses).

The keys beyond the seed's world (:mod:`refsim.dynamics.loads`) are named
generically, one name for every body: :data:`LOAD_KEYS`. An engine adapter
lists the ones it honours and calls :func:`refuse_unhonoured` before it
builds anything; the scene's shapes (``[[body]] shape``) need no support,
since every engine receives their meshes like a model file's.

Cost: O(B + pairs) per call.
"""

from __future__ import annotations

from collections.abc import Collection

from refsim.errors import UnposableKey

#: The generic names of the keys beyond the seed's world, in the order of the
#: key tables of docs/design.md (Scene files).
LOAD_KEYS = ("world.gravity_direction", "world.walls", "world.mu",
             "world.restitution_threshold", "body.fixed", "body.force", "body.torque",
             "body.restitution", "body.mu", "pair")


def keys_in_use(scene) -> dict[str, str]:
    """The :data:`LOAD_KEYS` that ``scene`` sets to other than their
    default, each with the first place it is set (``"body[2].force"``)."""
    from refsim.dynamics.world import DOWN, WALL_NAMES, WorldConfig

    world = scene.world
    found: dict[str, str] = {}
    if world.gravity_direction != DOWN:
        found["world.gravity_direction"] = "world.gravity_direction"
    if tuple(world.walls) != WALL_NAMES:
        found["world.walls"] = "world.walls"
    if world.mu is not None:
        found["world.mu"] = "world.mu"
    if world.restitution_threshold != WorldConfig.restitution_threshold:
        found["world.restitution_threshold"] = "world.restitution_threshold"
    for i, body in enumerate(scene.bodies):
        for key, set_ in (("fixed", body.fixed), ("force", any(body.force)),
                          ("torque", any(body.torque)),
                          ("restitution", body.restitution is not None),
                          ("mu", body.mu is not None)):
            if set_:
                found.setdefault(f"body.{key}", f"body[{i}].{key}")
    if scene.pairs:
        found["pair"] = "pair[0]"
    return found


def refuse_unhonoured(scene, engine: str, honoured: Collection[str]) -> None:
    """Raise a :class:`refsim.errors.UnposableKey` naming the scene file,
    the first key ``scene`` sets that ``engine`` does not honour (not in
    ``honoured``, a subset of :data:`LOAD_KEYS`), and the engine; nothing
    when it honours every key the scene sets."""
    poses = ", ".join(sorted(honoured)) or "none of the keys beyond the seed world"
    for name, where in keys_in_use(scene).items():
        if name not in honoured:
            raise UnposableKey(f"engine {engine!r} cannot pose this key (it honours {poses})",
                               scene.path, where)
