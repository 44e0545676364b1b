"""Tables the site generates from the code at build time, so that they
cannot drift from it.

``.. refsim-public-api::`` -- an autodoc entry for every name of
``refsim.__all__``, grouped by the module that defines it, in the order of
the package's layers (:data:`AREAS`).

``.. refsim-classes::`` -- the conformance kit's classes of a failing case,
most serious first, from :data:`refsim.conformance.results.CLASS_DEFINITIONS`.
"""

from __future__ import annotations

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective


def list_table(header: tuple[str, ...], rows: list[tuple[str, ...]]) -> list[str]:
    """The lines of a reST list-table with one header row."""
    lines = [".. list-table::", "   :header-rows: 1", ""]
    for row in (header, *rows):
        lines.append(f"   * - {row[0]}")
        lines.extend(f"     - {cell}" for cell in row[1:])
    return lines


#: The areas of the public API, in the order of the package's layers: the
#: module prefix and the heading of its group. A name whose module matches
#: none fails the build (a new area must be placed here).
AREAS = (
    ("refsim.models", "Models and meshes (S1)"),
    ("refsim.bounds", "Bounding boxes and the world cube (S2, S3)"),
    ("refsim.collision", "Collision (S4)"),
    ("refsim.solvers", "ODE solvers (S6)"),
    ("refsim.scenes", "Scenes (S11)"),
    ("refsim.dynamics", "Simulation and trajectories (S5, S7-S9)"),
    ("refsim.particles", "Particles (S10)"),
    ("refsim.viewer", "Viewer (S12)"),
    ("refsim.errors", "Errors"),
)


def defining_module(name: str) -> str:
    """The module ``refsim`` imports ``name`` from (``refsim._EXPORTS``)."""
    import refsim

    return refsim._EXPORTS[name]


class PublicApi(SphinxDirective):
    has_content = False

    def run(self) -> list[nodes.Node]:
        import inspect

        import refsim

        groups: dict[str, list[str]] = {prefix: [] for prefix, _ in AREAS}
        for name in refsim.__all__:
            module = defining_module(name)
            prefix = next((p for p, _ in AREAS if module.startswith(p)), None)
            if prefix is None:
                raise self.error(f"refsim.{name} (from {module}) is in no area of AREAS")
            groups[prefix].append(name)
        lines: list[str] = []
        for prefix, heading in AREAS:
            if not groups[prefix]:
                continue
            lines += [f".. rubric:: {heading}", ""]
            for name in groups[prefix]:
                value = getattr(refsim, name)
                if inspect.isclass(value):
                    kind = "autoexception" if issubclass(value, BaseException) else "autoclass"
                    lines += [f".. {kind}:: refsim.{name}", ""]
                elif callable(value):
                    lines += [f".. autofunction:: refsim.{name}", ""]
                else:
                    # data: documented where it is defined (its ``#:`` comment)
                    lines += [f".. autodata:: {defining_module(name)}.{name}",
                              "   :no-value:", ""]
        container = nodes.container()
        self.state.nested_parse(StringList(lines, "refsim.__all__"), self.content_offset,
                                container)
        return container.children


class ClassesTable(SphinxDirective):
    has_content = False

    def run(self) -> list[nodes.Node]:
        from refsim.conformance.results import CLASS_DEFINITIONS

        rows = [(f"``{name}``", meaning) for name, meaning in CLASS_DEFINITIONS.items()]
        container = nodes.container()
        self.state.nested_parse(StringList(list_table(("class", "meaning"), rows),
                                           "refsim.conformance.results"),
                                self.content_offset, container)
        return container.children


class _Table(SphinxDirective):
    """A two-column table of names and meanings from the package."""

    has_content = False
    header: tuple = ()

    def rows(self) -> list[tuple[str, str]]:
        raise NotImplementedError

    def run(self) -> list[nodes.Node]:
        container = nodes.container()
        self.state.nested_parse(StringList(list_table(self.header, self.rows()),
                                           "refsim.conformance"),
                                self.content_offset, container)
        return container.children


class StatusesTable(_Table):
    header = ("status", "meaning")

    def rows(self):
        from refsim.conformance.results import STATUS_DEFINITIONS

        return [(f"``{name}``", meaning) for name, meaning in STATUS_DEFINITIONS.items()]


class ChecksTable(_Table):
    header = ("check", "what it asks of the engine")

    def rows(self):
        from refsim.conformance.registry import CHECKS, TRUTH_CHECKS

        return [(f"``{c.key}``", c.doc + (" (The kit's own ground truth: the engine is not "
                                          "called.)" if c.key in TRUTH_CHECKS else ""))
                for c in CHECKS]


def setup(app: Sphinx) -> dict:
    app.add_directive("refsim-public-api", PublicApi)
    app.add_directive("refsim-classes", ClassesTable)
    app.add_directive("refsim-statuses", StatusesTable)
    app.add_directive("refsim-checks", ChecksTable)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
