"""Sphinx configuration: MyST markdown pages, numpydoc docstrings, autodoc API reference.

Build with warnings as errors: ``sphinx-build -W docs docs/_build/html``; the examples in the
pages are run by ``sphinx-build -W -b doctest docs docs/_build/doctest`` (tests/test_docs.py does
both).
"""
import os
import re
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
if ROOT not in sys.path:  # the checkout's packages when the docs are built from a source tree
    sys.path.insert(0, ROOT)


def _version():
    with open(os.path.join(ROOT, "pyproject.toml"), encoding="utf-8") as fh:
        m = re.search(r'^version\s*=\s*"([^"]+)"', fh.read(), re.M)
    return m.group(1) if m else "unknown"


project = "rocking-columns"
author = "the rocking-columns authors"
copyright = "the rocking-columns authors, BSD-3-Clause"
release = version = _version()

extensions = [
    "myst_parser",
    "numpydoc",
    "sphinx.ext.autodoc",
    "sphinx.ext.doctest",
    "sphinx.ext.mathjax",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3

# numpydoc: no autosummary tables of members (autodoc lists them), no cross-reference guessing
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "undoc-members": False}

# the examples: only the doctest directives of the pages are run (docstrings hold no doctests)
doctest_test_doctest_blocks = ""
doctest_global_setup = "import numpy as np"

html_theme = "alabaster"
html_static_path = []


# The docstrings write absolute values as |x| (plain text, as printed by help()) and may break an
# inline literal over two lines; in reStructuredText the first is a substitution and the second an
# error.  Both are read here as the docstrings mean them.
_ABS = re.compile(r"(?<![\\`|])\|([^|`\s][^|`]*?)\|(?![|_`])")


def _plain_docstring(app, what, name, obj, options, lines):
    joined = []
    for line in lines:
        if joined and joined[-1].count("``") % 2 == 1:
            joined[-1] = joined[-1].rstrip() + " " + line.strip()
        else:
            joined.append(line)
    # only outside inline literals: split at ``, the odd parts are literals
    lines[:] = ["``".join(part if k % 2 else _ABS.sub(r"\\|\1\\|", part) for k, part in enumerate(line.split("``")))
                for line in joined]


def setup(app):
    app.connect("autodoc-process-docstring", _plain_docstring)
