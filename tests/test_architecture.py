"""The import rules of docs/design.md's Architecture, checked on every module.

Data flows one way: algorithms -> engines -> studies and conformance ->
claims -> report, viewer, command line; each layer imports only the layers
to its left. This test reads the syntax tree of every module of refsim (and
of the oracle adapters, installed as ``refsim.oracles``), takes every import
in it, at the top or inside a function, and checks it against three tables:

- :data:`LAYERS`: every package and top-level module of refsim lies in one
  layer, and imports nothing of a later one;
- :data:`ALGORITHMS`: inside the algorithm layer, an order from the shared
  modules up to the scenes; an algorithm imports nothing above it, so the
  algorithms hold no import cycle;
- :data:`RULES`: what a layer's members may not take from each other, and
  the rules of particular packages.

The package root is a layer of its own at the bottom: a module may take
``refsim.__version__`` from it and nothing else, since its public names load
their modules lazily and an import through them would hide where it goes.
A failure lists every violation with its file and line.

Where today's code breaks a rule and the fix belongs to another piece of
work, :data:`ALLOWANCES` names the import and why; an allowance that no
longer matches an import fails the test too, so that it is removed with the
code it excused.
"""

from __future__ import annotations

import ast
import functools
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Source folders and the package they are installed as.
SOURCES = ((ROOT / "refsim", "refsim"), (ROOT / "oracles", "refsim.oracles"))

#: The algorithm layer (docs/design.md, Architecture: "Algorithms"), lowest
#: first: the shared modules (the error tree, the input limits, plain value
#: types, rounding bounds, signal holding, the readable/compiled switch, the
#: bundled data, files in and out), then one package per area. Each imports
#: only those before it.
ALGORITHMS = tuple(f"refsim.{name}" for name in (
    "errors", "lazy", "limits", "types", "rounding", "signals", "kernels", "bundled", "storage",
    "models", "bounds", "collision", "solvers", "dynamics", "particles", "scenes"))

#: Every package and top-level module of refsim by layer, lowest first. A
#: module imports nothing of a later layer.
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("package root", ("refsim",)),
    ("algorithms", ALGORITHMS),
    ("engines", ("refsim.engines", "refsim.oracles")),
    ("sweeps", ("refsim.sweep",)),
    ("studies and conformance", ("refsim.studies", "refsim.conformance")),
    ("claims", ("refsim.claims",)),
    ("advisor", ("refsim.advisor",)),
    ("views", ("refsim.viewer", "refsim.report", "refsim.warm", "refsim.cli")),
)

#: (rule, modules it applies to, imports they may not make, imports exempt
#: from that). A module or import "is" a prefix when it equals it or lies
#: inside it.
RULES: tuple[tuple[str, tuple[str, ...], tuple[str, ...], tuple[str, ...]], ...] = (
    ("the engine protocols and refsim's own engines import no oracle (a composition root "
     "chooses engines)", ("refsim.engines",), ("refsim.oracles",), ()),
    ("a study imports no oracle and no conformance module (it receives engines)",
     ("refsim.studies",), ("refsim.oracles", "refsim.conformance"), ()),
    ("the advisor imports no oracle, claim or view, its own view included (it runs studies)",
     ("refsim.advisor",),
     ("refsim.oracles", "refsim.claims", "refsim.report", "refsim.cli", "refsim.viewer",
      "refsim.advisor.view"), ()),
    ("a claim imports nothing of refsim but study records and plain value types",
     ("refsim.claims",), ("refsim",), ("refsim.claims", "refsim.studies", "refsim.types")),
    ("nothing outside the adapters imports one: a shipped engine is built by name from the "
     "one engine table (refsim.engines.registry.build), which names each adapter's factory",
     tuple(m for _, members in LAYERS for m in members if m not in ("refsim", "refsim.oracles")),
     ("refsim.oracles",), ("refsim.oracles.OracleUnavailable", "refsim.oracles.install_hint")),
    ("the viewer imports no report (the report shows the viewer's demos)",
     ("refsim.viewer",), ("refsim.report",), ()),
    ("nothing outside the command line imports it (the outermost composition root; the "
     "package root is below every layer, so the layers already forbid it there)",
     tuple(m for _, members in LAYERS for m in members if m not in ("refsim", "refsim.cli")),
     ("refsim.cli",), ()),
)

#: What may be taken from the package root.
ROOT_NAMES = ("refsim.__version__",)

#: Imports that break a rule today, each with the reason and whose work
#: removes it: (importing module, imported module) -> why.
ALLOWANCES: dict[tuple[str, str], str] = {}


def _is(name: str, prefix: str) -> bool:
    return name == prefix or name.startswith(prefix + ".")


@functools.cache
def modules() -> dict[str, Path]:
    """Every module of the installed refsim namespace, by dotted name."""
    found = {}
    for folder, package in SOURCES:
        for path in sorted(folder.rglob("*.py")):
            parts = list(path.relative_to(folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            found[".".join([package, *parts])] = path
    return found


def unit(name: str) -> str | None:
    """The package or top-level module of refsim that ``name`` (a module, or
    a name inside one) lies in: ``refsim`` for the package root and the names
    it defines; None outside refsim."""
    parts = name.split(".")
    if parts[0] != "refsim":
        return None
    top = ".".join(parts[:2])
    return top if top in modules() else "refsim"


def layer(name: str) -> int | None:
    """The index in :data:`LAYERS` of the layer ``name`` lies in, or None."""
    return next((i for i, (_, members) in enumerate(LAYERS) if unit(name) in members), None)


def imports(name: str, path: Path) -> list[tuple[str, int]]:
    """``(imported module, line)`` for every import in the file, nested ones
    included; ``from a import b`` counts as ``a.b`` (b may be a module)."""
    is_package = path.name == "__init__.py"
    out = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            out += [(alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = name.split(".")
                anchor = anchor if is_package else anchor[:-1]
                anchor = anchor[:len(anchor) - (node.level - 1)]
                base = ".".join(anchor + ([base] if base else []))
            out += [(f"{base}.{alias.name}" if alias.name != "*" else base, node.lineno)
                    for alias in node.names]
    return out


def broken_rules(module: str, target: str) -> list[str]:
    """The rules an import of ``target`` by ``module`` breaks, as text."""
    broken = [rule for rule, who, forbidden, exempt in RULES
              if any(_is(module, w) for w in who) and any(_is(target, f) for f in forbidden)
              and not any(_is(target, e) for e in exempt)]
    mine, theirs = unit(module), unit(target)
    if theirs is None or mine == theirs:
        return broken
    if theirs == "refsim" and target not in ROOT_NAMES:
        broken.append("a module takes nothing from the package root but its version (the "
                      "root's public names load lazily and hide where an import goes)")
    own, other = layer(module), layer(target)
    if own is None or other is None:
        return broken
    if other > own:
        broken.append(f"the {LAYERS[own][0]} import nothing of the {LAYERS[other][0]}")
    elif mine in ALGORITHMS and theirs in ALGORITHMS and (
            ALGORITHMS.index(theirs) > ALGORITHMS.index(mine)):
        broken.append(f"{mine} lies below {theirs} in the order of the algorithms")
    return broken


def violations() -> tuple[list[str], set[tuple[str, str]]]:
    """Every import that breaks a rule and is not allowed (as text), and the
    allowances that matched."""
    found, used = [], set()
    for name, path in modules().items():
        for target, line in imports(name, path):
            rules = broken_rules(name, target)
            if not rules:
                continue
            allowed = [key for key in ALLOWANCES if key[0] == name and _is(target, key[1])]
            if allowed:
                used.update(allowed)
                continue
            found += [f"{path.relative_to(ROOT)}:{line}: {name} imports {target}: {rule}"
                      for rule in rules]
    return found, used


def test_every_import_follows_the_architecture():
    found, _ = violations()
    assert not found, "\n".join(found)


def test_every_allowance_is_still_needed():
    _, used = violations()
    assert set(ALLOWANCES) - used == set()


def test_every_package_and_module_lies_in_one_layer():
    units = {unit(name) for name in modules()}
    listed = [member for _, members in LAYERS for member in members]
    assert sorted(units - set(listed)) == [], "not in any layer of LAYERS"
    assert sorted(set(listed) - units) == [], "listed in LAYERS but not in refsim"
    assert len(listed) == len(set(listed)), "listed in two layers"


#: Private names (a leading underscore) that a module takes from another
#: package of refsim, each with the reason: (importing module, imported
#: name) -> why. Everything else that crosses a package is public.
PRIVATE_ALLOWANCES: dict[tuple[str, str], str] = {
    ("refsim.dynamics._numba_kernels", "refsim.bounds._numba_kernels.incremental_update_numba"):
        "a compiled kernel calls compiled kernels only, and numba compiles the callee into "
        "the caller: the simulation loop's box update is the incremental box kernel "
        "itself, which lives with its readable twin in refsim.bounds",
}


def private(name: str) -> bool:
    """Whether a dotted name has a private part (``_x``; ``__x__`` is not)."""
    return any(part.startswith("_") and not part.endswith("__") for part in name.split("."))


def private_imports() -> tuple[list[str], set[tuple[str, str]]]:
    """Every import of a private name or module of another package of refsim
    (as text), not allowed, and the allowances that matched."""
    found, used = [], set()
    for name, path in modules().items():
        for target, line in imports(name, path):
            theirs = unit(target)
            if theirs is None or theirs == unit(name) or not private(target):
                continue
            if (name, target) in PRIVATE_ALLOWANCES:
                used.add((name, target))
                continue
            found.append(f"{path.relative_to(ROOT)}:{line}: {name} imports {target}, a private "
                         f"name of {theirs}")
    return found, used


def test_no_module_imports_a_private_name_of_another_package():
    found, _ = private_imports()
    assert not found, "\n".join(found)


def test_every_private_allowance_is_still_needed():
    _, used = private_imports()
    assert set(PRIVATE_ALLOWANCES) - used == set()


@pytest.mark.parametrize(("name", "is_private"), [
    ("refsim.collision.predicates.orient3d", False),
    ("refsim.collision.predicates._orient3d_terms", True),
    ("refsim.collision._numba_kernels.traverse", True),
    ("refsim.__version__", False),
])
def test_a_private_name_has_a_leading_underscore(name, is_private):
    assert private(name) is is_private


def test_the_walk_sees_nested_and_relative_imports(tmp_path):
    source = tmp_path / "demo.py"
    source.write_text("import os\n\ndef f():\n    from refsim.oracles import fcl_adapter\n"
                      "    from .sibling import thing\n")
    assert imports("refsim.studies.demo", source) == [
        ("os", 1), ("refsim.oracles.fcl_adapter", 4), ("refsim.studies.sibling.thing", 5)]


def test_a_name_lies_in_its_package_or_the_root():
    assert unit("refsim.collision.predicates.orient2d") == "refsim.collision"
    assert unit("refsim.errors.SceneError") == "refsim.errors"
    assert unit("refsim.oracles.fcl_adapter") == "refsim.oracles"
    assert unit("refsim.__version__") == unit("refsim") == "refsim"
    assert unit("numpy.linalg") is None


@pytest.mark.parametrize(("module", "target", "broken"), [
    ("refsim.collision.bodies", "refsim.studies.levels", True),
    ("refsim.collision.bodies", "refsim.types", False),
    ("refsim.studies.levels", "refsim.report.plan", True),
    ("refsim.studies.levels", "refsim.advisor.advice", True),
    ("refsim.advisor.search", "refsim.advisor.view", True),
    ("refsim.advisor.runs", "refsim.dynamics.simulation", False),
    ("refsim.cli", "refsim.advisor.view", False),
    ("refsim.claims.bounds", "refsim.studies.bounds", False),
    ("refsim.claims.bounds", "refsim.bounds.aabb_linear", True),
    ("refsim.report.sections.models", "refsim.oracles.trimesh_adapter", True),
    ("refsim.report.plan", "refsim.oracles.trimesh_adapter", True),
    ("refsim.report.entries.dynamics", "refsim.oracles.pybullet_adapter", True),
    ("refsim.viewer.demos", "refsim.oracles.pybullet_adapter", True),
    ("refsim.report.run", "refsim.oracles.OracleUnavailable", False),
    ("refsim.cli", "refsim.oracles.install_hint", False),
    ("refsim.oracles.trimesh_engine", "refsim.oracles.trimesh_adapter", False),
    # the layers
    ("refsim", "refsim.errors", True),
    ("refsim.cli", "refsim.__version__", False),
    ("refsim.sweep.examples", "refsim", True),
    ("refsim.sweep.examples", "refsim.load_scene", True),
    ("refsim.sweep.examples", "refsim.scenes.loader.load_scene", False),
    ("refsim.sweep.run", "refsim.studies.sweep", True),
    ("refsim.studies.sweep", "refsim.sweep.run", False),
    ("refsim.oracles.mujoco_adapter", "refsim.engines.protocols", False),
    ("refsim.engines.refsim_engines", "refsim.oracles.fcl_adapter", True),
    ("refsim.engines.refsim_engines", "refsim.sweep.run", True),
    ("refsim.conformance.cases_rigid", "refsim.studies.bounce", False),
    ("refsim.conformance.cases_rigid", "refsim.studies.bounce_scenes", False),
    ("refsim.studies.bounce_scenes", "refsim.conformance.cases_rigid", True),
    ("refsim.studies.bounce", "refsim.conformance.cases_rigid", True),
    ("refsim.conformance.matrix", "refsim.claims.bounds", True),
    ("refsim.report.tasks", "refsim.viewer.demos", False),
    ("refsim.viewer.demos", "refsim.report.plan", True),
    ("refsim.report.build", "refsim.cli", True),
    ("refsim.oracles.fcl_adapter", "refsim.cli", True),
    ("refsim.warm", "refsim.cli.common", True),
    ("refsim", "refsim.cli", True),
    ("refsim.cli.app", "refsim.cli.run", False),
    # the order of the algorithms
    ("refsim.errors", "refsim.limits", True),
    ("refsim.storage.npz", "refsim.errors", False),
    ("refsim.storage.npz", "refsim.models.mesh", True),
    ("refsim.models.ear_index", "refsim.rounding.O2D_ERRBOUND_A", False),
    ("refsim.models.ear_index", "refsim.collision.predicates", True),
    ("refsim.collision.bodies", "refsim.models.mesh", False),
    ("refsim.bounds.aabb_linear", "refsim.collision.bodies", True),
    ("refsim.dynamics.simulation", "refsim.scenes.schema.Scene", True),
    ("refsim.scenes.schema", "refsim.dynamics.forces.DRAG_MODELS", False),
    ("refsim.particles.config", "refsim.scenes.schema", True),
    ("refsim.scenes.schema", "refsim.particles.config", False),
])
def test_the_rules_table(module, target, broken):
    assert bool(broken_rules(module, target)) is broken
