"""Sphinx configuration for the spinorbit documentation.

Builds offline: no intersphinx, no remote images, no extension that fetches anything. The API pages
(``docs/api/*.rst``) are written by hand with autodoc directives, so a build never writes generated
files into the source tree. Build with ``sphinx-build -W -b html docs docs/_build/html``.
"""

import os
import re
import sys

# Document the checkout this file lives in, not some other installed copy.
sys.path.insert(0, os.path.abspath(".."))

import spinorbit  # noqa: E402

project = "spinorbit"
author = "The spinorbit developers"
copyright = "the spinorbit developers"
release = spinorbit.__version__
version = release

extensions = [
    "myst_parser",  # the narrative pages stay Markdown
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",  # numpydoc-style sections (Parameters, Returns, Raises, Notes, Examples)
    "sphinx.ext.mathjax",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]

# -- Markdown (myst) ------------------------------------------------------------------------------
myst_heading_anchors = 3

# -- API reference --------------------------------------------------------------------------------
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_default_options = {"members": True, "show-inheritance": False}
autosummary_generate = False  # the API pages are checked in; nothing is generated into docs/
napoleon_google_docstring = False
napoleon_numpy_docstring = True
napoleon_use_rtype = False
napoleon_use_ivar = True

# Docstrings here are written to read well in ``help()``: absolute values and conditional bars are plain
# ``|x|`` and ``F(φ | m)``. reST would read ``|x|`` as a substitution reference, so bars outside
# literals, roles and table/line-block lines are escaped before the docstring is parsed. Nothing else
# in a docstring is touched.
_LITERAL_OR_ROLE = re.compile(r"(:[\w:+-]+:`[^`]*`|``.+?``|`[^`]+`_?)")


_TABLE_OR_LINE_BLOCK = re.compile(r"^\s*(\| |\|$|\+[-=])")


def _escape_bars(line):
    if _TABLE_OR_LINE_BLOCK.match(line):
        return line
    parts = _LITERAL_OR_ROLE.split(line)
    return "".join(p if i % 2 else p.replace("|", r"\|") for i, p in enumerate(parts))


def _plain_bars(app, what, name, obj, options, lines):
    lines[:] = [_escape_bars(line) for line in lines]


def setup(app):
    app.connect("autodoc-process-docstring", _plain_bars)


# -- HTML -----------------------------------------------------------------------------------------
html_theme = "alabaster"  # ships with Sphinx: no extra dependency, no web fonts fetched
html_title = f"spinorbit {release}"
html_static_path = []
