"""The HTML accuracy report: one self-contained page plus results.json.

Its charts need matplotlib and its page jinja2, the ``report`` extra:
:func:`require_report` says what to install before any work starts.
"""

from __future__ import annotations

import importlib

from refsim.errors import RefsimError

#: What ``pip`` installs for the report (pyproject.toml's ``report`` extra).
INSTALL_HINT = "pip install 'refsim[report]'"

#: The modules of the ``report`` extra: matplotlib draws the charts, jinja2
#: fills the page's template.
REPORT_MODULES = ("matplotlib", "jinja2")


class ReportUnavailable(RefsimError, ImportError):
    """A package of the report extra (matplotlib, jinja2) is not installed."""


def require_report() -> None:
    """Nothing when the report's packages import; else
    :class:`ReportUnavailable` naming the first missing one and what to install."""
    for module in REPORT_MODULES:
        try:
            importlib.import_module(module)
        except ImportError:
            raise ReportUnavailable(f"the report needs {module}, which is not installed: "
                                    f"{INSTALL_HINT}") from None
