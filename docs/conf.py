"""Sphinx configuration for the spinorbit documentation.

Builds offline: no intersphinx, no remote images, no extension that fetches anything. The API pages
(``docs/api/*.rst``) are written by hand with autodoc directives. The one thing generated into the
source tree is sphinx-gallery's ``auto_examples/`` (and its ``sg_execution_times.rst``), which it
cannot write elsewhere; both are git-ignored and rebuilt by every build. The gallery does not run the
examples (they integrate orbits for seconds to minutes): each page shows the script with the output and
plot that ``docs/gallery_outputs.py`` committed under ``docs/gallery/`` (:func:`_gallery_outputs`).
Build with ``sphinx-build -W -b html docs docs/_build/html``.
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
    "sphinx_gallery.gen_gallery",  # the examples gallery over examples/*.py
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "gallery/*.txt"]

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


# -- Examples gallery (sphinx-gallery) ------------------------------------------------------------
# Every examples/*.py whose module docstring starts with a reST title becomes a page; other helpers'
# examples join by that alone. Not executed at build time (plot_gallery False): the committed output
# of docs/gallery_outputs.py is shown instead.
EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples")
_TITLED = re.compile(r'^\s*(?:#[^\n]*\n)*\s*[rRuU]?"""\s*(?P<title>[^\n]+)\n(?P<rule>[=\-~^#*+]+)\s*\n')


def _untitled_examples():
    """Names of examples/*.py whose module docstring does not open with a reST title (title line, rule)."""
    names = []
    for name in sorted(os.listdir(EXAMPLES)):
        if name.endswith(".py"):
            with open(os.path.join(EXAMPLES, name), encoding="utf-8") as file:
                match = _TITLED.match(file.read())
            if match is None or len(match["rule"]) < len(match["title"].strip()):
                names.append(name)
    return names


# An example without a title would stop the whole build; it is left out instead, and
# tests/test_docs.py names it (every example must have its page).
_IGNORED = "|".join(re.escape(name) for name in ["__init__.py", *_untitled_examples()])

sphinx_gallery_conf = {
    "examples_dirs": "../examples",
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"\.py$",
    "ignore_pattern": rf"(^|/)({_IGNORED})$",
    "plot_gallery": False,
    "download_all_examples": False,
    "show_signature": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
}

GALLERY_OUTPUTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gallery")


def _gallery_outputs(app, docname, source):
    """Append an example's committed plot and printed output (docs/gallery/<name>.png, .txt) to its page."""
    if not docname.startswith("auto_examples/") or docname.endswith("index"):
        return
    name = docname.split("/", 1)[1]
    image, text = (os.path.join(GALLERY_OUTPUTS, f"{name}.{ext}") for ext in ("png", "txt"))
    extra = []
    if os.path.isfile(text) or os.path.isfile(image):
        heading = "Output of the run (``docs/gallery_outputs.py``)"
        extra.append(f"\n\n{heading}\n{'-' * len(heading)}\n")
    if os.path.isfile(image):
        extra.append(f"\n.. image:: /gallery/{name}.png\n   :alt: plot of {name}\n")
    if os.path.isfile(text):
        extra.append(f"\n.. literalinclude:: /gallery/{name}.txt\n   :language: text\n")
    # before sphinx-gallery's download links at the end of the page, right after the code
    marker = source[0].find("\n.. _sphx_glr_download_")
    at = marker if marker >= 0 else len(source[0])
    source[0] = source[0][:at] + "".join(extra) + "\n" + source[0][at:]


def setup(app):
    app.connect("autodoc-process-docstring", _plain_bars)
    app.connect("source-read", _gallery_outputs)


# -- HTML -----------------------------------------------------------------------------------------
html_theme = "furo"  # wide, readable, used across the astropy ecosystem; its fonts are local (none fetched)
html_title = f"spinorbit {release}"
html_static_path = []
