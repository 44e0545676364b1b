"""The conformance kit: check any engine against ground truth that depends on
no float engine.

Three ways to run it, one engine at a time or side by side:

- ``refsim conform module:factory [-o DIR] [--cases N] [--seed S]
  [--only CAPABILITY] [--expected-failures FILE]`` writes
  ``DIR/conformance.json`` and a self-contained ``DIR/index.html``, prints a
  table and exits 0 (every check passed, declared expected failures aside),
  1 (a check failed) or 2 (a user error). ``refsim conform --all -o DIR``
  runs the engines refsim ships and writes their matrix
  (:mod:`refsim.conformance.matrix`).
- ``pytest --refsim-engine module:factory``: one test per check
  (:mod:`refsim.conformance.pytest_plugin`, loaded through its ``pytest11``
  entry point).
- in Python::

      from refsim.conformance import check_engine
      result = check_engine(my_engine, cases=500, seed=1)
      result.ok, result.failed_checks(), result.check("triangles.agreement").examples

The pieces: case sets with exact answers (``cases_triangles``,
``cases_meshes``, ``cases_boxes``, ``cases_ode``, ``cases_rigid``), the
checks (``checks_geometry``, ``checks_ode``, and the rigid checks in
``checks_bounces``, ``checks_contact``, ``checks_rotation`` and
``checks_strikes``, sharing ``rigid_runs``, re-exported by ``checks_rigid``;
listed in ``registry``), the textbook problems (``textbook_problems``), the
records (``results``), declared divergences (``expected``), the run
(``runner``), the page (``page``), the matrix of engines (``matrix``) and the
engines refsim ships (``shipped``).

Names are imported on first use, so that loading the pytest plugin (on every
pytest run where refsim is installed) costs nothing.
"""

from __future__ import annotations

from refsim.lazy import exports

_EXPORTS = {
    "check_engine": "refsim.conformance.runner",
    "DEFAULT_CASES": "refsim.conformance.runner",
    "CheckResult": "refsim.conformance.results",
    "ConformanceResult": "refsim.conformance.results",
    "CLASSES": "refsim.conformance.results",
    "summary_table": "refsim.conformance.results",
    "CHECKS": "refsim.conformance.registry",
    "build_cases": "refsim.conformance.registry",
    "read_expected": "refsim.conformance.expected",
    "parse_expected": "refsim.conformance.expected",
    "conformance_matrix": "refsim.conformance.matrix",
    "run_matrix": "refsim.conformance.matrix",
    "Matrix": "refsim.conformance.matrix",
    "SHIPPED_ENGINES": "refsim.conformance.shipped",
}

__all__ = sorted(_EXPORTS)

__getattr__, __dir__ = exports(__name__, _EXPORTS)
