"""The import rules of docs/design.md's Architecture, checked on every module.

Data flows one way: algorithms -> engines -> studies and conformance ->
claims -> report, viewer, command line; each layer imports only the layers
to its left. This test reads the syntax tree of every module of refsim (and
of the oracle adapters, installed as ``refsim.oracles``), takes every import
in it, at the top or inside a function, and checks it against :data:`RULES`.
A failure lists every violation with its file and line.

Where today's code breaks a rule and the fix belongs to another piece of
work, :data:`ALLOWANCES` names the import and why; an allowance that no
longer matches an import fails the test too, so that it is removed with the
code it excused.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Source folders and the package they are installed as.
SOURCES = ((ROOT / "refsim", "refsim"), (ROOT / "oracles", "refsim.oracles"))

#: The algorithm modules (docs/design.md, Architecture: "Algorithms"): one package per area, and
#: the shared modules of plain types, errors, limits and input/output.
ALGORITHMS = tuple(f"refsim.{name}" for name in (
    "models", "bounds", "collision", "solvers", "dynamics", "particles", "scenes",
    "types", "errors", "limits", "files", "io", "npz", "frames", "kernels", "bundled", "signals"))

#: Everything to the right of the algorithms.
ABOVE_ALGORITHMS = ("refsim.engines", "refsim.oracles", "refsim.studies", "refsim.claims",
                    "refsim.report", "refsim.viewer", "refsim.sweep", "refsim.conformance",
                    "refsim.advisor", "refsim.cli")

#: (rule, modules it applies to, imports they may not make, imports exempt
#: from that). A module or import "is" a prefix when it equals it or lies
#: inside it.
RULES: tuple[tuple[str, tuple[str, ...], tuple[str, ...], tuple[str, ...]], ...] = (
    ("an algorithm imports no engine, oracle, study, claim or view",
     ALGORITHMS, ABOVE_ALGORITHMS, ()),
    ("a study imports no oracle, claim or view (it receives engines), nor the advisor",
     ("refsim.studies",),
     ("refsim.oracles", "refsim.claims", "refsim.report", "refsim.cli", "refsim.viewer",
      "refsim.advisor"), ()),
    ("the advisor imports no oracle, claim or view, its own view included (it runs studies)",
     ("refsim.advisor",),
     ("refsim.oracles", "refsim.claims", "refsim.report", "refsim.cli", "refsim.viewer",
      "refsim.advisor.view"), ()),
    ("a claim imports nothing of refsim but study records and plain value types",
     ("refsim.claims",), ("refsim",), ("refsim.claims", "refsim.studies", "refsim.types")),
    ("a report section or entry imports no oracle (the plan chooses engines)",
     ("refsim.report.sections", "refsim.report.entries"), ("refsim.oracles",), ()),
)

#: Imports that break a rule today, each with the reason and whose work
#: removes it: (importing module, imported module) -> why.
ALLOWANCES: dict[tuple[str, str], str] = {}


def _is(name: str, prefix: str) -> bool:
    return name == prefix or name.startswith(prefix + ".")


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


def violations() -> tuple[list[str], set[tuple[str, str]]]:
    """Every import that breaks a rule and is not allowed (as text), and the
    allowances that matched."""
    found, used = [], set()
    for name, path in modules().items():
        for target, line in imports(name, path):
            for rule, who, forbidden, exempt in RULES:
                if not any(_is(name, w) for w in who):
                    continue
                if any(_is(target, f) for f in forbidden) and not any(
                        _is(target, e) for e in exempt):
                    allowed = [key for key in ALLOWANCES
                               if key[0] == name and _is(target, key[1])]
                    if allowed:
                        used.update(allowed)
                    else:
                        found.append(f"{path.relative_to(ROOT)}:{line}: {name} imports "
                                     f"{target}: {rule}")
    return found, used


def test_every_import_follows_the_architecture():
    found, _ = violations()
    assert not found, "\n".join(found)


def test_every_allowance_is_still_needed():
    _, used = violations()
    assert set(ALLOWANCES) - used == set()


def test_the_walk_sees_nested_and_relative_imports(tmp_path):
    source = tmp_path / "demo.py"
    source.write_text("import os\n\ndef f():\n    from refsim.oracles import fcl_adapter\n"
                      "    from .sibling import thing\n")
    assert imports("refsim.studies.demo", source) == [
        ("os", 1), ("refsim.oracles.fcl_adapter", 4), ("refsim.studies.sibling.thing", 5)]


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
    ("refsim.report.plan", "refsim.oracles.trimesh_adapter", False),
    ("refsim.report.entries.dynamics", "refsim.oracles.pybullet_adapter", True),
    ("refsim.report.run", "refsim.oracles", False),
])
def test_the_rules_table(module, target, broken):
    hits = [rule for rule, who, forbidden, exempt in RULES
            if any(_is(module, w) for w in who) and any(_is(target, f) for f in forbidden)
            and not any(_is(target, e) for e in exempt)]
    assert bool(hits) is broken
