"""The fidelity advisor behind ``refsim advise``: model no more than a scene
needs. It holds a scene's physics fixed and finds the cheapest solver, step,
collision level and box update whose run stays within a tolerance TOL
(metres) of a reference run. How it decides, and why, is in
docs/advisor.md.

From Python::

    from refsim.advisor import advise
    advice = advise("bounce.toml", 0.01)
    advice.recommended.fidelity(), advice.proxy_saving

The modules, in the order the work flows:

- ``records``: the settings varied (``Fidelity``) and the plain records
  returned (``Advice``, ``RunRow``, ``ReferenceRow``, ``Pruned``);
- ``runs``: one run of a scene at chosen settings, measured (a sweep task);
- ``metrics``: how far one run is from another (positions, events, energy);
- ``runner``: the ladder of steps tried and the runs made so far, made
  through :mod:`refsim.sweep` (with a store, an advice resumes);
- ``reference``: the reference run and whether a run meets TOL against it;
- ``search``: the rounds that find the cheapest run that meets TOL;
- ``advice``: :func:`advise` and :func:`advice_by_tolerance`, which put the
  rounds together;
- ``check``: an independent check of an answer through :func:`refsim.simulate`;
- ``view``: the advice as text, TOML, JSON and a chart, for ``refsim advise``.

The advisor runs refsim's own simulation and returns records, as a study
does; ``view`` is presentation, and nothing else in the package imports it
(docs/design.md, Architecture). The names below are imported on first use,
so that the view loads without the simulation.
"""

from __future__ import annotations

import importlib

_EXPORTS = {
    "advise": "refsim.advisor.advice",
    "advice_by_tolerance": "refsim.advisor.advice",
    "DEFAULT_TOLERANCE": "refsim.advisor.advice",
    "Advice": "refsim.advisor.records",
    "Fidelity": "refsim.advisor.records",
    "ToleranceSeries": "refsim.advisor.records",
    "check_advice": "refsim.advisor.check",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'refsim.advisor' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
