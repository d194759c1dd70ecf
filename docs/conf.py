"""Sphinx configuration: MyST pages, numpydoc docstrings, an API reference of one page per public
name (autosummary, written from each package's ``__all__``: docs/_ext/api_pages.py), a gallery
of examples run at build (sphinx-gallery, docs/examples -> docs/gallery), maths rendered by a
MathJax copied into the site (no network), and intersphinx only where its inventories answer.

Build with warnings as errors, offline: ``sphinx-build -W docs docs/_build/html``; the examples
of the pages and of every docstring are run by ``sphinx-build -W -b doctest docs
docs/_build/doctest`` (tests/test_docs.py does both).
"""
import os
import re
import sys
import urllib.request

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
if ROOT not in sys.path:  # the checkout's packages when the docs are built from a source tree
    sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(os.path.dirname(__file__), "_ext"))
os.environ.setdefault("MPLBACKEND", "Agg")  # the gallery and the examples draw without a display


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
    "sphinx.ext.autosummary",
    "sphinx.ext.doctest",
    "sphinx.ext.mathjax",
    "sphinx-mathjax-offline",  # MathJax 3 copied into _static: the theory renders with no network
    "sphinx_gallery.gen_gallery",
    "api_pages",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "examples", "_templates", "_ext"]
templates_path = ["_templates"]
myst_enable_extensions = ["dollarmath", "amsmath"]
myst_heading_anchors = 3

# numpydoc: the per-name pages list their members themselves; no cross-reference guessing
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "undoc-members": False}
autosummary_generate = True
autodoc_preserve_defaults = True  # settings=DEFAULT_SETTINGS, not its long repr
autosummary_imported_members = False

# the examples: the doctest directives of the pages and the Examples sections of the docstrings
doctest_test_doctest_blocks = "default"
doctest_global_setup = "import numpy as np"

# the gallery: every script of docs/examples runs at build, its figures embedded.  sphinx-gallery
# keeps the pages it wrote for an example since renamed or removed, which would then be pages in no
# toctree: those (docs/gallery is written by this build alone) are removed first
_GALLERY = os.path.join(os.path.dirname(os.path.abspath(__file__)), "gallery")
for _name in os.listdir(_GALLERY) if os.path.isdir(_GALLERY) else ():
    _example = os.path.join(os.path.dirname(_GALLERY), "examples", _name.split(".")[0] + ".py")
    if _name.startswith("plot_") and not os.path.exists(_example):
        os.remove(os.path.join(_GALLERY, _name))
sphinx_gallery_conf = {
    "examples_dirs": "examples",
    "gallery_dirs": "gallery",
    "filename_pattern": r"/plot_",
    "within_subsection_order": "FileNameSortKey",
    "download_all_examples": False,
    "write_computation_times": False,
    "remove_config_comments": True,
    "matplotlib_animations": False,
    "image_scrapers": ("matplotlib",),
    "show_memory": False,
    # each API page shows the gallery examples that use its name (docs/_templates/autosummary)
    "doc_module": ("pulses", "rocking", "pipeline"),
    "backreferences_dir": "api/backrefs",
}

# intersphinx to the libraries the package builds on, only where the inventory answers: offline
# (or behind a proxy that refuses) the build stays warning-free and cross-links are plain text
INTERSPHINX = {
    "python": "https://docs.python.org/3/",
    "numpy": "https://numpy.org/doc/stable/",
    "scipy": "https://docs.scipy.org/doc/scipy/",
    "pandas": "https://pandas.pydata.org/docs/",
    "matplotlib": "https://matplotlib.org/stable/",
    "obspy": "https://docs.obspy.org/",
}


def _answers(url: str) -> bool:
    if os.environ.get("DOCS_OFFLINE"):
        return False
    try:
        with urllib.request.urlopen(url + "objects.inv", timeout=3) as resp:
            return resp.status == 200
    except Exception:  # no network, DNS failure, proxy refusal, timeout: no link
        return False


intersphinx_mapping = {k: (url, None) for k, url in INTERSPHINX.items() if _answers(url)}
if intersphinx_mapping:
    extensions.append("sphinx.ext.intersphinx")

html_theme = "pydata_sphinx_theme"
html_title = f"rocking-columns {release}"
html_static_path = ["_static"]
html_css_files = ["wide.css"]
html_theme_options = {
    "show_toc_level": 2,
    "navigation_with_keys": False,
    "show_prev_next": True,
    "secondary_sidebar_items": ["page-toc"],
}
html_sidebars = {"index": []}
# a stated mode: with none stored yet the theme's script logs an error ("invalid theme mode")
html_context = {"default_mode": "light"}


# The docstrings write absolute values as |x| (plain text, as printed by help()) and may break an
# inline literal over two lines; in reStructuredText the first is a substitution and the second an
# error.  Both are read here as the docstrings mean them.
_ABS = re.compile(r"(?<![\\`|])\|([^|`\s][^|`]*?)\|(?![|_`])")


# "Eq. 31" and "Fig. 8" are not ends of sentences: a word joiner after the period keeps the
# summaries of the API tables (their first sentence) whole, and the text reads the same
_NUMBERED = re.compile(r"\b(Eqs?|Figs?)\. (?=\d)")
_KEEP = "\\1.\u2060\u00a0"


def _plain_docstring(app, what, name, obj, options, lines):
    joined, in_example = [], False
    for line in lines:
        # an example (``>>>`` and the output under it, to the next blank line) is code: as printed
        in_example = bool(line.strip()) and (in_example or line.lstrip().startswith(">>>"))
        if in_example:
            joined.append((line, True))
        elif joined and not joined[-1][1] and joined[-1][0].count("``") % 2 == 1:
            joined[-1] = (joined[-1][0].rstrip() + " " + line.strip(), False)
        else:
            joined.append((line, False))
    # only outside inline literals: split at ``, the odd parts are literals
    lines[:] = [line if code else "``".join(part if k % 2 else _NUMBERED.sub(_KEEP, _ABS.sub(r"\\|\1\\|", part))
                                            for k, part in enumerate(line.split("``")))
                for line, code in joined]


def _list_new_pages(app, docname, source):
    """A page added to docs/ and not yet placed in a section of the index is listed under
    "More" (so that it is never left out of the site, nor listed twice)."""
    if docname != root_doc:
        return
    here = os.path.dirname(__file__)
    pages = sorted(f[:-3] for f in os.listdir(here) if f.endswith(".md") and f[:-3] != root_doc)
    unlisted = [p for p in pages if not re.search(rf"^{re.escape(p)}$", source[0], re.M)]
    if unlisted:
        source[0] += "\n```{toctree}\n:caption: More\n:maxdepth: 1\n\n" + "\n".join(unlisted) + "\n```\n"


def setup(app):
    app.connect("autodoc-process-docstring", _plain_docstring)
    app.connect("source-read", _list_new_pages)
    # a page added or removed changes the index's "More" list: read the index again
    app.connect("env-get-outdated", lambda app, env, added, changed, removed:
                [root_doc] if added or removed else [])
