"""The engines refsim ships, in one table: the name the kit and the report
use, the title a page shows, the ``module:factory`` that builds it, and the
extra that installs its package. Everything that lists the shipped engines
reads this table (the kit's ``--all``, the report's matrix and titles, the
install hints), so that adding an engine is one row here plus its adapter
and its declared divergences (``refsim/conformance/expected/<name>.txt``).

Which capabilities an engine has is not written here: it is read from the
engine itself (:func:`refsim.engines.capabilities`).

Cost: O(1); nothing is imported until an engine is built.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class EngineEntry:
    """One shipped engine: ``name`` (the kit's, e.g. "mujoco"), ``title``
    (a page's, "MuJoCo"), ``spec`` (``module:factory``) and ``extra`` (the
    ``pip install 'refsim[EXTRA]'`` that brings its package; None for
    refsim's own)."""

    name: str
    title: str
    spec: str
    extra: str | None


#: The shipped engines, in the order the matrix shows them.
SHIPPED: tuple[EngineEntry, ...] = (
    EngineEntry("refsim-seed", "refsim seed", "refsim.engines.refsim_engines:seed", None),
    EngineEntry("refsim-corrected", "refsim corrected",
                "refsim.engines.refsim_engines:corrected", None),
    EngineEntry("fcl", "FCL", "refsim.oracles.fcl_adapter:engine", "oracles"),
    EngineEntry("coal", "coal", "refsim.oracles.coal_adapter:engine", "coal"),
    EngineEntry("trimesh", "trimesh", "refsim.conformance.shipped:trimesh", "oracles"),
    EngineEntry("pybullet", "pybullet", "refsim.oracles.pybullet_adapter:engine", "oracles"),
    EngineEntry("mujoco", "MuJoCo", "refsim.oracles.mujoco_adapter:engine", "oracles"),
    EngineEntry("drake", "Drake", "refsim.oracles.drake_adapter:engine", "drake"),
    EngineEntry("drake-hydroelastic", "Drake (hydroelastic)",
                "refsim.oracles.drake_adapter:engine_hydroelastic", "drake"),
)

#: Each shipped engine's title by name.
TITLES: dict[str, str] = {e.name: e.title for e in SHIPPED}


def title(name: str) -> str:
    """The page title of engine ``name`` (the name itself for an engine
    refsim does not ship)."""
    return TITLES.get(name, name)


def install_hint(names) -> str:
    """The ``pip`` command that installs the packages of the named shipped
    engines, ``pip install 'refsim[oracles,drake]'``: ``oracles`` first,
    then the engines' own extras; ``oracles`` for a name not shipped."""
    extras = {e.extra for e in SHIPPED if e.name in set(names) and e.extra} or {"oracles"}
    if any(n not in TITLES for n in names):
        extras.add("oracles")
    ordered = sorted(extras, key=lambda extra: (extra != "oracles", extra))
    return f"pip install 'refsim[{','.join(ordered)}]'"
