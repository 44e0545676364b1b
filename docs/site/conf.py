"""Sphinx configuration of refsim's documentation site (``make docs``).

The package's docstrings are numpydoc: autodoc reads them and napoleon turns
their sections into reST. The Markdown pages (README.md, docs/design.md) are
included where they stand, through myst-parser, never copied. Tutorials run
their code under ``sphinx.ext.doctest`` (``make docs`` runs that builder
before the HTML one). Why Sphinx: docs/decisions/docs-site.md.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE / "_ext"))

import refsim  # noqa: E402

project = "refsim"
author = "refsim's authors"
copyright = "refsim's authors"
release = version = refsim.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.doctest",
    "myst_parser",
    "refsim_tables",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build"]

# The docstrings are numpydoc; Google-style sections are not used.
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": True}

# README.md and docs/design.md name files of the repository by relative
# links and code spans; on the site those stay text.
myst_heading_anchors = 0

# The tutorials run where nothing of the checkout is the current directory:
# bundled models and scenes are named by their bare file names.
# Each page's code runs in a temporary directory of its own (a tutorial
# writes files), which is removed afterwards.
doctest_global_setup = """
import os, shutil, tempfile
_site_cwd, _site_tmp = os.getcwd(), tempfile.mkdtemp(prefix="refsim-doctest-")
os.chdir(_site_tmp)
"""
doctest_global_cleanup = """
os.chdir(_site_cwd)
shutil.rmtree(_site_tmp)
"""

html_theme = "alabaster"
html_title = f"refsim {release}"
html_theme_options = {"description": "a validated rigid-body reference", "fixed_sidebar": False}
