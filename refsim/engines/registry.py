"""Every engine refsim ships, in one table: the name the kit, the report,
the replays and the viewer use, the title a page shows, the
``module:factory`` that builds it, the extra that installs its package, and
whether the conformance kit's matrix has a column for it. Everything that
chooses or lists an engine reads this table (the kit's ``--all``, the
report's matrix, titles and oracles, the replay demos, the install hints)
and builds it with :func:`build`, so that adding an engine is one row here
plus its adapter and, for a kit engine, its declared divergences
(``refsim/conformance/expected/<name>.txt``).

Two kinds of rows:

- *kit engines* (``kit=True``, :data:`SHIPPED`): the matrix's columns,
  each answering the kit's capabilities (:mod:`refsim.engines`);
- *engines only the report asks* (``kit=False``): trimesh's mesh facts and
  its CollisionManager on their own, SciPy's tight ODE reference (a
  :class:`refsim.engines.ReferenceSolver`, not a kit capability), and
  refsim running a scene as posed, with the scene's wall speed or the
  seed's (:class:`refsim.engines.refsim_engines.PosedRefsim`: the bounce
  studies' refsim).

Which capabilities an engine has is not written here: it is read from the
engine itself (:func:`refsim.engines.capabilities`).

Cost: O(1); nothing is imported until an engine is built.
"""

from __future__ import annotations

from dataclasses import dataclass

from refsim.errors import check_option


@dataclass(frozen=True)
class EngineEntry:
    """One shipped engine: ``name`` (the kit's, e.g. "mujoco"), ``title``
    (a page's, "MuJoCo"), ``spec`` (``module:factory``) and ``extra`` (the
    ``pip install 'refsim[EXTRA]'`` that brings its package; None for
    refsim's own) and ``kit`` (whether the conformance matrix shows it)."""

    name: str
    title: str
    spec: str
    extra: str | None
    kit: bool = True


#: Every shipped engine: the kit's in the order the matrix shows them, then
#: the report's own oracles.
ENGINES: tuple[EngineEntry, ...] = (
    EngineEntry("refsim-seed", "refsim seed", "refsim.engines.refsim_engines:seed", None),
    EngineEntry("refsim-corrected", "refsim corrected",
                "refsim.engines.refsim_engines:corrected", None),
    EngineEntry("fcl", "FCL", "refsim.oracles.fcl_adapter:engine", "oracles"),
    EngineEntry("coal", "coal", "refsim.oracles.coal_adapter:engine", "coal"),
    EngineEntry("trimesh", "trimesh", "refsim.oracles.trimesh_engine:engine", "oracles"),
    EngineEntry("pybullet", "pybullet", "refsim.oracles.pybullet_adapter:engine", "oracles"),
    EngineEntry("mujoco", "MuJoCo", "refsim.oracles.mujoco_adapter:engine", "oracles"),
    EngineEntry("drake", "Drake", "refsim.oracles.drake_adapter:engine", "drake"),
    EngineEntry("drake-hydroelastic", "Drake (hydroelastic)",
                "refsim.oracles.drake_adapter:engine_hydroelastic", "drake"),
    EngineEntry("trimesh-mesh", "trimesh (mesh facts, boxes)",
                "refsim.oracles.trimesh_adapter:engine", "oracles", kit=False),
    EngineEntry("trimesh-collision", "trimesh (CollisionManager)",
                "refsim.oracles.trimesh_collision:engine", "oracles", kit=False),
    EngineEntry("scipy", "SciPy solve_ivp", "refsim.oracles.scipy_ivp:engine", None, kit=False),
    EngineEntry("refsim", "refsim", "refsim.engines.refsim_engines:as_posed", None, kit=False),
    EngineEntry("refsim-seed-wall-speed", "refsim, the seed's literal wall speed",
                "refsim.engines.refsim_engines:as_posed_seed_wall_speed", None, kit=False),
)

#: The kit's engines (its matrix's columns), in the matrix's order.
SHIPPED: tuple[EngineEntry, ...] = tuple(e for e in ENGINES if e.kit)

#: Each shipped engine's row and title by name.
BY_NAME: dict[str, EngineEntry] = {e.name: e for e in ENGINES}
TITLES: dict[str, str] = {e.name: e.title for e in ENGINES}


def title(name: str) -> str:
    """The page title of engine ``name`` (the name itself for an engine
    refsim does not ship)."""
    return TITLES.get(name, name)


def build(name: str, **settings):
    """A new engine ``name`` of :data:`ENGINES`, ``factory(**settings)``
    (the settings an adapter's factory takes, e.g. pybullet's
    ``use_split_impulse=0``).

    Raises
    ------
    OptionError
        No shipped engine is called ``name`` (a user's own engine is named
        by its spec instead: :func:`refsim.engines.load_engine`).
    refsim.oracles.OracleUnavailable
        The engine's package is not installed (the message names the
        extra that brings it).
    """
    from refsim.engines import resolve_factory

    check_option("engine", name, tuple(BY_NAME))
    return resolve_factory(BY_NAME[name].spec)(**settings)


def install_hint(names) -> str:
    """The ``pip`` command that installs the packages of the named shipped
    engines, ``pip install 'refsim[oracles,drake]'``: ``oracles`` first,
    then the engines' own extras; ``oracles`` for a name not shipped."""
    extras = {e.extra for e in ENGINES if e.name in set(names) and e.extra} or {"oracles"}
    if any(n not in TITLES for n in names):
        extras.add("oracles")
    ordered = sorted(extras, key=lambda extra: (extra != "oracles", extra))
    return f"pip install 'refsim[{','.join(ordered)}]'"
